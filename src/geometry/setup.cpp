// Triangle setup without perspective divide.
//
// Based on: SPEC §2 (seed 000 §1, seed 004 eqs. 1–7); Olano & Greer 1997 (2D homogeneous
// rasterization); the fixed-point edge setup of zeux/meshoptimizer's rasterizer and Mesa
// llvmpipe's lp_setup_tri.c (for the idea of snapping, not their code).
//
// Symbols. Each vertex k is taken to homogeneous *pixel* coordinates V_k = (X_k, Y_k, W_k) with
// X = (x_clip + w)·width/2, Y = (w − y_clip)·height/2 (y grows downward), W = w. For a pixel
// position p = (x, y, 1), write p = Σ λ_k V_k. Then, with adj_k = V_i × V_j ((k, i, j) cyclic) and
// det = V_0 · adj_0,
//     λ_k(p) = adj_k · p / det                                                       (SPEC §2)
// are linear in (x, y): the *edge functions*. For a point P of the triangle with 3D barycentric
// weights β_k, λ_k = β_k / w_P, so "all λ_k ≥ 0" holds exactly on the part of the triangle in front
// of the eye (w_P > 0): triangles crossing the eye plane need no clipping (SPEC §2, "clipping
// reduces to culling"). Parameters follow from the same λ:
//     1/w = Σ λ_k,    z/w = Σ λ_k Z_k,    f/w = Σ λ_k f_k,    f = (f/w) / (1/w).
// The near plane z ≥ −w is one more edge: Σ λ_k (Z_k + W_k) = (z_P + w_P)/w_P ≥ 0.
//
// Exactness. The inside test uses integer edges. For an edge whose two vertices are in front of the
// eye and within the guard band, the edge is rebuilt from the vertices' projections snapped to
// 1/256 px: A = y_i − y_j, B = x_j − x_i, C = x_i·y_j − x_j·y_i, exact in int64 (budget in
// setup.h); adj_k = w_i·w_j·(that edge), so the sign — and the inside test — is unchanged by the
// divide. Other edges (a vertex behind the eye or far outside the screen, and the near/far planes)
// are the homogeneous cross products in double, scaled by a power of two and rounded to the same
// integer form. Either way an edge depends only on its two vertices and is computed in a canonical
// order, so the neighbour across a shared edge gets exactly the negated coefficients: shared edges
// are watertight.
#include "geometry/setup.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace sv::geometry {
namespace {

constexpr double kGuardBand = double(1 << kGuardBandLog2);  // pixels
constexpr int64_t kHalfPixel = kSubPixelScale / 2;
constexpr int kHomogeneousCoefBits = 23;  // max(|A|, |B|) of a rounded homogeneous edge ≤ 2^23
constexpr double kMaxHomogeneousC = 70368744177664.0;  // 2^46: beyond it the line misses the raster

struct HomVertex {
  double x, y, w;
};

HomVertex cross(const HomVertex& a, const HomVertex& b) {
  return {a.y * b.w - a.w * b.y, a.w * b.x - a.x * b.w, a.x * b.y - a.y * b.x};
}
double dot(const HomVertex& a, const HomVertex& b) { return a.x * b.x + a.y * b.y + a.w * b.w; }

bool lexLess(const HomVertex& a, const HomVertex& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.w < b.w;
}

// V_i × V_j computed in a canonical vertex order, so that V_j × V_i is exactly its negation.
HomVertex canonicalCross(const HomVertex& a, const HomVertex& b) {
  if (lexLess(b, a)) {
    HomVertex c = cross(b, a);
    return {-c.x, -c.y, -c.w};
  }
  return cross(a, b);
}

// Turns e(x_f, y_f) = a·x_f + b·y_f + c in sub-pixel units (inside ≥ 0) into per-pixel form at
// pixel centres, with the fill rule folded in: "e ≥ 0" becomes "e > 0" for edges that do not own
// their boundary, i.e. c − 1 on integers.
EdgeFunction toPixelEdge(int64_t a, int64_t b, int64_t c) {
  EdgeFunction e;
  e.c = a * kHalfPixel + b * kHalfPixel + c - (ownsBoundary(a, b) ? 0 : 1);
  e.a = static_cast<int32_t>(a);
  e.b = static_cast<int32_t>(b);
  return e;
}

// Rounds a homogeneous edge a·x + b·y + c (x, y in pixels) to integer sub-pixel form. The scale is
// a power of two chosen from max(|a|, |b|) alone, and rounding is symmetric about zero, so the
// negated input gives exactly the negated output.
EdgeFunction roundHomogeneousEdge(const HomVertex& e) {
  double a = e.x / kSubPixelScale, b = e.y / kSubPixelScale;
  double m = std::max(std::fabs(a), std::fabs(b));
  if (m == 0) {
    // A line at infinity: the sign of c decides for the whole plane.
    return toPixelEdge(0, 0, e.w > 0 ? 1 : (e.w < 0 ? -1 : 0));
  }
  int exponent;
  std::frexp(m, &exponent);  // m ∈ [2^(exponent−1), 2^exponent)
  double scale = std::ldexp(1.0, kHomogeneousCoefBits - exponent);
  double cs = std::clamp(e.w * scale, -kMaxHomogeneousC, kMaxHomogeneousC);
  return toPixelEdge(std::llround(a * scale), std::llround(b * scale), std::llround(cs));
}

// Clip-space outcodes: a triangle whose three vertices are all outside the same plane of the view
// volume cannot show a pixel, whatever the signs of w.
unsigned outcode(const ClipVertex& v) {
  unsigned code = 0;
  if (v.x < -v.w) code |= 1;
  if (v.x > v.w) code |= 2;
  if (v.y < -v.w) code |= 4;
  if (v.y > v.w) code |= 8;
  if (v.z < -v.w) code |= 16;
  if (v.z > v.w) code |= 32;
  return code;
}

int64_t floorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// The plane of a parameter with per-vertex values f_k, given the three edge functions
// g_k(p) = gx_k·x + gy_k·y + gc_k (x, y in pixels) with λ_k = g_k(p)·scale; evaluated relative to
// the centre of pixel (px0, py0) − 0.5.
Plane makePlane(const double g[3][3], const double f[3], double scale, double px, double py) {
  const double a = (f[0] * g[0][0] + f[1] * g[1][0] + f[2] * g[2][0]) * scale;
  const double b = (f[0] * g[0][1] + f[1] * g[1][1] + f[2] * g[2][1]) * scale;
  const double c = (f[0] * g[0][2] + f[1] * g[1][2] + f[2] * g[2][2]) * scale;
  return {static_cast<float>(a * px + b * py + c), static_cast<float>(a), static_cast<float>(b)};
}

// The per-vertex part of setup: the position on the raster snapped to 24.8 fixed point, valid
// (`snapped`) when the vertex is in front of the eye (w > 0) and inside the guard band. A pure
// function of the vertex: shared vertices snap identically in all their triangles.
struct ScreenVertex {
  int32_t x = 0, y = 0;  // 24.8
  bool snapped = false;
  double invW = 0;  // 1/w, kept for the parameter planes when snapped
};

// Always inlined into setup: called out of line, its 12-byte result went back through the stack
// with mismatched store and load sizes — store-forwarding stalls (docs/performance.md, "Setup
// and binning").
[[gnu::always_inline]] inline ScreenVertex snapVertex(const ClipVertex& c,
                                                      const Viewport& viewport) {
  ScreenVertex s;
  if (!(c.w > 0) || !std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.w)) return s;
  const double invW = 1.0 / c.w;
  const double px = (double(c.x) + c.w) * (0.5 * viewport.width) * invW;
  const double py = (double(c.w) - c.y) * (0.5 * viewport.height) * invW;
  s.invW = invW;
  if (std::fabs(px) < kGuardBand && std::fabs(py) < kGuardBand) {
    s.x = static_cast<int32_t>(std::lrint(px * kSubPixelScale));  // 24.8
    s.y = static_cast<int32_t>(std::lrint(py * kSubPixelScale));
    s.snapped = true;
  }
  return s;
}

// The barycentric functions λ_k = g_k(p)·scale (p in pixels) and the vertices' 1/w factors that
// parameters are multiplied by. Snapped triangles use the integer edges: adj_k = w_i·w_j·(edge
// k), det = w0·w1·w2·area2, so λ_k = edge_k(p) / (w_k·area2) — the screen-space form of the same
// functions, cheaper and consistent with the coverage test. Others use the homogeneous adjugate.
struct Lambda {
  double g[3][3];
  double scale;
  double invW[3];
};

Lambda lambdaFunctions(bool allSnapped, const int64_t intEdge[3][3], const ScreenVertex s[3],
                       const HomVertex adj[3], double det, int64_t area2) {
  Lambda l;
  for (int k = 0; k < 3; ++k) {
    if (allSnapped) {
      // edge in pixel units: A·256·x + B·256·y + C  (x_f = 256·x)
      l.g[k][0] = double(intEdge[k][0]) * kSubPixelScale;
      l.g[k][1] = double(intEdge[k][1]) * kSubPixelScale;
      l.g[k][2] = double(intEdge[k][2]);
      l.invW[k] = s[k].invW;
    } else {
      l.g[k][0] = adj[k].x;
      l.g[k][1] = adj[k].y;
      l.g[k][2] = adj[k].w;
      l.invW[k] = 1.0;
    }
  }
  l.scale = allSnapped ? 1.0 / double(area2) : 1.0 / det;
  return l;
}

}  // namespace

// Snapping happens here, per triangle, rather than once per vertex in a pass of its own: it is a
// pure function of the vertex, so a shared vertex still snaps identically in all its triangles, and
// the vertex is in registers here (a separate pass cost 12 ns per vertex, mostly memory traffic).
SetupOutcome setupTriangle(const ClipVertex& v0, const ClipVertex& v1, const ClipVertex& v2,
                           const Viewport& viewport, CullMode cull, TriangleSetup& out) {
  const ClipVertex* const v[3] = {&v0, &v1, &v2};

  // Step 1: reject non-finite input before any arithmetic (RASTER-NOTES pitfall 8).
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(v[k]->x) || !std::isfinite(v[k]->y) || !std::isfinite(v[k]->z) ||
        !std::isfinite(v[k]->w))
      return SetupOutcome::culledInvalid;

  // Step 2: trivial reject against the view volume.
  if ((outcode(v0) & outcode(v1) & outcode(v2)) != 0) return SetupOutcome::culledOutside;
  // No point of the triangle is in front of the eye (w > 0) when no vertex is.
  if (v0.w <= 0 && v1.w <= 0 && v2.w <= 0) return SetupOutcome::culledOutside;

  const ScreenVertex s[3] = {snapVertex(v0, viewport), snapVertex(v1, viewport),
                             snapVertex(v2, viewport)};
  const ScreenVertex* const sv[3] = {&s[0], &s[1], &s[2]};
  const bool allSnapped = sv[0]->snapped && sv[1]->snapped && sv[2]->snapped;
  bool needNear = false, needFar = false;
  for (int k = 0; k < 3; ++k) {
    needNear |= v[k]->z < -v[k]->w;
    needFar |= v[k]->z > v[k]->w;
  }
  int64_t sx[3], sy[3];
  for (int k = 0; k < 3; ++k) {
    sx[k] = sv[k]->x;
    sy[k] = sv[k]->y;
  }

  // Step 3: integer edges where both vertices are snapped: A = y_i − y_j, B = x_j − x_i,
  // C = x_i·y_j − x_j·y_i in 24.8 (exact; budget in setup.h).
  int64_t intEdge[3][3] = {};
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    if (sv[i]->snapped && sv[j]->snapped) {
      intEdge[k][0] = sy[i] - sy[j];
      intEdge[k][1] = sx[j] - sx[i];
      intEdge[k][2] = sx[i] * sy[j] - sx[j] * sy[i];
    }
  }

  // Step 4: orientation (the sign of det, which is the facing) and, for triangles with a vertex
  // behind the eye or outside the guard band, the homogeneous adjugate rows.
  int orientation;
  int64_t area2 = 0;  // twice the signed snapped area, (1/256 px)²
  HomVertex hv[3], adj[3];
  double det = 0;
  if (allSnapped) {
    area2 = intEdge[0][0] * sx[0] + intEdge[0][1] * sy[0] + intEdge[0][2];
    orientation = (area2 > 0) - (area2 < 0);
  } else {
    const double halfW = 0.5 * viewport.width, halfH = 0.5 * viewport.height;
    for (int k = 0; k < 3; ++k)
      hv[k] = {(double(v[k]->x) + v[k]->w) * halfW, (double(v[k]->w) - v[k]->y) * halfH,
               double(v[k]->w)};
    for (int k = 0; k < 3; ++k) adj[k] = canonicalCross(hv[(k + 1) % 3], hv[(k + 2) % 3]);
    det = dot(hv[0], adj[0]);
    orientation = std::isfinite(det) ? (det > 0) - (det < 0) : 0;
  }
  if (orientation == 0) return SetupOutcome::culledDegenerate;

  // Step 5: facing. Counter-clockwise in NDC (y up) is clockwise on the raster (y down): det < 0.
  const bool front = orientation < 0;
  if ((cull == CullMode::back && !front) || (cull == CullMode::front && front))
    return SetupOutcome::culledFacing;

  // Step 6: bounding box of the pixels reached (centres, or squares with an aperture). Only snapped
  // triangles have a trustworthy one: with a vertex behind the eye the projected corners do not
  // bound the triangle (pitfall 7), so the subdivision starts from the whole raster, as SPEC §3
  // does.
  int64_t minX = 0, minY = 0, maxX = viewport.width - 1, maxY = viewport.height - 1;
  out.small = false;
  if (allSnapped) {
    const int64_t x0 = std::min({sx[0], sx[1], sx[2]}), x1 = std::max({sx[0], sx[1], sx[2]});
    const int64_t y0 = std::min({sy[0], sy[1], sy[2]}), y1 = std::max({sy[0], sy[1], sy[2]});
    // Pixel px's centre is at 256·px + 128; its square spans [256·px, 256·px + 256).
    const int64_t low = boxInsetLow(viewport), high = boxInsetHigh(viewport);
    minX = std::max<int64_t>(minX, -floorDiv(low - x0, kSubPixelScale));
    maxX = std::min<int64_t>(maxX, floorDiv(x1 - high, kSubPixelScale));
    minY = std::max<int64_t>(minY, -floorDiv(low - y0, kSubPixelScale));
    maxY = std::min<int64_t>(maxY, floorDiv(y1 - high, kSubPixelScale));
    out.small = !needNear && !needFar &&
                std::max(x1 - x0, y1 - y0) <= int64_t(kSmallExtent) * kSubPixelScale;
  }
  if (minX > maxX || minY > maxY) return SetupOutcome::culledOutside;

  // Step 7: edges, oriented so that inside is ≥ 0.
  int edgeCount = 0;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    if (sv[i]->snapped && sv[j]->snapped) {
      out.edges[edgeCount++] = toPixelEdge(orientation * intEdge[k][0], orientation * intEdge[k][1],
                                           orientation * intEdge[k][2]);
    } else {
      out.edges[edgeCount++] = roundHomogeneousEdge(
          {orientation * adj[k].x, orientation * adj[k].y, orientation * adj[k].w});
    }
  }
  // Step 8: parameter planes, λ_k = g_k(p)·scale (lambdaFunctions).
  const Lambda lambda = lambdaFunctions(allSnapped, intEdge, s, adj, det, area2);
  const auto& g = lambda.g;
  const double scale = lambda.scale;
  const double* invW = lambda.invW;
  // The near (z ≥ −w) and far (z ≤ w) planes as edges (SPEC §2), only when some vertex is beyond:
  // Σ λ_k (w_k ± z_k) ≥ 0.
  auto planeEdge = [&](double sign) {
    HomVertex e = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      const double f = (double(v[k]->w) + sign * v[k]->z) * invW[k];
      e.x += f * g[k][0];
      e.y += f * g[k][1];
      e.w += f * g[k][2];
    }
    const double o = scale > 0 ? 1 : -1;  // orient so that inside is ≥ 0
    out.edges[edgeCount++] = roundHomogeneousEdge({o * e.x, o * e.y, o * e.w});
  };
  if (needNear) planeEdge(+1);
  if (needFar) planeEdge(-1);
  out.edgeCount = static_cast<uint8_t>(edgeCount);

  out.minX = static_cast<int16_t>(minX);
  out.minY = static_cast<int16_t>(minY);
  out.maxX = static_cast<int16_t>(maxX);
  out.maxY = static_cast<int16_t>(maxY);
  const double px = double(minX) + 0.5, py = double(minY) + 0.5;
  double f[3];
  for (int k = 0; k < 3; ++k) f[k] = 0.5 * (double(v[k]->z) + v[k]->w) * invW[k];  // depth 0…1
  out.depth = makePlane(g, f, scale, px, py);
  out.invW = makePlane(g, invW, scale, px, py);
  for (int k = 0; k < 3; ++k) f[k] = v[k]->r * invW[k];
  out.red = makePlane(g, f, scale, px, py);
  for (int k = 0; k < 3; ++k) f[k] = v[k]->g * invW[k];
  out.green = makePlane(g, f, scale, px, py);
  for (int k = 0; k < 3; ++k) f[k] = v[k]->b * invW[k];
  out.blue = makePlane(g, f, scale, px, py);
  return SetupOutcome::drawn;
}

void attributePlanes(const ClipVertex& v0, const ClipVertex& v1, const ClipVertex& v2,
                     const Viewport& viewport, const TriangleSetup& setup,
                     const float* const values[3], int count, Plane* out, unsigned used,
                     const uint8_t* slots) {
  // The same λ as setupTriangle's steps 3, 4 and 8 for this (drawn, so valid) triangle.
  const ClipVertex* const v[3] = {&v0, &v1, &v2};
  const ScreenVertex s[3] = {snapVertex(v0, viewport), snapVertex(v1, viewport),
                             snapVertex(v2, viewport)};
  const bool allSnapped = s[0].snapped && s[1].snapped && s[2].snapped;
  int64_t intEdge[3][3] = {};
  HomVertex adj[3] = {};
  double det = 0;
  int64_t area2 = 0;
  if (allSnapped) {
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      intEdge[k][0] = int64_t(s[i].y) - s[j].y;
      intEdge[k][1] = int64_t(s[j].x) - s[i].x;
      intEdge[k][2] = int64_t(s[i].x) * s[j].y - int64_t(s[j].x) * s[i].y;
    }
    area2 = intEdge[0][0] * s[0].x + intEdge[0][1] * s[0].y + intEdge[0][2];
  } else {
    const double halfW = 0.5 * viewport.width, halfH = 0.5 * viewport.height;
    HomVertex hv[3];
    for (int k = 0; k < 3; ++k)
      hv[k] = {(double(v[k]->x) + v[k]->w) * halfW, (double(v[k]->w) - v[k]->y) * halfH,
               double(v[k]->w)};
    for (int k = 0; k < 3; ++k) adj[k] = canonicalCross(hv[(k + 1) % 3], hv[(k + 2) % 3]);
    det = dot(hv[0], adj[0]);
  }
  const Lambda lambda = lambdaFunctions(allSnapped, intEdge, s, adj, det, area2);
  const double px = double(setup.minX) + 0.5, py = double(setup.minY) + 0.5;
  for (int a = 0; a < count; ++a) {
    if (!(used >> a & 1)) {
      out[a] = Plane{};
      continue;
    }
    const size_t at = slots ? slots[a] : size_t(a);
    const double f[3] = {values[0][at] * lambda.invW[0], values[1][at] * lambda.invW[1],
                         values[2][at] * lambda.invW[2]};
    out[a] = makePlane(lambda.g, f, lambda.scale, px, py);
  }
}

}  // namespace sv::geometry
