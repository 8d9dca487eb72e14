// Scene formats (docs/scene-format.md): the readers that build a Scene from files and the writers
// that save one — the database's formats, apart from the database (synthvis/scene.h), which knows
// none of them. One file per format under src/formats/ (the JSON scene format one file per
// section, src/formats/json/).
//
// Every reader reads one file and returns a Scene or an Error naming the file and the problem.
// None crashes, hangs or allocates without bound on malformed input (each has a fuzz target, but
// Assimp's, whose library runs in a child process with a time and a memory limit);
// every limit is in docs/scene-format.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::formats {

using scene::Scene;

// Limits and switches shared by all readers. The defaults suit files from disk.
struct LoadOptions {
  // Most triangles one loaded scene may hold, counted over all instances.
  uint64_t maxTriangles = uint64_t(1) << 26;
  // Longest chain of scene files referencing scene files below the one being loaded.
  int maxNesting = 8;
  // False: never open any other file (referenced meshes, .mtl libraries, external glTF buffers
  // and images all fail as missing). For untrusted text and fuzzing.
  bool followReferences = true;
  // Most texels (full-resolution images, summed over the textures of one file) a load may decode
  // or generate: 2^28 texels hold 2 GiB with their pyramids.
  uint64_t maxTexels = uint64_t(1) << 28;
};

// Any scene file, by extension: .json, .gltf, .glb, .obj, .flt, .svdb (a prepared database); any
// other through Assimp. The scene's instance tree is built (buildInstanceTree); a file that holds
// nothing drawable loads with the warning "nothing to draw".
Result<Scene> loadScene(const std::string& path, const LoadOptions& options = {});

// The JSON scene format. parseJsonScene reads text; `path` names it in errors and is the base
// for relative references.
Result<Scene> loadJsonScene(const std::string& path);
Result<Scene> parseJsonScene(const std::string& text, const std::string& path,
                             const LoadOptions& options = {});
// glTF 2.0 (.gltf text or .glb, recognized by its magic; Draco-compressed meshes included).
// loadGltfFromMemory: `path` names the input in errors and is the base for its references.
Result<Scene> loadGltf(const std::string& path);
Result<Scene> loadGltfFromMemory(const std::string& bytes, const std::string& path,
                                 const LoadOptions& options = {});
// Wavefront OBJ with its .mtl materials.
Result<Scene> loadObj(const std::string& path);
Result<Scene> parseObj(const std::string& text, const std::string& path,
                       const LoadOptions& options = {});
// OpenFlight (.flt, revisions 15.0 to 16.x; docs/scene-format.md "OpenFlight"): `bytes` the whole
// file, `path` names it and is the base for its textures and external references.
Result<Scene> parseOpenFlight(const std::string& bytes, const std::string& path,
                              const LoadOptions& options = {});

// The prepared database (docs/prep.md, `synthvis prep`): the scene's own arrays in one file,
// versioned and checksummed, loaded by mapping the file.
Status saveDatabase(const Scene& scene, const std::string& path);
Result<Scene> loadDatabase(const std::string& path, const LoadOptions& options = {});
// The same from bytes in memory (`path` names them in errors).
Result<Scene> parseDatabase(const char* data, size_t size, const std::string& path,
                            const LoadOptions& options = {});

// Writes `scene` as glTF 2.0: binary for a path ending in .glb, text with the buffer embedded for
// .gltf. loadGltf reads it back to the same meshes, materials, instances and cameras.
Status saveGltf(const Scene& scene, const std::string& path);

// A volume file (docs/scene-format.md "Volumes"): NIfTI-1 (.nii, .nii.gz: one volume, unsigned
// or signed 8-, 16- or 32-bit, float or double, scl_slope and scl_inter applied, the voxel sizes
// as its spacing), NRRD (.nrrd, or .nhdr with a detached data file; 3 dimensions, raw or gzip,
// spacings or space directions' lengths) or OpenVDB (.vdb, recognized by its magic: the grid
// named "density", else the first float, double or int32 grid by name, densified over its active
// voxels' bounding box; a linear transform's voxel size as the spacing; read by the OpenVDB
// library in a child process with a time and a memory limit, since that reader is not hardened).
// Orientation (qform, sform, space origin, an OpenVDB transform's rotation and translation) is
// not applied: the volume's own space is index × spacing, placed by the scene. Every size is
// checked before allocating; the error names the file and the problem. parseVolume reads
// `bytes`, the whole file, named `path` (whose directory a detached data file is found in, unless
// !followReferences), and refuses a grid of more than `maxSamples` (at most scene::kMaxVolumeSamples): a
// short OpenVDB file may describe a large grid.
Result<scene::VolumeGrid> loadVolume(const std::string& path);
Result<scene::VolumeGrid> parseVolume(const std::string& bytes, const std::string& path,
                                      bool followReferences,
                                      size_t maxSamples = scene::kMaxVolumeSamples);

// Procedural volumes, which a scene file may name instead of a file ("generate"):
// the Marschner–Lobb test signal (Marschner and Lobb 1994, f_M = 6, α = 1/4) on [−1, 1]³, in
// [0, 1]: ρ = (1 − sin(πz/2) + α(1 + cos(2π f_M cos(π r / 2)))) / (2(1 + α)), r = √(x² + y²).
double marschnerLobb(double x, double y, double z);
// It sampled on a size³ grid spanning [−1, 1]³ (spacing 2/(size − 1), its own space's origin at
// (−1, −1, −1): place it by a translation of (−1, −1, −1)), quantized to `bits` (8 or 16) — values
// 0 … 1. size 2 … 1024.
scene::VolumeGrid marschnerLobbGrid(int size, int bits = 8);
// A seeded cloud: fractal value noise (4 octaves) over a size × size/4 × size grid (x, z across,
// y up; spacing 1), thinned toward the layer's top and bottom and cut below `cover` (0 … 1: the
// share of the layer left empty), 8-bit densities 0 … 1. size 8 … 1024.
scene::VolumeGrid cloudGrid(int size, uint64_t seed, float cover = 0.55f);

// The star catalogue (docs/lights.md#stars): xplanet's Bright Star Catalogue format — per line
// declination (degrees), right ascension (hours), magnitude, an optional B−V colour index, then
// anything (a quoted name, numbers); '#' comments. Errors name the file and line.
Result<std::vector<scene::Star>> loadStarCatalog(const std::string& path);
Result<std::vector<scene::Star>> parseStarCatalog(std::string_view text, const std::string& path);
// A star's linear colour (maximum component 1) from its B−V index: the black-body temperature
// by Ballesteros' formula, its chromaticity by a fit of the Planckian locus.
Vec3 starColor(float bv);

// The built-in demo scene (scenes/demo.json compiled into the binary), and its text.
Scene demoScene();
const char* demoSceneJson();

}  // namespace sv::formats
