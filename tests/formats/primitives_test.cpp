// The primitive generators: topology, normals, winding, closedness and size, each checked against
// an independent evaluation (the divergence-theorem volume against the analytic one, the summed
// triangle area against the analytic area).
#include "formats/primitives.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <numbers>
#include <string>
#include <tuple>

#include "formats/formats_test_util.h"

namespace sv::formats::detail {
namespace {

struct Case {
  const char* name;
  PrimitiveParams params;
  bool closed;
};

PrimitiveParams params(PrimitiveKind kind) {
  PrimitiveParams p;
  p.kind = kind;
  return p;
}

// Every kind, in a few shapes: defaults, the fewest divisions allowed, and uneven sizes.
std::vector<Case> allCases() {
  std::vector<Case> cases;
  auto add = [&](const char* name, PrimitiveParams p, bool closed) {
    cases.push_back({name, p, closed});
  };
  PrimitiveParams p = params(PrimitiveKind::kBox);
  add("box", p, true);
  p.size = {2, 0.5f, 3};
  add("flat box", p, true);
  p = params(PrimitiveKind::kSphere);
  add("sphere", p, true);
  p.segments = 3, p.rings = 2;
  add("coarsest sphere", p, true);
  p = params(PrimitiveKind::kPlane);
  add("plane", p, false);
  p.size = {3, 1, 2}, p.divisionsX = 5, p.divisionsZ = 2;
  add("subdivided plane", p, false);
  p = params(PrimitiveKind::kChecker);
  p.divisionsX = 4, p.divisionsZ = 3;
  add("checker", p, false);
  p = params(PrimitiveKind::kCylinder);
  add("cylinder", p, true);
  p.caps = false;
  add("open cylinder", p, false);
  p.caps = true, p.segments = 3;
  add("triangular prism", p, true);
  p = params(PrimitiveKind::kCone);
  add("cone", p, true);
  p.caps = false;
  add("open cone", p, false);
  p = params(PrimitiveKind::kTorus);
  add("torus", p, true);
  p.segments = 3, p.sides = 3;
  add("coarsest torus", p, true);
  return cases;
}

Vec3 corner(const Mesh& m, size_t t, int k) { return m.positions[m.indices[3 * t + size_t(k)]]; }

Vec3 faceNormal(const Mesh& m, size_t t) {
  Vec3 a = corner(m, t, 0), b = corner(m, t, 1), c = corner(m, t, 2);
  return cross(b - a, c - a);  // length = twice the area; counter-clockwise → outward
}

TEST(Primitives, EveryKindHasConsistentIndicesAndAttributes) {
  for (const Case& c : allCases()) {
    SCOPED_TRACE(c.name);
    Mesh m = makePrimitive(c.params);
    ASSERT_FALSE(m.positions.empty());
    EXPECT_EQ(m.normals.size(), m.positions.size());
    EXPECT_EQ(m.uvs.size(), m.positions.size());
    ASSERT_EQ(m.indices.size() % 3, 0u);
    EXPECT_EQ(m.triangleCount(), primitiveTriangleCount(c.params));
    for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size());
    Scene scene;
    scene.meshes.push_back(m);
    scene.instances.push_back({0, Mat4{}});
    EXPECT_TRUE(validate(scene, c.name).ok());
  }
}

TEST(Primitives, NormalsAreUnitLength) {
  for (const Case& c : allCases()) {
    SCOPED_TRACE(c.name);
    Mesh m = makePrimitive(c.params);
    for (Vec3 n : m.normals) ASSERT_NEAR(length(n), 1.0f, 1e-5f);
  }
}

TEST(Primitives, TrianglesAreCounterClockwiseSeenFromTheSideTheirNormalsFace) {
  for (const Case& c : allCases()) {
    SCOPED_TRACE(c.name);
    Mesh m = makePrimitive(c.params);
    for (size_t t = 0; t < m.triangleCount(); ++t) {
      Vec3 g = faceNormal(m, t);
      ASSERT_GT(length(g), 0) << "degenerate triangle " << t;
      Vec3 n = m.normals[m.indices[3 * t]] + m.normals[m.indices[3 * t + 1]] +
               m.normals[m.indices[3 * t + 2]];
      ASSERT_GT(dot(normalize(g), normalize(n)), 0.2f) << "triangle " << t;
    }
  }
}

// Closed surfaces: every directed edge, compared by position, meets its reverse exactly once.
// This also proves the seams are bit-identical, which an exact rasterizer needs for watertightness.
TEST(Primitives, ClosedShapesAreWatertightByPosition) {
  using Key = std::tuple<float, float, float, float, float, float>;
  for (const Case& c : allCases()) {
    if (!c.closed) continue;
    SCOPED_TRACE(c.name);
    Mesh m = makePrimitive(c.params);
    std::map<Key, int> edges;
    for (size_t t = 0; t < m.triangleCount(); ++t)
      for (int k = 0; k < 3; ++k) {
        Vec3 a = corner(m, t, k), b = corner(m, t, (k + 1) % 3);
        ++edges[{a.x, a.y, a.z, b.x, b.y, b.z}];
      }
    for (const auto& [e, count] : edges) {
      auto [ax, ay, az, bx, by, bz] = e;
      auto reverse = edges.find({bx, by, bz, ax, ay, az});
      ASSERT_EQ(count, 1);
      ASSERT_TRUE(reverse != edges.end() && reverse->second == 1)
          << "open edge (" << ax << " " << ay << " " << az << ") → (" << bx << " " << by << " "
          << bz << ")";
    }
  }
}

// Volume by the divergence theorem: the sum over triangles of a·(b × c) / 6.
double enclosedVolume(const Mesh& m) {
  double v = 0;
  for (size_t t = 0; t < m.triangleCount(); ++t)
    v += dot(corner(m, t, 0), cross(corner(m, t, 1), corner(m, t, 2))) / 6.0;
  return v;
}

double area(const Mesh& m) {
  double a = 0;
  for (size_t t = 0; t < m.triangleCount(); ++t) a += length(faceNormal(m, t)) / 2.0;
  return a;
}

TEST(Primitives, EnclosedVolumesMatchTheAnalyticSolids) {
  // The box and the polygonal prism and pyramid are exact; the sphere and torus converge to the
  // smooth solids as the divisions grow, within 0.5% at 128 divisions.
  EXPECT_NEAR(enclosedVolume(makeBox({2, 3, 4})), 24.0, 1e-4);
  const int n = 128;
  const double r = 1.5, h = 2.0;
  const double polygonArea = n / 2.0 * r * r * std::sin(2 * std::numbers::pi / n);  // regular n-gon
  EXPECT_NEAR(enclosedVolume(makeCylinder(float(r), float(h), n, true)), polygonArea * h, 1e-4);
  EXPECT_NEAR(enclosedVolume(makeCone(float(r), float(h), n, true)), polygonArea * h / 3, 1e-4);
  EXPECT_NEAR(enclosedVolume(makeSphere(float(r), n, n / 2)),
              4.0 / 3.0 * std::numbers::pi * r * r * r,
              0.005 * 4.0 / 3.0 * std::numbers::pi * r * r * r);
  const double torus = 2 * std::numbers::pi * std::numbers::pi * 1.0 * 0.25 * 0.25;  // 2π²·R·t²
  EXPECT_NEAR(enclosedVolume(makeTorus(1.0f, 0.25f, n, n)), torus, 0.005 * torus);
}

TEST(Primitives, FlatShapesCoverTheirExtent) {
  EXPECT_NEAR(area(makePlane(3, 2, 5, 4)), 6.0, 1e-5);
  EXPECT_NEAR(area(makeChecker(10, 4, 7, 3, {1, 1, 1, 1}, {0, 0, 0, 1})), 40.0, 1e-4);
  for (Vec3 p : makePlane(3, 2, 5, 4).positions) {
    EXPECT_EQ(p.y, 0.0f);
    EXPECT_LE(std::fabs(p.x), 1.5f);
    EXPECT_LE(std::fabs(p.z), 1.0f);
  }
}

TEST(Primitives, CheckerSquaresHaveTheirOwnVerticesAndAlternatingColours) {
  const Vec4 light{0.9f, 0.9f, 0.9f, 1}, dark{0.1f, 0.1f, 0.1f, 1};
  Mesh m = makeChecker(4, 4, 4, 4, light, dark);
  ASSERT_EQ(m.positions.size(), 4u * 16u);
  ASSERT_EQ(m.colors.size(), m.positions.size());
  // Square k (row-major along x) owns vertices 4k..4k+3 and triangles 2k, 2k+1.
  for (int k = 0; k < 16; ++k) {
    int i = k % 4, j = k / 4;
    Vec4 expected = (i + j) % 2 == 0 ? light : dark;
    for (int v = 0; v < 4; ++v) EXPECT_EQ(m.colors[size_t(4 * k + v)], expected) << "square " << k;
    for (size_t t = 2 * size_t(k); t < 2 * size_t(k) + 2; ++t)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(m.indices[3 * t + size_t(c)] / 4, uint32_t(k));
  }
}

TEST(Primitives, SphereVerticesLieOnTheSphere) {
  Mesh m = makeSphere(2.5f, 24, 12);
  for (Vec3 p : m.positions) ASSERT_NEAR(length(p), 2.5f, 1e-5f);
  for (size_t i = 0; i < m.positions.size(); ++i)
    ASSERT_NEAR(dot(m.normals[i], m.positions[i] * (1 / 2.5f)), 1.0f, 1e-5f);
}

TEST(Primitives, OutputIsDeterministic) {
  for (const Case& c : allCases()) {
    Mesh a = makePrimitive(c.params), b = makePrimitive(c.params);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    EXPECT_EQ(
        0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3)))
        << c.name;
    EXPECT_EQ(a.indices, b.indices) << c.name;
  }
}

}  // namespace
}  // namespace sv::formats::detail
