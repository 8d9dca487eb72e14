// The scene database (SPEC §1, stage 1): what the loaders build and the renderer consumes.
//
// A Scene is plain data: meshes (triangle lists with per-vertex attributes), materials, instances
// placing meshes in the world, cameras, one directional light and a background colour.
// Colours are linear-light RGB(A) in [0, 1].
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/math.h"
#include "synthvis/result.h"

namespace sv::scene {

struct Material {
  std::string name;
  Vec4 baseColor{1, 1, 1, 1};  // linear RGBA, multiplies vertex colours
  bool doubleSided = false;    // if false, back faces are culled when culling is on
  bool unlit = false;          // if true, the light is ignored (colour used as is)
};

// An indexed triangle list. `positions` is required; every other attribute array is either empty
// or has exactly positions.size() entries. `indices` holds 3 entries per triangle, each
// < positions.size(). Loaders guarantee these invariants (`validate` checks them).
struct Mesh {
  std::string name;
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;
  std::vector<Vec4> colors;  // linear RGBA
  std::vector<Vec2> uvs;
  std::vector<uint32_t> indices;
  int material = -1;  // index into Scene::materials, or −1 for the default white material

  size_t triangleCount() const { return indices.size() / 3; }
};

// A mesh placed in the world.
struct Instance {
  int mesh = 0;  // index into Scene::meshes
  Mat4 transform;
};

struct Camera {
  std::string name;
  Vec3 position{0, 0, 5};
  Vec3 target{0, 0, 0};
  Vec3 up{0, 1, 0};
  float yfovDegrees = 60.0f;  // vertical field of view
  float znear = 0.1f;
  float zfar = 1000.0f;
};

// One directional light for Gouraud shading (SPEC §8): per-vertex intensity
// ambient + diffuse·max(0, n·l), interpolated across the triangle.
struct Light {
  Vec3 direction{-0.4f, -1.0f, -0.6f};  // the direction the light travels (toward the scene)
  Vec3 color{1, 1, 1};
  float ambient = 0.25f;
  bool enabled = true;
};

struct Scene {
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Instance> instances;
  std::vector<Camera> cameras;  // the first one is used unless another is chosen
  Light light;
  Vec3 background{0.05f, 0.06f, 0.09f};

  size_t triangleCount() const;  // over all instances
};

// Checks the invariants stated on Mesh and Instance; the error names `file`.
Status validate(const Scene& scene, const std::string& file);

// Appends `other`'s meshes and materials to `scene`, placing each of `other`'s instances under
// `transform`. Cameras and light of `other` are appended/ignored as documented in scene-format.md.
void appendScene(Scene& scene, Scene other, const Mat4& transform);

// Loaders. Each reads one file and returns a Scene or an Error naming the file and the problem.
// They never crash, hang or allocate without bound on malformed input (each has a fuzz target).
// The formats and every limit are described in docs/scene-format.md.
Result<Scene> loadScene(const std::string& path);  // by extension: .json, .gltf, .glb, .obj
Result<Scene> loadJsonScene(const std::string& path);
// Parses JSON scene text; `path` names it in errors and is the base for relative mesh paths.
Result<Scene> parseJsonScene(const std::string& text, const std::string& path);
Result<Scene> loadGltf(const std::string& path);
Result<Scene> loadObj(const std::string& path);

// Limits and switches shared by all loaders. The defaults suit files from disk.
struct LoadOptions {
  // Most triangles one loaded scene may hold, counted over all instances.
  uint64_t maxTriangles = uint64_t(1) << 26;
  // Longest chain of scene files referencing scene files below the one being loaded.
  int maxNesting = 8;
  // False: never open any other file (referenced meshes, .mtl libraries, external glTF buffers
  // all fail as missing). For untrusted text and fuzzing.
  bool followReferences = true;
};

Result<Scene> loadScene(const std::string& path, const LoadOptions& options);
Result<Scene> parseJsonScene(const std::string& text, const std::string& path,
                             const LoadOptions& options);
// In-memory variants of loadGltf and loadObj: `path` names the input in errors and is the base
// for its relative references. `bytes` may be .gltf text or .glb (recognized by its magic).
Result<Scene> loadGltfFromMemory(const std::string& bytes, const std::string& path,
                                 const LoadOptions& options = {});
Result<Scene> parseObj(const std::string& text, const std::string& path,
                       const LoadOptions& options = {});

// Writes `scene` as glTF 2.0: binary for a path ending in .glb, text with the buffer embedded for
// .gltf. loadGltf reads it back to the same meshes, materials, instances and cameras.
Status saveGltf(const Scene& scene, const std::string& path);

// The built-in demo scene (scenes/demo.json compiled into the binary).
Scene demoScene();
// The text of the built-in demo scene.
const char* demoSceneJson();

}  // namespace sv::scene
