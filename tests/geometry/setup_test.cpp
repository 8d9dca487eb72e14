// Triangle setup (SPEC §2) against independent evaluations: exact point-in-triangle with the
// top-left rule, perspective-correct parameters against ray–plane intersection, the near plane.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "hwy/targets.h"
#include "support/raster_harness.h"
#include "synthvis/math.h"

namespace sv {
namespace {

using geometry::ClipVertex;
using geometry::TriangleSetup;
using test::pixelVertex;

bool edgeInside(const TriangleSetup& t, int x, int y) {
  for (int k = 0; k < t.edgeCount; ++k)
    if (t.edges[k].c + t.edges[k].stepX() * x + t.edges[k].stepY() * y < 0) return false;
  return true;
}

// Independent inside test on a 1/256 grid: orientation by exact integer cross products; a centre
// on an edge belongs to the triangle if that edge is a left edge (inside towards +x) or a top edge
// (horizontal, inside towards +y, y down).
bool exactInside(const int64_t vx[3], const int64_t vy[3], int px, int py) {
  const int64_t cx = int64_t(px) * 256 + 128, cy = int64_t(py) * 256 + 128;
  const __int128 area =
      __int128(vx[1] - vx[0]) * (vy[2] - vy[0]) - __int128(vy[1] - vy[0]) * (vx[2] - vx[0]);
  if (area == 0) return false;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    __int128 e = __int128(vx[j] - vx[i]) * (cy - vy[i]) - __int128(vy[j] - vy[i]) * (cx - vx[i]);
    if (area < 0) e = -e;
    if (e < 0) return false;
    if (e == 0) {
      // Inward normal of edge i→j: perpendicular (−dy, dx) oriented like the area.
      int64_t nx = -(vy[j] - vy[i]), ny = vx[j] - vx[i];
      if (area < 0) nx = -nx, ny = -ny;
      if (!(nx > 0 || (nx == 0 && ny > 0))) return false;
    }
  }
  return true;
}

TEST(Setup, IntegerEdgesAgreeWithExactPointInTriangleIncludingTies) {
  std::mt19937 rng(7);
  const int w = 64, h = 64;
  // Vertices on a coarse sub-pixel grid (multiples of 1/8 px) so that many centres fall exactly on
  // edges and ties are exercised.
  std::uniform_int_distribution<int> coord(-40 * 8, 100 * 8);
  for (int n = 0; n < 400; ++n) {
    int64_t vx[3], vy[3];
    ClipVertex v[3];
    for (int k = 0; k < 3; ++k) {
      const int gx = coord(rng), gy = coord(rng);
      vx[k] = gx * 32;  // 1/8 px in 1/256 units
      vy[k] = gy * 32;
      v[k] = pixelVertex(gx / 8.0, gy / 8.0, w, h);
    }
    TriangleSetup t;
    const auto outcome =
        geometry::setupTriangle(v[0], v[1], v[2], {w, h}, geometry::CullMode::none, t);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool expected = exactInside(vx, vy, x, y);
        const bool got = outcome == geometry::SetupOutcome::drawn && edgeInside(t, x, y) &&
                         x >= t.minX && x <= t.maxX && y >= t.minY && y <= t.maxY;
        ASSERT_EQ(got, expected) << "triangle " << n << " pixel " << x << "," << y;
      }
  }
}

TEST(Setup, IncrementalChildValuesEqualDirectEvaluation) {
  // The kernel carries e at a window's top-left pixel centre and steps it by sX·h, sY·h (seed 000
  // eq. 1); this must equal evaluating the edge directly at the child's corner.
  TriangleSetup t;
  ASSERT_EQ(geometry::setupTriangle(
                pixelVertex(3.3, 2.1, 256, 256), pixelVertex(250.7, 40.2, 256, 256),
                pixelVertex(30.9, 251.4, 256, 256), {256, 256}, geometry::CullMode::none, t),
            geometry::SetupOutcome::drawn);
  for (int k = 0; k < 3; ++k) {
    const auto& e = t.edges[k];
    int64_t tl = e.c;  // window (0,0) of size 256
    int x = 0, y = 0;
    for (int h = 128; h >= 1; h /= 2) {  // walk to child (1,0), then (0,1), alternately
      if ((h & 1) || h % 4 == 0) {
        tl += e.stepX() * h;
        x += h;
      } else {
        tl += e.stepY() * h;
        y += h;
      }
      EXPECT_EQ(tl, e.c + e.stepX() * x + e.stepY() * y);
    }
  }
}

TEST(Setup, FacingFollowsCounterClockwiseFrontFaces) {
  const int w = 32, h = 32;
  // Counter-clockwise in NDC (y up) = clockwise on the raster (y down): (0,0) (10,0) (0,10) on the
  // raster is clockwise there, so counter-clockwise in NDC: a front face.
  const ClipVertex a = pixelVertex(0, 10, w, h), b = pixelVertex(10, 10, w, h),
                   c = pixelVertex(0, 0, w, h);
  TriangleSetup t;
  EXPECT_EQ(geometry::setupTriangle(a, b, c, {w, h}, geometry::CullMode::back, t),
            geometry::SetupOutcome::drawn);
  EXPECT_EQ(geometry::setupTriangle(a, c, b, {w, h}, geometry::CullMode::back, t),
            geometry::SetupOutcome::culledFacing);
  EXPECT_EQ(geometry::setupTriangle(a, c, b, {w, h}, geometry::CullMode::front, t),
            geometry::SetupOutcome::drawn);
}

// A quad tilted in depth, seen in perspective; colour red = the object-space coordinate u ∈ [0,1]
// across it. The rendered value at a pixel must equal u at the ray–plane intersection.
TEST(Setup, ColourIsPerspectiveCorrectAgainstRayPlaneIntersection) {
  const int w = 128, h = 128;
  const float fov = 1.0f;
  const Mat4 proj = Mat4::perspective(fov, 1.0f, 0.1f, 50.0f);
  // Plane through P0 with axes U (u direction) and V; points P0 + u·U + v·V, u, v ∈ [0,1].
  const Vec3 p0{-2, -1.5f, -2}, U{4, 0, -10}, V{0, 3, 0};
  auto corner = [&](float u, float v) {
    const Vec3 p = p0 + U * u + V * v;
    const Vec4 c = proj * Vec4{p.x, p.y, p.z, 1};
    return ClipVertex{c.x, c.y, c.z, c.w, u, v, 0, 1};
  };
  render::DrawPackets pk;
  test::addTriangle(pk, corner(0, 0), corner(1, 0), corner(1, 1));
  test::addTriangle(pk, corner(0, 0), corner(1, 1), corner(0, 1));
  render::FrameSettings s;
  s.width = w;
  s.height = h;
  const test::Frame f = test::renderQuadtree(pk, s);
  const Vec3 n = cross(U, V);
  int checked = 0;
  double worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // The eye ray through the pixel centre.
      const double t = std::tan(fov / 2);
      const double rx = ((x + 0.5) / w * 2 - 1) * t, ry = (1 - (y + 0.5) / h * 2) * t, rz = -1;
      const double denom = n.x * rx + n.y * ry + n.z * rz;
      const double s0 = (n.x * p0.x + n.y * p0.y + n.z * p0.z) / denom;
      const double px = rx * s0 - p0.x, py = ry * s0 - p0.y, pz = rz * s0 - p0.z;
      // Solve p = u·U + v·V (U and V are orthogonal here).
      const double u = (px * U.x + py * U.y + pz * U.z) / dot(U, U);
      const double v = (px * V.x + py * V.y + pz * V.z) / dot(V, V);
      if (u < 0.01 || u > 0.99 || v < 0.01 || v > 0.99) continue;
      const double got = f.channel(x, y, 0) / 65535.0;
      worst = std::max(worst, std::fabs(got - u));
      ++checked;
    }
  EXPECT_GT(checked, 1000);
  EXPECT_LT(worst, 2e-4);  // 16-bit storage is 1.5e-5; the rest is float interpolation
}

TEST(Setup, NearPlaneBecomesAnEdgeOnlyWhenAVertexIsInFrontOfIt) {
  const int w = 64, h = 64;
  TriangleSetup t;
  const ClipVertex a = pixelVertex(5, 5, w, h, 0.5f), b = pixelVertex(60, 5, w, h, 0.5f);
  ASSERT_EQ(geometry::setupTriangle(a, b, pixelVertex(5, 60, w, h, 0.5f), {w, h},
                                    geometry::CullMode::none, t),
            geometry::SetupOutcome::drawn);
  EXPECT_EQ(t.edgeCount, 3);
  // Third vertex nearer than the near plane (window depth < 0): four edges, and the pixels near
  // that vertex are cut away.
  ASSERT_EQ(geometry::setupTriangle(a, b, pixelVertex(5, 60, w, h, -0.5f), {w, h},
                                    geometry::CullMode::none, t),
            geometry::SetupOutcome::drawn);
  EXPECT_EQ(t.edgeCount, 4);
  EXPECT_TRUE(edgeInside(t, 20, 10));
  EXPECT_FALSE(edgeInside(t, 6, 55));
}

TEST(Setup, TriangleEntirelyBehindTheEyeIsCulled) {
  const ClipVertex a{0, 0, 0.5f, -1, 1, 1, 1, 1}, b{1, 0, 0.5f, -1, 1, 1, 1, 1},
      c{0, 1, 0.5f, -2, 1, 1, 1, 1};
  TriangleSetup t;
  EXPECT_NE(geometry::setupTriangle(a, b, c, {64, 64}, geometry::CullMode::none, t),
            geometry::SetupOutcome::drawn);
}

// The fixed-point budget at the largest raster (RASTER-NOTES pitfall 1): on 8192×8192, with
// vertices far outside the raster (inside the guard band), the int64 edge functions still give
// the exact inside test at pixels anywhere on the raster, corners included.
TEST(Setup, EdgesAreExactOnTheLargestRaster) {
  const int w = 8192, h = 8192;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(-6000, 14000);
  std::uniform_int_distribution<int> pixel(0, w - 1);
  int tested = 0;
  for (int n = 0; n < 300; ++n) {
    ClipVertex v[3];
    int64_t vx[3], vy[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = pixelVertex(coord(rng), coord(rng), w, h);
      // The snapping rule of setup.h: the projection rounded to 1/256 px.
      const double px = (double(v[k].x) + v[k].w) * (0.5 * w) / v[k].w;
      const double py = (double(v[k].w) - v[k].y) * (0.5 * h) / v[k].w;
      vx[k] = std::llrint(px * 256);
      vy[k] = std::llrint(py * 256);
    }
    TriangleSetup t;
    if (geometry::setupTriangle(v[0], v[1], v[2], {w, h}, geometry::CullMode::none, t) !=
        geometry::SetupOutcome::drawn)
      continue;
    ASSERT_FALSE(t.small);
    std::vector<std::array<int, 2>> pixels = {{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}};
    for (int i = 0; i < 400; ++i) pixels.push_back({pixel(rng), pixel(rng)});
    for (const auto& [x, y] : pixels) {
      const bool inBox = x >= t.minX && x <= t.maxX && y >= t.minY && y <= t.maxY;
      ASSERT_EQ(inBox && edgeInside(t, x, y), exactInside(vx, vy, x, y))
          << "triangle " << n << " pixel " << x << "," << y;
      ++tested;
    }
  }
  EXPECT_GT(tested, 50000);
}

// SPEC §3.2 with the pixel aperture: the box holds exactly the pixels whose square [p, p + 1)
// the vertices' extent reaches, so no pixel with a covered sample is left out of binning.
TEST(Setup, ApertureBoxSpansEveryPixelSquareTheTriangleReaches) {
  const int w = 64, h = 48;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> coord(-300, 64 * 256 + 300);
  for (int t = 0; t < 2000; ++t) {
    int64_t x[3], y[3];
    ClipVertex v[3];
    for (int k = 0; k < 3; ++k) {
      x[k] = coord(rng) % (w * 256);
      y[k] = coord(rng) % (h * 256);
      if (t % 3 == 0) x[k] = x[k] / 256 * 256;  // on pixel borders
      v[k] = pixelVertex(x[k] / 256.0, y[k] / 256.0, w, h);
    }
    TriangleSetup point, aperture;
    const auto o1 =
        geometry::setupTriangle(v[0], v[1], v[2], {w, h, false}, geometry::CullMode::none, point);
    const auto o2 =
        geometry::setupTriangle(v[0], v[1], v[2], {w, h, true}, geometry::CullMode::none, aperture);
    if (o2 != geometry::SetupOutcome::drawn) {
      EXPECT_NE(o1, geometry::SetupOutcome::drawn) << t;  // the aperture only ever adds pixels
      continue;
    }
    auto floorDiv = [](int64_t a) { return a >= 0 ? a / 256 : -((-a + 255) / 256); };
    const int64_t x0 = std::min({x[0], x[1], x[2]}), x1 = std::max({x[0], x[1], x[2]});
    const int64_t y0 = std::min({y[0], y[1], y[2]}), y1 = std::max({y[0], y[1], y[2]});
    EXPECT_EQ(aperture.minX, std::max<int64_t>(0, floorDiv(x0))) << t;
    EXPECT_EQ(aperture.maxX, std::min<int64_t>(w - 1, -floorDiv(-x1) - 1)) << t;
    EXPECT_EQ(aperture.minY, std::max<int64_t>(0, floorDiv(y0))) << t;
    EXPECT_EQ(aperture.maxY, std::min<int64_t>(h - 1, -floorDiv(-y1) - 1)) << t;
    if (o1 == geometry::SetupOutcome::drawn) {
      EXPECT_LE(aperture.minX, point.minX);
      EXPECT_GE(aperture.maxX, point.maxX);
      EXPECT_LE(aperture.minY, point.minY);
      EXPECT_GE(aperture.maxY, point.maxY);
    }
  }
}

// Attributes stored packed (only the used ones, at their slots) give the planes they give stored
// whole, in the batch and one by one.
TEST(Setup, PackedAttributesGiveTheSamePlanes) {
  const int w = 640, h = 480;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<ClipVertex> v;
  for (int t = 0; t < 300; ++t) {
    const double cx = u(rng) * w, cy = u(rng) * h, size = 2 + u(rng) * 200;
    for (int k = 0; k < 3; ++k)
      v.push_back(pixelVertex(cx + (u(rng) - 0.5) * size, cy + (u(rng) - 0.5) * size, w, h, u(rng),
                              0.2f + 3 * u(rng), u(rng), u(rng), u(rng)));
  }
  std::vector<uint32_t> indices(v.size());
  for (size_t i = 0; i < indices.size(); ++i) indices[i] = uint32_t(i);
  const size_t count = v.size() / 3;
  constexpr int kValues = 5;
  constexpr unsigned kUsed = 0b10101;
  const uint8_t slots[kValues] = {0, 9, 1, 9, 2};  // 9: never read
  std::vector<float> whole(v.size() * kValues), packed(v.size() * 3);
  for (size_t i = 0; i < v.size(); ++i) {
    for (int a = 0; a < kValues; ++a) {
      whole[i * kValues + size_t(a)] = u(rng) * 4 - 2;
      if (kUsed >> a & 1) packed[i * 3 + slots[a]] = whole[i * kValues + size_t(a)];
    }
  }
  const geometry::Viewport vp{w, h, false};
  auto planes = [&](const float* values, size_t stride, const uint8_t* slot) {
    std::vector<TriangleSetup> setups(count);
    std::vector<geometry::Plane> out(count * kValues, {7, 7, 7});
    geometry::AttributeRequest request{
        values, stride, kValues, kUsed, out.data(), sizeof(geometry::Plane) * kValues, slot};
    uint64_t outcomes[geometry::kSetupOutcomes] = {};
    const size_t n =
        geometry::setupTriangles(v.data(), indices.data(), count, vp, geometry::CullMode::none,
                                 setups.data(), outcomes, 0, &request);
    out.resize(n * kValues);
    // One by one, the same request's values.
    for (size_t r = 0; r < n; ++r) {
      const size_t t = setups[r].triangle;
      const float* vals[3] = {values + 3 * t * stride, values + (3 * t + 1) * stride,
                              values + (3 * t + 2) * stride};
      geometry::Plane one[kValues];
      geometry::attributePlanes(v[3 * t], v[3 * t + 1], v[3 * t + 2], vp, setups[r], vals, kValues,
                                one, kUsed, slot);
      for (int a = 0; a < kValues; ++a)
        EXPECT_EQ(0, std::memcmp(&one[a], &out[r * kValues + size_t(a)], sizeof one[a]));
    }
    return out;
  };
  const std::vector<geometry::Plane> a = planes(whole.data(), kValues, nullptr);
  const std::vector<geometry::Plane> b = planes(packed.data(), 3, slots);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), size_t(kValues) * 200);
  for (size_t i = 0; i < a.size(); ++i)  // (the unused planes are zero in both)
    ASSERT_EQ(0, std::memcmp(&a[i], &b[i], sizeof a[i])) << i;
}

// setupTriangles (SIMD lanes) must give setupTriangle's records bit for bit, on every SIMD target,
// in every regime: small and large, culled either way, degenerate, behind and across the eye,
// beyond the far plane, outside the guard band, NaN and infinite —
// and the attribute planes attributePlanes gives.
TEST(Setup, BatchedSetupEqualsOneByOneOnEveryTarget) {
  const int w = 1000, h = 700;
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<ClipVertex> v;
  auto add = [&](ClipVertex a) { v.push_back(a); };
  for (int t = 0; t < 4000; ++t) {
    const int regime = t % 10;
    const double cx = u(rng) * w, cy = u(rng) * h,
                 size = regime < 4 ? 1 + u(rng) * 20 : u(rng) * 900;
    for (int k = 0; k < 3; ++k) {
      ClipVertex c = pixelVertex(cx + (u(rng) - 0.5) * size, cy + (u(rng) - 0.5) * size, w, h,
                                 u(rng), 0.2f + 3 * u(rng), u(rng), u(rng), u(rng));
      if (regime == 5 && k == 0) c.w = -c.w;       // behind the eye
      if (regime == 6 && k == 1) c.z = -2 * c.w;   // before the near plane
      if (regime == 7 && k == 2) c.z = 2 * c.w;    // beyond the far plane
      if (regime == 8 && k == 0) c.x = c.w * 200;  // outside the guard band
      if (regime == 9 && k == 1 && t % 20 == 9) c.y = std::numeric_limits<float>::quiet_NaN();
      if (regime == 9 && k == 1 && t % 20 == 19) c.w = std::numeric_limits<float>::infinity();
      add(c);
    }
    if (regime == 3) v[v.size() - 1] = v[v.size() - 2];  // degenerate
  }
  std::vector<uint32_t> indices(v.size());
  for (size_t i = 0; i < indices.size(); ++i) indices[i] = uint32_t(i);
  const size_t count = v.size() / 3;
  // Pixel shading's planes asked of the batch: five values per vertex, the fourth unused.
  constexpr int kValues = 5;
  constexpr unsigned kUsed = 0b10111;
  std::vector<float> values(v.size() * kValues);
  for (float& x : values) x = u(rng) * 4 - 2;
  int targets = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (int mode = 0; mode < 4; ++mode) {
      // Every culling mode with point sampling, and back-face culling with the pixel aperture.
      const geometry::CullMode cull =
          mode == 3 ? geometry::CullMode::back : geometry::CullMode(mode);
      const geometry::Viewport vp{w, h, mode == 3};
      std::vector<TriangleSetup> one, batch(count);
      std::vector<geometry::Plane> onePlanes, batchPlanes(count * kValues, {7, 7, 7});
      uint64_t oneOutcomes[geometry::kSetupOutcomes] = {},
               batchOutcomes[geometry::kSetupOutcomes] = {};
      for (size_t t = 0; t < count; ++t) {
        TriangleSetup s;
        const auto o = geometry::setupTriangle(v[3 * t], v[3 * t + 1], v[3 * t + 2], vp, cull, s);
        ++oneOutcomes[int(o)];
        if (o != geometry::SetupOutcome::drawn) continue;
        one.push_back(s);
        const float* vals[3] = {&values[(3 * t) * kValues], &values[(3 * t + 1) * kValues],
                                &values[(3 * t + 2) * kValues]};
        geometry::Plane planes[kValues];
        geometry::attributePlanes(v[3 * t], v[3 * t + 1], v[3 * t + 2], vp, s, vals, kValues,
                                  planes, kUsed);
        onePlanes.insert(onePlanes.end(), planes, planes + kValues);
      }
      geometry::AttributeRequest request{values.data(),
                                         kValues,
                                         kValues,
                                         kUsed,
                                         batchPlanes.data(),
                                         sizeof(geometry::Plane) * kValues};
      const size_t n = geometry::setupTriangles(v.data(), indices.data(), count, vp, cull,
                                                batch.data(), batchOutcomes, 0, &request);
      ASSERT_EQ(n, one.size()) << hwy::TargetName(target);
      for (int o = 0; o < geometry::kSetupOutcomes; ++o)
        EXPECT_EQ(batchOutcomes[o], oneOutcomes[o]) << "outcome " << o;
      for (size_t i = 0; i < n; ++i) {
        const TriangleSetup &a = one[i], &b = batch[i];
        ASSERT_EQ(a.edgeCount, b.edgeCount) << i;
        for (int k = 0; k < a.edgeCount; ++k) {
          ASSERT_EQ(a.edges[k].c, b.edges[k].c) << i;
          ASSERT_EQ(a.edges[k].a, b.edges[k].a) << i;
          ASSERT_EQ(a.edges[k].b, b.edges[k].b) << i;
        }
        const geometry::Plane* pa[] = {&a.depth, &a.invW, &a.red, &a.green, &a.blue};
        const geometry::Plane* pb[] = {&b.depth, &b.invW, &b.red, &b.green, &b.blue};
        for (int p = 0; p < 5; ++p)
          ASSERT_EQ(0, std::memcmp(pa[p], pb[p], sizeof(geometry::Plane))) << i << " plane " << p;
        for (int p = 0; p < kValues; ++p)
          ASSERT_EQ(0, std::memcmp(&onePlanes[i * kValues + p], &batchPlanes[i * kValues + p],
                                   sizeof(geometry::Plane)))
              << i << " attribute plane " << p;
        ASSERT_EQ(a.minX, b.minX);
        ASSERT_EQ(a.minY, b.minY);
        ASSERT_EQ(a.maxX, b.maxX);
        ASSERT_EQ(a.maxY, b.maxY);
        ASSERT_EQ(a.small, b.small);
      }
    }
    ++targets;
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(targets, 1);
}

}  // namespace
}  // namespace sv
