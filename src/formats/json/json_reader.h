// The JSON scene format's reader (docs/scene-format.md): a SceneReader walks a parsed document
// section by section, each section in a file of its own (json_<section>.cpp), and builds the
// Scene. json_values.h reads its values; parseJsonSceneIn (json_scene.cpp) runs it.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "formats/json/json_values.h"

namespace sv::formats::json {

// Turns a scene document into a Scene.
class SceneReader {
 public:
  SceneReader(const std::string& path, LoadContext& context) : path_(path), context_(context) {}

  Scene read(const Json& root);

 private:
  Camera readCamera(const Json& v, const std::string& where) const;
  std::vector<Channel> readChannels(const Json& v, const std::string& where) const;
  void readLight(const Json& v, const std::string& where);
  void readMaterials(const Json& v, const std::string& where);
  void readTextures(const Json& v, const std::string& where);
  void readFog(const Json& v, const std::string& where);
  void readPointLights(const Json& v, const std::string& where);
  void readColorTable(const Json& v, const std::string& where);
  void readObject(const Json& v, const std::string& where);
  void readObjectGeometry(const Json& v, const std::string& where);
  // "lodGroups" (docs/scene-format.md#levels-of-detail): named groups of levels, each level an
  // object of one mesh.
  void readLodGroups(const Json& v, const std::string& where);
  // An object with "lod": its group's instances, at its placements ("at") or its transform.
  void readLodObject(const Json& v, const std::string& where);
  // The highest terrain's height at world (x, z), for objects placed "onGround".
  double groundHeight(double x, double z, const std::string& where) const;
  // The object's "material" and "color" keys as a material index (or −1).
  int readObjectMaterial(const Json& object, const std::string& where);
  void readPrimitive(const Json& object, const std::string& where);
  void readFreeFormObject(const Json& object, const std::string& where);
  void readGeodetic(const Json& v, const std::string& where);
  void readTerrain(const Json& v, const std::string& where);
  // "lights" (docs/scene-format.md#light-points): appearances, groups, points, strings, arrays,
  // settings, the star field.
  void readLights(const Json& v, const std::string& where);
  LightAppearance readLightAppearance(const Json& v, const std::string& where) const;
  // A light item's "appearance" and "group" (by name or index), "phase".
  LightPoint readLightCommon(const Json& v, const std::string& where,
                             const std::map<std::string, int>& appearances,
                             const std::map<std::string, int>& groups) const;
  void readLightItems(const Json& v, const std::string& where,
                      const std::map<std::string, int>& appearances,
                      const std::map<std::string, int>& groups);
  void addLight(const LightPoint& p, const std::string& where);
  // "lines" (docs/scene-format.md#lines): settings and polylines.
  void readLines(const Json& v, const std::string& where);
  // "volumes" (docs/scene-format.md#volumes): settings and volume objects.
  void readVolumes(const Json& v, const std::string& where);
  // The table of a terrain: "heights" (a file, or a mosaic of files) or "generate" (a fractal).
  HeightField readHeights(const Json& v, const std::string& where);
  int textureRef(const Json& v, const std::string& where) const;
  FreeFormNode readFreeForm(const Json& v, const std::string& where, int depth, int& quadrics,
                            bool root) const;
  void readInlineMesh(const Json& v, const std::string& where, Mesh& mesh) const;
  void readMeshFile(const Json& v, const std::string& where, std::optional<int> material,
                    const Mat4& m);
  // Charges `triangles` (instanced) to the scene's budget.
  void addTriangles(uint64_t triangles, const std::string& where);

  const std::string& path_;
  LoadContext& context_;
  Scene scene_;
  uint64_t triangles_ = 0;
  std::map<std::string, int> materialByName_;
  std::map<std::string, int> textureByName_;
  uint64_t texels_ = 0;  // decoded or generated so far (LoadOptions::maxTexels)
  std::vector<Vec3> colorTable_;
  // Materials made for objects' "color" overrides, by (base material, colour), to share them.
  std::map<std::pair<int, std::array<float, 4>>, int> colorMaterials_;
  // Where a referenced file's meshes and level-of-detail groups were placed in this scene (its
  // first mesh, its first group), by (file, material override), so that further references to it
  // add instances only.
  std::map<std::pair<std::string, int>, std::pair<int, int>> placedMeshes_;
  std::map<std::string, int> lodGroupByName_;
};

}  // namespace sv::formats::json
