// SurfacePoints (surface_points.h): the object point, gradient, normal and eye position of up to
// 16 hits, every hit a SIMD lane (Highway, per target), by the operations of Mat4d::transformPoint,
// FreeForm::gradient and normalize in their order (the build contracts nothing into FMAs).
//
// Based on: SPEC §12 (seed 003: at a leaf, the normal from the gradient).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "freeform/surface_points.cpp"
// clang-format off: foreach_target.h first, the per-target -inl.h headers after it
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
// clang-format on

#include <algorithm>

#include "freeform/interval_lanes-inl.h"
#include "freeform/surface_points.h"

HWY_BEFORE_NAMESPACE();
namespace sv::freeform {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

struct V3 {
  VD x, y, z;
};

// Mat4d::transformPoint.
HWY_INLINE V3 TransformPoint(DD d, const Mat4d& m, const V3& p) {
  VD r[4];
  for (int i = 0; i < 4; ++i)
    r[i] = hn::Add(
        hn::Add(hn::Add(hn::Mul(hn::Set(d, m.m[i][0]), p.x), hn::Mul(hn::Set(d, m.m[i][1]), p.y)),
                hn::Mul(hn::Set(d, m.m[i][2]), p.z)),
        hn::Set(d, m.m[i][3] * 1.0));
  return {hn::Div(r[0], r[3]), hn::Div(r[1], r[3]), hn::Div(r[2], r[3])};
}

// The 3×3 part of m times v (Mat4d acting on a direction).
HWY_INLINE V3 Apply3(DD d, const Mat4d& m, const V3& v) {
  VD r[3];
  for (int i = 0; i < 3; ++i)
    r[i] =
        hn::Add(hn::Add(hn::Mul(hn::Set(d, m.m[i][0]), v.x), hn::Mul(hn::Set(d, m.m[i][1]), v.y)),
                hn::Mul(hn::Set(d, m.m[i][2]), v.z));
  return {r[0], r[1], r[2]};
}

// Quadric::evaluate.
HWY_INLINE VD QuadricValue(DD d, const Quadric& q, const V3& p) {
  const auto& c = q.c;
  auto term = [&](double k, VD a, VD b) { return hn::Mul(hn::Mul(hn::Set(d, k), a), b); };
  VD f = hn::Add(term(c[0], p.x, p.x), term(c[1], p.y, p.y));
  f = hn::Add(f, term(c[2], p.z, p.z));
  f = hn::Add(f, term(c[3], p.x, p.y));
  f = hn::Add(f, term(c[4], p.x, p.z));
  f = hn::Add(f, term(c[5], p.y, p.z));
  f = hn::Add(f, hn::Mul(hn::Set(d, c[6]), p.x));
  f = hn::Add(f, hn::Mul(hn::Set(d, c[7]), p.y));
  f = hn::Add(f, hn::Mul(hn::Set(d, c[8]), p.z));
  return hn::Add(f, hn::Set(d, c[9]));
}

// Quadric::gradient.
HWY_INLINE V3 QuadricGradient(DD d, const Quadric& q, const V3& p) {
  const auto& c = q.c;
  auto row = [&](double a, VD u, double b, VD v, double e, VD w, double k) {
    return hn::Add(hn::Add(hn::Add(hn::Mul(hn::Set(d, a), u), hn::Mul(hn::Set(d, b), v)),
                           hn::Mul(hn::Set(d, e), w)),
                   hn::Set(d, k));
  };
  return {row(2 * c[0], p.x, c[3], p.y, c[4], p.z, c[6]),
          row(2 * c[1], p.y, c[3], p.x, c[5], p.z, c[7]),
          row(2 * c[2], p.z, c[4], p.x, c[5], p.y, c[8])};
}

// FreeForm::evaluate and FreeForm::gradient of node i's subtree (without clips); of the root's
// perturbations, those `active` holds.
VD ValueAndGradient(DD d, const ProjectedFreeForm::Node* nodes, uint32_t i, const V3& p, V3& g,
                    uint64_t active = kAllActive) {
  VD f = QuadricValue(d, nodes[i].q, p);
  g = QuadricGradient(d, nodes[i].q, p);
  int k = 0;
  for (uint32_t c = i + 1; c < nodes[i].end; c = nodes[c].end, ++k) {
    if (k < 64 && (active >> k & 1) == 0) continue;
    V3 gc;
    const VD v = ValueAndGradient(d, nodes, c, p, gc);
    const MD positive = hn::Gt(v, hn::Zero(d));
    const double w = nodes[c].weight;
    f = hn::IfThenElse(positive, hn::Add(f, hn::Mul(hn::Mul(hn::Mul(hn::Set(d, w), v), v), v)), f);
    const VD s = hn::Mul(hn::Mul(hn::Set(d, 3 * w), v), v);
    g = {hn::IfThenElse(positive, hn::Add(g.x, hn::Mul(gc.x, s)), g.x),
         hn::IfThenElse(positive, hn::Add(g.y, hn::Mul(gc.y, s)), g.y),
         hn::IfThenElse(positive, hn::Add(g.z, hn::Mul(gc.z, s)), g.z)};
  }
  return f;
}

void SurfaceAt(const ProjectedFreeForm& object, const Mat4d& cubeToObject, const Mat4d& objectToEye,
               const Mat4d& normalToEye, const double* x, const double* y, const double* z,
               int count, double uScale, double vScale, SurfaceLanes& out, uint64_t active,
               float (*floats)[16]) {
  const DD d;
  const size_t n = hn::Lanes(d);
  const ProjectedFreeForm::Node* nodes = object.nodes().data();
  // The hits, and zeros up to the last vector's end (the whole array cleared cost a `rep stos`
  // per call).
  alignas(64) double in[3][16];
  const size_t padded = (size_t(count) + n - 1) / n * n;
  const double* const from[3] = {x, y, z};
  for (int c = 0; c < 3; ++c) {
    std::copy_n(from[c], count, in[c]);
    std::fill(in[c] + count, in[c] + padded, 0.0);
  }
  for (size_t i = 0; i < size_t(count); i += n) {
    const V3 q{hn::Load(d, in[0] + i), hn::Load(d, in[1] + i), hn::Load(d, in[2] + i)};
    const V3 p = TransformPoint(d, cubeToObject, q);
    V3 g;
    VD f = ValueAndGradient(d, nodes, 0, p, g, active);
    // With clips, the gradient of whichever term is the minimum.
    for (const Quadric& clip : object.clips()) {
      const VD v = QuadricValue(d, clip, p);
      const MD below = hn::Lt(v, f);
      f = hn::IfThenElse(below, v, f);
      const V3 gc = QuadricGradient(d, clip, p);
      g = {hn::IfThenElse(below, gc.x, g.x), hn::IfThenElse(below, gc.y, g.y),
           hn::IfThenElse(below, gc.z, g.z)};
    }
    // normalize(normalToEye · (−∇F)): inside is F ≥ 0, so the outward normal is −∇F.
    const V3 m = Apply3(d, normalToEye, {hn::Neg(g.x), hn::Neg(g.y), hn::Neg(g.z)});
    const VD l =
        hn::Sqrt(hn::Add(hn::Add(hn::Mul(m.x, m.x), hn::Mul(m.y, m.y)), hn::Mul(m.z, m.z)));
    const MD positive = hn::Gt(l, hn::Zero(d));
    const VD r = hn::Div(hn::Set(d, 1.0), l);
    const V3 e = TransformPoint(d, objectToEye, p);
    const VD lanes[4][3] = {{p.x, p.y, p.z},
                            {g.x, g.y, g.z},
                            {hn::IfThenElse(positive, hn::Mul(m.x, r), m.x),
                             hn::IfThenElse(positive, hn::Mul(m.y, r), m.y),
                             hn::IfThenElse(positive, hn::Mul(m.z, r), m.z)},
                            {e.x, e.y, e.z}};
    double(*outs[4])[16] = {out.point, out.gradient, out.normal, out.eye};
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c) hn::Store(lanes[k][c], d, outs[k][c] + i);
    // The floats shading reads (round to nearest, as float(double) does).
    const hn::Rebind<float, DD> df;
    hn::Store(hn::DemoteTo(df, hn::Mul(p.x, hn::Set(d, uScale))), df, floats[out.kU] + i);
    hn::Store(hn::DemoteTo(df, hn::Mul(p.z, hn::Set(d, vScale))), df, floats[out.kV] + i);
    for (int c = 0; c < 3; ++c) {
      hn::Store(hn::DemoteTo(df, lanes[2][c]), df, floats[out.kNormal + c] + i);
      hn::Store(hn::DemoteTo(df, lanes[3][c]), df, floats[out.kEye + c] + i);
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::freeform
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::freeform {

HWY_EXPORT(SurfaceAt);

SurfacePoints::SurfacePoints(const FreeForm& form, const Mat4d& cubeToObject,
                             const Mat4d& objectToEye, const Mat4d& normalToEye, double uScale,
                             double vScale)
    : object_(*ProjectedFreeForm::make(form, Mat4d{})),  // the identity is never singular
      cubeToObject_(cubeToObject),
      objectToEye_(objectToEye),
      normalToEye_(normalToEye),
      uScale_(uScale),
      vScale_(vScale) {}

void SurfacePoints::at(const double* x, const double* y, const double* z, int count,
                       SurfaceLanes& out, uint64_t active, float (*floats)[16]) const {
  HWY_DYNAMIC_DISPATCH(SurfaceAt)
  (object_, cubeToObject_, objectToEye_, normalToEye_, x, y, z, std::clamp(count, 0, 16), uScale_,
   vScale_, out, active, floats ? floats : out.floats);
}

}  // namespace sv::freeform
#endif  // HWY_ONCE
