// Based on: SPEC §11–§12 (seed 003). Perturbed quadrics, their gradient and interval bounds, and
// their form in the projectively transformed view volume.
#include "freeform/freeform.h"

#include <cmath>
#include <limits>

namespace sv::freeform {

double FreeForm::evaluate(Vec3d p) const {
  double f = base.evaluate(p);
  for (const FreeForm& q : perturbations) {
    const double v = q.evaluate(p);
    if (v > 0) f += q.weight * v * v * v;
  }
  return f;
}

Vec3d FreeForm::gradient(Vec3d p) const {
  Vec3d g = base.gradient(p);
  for (const FreeForm& q : perturbations) {
    const double v = q.evaluate(p);
    if (v > 0) g = g + q.gradient(p) * (3 * q.weight * v * v);
  }
  return g;
}

Interval FreeForm::bound(Interval x, Interval y, Interval z) const {
  Interval f = base.bound(x, y, z);
  for (const FreeForm& q : perturbations)
    f = f + cube(positivePart(q.bound(x, y, z))) * q.weight;
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
  return evaluateNode(0, q, 1 / (u2 * u2));
}

Interval ProjectedFreeForm::boundNode(uint32_t i, Interval x, Interval y, Interval z,
                                      Interval invU4) const {
  Interval h = nodes_[i].q.bound(x, y, z);
  for (uint32_t c = i + 1; c < nodes_[i].end; c = nodes_[c].end)
    h = h + cube(positivePart(boundNode(c, x, y, z, invU4))) * invU4 * nodes_[c].weight;
  return h;
}

Interval ProjectedFreeForm::bound(Interval x, Interval y, Interval z) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const auto& w = inverse_.m[3];
  const Interval u = x * w[0] + y * w[1] + z * w[2] + w[3];
  if (!(u.lo > 0)) return {-kInf, kInf};
  const double lo2 = u.lo * u.lo, hi2 = u.hi * u.hi;
  const Interval h = boundNode(0, x, y, z, {1 / (hi2 * hi2), 1 / (lo2 * lo2)});
  // The arithmetic rounds to nearest: widen by a few ulps of the magnitudes involved so that a
  // cell the surface passes through is never rejected.
  const double margin = 1e-12 * (std::fabs(h.lo) + std::fabs(h.hi)) + 1e-300;
  return {h.lo - margin, h.hi + margin};
}

}  // namespace sv::freeform
