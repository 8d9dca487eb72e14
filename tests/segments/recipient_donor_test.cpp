// The recipient–donor filter's parts (segments/recipient_donor.h): a square's area inside a
// half-plane against the area of the square clipped by the line as a polygon; and a triangle's
// recipient area in pixels one edge crosses against that formula from the triangle's vertices,
// its donor across the edge.
#include "segments/recipient_donor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace sv {
namespace {

struct P {
  double x, y;
};

// The area of the unit square centred at the origin on the side n·p + d ≥ 0: the square clipped
// by the line (Sutherland–Hodgman), then the shoelace formula.
double clippedArea(double nx, double ny, double d) {
  std::vector<P> poly{{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}, out;
  const auto f = [&](P p) { return nx * p.x + ny * p.y + d; };
  for (size_t i = 0; i < poly.size(); ++i) {
    const P a = poly[i], b = poly[(i + 1) % poly.size()];
    const double fa = f(a), fb = f(b);
    if (fa >= 0) out.push_back(a);
    if ((fa >= 0) != (fb >= 0)) {
      const double t = fa / (fa - fb);
      out.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
    }
  }
  double area = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    const P a = out[i], b = out[(i + 1) % out.size()];
    area += a.x * b.y - b.x * a.y;
  }
  return std::fabs(area) / 2;
}

TEST(RecipientDonor, HalfPlaneAreaIsTheClippedSquaresArea) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), dist(-1, 1);
  for (int i = 0; i < 20000; ++i) {
    const double a = i < 8 ? i * M_PI / 4 : angle(rng), d = dist(rng);
    const double nx = std::cos(a), ny = std::sin(a);
    EXPECT_NEAR(segments::halfPlaneArea(nx, ny, d), clippedArea(nx, ny, d), 1e-12)
        << nx << " " << ny << " " << d;
  }
}

TEST(RecipientDonor, ABoundaryPixelsAreaAndDonorComeFromTheEdgeCrossingIt) {
  // A large triangle whose one edge runs through the raster at various slopes; the others far
  // outside. In every pixel that edge crosses, the recipient's area is the formula's from the
  // edge's own line, and the donor lies on the edge's far side.
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  const int w = 64, h = 48;
  geometry::Viewport vp;
  vp.width = w;
  vp.height = h;
  int checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // The edge from p to q in pixels (y down); the third vertex far on its left (counter-clockwise
    // in NDC after the flip of y), so the triangle lies on one side of it.
    const double a = u(rng) * 2 * M_PI;
    const double cx = 20 + 24 * u(rng), cy = 14 + 20 * u(rng);
    const P p{cx - 400 * std::cos(a), cy - 400 * std::sin(a)};
    const P q{cx + 400 * std::cos(a), cy + 400 * std::sin(a)};
    const P r{cx - 400 * std::sin(a), cy + 400 * std::cos(a)};
    const auto clip = [&](P v) {
      return geometry::ClipVertex{
          float(2 * v.x / w - 1), float(1 - 2 * v.y / h), 0.5f, 1, 1, 1, 1, 1};
    };
    geometry::TriangleSetup t;
    ASSERT_EQ(geometry::setupTriangle(clip(p), clip(q), clip(r), vp, geometry::CullMode::none, t),
              geometry::SetupOutcome::drawn);
    // The edge's inward unit normal in pixels (toward r); snapping moves the line by 1/256 px.
    double nx = -(q.y - p.y), ny = q.x - p.x;
    const double len = std::hypot(nx, ny);
    nx /= len;
    ny /= len;
    if (nx * (r.x - p.x) + ny * (r.y - p.y) < 0) nx = -nx, ny = -ny;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double d = nx * (x + 0.5 - p.x) + ny * (y + 0.5 - p.y);
        const double area = clippedArea(nx, ny, d);
        if (area <= 0.01 || area >= 0.99) continue;
        const segments::Recipient rec = segments::recipientOf(t, x, y);
        EXPECT_NEAR(rec.area, area, 0.01) << trial << " at " << x << "," << y;
        // Across the edge: the donor's direction against the inward normal.
        EXPECT_LT(rec.dx * nx + rec.dy * ny, 0) << trial << " at " << x << "," << y;
        ++checked;
      }
  }
  EXPECT_GT(checked, 1000);
}

}  // namespace
}  // namespace sv
