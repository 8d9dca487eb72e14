// The Wavefront OBJ loader: the sample house with its .mtl colours, corner de-duplication, vertex
// colours, and malformed faces.
#include <gtest/gtest.h>

#include <string>

#include "scene/scene_test_util.h"
#include "synthvis/scene.h"

namespace sv::scene {
namespace {

using testing::contains;
using testing::dataPath;
using testing::expectLoadError;
using testing::sourcePath;
using testing::TempDir;

const Material* findMaterial(const Scene& s, const std::string& name) {
  for (const Material& m : s.materials)
    if (m.name == name) return &m;
  return nullptr;
}

TEST(Obj, LoadsTheSampleHouseWithMaterialColours) {
  Result<Scene> r = loadScene(sourcePath("scenes/house.obj"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  EXPECT_EQ(s.triangleCount(), 16u);  // 7 quads and 2 triangles
  ASSERT_EQ(s.meshes.size(), 2u);     // one per material
  const Material* walls = findMaterial(s, "walls");
  const Material* roof = findMaterial(s, "roof");
  ASSERT_TRUE(walls && roof);
  EXPECT_EQ(walls->baseColor, (Vec4{0.85f, 0.75f, 0.55f, 1}));
  EXPECT_EQ(roof->baseColor, (Vec4{0.60f, 0.12f, 0.08f, 1}));
  for (const Mesh& m : s.meshes) {
    SCOPED_TRACE(m.name);
    EXPECT_EQ(s.materials[size_t(m.material)].name, m.name.substr(m.name.find(':') + 1));
    ASSERT_EQ(m.normals.size(), m.positions.size());
    // Counter-clockwise from outside: the geometric normal agrees with the file's normals.
    for (size_t t = 0; t < m.triangleCount(); ++t) {
      Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
           c = m.positions[m.indices[3 * t + 2]];
      EXPECT_GT(dot(cross(b - a, c - a), m.normals[m.indices[3 * t]]), 0) << "triangle " << t;
    }
  }
}

TEST(Obj, SharesVerticesOnlyBetweenIdenticalCorners) {
  // A quad with one normal: 4 distinct corners. A second quad reusing positions 2 and 3 with
  // another normal needs its own vertices there.
  Result<Scene> r = parseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 2 0\nv 0 2 0\n"
      "vn 0 0 1\nvn 0 1 0\n"
      "f 1//1 2//1 3//1 4//1\nf 4//2 3//2 5//2 6//2\n",
      "q.obj");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Mesh& m = r->meshes[0];
  EXPECT_EQ(m.triangleCount(), 4u);
  EXPECT_EQ(m.positions.size(), 8u);
  EXPECT_TRUE(m.uvs.empty());
}

TEST(Obj, DropsAnAttributeThatNotEveryCornerHas) {
  Result<Scene> r = parseObj(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n"
      "f 1/1/1 2//1 3/1/1\n",
      "t.obj");
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->meshes[0].normals.size(), 3u);
  EXPECT_TRUE(r->meshes[0].uvs.empty());  // corner 2 has no texture coordinate
}

TEST(Obj, ReadsVertexColours) {
  Result<Scene> r = parseObj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n", "c.obj");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->meshes[0].colors.size(), 3u);
  EXPECT_EQ(r->meshes[0].colors[1], (Vec4{0, 1, 0, 1}));
}

TEST(Obj, RejectsAFaceIndexPastTheVertices) {
  expectLoadError("scene/bad_index.obj",
                  "shape '': face 1 uses vertex 4, but there are 3 vertices");
}

TEST(Obj, RejectsMalformedFacesWithTheLineNumber) {
  Result<Scene> r = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "z.obj");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().position, "4");
  EXPECT_TRUE(contains(r.error().str(), "z.obj:4: invalid OBJ: "));
  EXPECT_EQ(r.error().str().find('\n'), std::string::npos);
}

TEST(Obj, RejectsFacesTooLargeToTriangulate) {
  std::string text = "v 0 0 0\n";
  std::string face = "f";
  for (int i = 0; i < 300; ++i) face += " 1";
  Result<Scene> r = parseObj(text + face + "\n", "big.obj");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().str(), "big.obj:2: a face with 300 vertices (the limit is 255)");
}

TEST(Obj, MissingMaterialLibraryFallsBackToTheDefaultMaterial) {
  TempDir dir;
  std::string path =
      dir.write("m.obj", "mtllib nowhere.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Result<Scene> r = loadObj(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->meshes[0].material, -1);
}

TEST(Obj, ReadsNoMaterialLibraryWhenReferencesAreOff) {
  LoadOptions options;
  options.followReferences = false;
  Result<Scene> r = parseObj(testing::readText(sourcePath("scenes/house.obj")),
                             sourcePath("scenes/house.obj"), options);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_TRUE(r->materials.empty());
  EXPECT_EQ(r->triangleCount(), 16u);
}

}  // namespace
}  // namespace sv::scene
