// Triangle setup for runs of triangles, several at once in SIMD lanes (RASTER-NOTES: "make small
// triangles cheap: SIMD setup across several triangles").
//
// The common case — every vertex finite, in front of the eye, inside the guard band and between
// the near and far planes — is computed in double lanes with exactly the operations, in exactly
// the order, of setupTriangle in setup.cpp, so every record is bit-identical to the scalar one
// (tests/geometry/setup_test.cpp compares them). The integer quantities of setup.cpp (snapped
// coordinates, edge coefficients, the doubled area, the fill-rule constant) are exact in double:
// |x_f|, |y_f| < 2^23, so products are < 2^46 and every sum < 2^50 < 2^53. Lanes outside the
// common case, and the tail of a run, go through setupTriangle itself.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "geometry/setup_batch.cpp"
#include <algorithm>
#include <cstring>

#include "core/check.h"
#include "geometry/setup.h"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace sv::geometry {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int kMaxLanes = 16;
// The lanes' results, a row per value (setupLanes writes them, storeRecords reads them): three
// edges (c, a, b), five planes (c0, dx, dy), the box, the outcome code and the small flag.
constexpr int kEdgeRows = 9, kPlaneRows = 15, kBoxRow = kEdgeRows + kPlaneRows;
constexpr int kCodeRow = kBoxRow + 4, kSmallRow = kCodeRow + 1;
constexpr int kLanesCode = 9;  // the outcome code of lanes left to the scalar path

// One group of N triangles in double lanes.
struct Lanes {
  alignas(64) double in[3][7][kMaxLanes];          // vertex k, component x y z w r g b, lane
  alignas(64) double o[kSmallRow + 1][kMaxLanes];  // results, per lane
  alignas(64) double ao[kMaxAttributePlanes][3][kMaxLanes];  // attribute planes, per lane
};

// Pixel shading's planes of record `record` in the request's output.
Plane* planesOf(const AttributeRequest& attributes, size_t record) {
  return reinterpret_cast<Plane*>(reinterpret_cast<char*>(attributes.out) +
                                  record * attributes.outStride);
}

// Triangle `tri` (its position in `indices`), drawn as record `record` by setupTriangle: its
// attribute planes by attributePlanes, as the lanes compute them.
void scalarAttributes(const ClipVertex* vertices, const uint32_t* indices, const Viewport& viewport,
                      const TriangleSetup* out, const AttributeRequest* attributes, size_t tri,
                      size_t record) {
  if (!attributes) return;
  const uint32_t* idx = indices + tri * 3;
  const float* values[3];
  for (int k = 0; k < 3; ++k) values[k] = attributes->values + idx[k] * attributes->valueStride;
  attributePlanes(vertices[idx[0]], vertices[idx[1]], vertices[idx[2]], viewport, out[record],
                  values, attributes->count, planesOf(*attributes, record), attributes->used,
                  attributes->slots);
}

// Triangle `tri` by setupTriangle itself, as record out[drawn] (and its attribute planes).
void setupScalar(const ClipVertex* vertices, const uint32_t* indices, const Viewport& viewport,
                 CullMode cull, TriangleSetup* out, uint64_t* outcomes, uint32_t firstTriangle,
                 const AttributeRequest* attributes, size_t tri, size_t& drawn) {
  const uint32_t* idx = indices + tri * 3;
  const SetupOutcome so = setupTriangle(vertices[idx[0]], vertices[idx[1]], vertices[idx[2]],
                                        viewport, cull, out[drawn]);
  out[drawn].triangle = firstTriangle + uint32_t(tri);
  ++outcomes[int(so)];
  if (so == SetupOutcome::drawn)
    scalarAttributes(vertices, indices, viewport, out, attributes, tri, drawn++);
}

// The helpers below are setupLanes' steps, force-inlined (HWY_INLINE) so that the kernel compiles
// as one body: their vectors stay in registers, and every operation keeps its order.

// Triangles [t, t + N)'s vertices into lanes.in, in double.
HWY_INLINE void gatherVertices(const ClipVertex* vertices, const uint32_t* indices, size_t t,
                               size_t N, Lanes& lanes) {
  for (size_t l = 0; l < N; ++l)
    for (int k = 0; k < 3; ++k) {
      const ClipVertex& v = vertices[indices[(t + l) * 3 + size_t(k)]];
      const float c[7] = {v.x, v.y, v.z, v.w, v.r, v.g, v.b};
      for (int q = 0; q < 7; ++q) lanes.in[k][q][l] = double(c[q]);
    }
}

// Step 1 (setup.cpp steps 1–3 and snapVertex): per lane whether the triangle is the common case
// (`common`) and whether its vertices all lie beyond one side of the view (`outside`); per vertex
// its z, w, 1/w and snapped position (sx, sy).
template <class D>
HWY_INLINE void snapVertices(D d, const Lanes& lanes, const Viewport& viewport, hn::Vec<D> z[3],
                             hn::Vec<D> w[3], hn::Vec<D> invW[3], hn::Vec<D> sx[3],
                             hn::Vec<D> sy[3], hn::Mask<D>& common, hn::Mask<D>& outside) {
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0);
  const auto sub = hn::Set(d, double(kSubPixelScale));
  const auto guard = hn::Set(d, double(1 << kGuardBandLog2));
  const auto halfW = hn::Set(d, 0.5 * viewport.width), halfH = hn::Set(d, 0.5 * viewport.height);
  const auto& in = lanes.in;
  common = hn::Eq(zero, zero);
  auto outLeft = common, outRight = common, outBottom = common, outTop = common;
  for (int k = 0; k < 3; ++k) {
    const auto x = hn::Load(d, in[k][0]);
    const auto y = hn::Load(d, in[k][1]);
    z[k] = hn::Load(d, in[k][2]);
    w[k] = hn::Load(d, in[k][3]);
    common = hn::And(common, hn::And(hn::And(hn::IsFinite(x), hn::IsFinite(y)),
                                     hn::And(hn::IsFinite(z[k]), hn::IsFinite(w[k]))));
    common = hn::And(common, hn::Gt(w[k], zero));
    // Between the near and far planes: no extra edges.
    common = hn::And(common, hn::And(hn::Ge(z[k], hn::Neg(w[k])), hn::Le(z[k], w[k])));
    outLeft = hn::And(outLeft, hn::Lt(x, hn::Neg(w[k])));
    outRight = hn::And(outRight, hn::Gt(x, w[k]));
    outBottom = hn::And(outBottom, hn::Lt(y, hn::Neg(w[k])));
    outTop = hn::And(outTop, hn::Gt(y, w[k]));
    invW[k] = hn::Div(one, w[k]);  // the snapping's and, in step 8, the planes' 1/w
    const auto px = hn::Mul(hn::Mul(hn::Add(x, w[k]), halfW), invW[k]);
    const auto py = hn::Mul(hn::Mul(hn::Sub(w[k], y), halfH), invW[k]);
    common = hn::And(common, hn::And(hn::Lt(hn::Abs(px), guard), hn::Lt(hn::Abs(py), guard)));
    sx[k] = hn::Round(hn::Mul(px, sub));  // lrint: to nearest, ties to even
    sy[k] = hn::Round(hn::Mul(py, sub));
  }
  outside = hn::Or(hn::Or(outLeft, outRight), hn::Or(outBottom, outTop));
}

// Steps 3–4: integer edges A = y_i − y_j, B = x_j − x_i, C = x_i·y_j − x_j·y_i of the snapped
// vertices (edge k opposite vertex k).
template <class D>
HWY_INLINE void integerEdges(D, const hn::Vec<D> sx[3], const hn::Vec<D> sy[3], hn::Vec<D> A[3],
                             hn::Vec<D> B[3], hn::Vec<D> C[3]) {
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    A[k] = hn::Sub(sy[i], sy[j]);
    B[k] = hn::Sub(sx[j], sx[i]);
    C[k] = hn::Sub(hn::Mul(sx[i], sy[j]), hn::Mul(sx[j], sy[i]));
  }
}

// Step 7: the edges oriented by `orient` (±1: inside positive) with the fill rule folded in
// (setup.cpp, toPixelEdge), rows c, a, b per edge: `owns` is geometry::ownsBoundary in lanes (the
// setup tests compare every record with the scalar one).
template <class D>
HWY_INLINE void storeEdges(D d, hn::Vec<D> orient, const hn::Vec<D> A[3], const hn::Vec<D> B[3],
                           const hn::Vec<D> C[3], double (*rows)[kMaxLanes]) {
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0);
  const auto halfPixel = hn::Set(d, double(kSubPixelScale / 2));
  for (int k = 0; k < 3; ++k) {
    const auto a = hn::Mul(orient, A[k]), b = hn::Mul(orient, B[k]), c = hn::Mul(orient, C[k]);
    const auto owns = hn::Or(hn::Gt(a, zero), hn::And(hn::Eq(a, zero), hn::Gt(b, zero)));
    const auto e = hn::Sub(hn::Add(hn::Add(hn::Mul(a, halfPixel), hn::Mul(b, halfPixel)), c),
                           hn::IfThenElseZero(hn::Not(owns), one));
    hn::Store(e, d, rows[3 * k]);
    hn::Store(a, d, rows[3 * k + 1]);
    hn::Store(b, d, rows[3 * k + 2]);
  }
}

// Step 8's basis: parameter planes λ_k = edge_k(p) / (w_k·area2), relative to (minX, minY) + ½.
template <class D>
struct PlaneBasis {
  hn::Vec<D> g[3][3];   // per vertex k: edge k's a, b (per pixel) and c
  hn::Vec<D> scale;     // 1 / area2
  hn::Vec<D> px0, py0;  // the box's first pixel centre
};

template <class D>
HWY_INLINE void planeBasis(D d, const hn::Vec<D> A[3], const hn::Vec<D> B[3], const hn::Vec<D> C[3],
                           hn::Vec<D> area2, hn::Vec<D> bx0, hn::Vec<D> by0, PlaneBasis<D>& basis) {
  const auto sub = hn::Set(d, double(kSubPixelScale)), half = hn::Set(d, 0.5);
  for (int k = 0; k < 3; ++k) {
    basis.g[k][0] = hn::Mul(A[k], sub);
    basis.g[k][1] = hn::Mul(B[k], sub);
    basis.g[k][2] = C[k];
  }
  basis.scale = hn::Div(hn::Set(d, 1.0), area2);
  basis.px0 = hn::Add(bx0, half);
  basis.py0 = hn::Add(by0, half);
}

// The plane of f (per vertex: value/w) into rows[0, 3): c0, dx, dy.
template <class D>
HWY_INLINE void storePlane(D d, const PlaneBasis<D>& basis, const hn::Vec<D> f[3],
                           double (*rows)[kMaxLanes]) {
  const auto& g = basis.g;
  const auto a = hn::Mul(
      hn::Add(hn::Add(hn::Mul(f[0], g[0][0]), hn::Mul(f[1], g[1][0])), hn::Mul(f[2], g[2][0])),
      basis.scale);
  const auto b = hn::Mul(
      hn::Add(hn::Add(hn::Mul(f[0], g[0][1]), hn::Mul(f[1], g[1][1])), hn::Mul(f[2], g[2][1])),
      basis.scale);
  const auto c = hn::Mul(
      hn::Add(hn::Add(hn::Mul(f[0], g[0][2]), hn::Mul(f[1], g[1][2])), hn::Mul(f[2], g[2][2])),
      basis.scale);
  hn::Store(hn::Add(hn::Add(hn::Mul(a, basis.px0), hn::Mul(b, basis.py0)), c), d, rows[0]);
  hn::Store(a, d, rows[1]);
  hn::Store(b, d, rows[2]);
}

// Step 8: the planes of depth (z/w mapped to [0, 1]), 1/w and the three colours, rows c0, dx, dy
// each.
template <class D>
HWY_INLINE void storePlanes(D d, const PlaneBasis<D>& basis, const Lanes& lanes,
                            const hn::Vec<D> z[3], const hn::Vec<D> w[3], const hn::Vec<D> invW[3],
                            double (*rows)[kMaxLanes]) {
  const auto half = hn::Set(d, 0.5);
  hn::Vec<D> f[3];
  for (int k = 0; k < 3; ++k) f[k] = hn::Mul(hn::Mul(half, hn::Add(z[k], w[k])), invW[k]);
  storePlane(d, basis, f, rows);
  storePlane(d, basis, invW, rows + 3);
  for (int ch = 0; ch < 3; ++ch) {
    for (int k = 0; k < 3; ++k) f[k] = hn::Mul(hn::Load(d, lanes.in[k][4 + ch]), invW[k]);
    storePlane(d, basis, f, rows + 6 + 3 * ch);
  }
}

// Pixel shading's planes of triangles [t, t + N) into lanes.ao: attributePlanes' λ is this one
// (the common case is all snapped).
template <class D>
HWY_INLINE void storeAttributePlanes(D d, const PlaneBasis<D>& basis, const uint32_t* indices,
                                     size_t t, const AttributeRequest& attributes,
                                     const hn::Vec<D> invW[3], Lanes& lanes) {
  const size_t N = hn::Lanes(d);
  hn::Vec<D> f[3];
  for (int a = 0; a < attributes.count; ++a) {
    if (!(attributes.used >> a & 1)) continue;
    alignas(64) double value[3][kMaxLanes];
    const size_t at = attributes.slots ? attributes.slots[a] : size_t(a);
    for (size_t l = 0; l < N; ++l)
      for (int k = 0; k < 3; ++k)
        value[k][l] = double(
            attributes.values[indices[(t + l) * 3 + size_t(k)] * attributes.valueStride + at]);
    for (int k = 0; k < 3; ++k) f[k] = hn::Mul(hn::Load(d, value[k]), invW[k]);
    storePlane(d, basis, f, lanes.ao[a]);
  }
}

// Setup of triangles [t, t + N) in the lanes of `d`, into lanes.o and (laneAttributes) lanes.ao.
template <class D>
HWY_INLINE void setupLanes(D d, const ClipVertex* vertices, const uint32_t* indices, size_t t,
                           const Viewport& viewport, CullMode cull,
                           const AttributeRequest* attributes, bool laneAttributes, Lanes& lanes) {
  const auto zero = hn::Zero(d), one = hn::Set(d, 1.0);
  const auto small = hn::Set(d, double(kSmallExtent) * kSubPixelScale);
  const auto maxX = hn::Set(d, double(viewport.width - 1)),
             maxY = hn::Set(d, double(viewport.height - 1));
  const auto inv256 = hn::Set(d, 1.0 / kSubPixelScale);
  const auto insetLow = hn::Set(d, double(boxInsetLow(viewport))),
             insetHigh = hn::Set(d, double(boxInsetHigh(viewport)));
  auto& o = lanes.o;
  gatherVertices(vertices, indices, t, hn::Lanes(d), lanes);
  // Step 1: the common case, and the snapped positions.
  hn::Vec<D> z[3], w[3], invW[3], sx[3], sy[3];
  hn::Mask<D> common, outside;
  snapVertices(d, lanes, viewport, z, w, invW, sx, sy, common, outside);
  // Steps 3–4: the integer edges; the doubled area.
  hn::Vec<D> A[3], B[3], C[3];
  integerEdges(d, sx, sy, A, B, C);
  const auto area2 = hn::Add(hn::Add(hn::Mul(A[0], sx[0]), hn::Mul(B[0], sy[0])), C[0]);
  const auto positive = hn::Gt(area2, zero), negative = hn::Lt(area2, zero);
  const auto orient = hn::IfThenElse(positive, one, hn::IfThenElseZero(negative, hn::Neg(one)));
  // Step 5: facing (front = clockwise on the raster = negative area).
  const auto degenerate = hn::Not(hn::Or(positive, negative));
  auto facing = hn::Eq(one, zero);
  if (cull == CullMode::back) facing = positive;
  if (cull == CullMode::front) facing = negative;
  // Step 6: the bounding box of the pixels reached (setup.h, boxInsetLow).
  const auto x0 = hn::Min(hn::Min(sx[0], sx[1]), sx[2]), x1 = hn::Max(hn::Max(sx[0], sx[1]), sx[2]);
  const auto y0 = hn::Min(hn::Min(sy[0], sy[1]), sy[2]), y1 = hn::Max(hn::Max(sy[0], sy[1]), sy[2]);
  const auto bx0 = hn::Max(zero, hn::Neg(hn::Floor(hn::Mul(hn::Sub(insetLow, x0), inv256))));
  const auto bx1 = hn::Min(maxX, hn::Floor(hn::Mul(hn::Sub(x1, insetHigh), inv256)));
  const auto by0 = hn::Max(zero, hn::Neg(hn::Floor(hn::Mul(hn::Sub(insetLow, y0), inv256))));
  const auto by1 = hn::Min(maxY, hn::Floor(hn::Mul(hn::Sub(y1, insetHigh), inv256)));
  const auto empty = hn::Or(hn::Gt(bx0, bx1), hn::Gt(by0, by1));
  const auto isSmall = hn::Le(hn::Max(hn::Sub(x1, x0), hn::Sub(y1, y0)), small);
  // Step 7: the oriented edges.
  storeEdges(d, orient, A, B, C, o);
  // Step 8: the planes, and pixel shading's.
  PlaneBasis<D> basis;
  planeBasis(d, A, B, C, area2, bx0, by0, basis);
  storePlanes(d, basis, lanes, z, w, invW, o + kEdgeRows);
  if (laneAttributes) storeAttributePlanes(d, basis, indices, t, *attributes, invW, lanes);
  hn::Store(bx0, d, o[kBoxRow]);
  hn::Store(by0, d, o[kBoxRow + 1]);
  hn::Store(bx1, d, o[kBoxRow + 2]);
  hn::Store(by1, d, o[kBoxRow + 3]);
  // Outcome code per lane, in setup.cpp's order: outside (outcodes), degenerate, facing,
  // outside (empty box), drawn; 9 for lanes left to the scalar path.
  auto code = hn::Set(d, double(SetupOutcome::drawn));
  code = hn::IfThenElse(empty, hn::Set(d, double(SetupOutcome::culledOutside)), code);
  code = hn::IfThenElse(facing, hn::Set(d, double(SetupOutcome::culledFacing)), code);
  code = hn::IfThenElse(degenerate, hn::Set(d, double(SetupOutcome::culledDegenerate)), code);
  code = hn::IfThenElse(outside, hn::Set(d, double(SetupOutcome::culledOutside)), code);
  code = hn::IfThenElse(common, code, hn::Set(d, double(kLanesCode)));
  hn::Store(code, d, o[kCodeRow]);
  hn::Store(hn::IfThenElseZero(isSmall, one), d, o[kSmallRow]);
}

// The records of the group's drawn lanes into out[drawn …), outcomes counted; lanes outside the
// common case through setupTriangle.
HWY_INLINE void storeRecords(const Lanes& lanes, size_t N, const ClipVertex* vertices,
                             const uint32_t* indices, size_t t, const Viewport& viewport,
                             CullMode cull, TriangleSetup* out, uint64_t* outcomes,
                             uint32_t firstTriangle, const AttributeRequest* attributes,
                             bool laneAttributes, size_t& drawn) {
  const auto& o = lanes.o;
  const auto& ao = lanes.ao;
  for (size_t l = 0; l < N; ++l) {
    const int outcome = int(o[kCodeRow][l]);
    if (outcome == kLanesCode) {
      setupScalar(vertices, indices, viewport, cull, out, outcomes, firstTriangle, attributes,
                  t + l, drawn);
      continue;
    }
    ++outcomes[outcome];
    if (outcome != int(SetupOutcome::drawn)) continue;
    TriangleSetup& s = out[drawn++];
    int q = 0;
    for (int k = 0; k < 3; ++k) {
      s.edges[k].c = int64_t(o[q++][l]);
      s.edges[k].a = int32_t(o[q++][l]);
      s.edges[k].b = int32_t(o[q++][l]);
    }
    for (Plane* p : {&s.depth, &s.invW, &s.red, &s.green, &s.blue}) {
      p->c0 = float(o[q++][l]);
      p->dx = float(o[q++][l]);
      p->dy = float(o[q++][l]);
    }
    s.minX = int16_t(o[q++][l]);
    s.minY = int16_t(o[q++][l]);
    s.maxX = int16_t(o[q++][l]);
    s.maxY = int16_t(o[q++][l]);
    s.edgeCount = 3;
    s.small = o[kSmallRow][l] != 0;
    s.triangle = firstTriangle + uint32_t(t + l);
    if (attributes && !laneAttributes)
      scalarAttributes(vertices, indices, viewport, out, attributes, t + l, drawn - 1);
    if (laneAttributes) {
      Plane* planes = planesOf(*attributes, drawn - 1);
      for (int a = 0; a < attributes->count; ++a)
        planes[a] = attributes->used >> a & 1
                        ? Plane{float(ao[a][0][l]), float(ao[a][1][l]), float(ao[a][2][l])}
                        : Plane{};
    }
  }
}

size_t SetupTriangles(const ClipVertex* vertices, const uint32_t* indices, size_t count,
                      const Viewport& viewport, CullMode cull, TriangleSetup* out,
                      uint64_t* outcomes, uint32_t firstTriangle,
                      const AttributeRequest* attributes) {
  const hn::ScalableTag<double> d;
  const size_t N = hn::Lanes(d);
  size_t drawn = 0;
  size_t t = 0;
  if (N >= 2 && N <= size_t(kMaxLanes)) {
    Lanes lanes;
    const bool laneAttributes = attributes && attributes->count <= kMaxAttributePlanes;
    for (; t + N <= count; t += N) {
      setupLanes(d, vertices, indices, t, viewport, cull, attributes, laneAttributes, lanes);
      storeRecords(lanes, N, vertices, indices, t, viewport, cull, out, outcomes, firstTriangle,
                   attributes, laneAttributes, drawn);
    }
  }
  for (; t < count; ++t)
    setupScalar(vertices, indices, viewport, cull, out, outcomes, firstTriangle, attributes, t,
                drawn);
  return drawn;
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::geometry
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::geometry {
HWY_EXPORT(SetupTriangles);

size_t setupTriangles(const ClipVertex* vertices, const uint32_t* indices, size_t count,
                      const Viewport& viewport, CullMode cull, TriangleSetup* out,
                      uint64_t outcomes[kSetupOutcomes], uint32_t firstTriangle,
                      const AttributeRequest* attributes) {
  return HWY_DYNAMIC_DISPATCH(SetupTriangles)(vertices, indices, count, viewport, cull, out,
                                              outcomes, firstTriangle, attributes);
}
}  // namespace sv::geometry
#endif
