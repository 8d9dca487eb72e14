// Based on: SPEC §11–§12 (seed 003). Perturbed quadrics, their gradient and interval bounds, and
// their form in the projectively transformed view volume.
#include "freeform/freeform.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sv::freeform {

FreeForm fromNode(const scene::FreeFormNode& n) {
  FreeForm f;
  f.base.c = n.quadric;
  f.weight = n.weight;
  for (const scene::FreeFormNode& p : n.perturbations) f.perturbations.push_back(fromNode(p));
  for (const auto& c : n.clips) f.clips.push_back(Quadric{c});
  return f;
}

// u⁻⁴ and u⁻⁵ over u > 0: the factors of a perturbation's term in the cube (freeform.h).
struct InversePowers {
  Interval u4, u5;
};

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

InversePowers inversePowers(Interval u) {
  const double lo2 = u.lo * u.lo, hi2 = u.hi * u.hi;
  return {{1 / (hi2 * hi2), 1 / (lo2 * lo2)}, {1 / (hi2 * hi2 * u.hi), 1 / (lo2 * lo2 * u.lo)}};
}

// A perturbation's term w·max(0, v)³·u⁻⁴ added to `value`, and its derivative in z,
// w·(3p²·p'·u⁻⁴ − 4p³·u'·u⁻⁵) with p = max(0, v), u' = u1, added to `slope`.
void addPerturbation(Interval v, Interval dv, double w, const InversePowers& inv, double u1,
                     Interval& value, Interval& slope) {
  const Interval p = positivePart(v);
  const Interval dp = p.hi > 0 ? dv : Interval{0, 0};
  value = value + cube(p) * inv.u4 * w;
  slope = slope + ((square(p) * dp) * inv.u4 * 3 + cube(p) * inv.u5 * (-4 * u1)) * w;
}

// min(F', C) for a clip bounded by `clip`: its slope where it is the minimum throughout, both
// slopes where either may be.
Interval minimum(Interval a, Interval b) { return {std::min(a.lo, b.lo), std::min(a.hi, b.hi)}; }
void takeMinimum(Interval clip, Interval clipSlope, Interval& value, Interval& slope) {
  if (clip.hi < value.lo)
    slope = clipSlope;
  else if (clip.lo <= value.hi)
    slope = {std::min(slope.lo, clipSlope.lo), std::max(slope.hi, clipSlope.hi)};
  value = minimum(value, clip);
}

// The arithmetic rounds to nearest: bounds are widened by a few ulps of the magnitudes involved,
// so that a cell the surface passes through is never rejected.
Interval widened(Interval h) {
  const double margin = 1e-12 * (std::fabs(h.lo) + std::fabs(h.hi)) + 1e-300;
  return {h.lo - margin, h.hi + margin};
}

}  // namespace

double FreeForm::evaluate(Vec3d p) const {
  double f = base.evaluate(p);
  for (const FreeForm& q : perturbations) {
    const double v = q.evaluate(p);
    if (v > 0) f += q.weight * v * v * v;
  }
  for (const Quadric& c : clips) f = std::min(f, c.evaluate(p));
  return f;
}

Vec3d FreeForm::gradient(Vec3d p) const {
  if (!clips.empty()) {  // the gradient of whichever term is the minimum
    double f = base.evaluate(p);
    for (const FreeForm& q : perturbations) {
      const double v = q.evaluate(p);
      if (v > 0) f += q.weight * v * v * v;
    }
    const Quadric* active = nullptr;
    for (const Quadric& c : clips)
      if (const double v = c.evaluate(p); v < f) f = v, active = &c;
    if (active) return active->gradient(p);
  }
  Vec3d g = base.gradient(p);
  for (const FreeForm& q : perturbations) {
    const double v = q.evaluate(p);
    if (v > 0) g = g + q.gradient(p) * (3 * q.weight * v * v);
  }
  return g;
}

Interval FreeForm::bound(Interval x, Interval y, Interval z) const {
  Interval f = base.bound(x, y, z);
  for (const FreeForm& q : perturbations) f = f + cube(positivePart(q.bound(x, y, z))) * q.weight;
  for (const Quadric& c : clips) {
    const Interval b = c.bound(x, y, z);
    f = {std::min(f.lo, b.lo), std::min(f.hi, b.hi)};
  }
  return f;
}

int FreeForm::quadricCount() const {
  int n = 1;
  for (const FreeForm& q : perturbations) n += q.quadricCount();
  return n;
}

void ProjectedFreeForm::flatten(const FreeForm& form, const Mat4d& inverse,
                                std::vector<Node>& out) {
  const size_t at = out.size();
  out.push_back({form.base.transformedByInverse(inverse), form.weight, 0});
  for (const FreeForm& q : form.perturbations) flatten(q, inverse, out);
  out[at].end = uint32_t(out.size());
}

std::optional<ProjectedFreeForm> ProjectedFreeForm::make(const FreeForm& form,
                                                         const Mat4d& toCube) {
  const std::optional<Mat4d> inverse = toCube.inverse();
  if (!inverse) return std::nullopt;
  ProjectedFreeForm p;
  p.inverse_ = *inverse;
  flatten(form, *inverse, p.nodes_);
  for (const Quadric& c : form.clips) p.clips_.push_back(c.transformedByInverse(*inverse));
  const size_t perturbations = form.perturbations.size();
  p.manyPerturbations_ = perturbations > 64;
  p.rootPerturbations_ = perturbations >= 64 ? kAllActive : (uint64_t(1) << perturbations) - 1;
  return p;
}

double ProjectedFreeForm::evaluateNode(uint32_t i, Vec3d q, double invU4) const {
  double h = nodes_[i].q.evaluate(q);
  for (uint32_t c = i + 1; c < nodes_[i].end; c = nodes_[c].end) {
    const double v = evaluateNode(c, q, invU4);
    if (v > 0) h += nodes_[c].weight * v * v * v * invU4;
  }
  return h;
}

double ProjectedFreeForm::evaluate(Vec3d q) const {
  const auto& w = inverse_.m[3];
  const double u = w[0] * q.x + w[1] * q.y + w[2] * q.z + w[3];
  const double u2 = u * u;
  double h = evaluateNode(0, q, 1 / (u2 * u2));
  for (const Quadric& c : clips_) h = std::min(h, c.evaluate(q));
  return h;
}

Interval ProjectedFreeForm::boundNode(uint32_t i, Interval x, Interval y, Interval z,
                                      Interval invU4) const {
  Interval h = nodes_[i].q.bound(x, y, z);
  for (uint32_t c = i + 1; c < nodes_[i].end; c = nodes_[c].end)
    h = h + cube(positivePart(boundNode(c, x, y, z, invU4))) * invU4 * nodes_[c].weight;
  return h;
}

Interval ProjectedFreeForm::bound(Interval x, Interval y, Interval z) const {
  const auto& w = inverse_.m[3];
  const Interval u = x * w[0] + y * w[1] + z * w[2] + w[3];
  if (!(u.lo > 0)) return {-kInf, kInf};
  Interval h = boundNode(0, x, y, z, inversePowers(u).u4);
  for (const Quadric& c : clips_) h = minimum(h, c.bound(x, y, z));
  return widened(h);
}

void ProjectedFreeForm::boundNodeSlope(uint32_t i, Interval x, Interval y, Interval z,
                                       const InversePowers& inv, Interval& value,
                                       Interval& slope) const {
  const Quadric& q = nodes_[i].q;
  value = q.bound(x, y, z);
  slope = z * (2 * q.c[2]) + x * q.c[4] + y * q.c[5] + q.c[8];
  for (uint32_t c = i + 1; c < nodes_[i].end; c = nodes_[c].end) {
    Interval v, dv;
    boundNodeSlope(c, x, y, z, inv, v, dv);
    addPerturbation(v, dv, nodes_[c].weight, inv, inverse_.m[3][2], value, slope);
  }
}

void ProjectedFreeForm::bound(Interval x, Interval y, Interval z, Interval& value, Interval& slope,
                              uint64_t* active) const {
  const auto& w = inverse_.m[3];
  const Interval u = x * w[0] + y * w[1] + z * w[2] + w[3];
  const uint64_t take = active ? *active : kAllActive;
  if (!(u.lo > 0)) {
    value = slope = {-kInf, kInf};
    return;
  }
  // boundNodeSlope(0, …), noting which perturbations may be positive.
  const InversePowers inv = inversePowers(u);
  const Quadric& q = nodes_[0].q;
  value = q.bound(x, y, z);
  slope = z * (2 * q.c[2]) + x * q.c[4] + y * q.c[5] + q.c[8];
  int i = 0;
  for (uint32_t c = 1; c < nodes_[0].end; c = nodes_[c].end, ++i) {
    if (i < 64 && (take >> i & 1) == 0) continue;
    Interval v, dv;
    boundNodeSlope(c, x, y, z, inv, v, dv);
    if (active && i < 64 && v.hi <= 0) *active &= ~(uint64_t(1) << i);
    addPerturbation(v, dv, nodes_[c].weight, inv, inverse_.m[3][2], value, slope);
  }
  for (const Quadric& c : clips_)
    takeMinimum(c.bound(x, y, z), z * (2 * c.c[2]) + x * c.c[4] + y * c.c[5] + c.c[8], value,
                slope);
  value = widened(value);
  slope = widened(slope);
}

namespace {
// The quadric at fixed (x, y) as a·z² + b·z + c.
void alongZ(const Quadric& q, double x, double y, double& a, double& b, double& c) {
  const auto& k = q.c;
  a = k[2];
  b = k[4] * x + k[5] * y + k[8];
  c = (k[0] * x + k[3] * y + k[6]) * x + (k[1] * y + k[7]) * y + k[9];
}
}  // namespace

void ProjectedFreeForm::ray(double x, double y, RayFunction& out, uint64_t active) const {
  // The nodes in preorder, without the root's perturbations `active` leaves out (and their own):
  // the indices after a left-out subtree move down by its size.
  out.nodes_.resize(nodes_.size());
  uint32_t kept = 0, shift = 0;
  const auto keep = [&](uint32_t i) {
    RayFunction::Node& n = out.nodes_[kept++];
    alongZ(nodes_[i].q, x, y, n.a, n.b, n.c);
    n.weight = nodes_[i].weight;
    n.end = nodes_[i].end - shift;
  };
  keep(0);
  int k = 0;
  for (uint32_t c = 1; c < nodes_[0].end; c = nodes_[c].end, ++k) {
    if (k < 64 && (active >> k & 1) == 0) {
      shift += nodes_[c].end - c;
      continue;
    }
    for (uint32_t i = c; i < nodes_[c].end; ++i) keep(i);
  }
  out.nodes_[0].end = kept;
  out.nodes_.resize(kept);
  out.clips_.resize(clips_.size());
  for (size_t i = 0; i < clips_.size(); ++i) {
    RayFunction::Node& n = out.clips_[i];
    alongZ(clips_[i], x, y, n.a, n.b, n.c);
    n.weight = 1;
    n.end = 0;
  }
  const auto& w = inverse_.m[3];
  out.u0_ = w[0] * x + w[1] * y + w[3];
  out.u1_ = w[2];
}

double RayFunction::evaluateNode(uint32_t i, double z, double invU4) const {
  const Node& n = nodes_[i];
  double h = (n.a * z + n.b) * z + n.c;
  for (uint32_t c = i + 1; c < n.end; c = nodes_[c].end) {
    const double v = evaluateNode(c, z, invU4);
    if (v > 0) h += nodes_[c].weight * v * v * v * invU4;
  }
  return h;
}

// With the slope: d/dz [w·p³·u⁻⁴] = w·(3p²·p'·u⁻⁴ − 4p³·u'·u⁻⁵); du4 = −4u'·u⁻⁵.
double RayFunction::evaluateNode(uint32_t i, double z, double invU4, double du4,
                                 double& slope) const {
  const Node& n = nodes_[i];
  double h = (n.a * z + n.b) * z + n.c;
  slope = 2 * n.a * z + n.b;
  for (uint32_t c = i + 1; c < n.end; c = nodes_[c].end) {
    double dv;
    const double v = evaluateNode(c, z, invU4, du4, dv);
    if (v > 0) {
      const double w = nodes_[c].weight, v2 = v * v;
      h += w * v2 * v * invU4;
      slope += w * (3 * v2 * dv * invU4 + v2 * v * du4);
    }
  }
  return h;
}

double RayFunction::evaluate(double z, double& slope) const {
  const double u = u0_ + u1_ * z, u2 = u * u, invU4 = 1 / (u2 * u2);
  double h = evaluateNode(0, z, invU4, -4 * u1_ * invU4 / u, slope);
  for (const Node& c : clips_) {
    const double v = (c.a * z + c.b) * z + c.c;
    if (v < h) h = v, slope = 2 * c.a * z + c.b;
  }
  return h;
}

double RayFunction::evaluate(double z) const {
  const double u = u0_ + u1_ * z, u2 = u * u;
  double h = evaluateNode(0, z, 1 / (u2 * u2));
  for (const Node& c : clips_) h = std::min(h, (c.a * z + c.b) * z + c.c);
  return h;
}

}  // namespace sv::freeform
