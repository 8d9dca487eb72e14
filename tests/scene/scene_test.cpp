// The Scene database operations: triangle counting, validation, appending.
#include "synthvis/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/expect.h"

namespace sv::scene {
namespace {

using sv::tests::contains;

Scene oneTriangleScene() {
  Scene s;
  Mesh m;
  m.name = "tri";
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {0, 1, 2};
  m.material = 0;
  s.meshes.push_back(m);
  s.materials.push_back(Material{"red", {1, 0, 0, 1}, false, false});
  s.instances.push_back({0, Mat4{}});
  return s;
}

TEST(Scene, TriangleCountCountsEveryInstance) {
  Scene s = oneTriangleScene();
  s.instances.push_back({0, Mat4::translation({2, 0, 0})});
  EXPECT_EQ(s.triangleCount(), 2u);
}

TEST(Scene, ValidateAcceptsEmptyAndWellFormedScenes) {
  EXPECT_TRUE(validate(Scene{}, "empty").ok());
  EXPECT_TRUE(validate(oneTriangleScene(), "tri").ok());
}

// Each row breaks one invariant; the error must name the file, the mesh or instance, and the rule.
TEST(Scene, ValidateNamesTheFileAndTheBrokenInvariant) {
  struct Row {
    const char* why;
    void (*breakIt)(Scene&);
    const char* expected;
  };
  const Row rows[] = {
      {"index past the vertices", [](Scene& s) { s.meshes[0].indices[2] = 3; },
       "indices[2] = 3 is out of range (3 vertices)"},
      {"incomplete triangle", [](Scene& s) { s.meshes[0].indices.push_back(0); },
       "not a multiple of 3"},
      {"normals for some vertices only",
       [](Scene& s) {
         s.meshes[0].normals = {{0, 0, 1}};
       },
       "attribute arrays"},
      {"colours for too many vertices", [](Scene& s) { s.meshes[0].colors.resize(4); },
       "attribute arrays"},
      {"NaN position",
       [](Scene& s) { s.meshes[0].positions[1].y = std::numeric_limits<float>::quiet_NaN(); },
       "positions[1] is not finite"},
      {"infinite position", [](Scene& s) { s.meshes[0].positions[0].x = INFINITY; },
       "positions[0] is not finite"},
      {"missing material", [](Scene& s) { s.meshes[0].material = 1; }, "material 1 does not exist"},
      {"material below −1", [](Scene& s) { s.meshes[0].material = -2; },
       "material -2 does not exist"},
      {"instance of a missing mesh", [](Scene& s) { s.instances[0].mesh = 1; },
       "instances[0]: mesh 1 does not exist"},
      {"negative mesh index", [](Scene& s) { s.instances[0].mesh = -1; }, "instances[0]: mesh -1"},
      {"non-finite transform", [](Scene& s) { s.instances[0].transform.m[3][0] = NAN; },
       "transform is not finite"},
      {"missing level-of-detail group", [](Scene& s) { s.instances[0].lod = 0; },
       "instances[0]: level-of-detail group 0 does not exist"},
      {"instance mesh not its level 0",
       [](Scene& s) {
         s.lodGroups.push_back({"g", {{0, 10}}, 0, {}});
         s.meshes.push_back(s.meshes[0]);
         s.instances[0] = {1, Mat4{}, 0, 0};
       },
       "mesh 1 is not level 0 of its level-of-detail group (mesh 0)"},
      {"ranges that do not increase",
       [](Scene& s) { s.lodGroups.push_back({"g", {{0, 10}, {0, 10}}, 0, {}}); },
       "LOD group 'g': level 1: 'to' 10 must exceed 10"},
      {"a fade longer than a level",
       [](Scene& s) { s.lodGroups.push_back({"g", {{0, 10}, {0, 12}}, 3, {}}); },
       "the fade of 3 is longer than its span [10, 12)"},
      {"a group without levels", [](Scene& s) { s.lodGroups.push_back({}); },
       "lodGroups[0]: 0 levels (1 to 8)"},
      {"a level of a missing mesh", [](Scene& s) { s.lodGroups.push_back({"", {{4, 10}}, 0, {}}); },
       "level 0: mesh 4 does not exist"},
      {"a stale instance tree",
       [](Scene& s) {
         s.instances.push_back(s.instances[0]);
         buildInstanceTree(s);
         s.instances.pop_back();
       },
       "the instance tree covers 2 instances, the scene has 1"},
  };
  for (const Row& row : rows) {
    SCOPED_TRACE(row.why);
    Scene s = oneTriangleScene();
    row.breakIt(s);
    Status status = validate(s, "broken.json");
    ASSERT_FALSE(status.ok());
    EXPECT_TRUE(contains(status.error().str(), "broken.json: "));
    EXPECT_TRUE(contains(status.error().str(), row.expected));
  }
}

TEST(Scene, AppendSceneOffsetsIndicesAndComposesTransforms) {
  Scene s = oneTriangleScene();
  Scene other = oneTriangleScene();
  other.instances[0].transform = Mat4::translation({0, 0, 1});
  other.cameras.push_back(Camera{"cam", {0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 45, 0.1f, 100});
  other.light.ambient = 0.9f;
  appendScene(s, other, Mat4::translation({10, 0, 0}));

  ASSERT_EQ(s.meshes.size(), 2u);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.meshes[1].material, 1);
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[1].mesh, 1);
  Vec3 p = s.instances[1].transform.transformPoint({0, 0, 0});
  EXPECT_EQ(p, (Vec3{10, 0, 1}));
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_EQ(s.cameras[0].position, (Vec3{10, 0, 5}));
  EXPECT_EQ(s.cameras[0].target, (Vec3{10, 0, 0}));
  EXPECT_EQ(s.light.ambient, Light{}.ambient);  // the outer scene keeps its light
  EXPECT_TRUE(validate(s, "merged").ok());
}

}  // namespace
}  // namespace sv::scene
