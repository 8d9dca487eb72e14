// The Wavefront OBJ loader: the sample house with its .mtl colours, corner de-duplication, vertex
// colours, and malformed faces.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "formats/formats_test_util.h"
#include "synthvis/scene.h"

namespace sv::formats {
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

// `l` elements: each polyline's consecutive pairs, in the vertex colours averaged.
TEST(Obj, ReadsLinesAsSegments) {
  Result<Scene> r =
      parseObj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nl 1 2 3\nl 3 1\nf 1 2 3\n", "l.obj");
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->triangleCount(), 1u);
  ASSERT_EQ(r->lines.size(), 3u);
  EXPECT_EQ(r->lines[1].a, (Vec3{1, 0, 0}));
  EXPECT_EQ(r->lines[1].b, (Vec3{0, 1, 0}));
  EXPECT_EQ(r->lines[0].color, (Vec3{0.5f, 0.5f, 0}));
  EXPECT_EQ(r->lines[2].b, (Vec3{0, 0, 0}));
  Result<Scene> withPoints = parseObj("v 0 0 0\nv 1 0 0\np 1 2\nl 1 2\n", "p.obj");
  ASSERT_TRUE(withPoints.ok()) << withPoints.error().str();
  ASSERT_EQ(withPoints->warnings.size(), 1u);
  EXPECT_EQ(withPoints->warnings[0],
            "p.obj: 2 points (`p`) are not drawn (only faces and lines are)");
  Result<Scene> bad = parseObj("v 0 0 0\nl 1 7\n", "bad.obj");
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.error().str(), "line 1 uses vertex 7, but there are 1 vertices"))
      << bad.error().str();
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

// Faces of more than tinyobjloader's 255 vertices are triangulated by the loader: a star of 400
// vertices (concave at every other one), given with relative indices, becomes 398 triangles that
// tile it exactly — their areas sum to its own, each turns as the outline does — in its material
// and object; beyond 8 192 vertices a face is refused with its line.
TEST(Obj, TriangulatesFacesOfAnyVertexCount) {
  const int n = 400;
  std::string text = "mtllib none.mtl\no star\nusemtl gold\n";
  std::vector<std::array<double, 2>> star;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n, r = i % 2 ? 0.6 : 1.0;
    star.push_back({r * std::cos(a), r * std::sin(a)});
    text += fmt::format("v {} {} 0\n", star.back()[0], star.back()[1]);
  }
  text += "f";
  for (int i = 0; i < n; ++i) text += fmt::format(" {}", i - n);  // -400 … -1
  text += "\n";
  Result<Scene> r = parseObj(text, "star.obj");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->meshes.size(), 1u);
  const Mesh& m = r->meshes[0];
  EXPECT_EQ(m.name, "star");
  ASSERT_EQ(m.triangleCount(), size_t(n - 2));
  double outline = 0;
  for (int i = 0; i < n; ++i) {
    const auto& a = star[size_t(i)];
    const auto& b = star[size_t((i + 1) % n)];
    outline += 0.5 * (a[0] * b[1] - a[1] * b[0]);
  }
  double sum = 0;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const Vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]],
               c = m.positions[m.indices[t + 2]];
    const double area = 0.5 * ((double(b.x) - a.x) * (double(c.y) - a.y) -
                               (double(b.y) - a.y) * (double(c.x) - a.x));
    EXPECT_GT(area, 0) << "triangle " << t / 3;
    sum += area;
  }
  EXPECT_NEAR(sum, outline, 1e-4);
  std::string face = "f";
  for (int i = 0; i < 8193; ++i) face += " 1";
  Result<Scene> huge = parseObj("v 0 0 0\n" + face + "\n", "big.obj");
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.error().str(), "big.obj:2: a face with 8193 vertices (the limit is 8192)");
}

// Faces without a material get the OBJ's default, white and two-sided (OBJ says nothing of
// sidedness), made once however many faces need it.
TEST(Obj, MissingMaterialLibraryFallsBackToTheTwoSidedDefaultMaterial) {
  TempDir dir;
  std::string path = dir.write(
      "m.obj",
      "mtllib nowhere.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nf 3 2 1\n");
  Result<Scene> r = loadObj(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->materials.size(), 1u);
  EXPECT_EQ(r->materials[0].name, "OBJ default");
  EXPECT_TRUE(r->materials[0].doubleSided);
  for (const Mesh& m : r->meshes) EXPECT_EQ(m.material, 0);
}

// A model that faces away from the camera is drawn: its .mtl materials are two-sided too.
TEST(Obj, MaterialsAreTwoSided) {
  Result<Scene> r = loadObj(sourcePath("scenes/house.obj"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_FALSE(r->materials.empty());
  for (const Material& m : r->materials) EXPECT_TRUE(m.doubleSided) << m.name;
}

TEST(Obj, ReadsNoMaterialLibraryWhenReferencesAreOff) {
  LoadOptions options;
  options.followReferences = false;
  Result<Scene> r = parseObj(testing::readText(sourcePath("scenes/house.obj")),
                             sourcePath("scenes/house.obj"), options);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->materials.size(), 1u);  // the OBJ default alone
  EXPECT_EQ(r->materials[0].name, "OBJ default");
  EXPECT_EQ(r->triangleCount(), 16u);
}

}  // namespace
}  // namespace sv::formats
