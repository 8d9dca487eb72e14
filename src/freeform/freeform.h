// Free-form surfaces: perturbed quadrics (SPEC §11), in object space and in the projectively
// transformed view volume where they are ray cast (SPEC §12).
//
// Based on: SPEC §11 (seed 003; R = Q³ where Q ≥ 0, restored from the authors' later papers),
// §12 (the frustum mapped onto the cube [−1, 1]³ without raising the order of the surfaces).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "freeform/quadric.h"

namespace sv::freeform {

// F'(p) = F(p) + Σ_i R_i(p), R_i = w_i·Q_i(p)³ where Q_i(p) ≥ 0 and 0 elsewhere (SPEC §11): `base`
// is F, each perturbation a Q_i — itself a perturbed quadric, recursively — with its `weight` w_i.
// Inside is F' ≥ 0. Each R_i is C² (Q³ meets 0 with two vanishing derivatives) and local to the
// region Q_i ≥ 0. The seed's R = Q³ is w = 1, a bump; w < 0 makes a dent (BENCH.md's
// `freeform-one` has both).
struct FreeForm {
  Quadric base;
  double weight = 1;  // w of this form where it perturbs another (unused at the root)
  std::vector<FreeForm> perturbations;

  double evaluate(Vec3d p) const;
  Vec3d gradient(Vec3d p) const;  // analytic: ∇F + Σ 3·w_i·max(0, Q_i)²·∇Q_i
  // A range containing F' over the box (Q³ bounded through Q's bound).
  Interval bound(Interval x, Interval y, Interval z) const;
  int quadricCount() const;  // base and every perturbation, recursively
};

// A free form carried into the cube by a projective map M (object → cube, e.g. projection · view
// · model): every quadric becomes S' = M^{-T} S M^{-1} (SPEC §12). A projective map scales a
// quadric's values by u², u(q) the w of M^{-1}·(q, 1) (Quadric::transformedByInverse), which would
// not commute with the cube of a perturbation; so the function cast is
//   H(q) = u(q)²·F'(p(q)) = F_M(q) + Σ_i w_i·max(0, H_i(q))³ / u(q)⁴,
// recursively — the same surface and inside wherever u > 0 (in front of the eye).
class ProjectedFreeForm {
 public:
  // Nothing when M is singular.
  static std::optional<ProjectedFreeForm> make(const FreeForm& form, const Mat4d& toCube);

  double evaluate(Vec3d q) const;
  // A range containing H over the box, widened for the rounding of its double arithmetic;
  // everything (−∞, ∞) where the box reaches u ≤ 0 (behind the eye).
  Interval bound(Interval x, Interval y, Interval z) const;
  Vec3d toObject(Vec3d q) const { return inverse_.transformPoint(q); }
  const Mat4d& inverse() const { return inverse_; }

 private:
  // The quadrics in preorder: a node's perturbations follow it, its subtree ends at `end`.
  struct Node {
    Quadric q;
    double weight;
    uint32_t end;
  };
  double evaluateNode(uint32_t i, Vec3d q, double invU4) const;
  Interval boundNode(uint32_t i, Interval x, Interval y, Interval z, Interval invU4) const;
  static void flatten(const FreeForm& form, const Mat4d& inverse, std::vector<Node>& out);

  std::vector<Node> nodes_;
  Mat4d inverse_;
};

}  // namespace sv::freeform
