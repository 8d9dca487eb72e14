// The long tail through Assimp (scene/assimp_loader.h): AC3D (FlightGear's format) and STL load
// with their geometry and material colours; Assimp's own errors and unknown types come back as
// one line naming the file, from its child process.
#include <gtest/gtest.h>

#include <string>

#include "formats/formats_test_util.h"
#include "synthvis/scene.h"

namespace sv::formats {
namespace {

using testing::contains;
using testing::TempDir;

TEST(Assimp, ReadsAc3dAndStl) {
  TempDir dir;
  const std::string ac = dir.write("quad.ac", R"(AC3Db
MATERIAL "red" rgb 1 0 0  amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  trans 0
OBJECT world
kids 1
OBJECT poly
name "quad"
numvert 4
0 0 0
2 0 0
2 1 0
0 1 0
numsurf 1
SURF 0x10
mat 0
refs 4
0 0 0
1 0 0
2 0 0
3 0 0
kids 0
)");
  Result<Scene> r = loadScene(ac);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->triangleCount(), 2u);
  ASSERT_FALSE(r->meshes.empty());
  const Material& m = r->materialAt(r->meshes[0].material);
  EXPECT_NEAR(m.baseColor.x, 1, 1e-6);
  EXPECT_NEAR(m.baseColor.y, 0, 1e-6);
  const auto [lo, hi] = r->meshes[0].bounds();
  EXPECT_NEAR(hi.x - lo.x, 2, 1e-5);
  EXPECT_NEAR(hi.y - lo.y, 1, 1e-5);

  const std::string stl = dir.write("two.stl", R"(solid t
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 1 0
endloop
endfacet
facet normal 0 0 1
outer loop
vertex 1 0 0
vertex 1 1 0
vertex 0 1 0
endloop
endfacet
endsolid t
)");
  Result<Scene> s = loadScene(stl);
  ASSERT_TRUE(s.ok()) << s.error().str();
  EXPECT_EQ(s->triangleCount(), 2u);
}

// AC3D's line surfaces (type 1 closed, 2 open) become line segments in the material's colour.
TEST(Assimp, ReadsLines) {
  TempDir dir;
  const std::string ac = dir.write("lines.ac", R"(AC3Db
MATERIAL "green" rgb 0 1 0  amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  trans 0
OBJECT world
kids 1
OBJECT poly
name "outline"
numvert 4
0 0 0
2 0 0
2 1 0
0 1 0
numsurf 2
SURF 0x1
mat 0
refs 4
0 0 0
1 0 0
2 0 0
3 0 0
SURF 0x2
mat 0
refs 2
0 0 0
2 0 0
kids 0
)");
  Result<Scene> r = loadScene(ac);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_TRUE(r->warnings.empty()) << r->warnings[0];
  ASSERT_EQ(r->lines.size(), 4u + 1u);
  for (const LineSegment& l : r->lines) EXPECT_NEAR(l.color.y, 1, 1e-6);
  EXPECT_NEAR(r->lines[4].b.x, 2, 1e-6);  // the open line, vertex 0 to vertex 2
}

TEST(Assimp, ItsFailuresAreOneLineNamingTheFile) {
  TempDir dir;
  const std::string bad = dir.write("bad.3ds", "garbage that is not a model");
  Result<Scene> r = loadScene(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().str(), bad + ": Assimp: ")) << r.error().str();
  EXPECT_EQ(r.error().str().find('\n'), std::string::npos);
  const std::string unknown = dir.write("x.nothing", "x");
  Result<Scene> u = loadScene(unknown);
  ASSERT_FALSE(u.ok());
  EXPECT_EQ(
      u.error().str(),
      unknown + ": unknown scene file type '.nothing' (neither synthvis nor Assimp reads it)");
  Result<Scene> missing = loadScene(dir.path("absent.dae"));
  ASSERT_FALSE(missing.ok());
  EXPECT_TRUE(contains(missing.error().str(), "no such file")) << missing.error().str();
}

}  // namespace
}  // namespace sv::formats
