// Free-form surfaces: perturbed quadrics (SPEC §11), in object space and in the projectively
// transformed view volume where they are ray cast (SPEC §12).
//
// Based on: SPEC §11 (seed 003; R = Q³ where Q ≥ 0, restored from the authors' later papers),
// §12 (the frustum mapped onto the cube [−1, 1]³ without raising the order of the surfaces).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/quadric.h"
#include "synthvis/free_forms.h"

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
  // Set-theoretic intersection (issue 7's documented extension; at the root only): the form is
  // min(F', C_1, …, C_k) — its inside cut to the insides of these plain quadrics, e.g. a cylinder
  // capped by two half-spaces. Empty: F' alone.
  std::vector<Quadric> clips;

  double evaluate(Vec3d p) const;
  // Analytic: ∇F + Σ 3·w_i·max(0, Q_i)²·∇Q_i, or the gradient of the clip that is the minimum.
  Vec3d gradient(Vec3d p) const;
  // A range containing F' over the box (Q³ bounded through Q's bound).
  Interval bound(Interval x, Interval y, Interval z) const;
  int quadricCount() const;  // base and every perturbation, recursively
};

// A free form as the scene records it (synthvis/free_forms.h), as this stage models it.
FreeForm fromNode(const scene::FreeFormNode& node);

// A free form carried into the cube by a projective map M (object → cube, e.g. projection · view
// · model): every quadric becomes S' = M^{-T} S M^{-1} (SPEC §12). A projective map scales a
// quadric's values by u², u(q) the w of M^{-1}·(q, 1) (Quadric::transformedByInverse), which would
// not commute with the cube of a perturbation; so the function cast is
//   H(q) = u(q)²·F'(p(q)) = F_M(q) + Σ_i w_i·max(0, H_i(q))³ / u(q)⁴,
// recursively — the same surface and inside wherever u > 0 (in front of the eye).
class ProjectedFreeForm;
struct InversePowers;

// Where ProjectedFreeForm::quadricHits takes its hits: a window's per-pixel rows (pixel (i, j) at
// j·stride + i; object, cubeZ and active optional) and the masking pyramid's finest level
// (j·nodeStride + i), each hit writing its depth to both, `id`, its cube depth and `activeBits`.
struct HitRows {
  float* depth = nullptr;
  uint32_t* object = nullptr;
  double* cubeZ = nullptr;
  uint64_t* active = nullptr;
  size_t stride = 0;
  float* node = nullptr;
  size_t nodeStride = 0;
  uint32_t id = 0;
  uint64_t activeBits = 0;
};

// Every perturbation of a form taken as possibly active (ProjectedFreeForm::bound's `active`).
inline constexpr uint64_t kAllActive = ~uint64_t(0);

// Roots along a ray are refined until their bracket or Newton step is narrower than this (cube
// depth): float window depth resolves about 6e-8, and 1e-10 of cube depth is under 1e-5 of a
// pixel's footprint at any depth of BENCH.md's scenes (tests/freeform: within 1e-3 of a cell of
// the analytic hit).
inline constexpr double kRootTolerance = 1e-10;

// Newton's method along a ray has converged when its step s is below kRootTolerance, or when it
// converges quadratically and the error left after the step — about K·s², K ≈ s/previous² from
// the step before — is a hundredth of the tolerance: s³ ≤ 0.01·tol·previous², s < previous. This
// saves the step that would only confirm (measured: ~2.8 steps per ray before). `previous` 0:
// no Newton step before this one.
inline bool newtonConverged(double step, double previous) {
  return step <= kRootTolerance ||
         (step < previous && step * step * step <= 0.01 * kRootTolerance * previous * previous);
}  // u⁻⁴ and u⁻⁵ over a cell (freeform.cpp)

// H along one ray of the cube — x and y fixed, z free — where every quadric is a quadratic in z and
// u is linear: evaluation costs a few operations per quadric, and bounds over a z interval are
// exact per quadric (quadraticRange; the rays' bounds are taken in SIMD lanes, window_rays.cpp's
// BoundLanes). Built by ProjectedFreeForm::ray; reused from ray to ray.
class RayFunction {
 public:
  double evaluate(double z) const;
  double evaluate(double z, double& slope) const;  // and dH/dz there (Newton's method)
  // Cube depth ↔ eye depth along this ray: t = 1/u(z), u linear in z (ProjectedFreeForm).
  double eyeDepth(double z) const { return 1 / (u0_ + u1_ * z); }
  double cubeDepth(double t) const { return (1 / t - u0_) / u1_; }

 private:
  friend class ProjectedFreeForm;
  struct Node {
    double a, b, c, weight;  // the quadric a·z² + b·z + c; its weight as a perturbation
    uint32_t end;            // as ProjectedFreeForm::Node
  };
  double evaluateNode(uint32_t i, double z, double invU4) const;
  double evaluateNode(uint32_t i, double z, double invU4, double du4, double& slope) const;
  std::vector<Node> nodes_;
  std::vector<Node> clips_;
  double u0_ = 1, u1_ = 0;  // u(z) = u0 + u1·z
};

class ProjectedFreeForm {
 public:
  // Nothing when M is singular.
  static std::optional<ProjectedFreeForm> make(const FreeForm& form, const Mat4d& toCube);

  double evaluate(Vec3d q) const;
  // A range containing H over the box, widened for the rounding of its double arithmetic;
  // everything (−∞, ∞) where the box reaches u ≤ 0 (behind the eye).
  Interval bound(Interval x, Interval y, Interval z) const;
  // The same bound, and one of ∂H/∂z over the box: where that excludes 0, every ray (x, y) of the
  // box meets the surface at most once in it. `active` (if given): on entry, the root's
  // perturbations to bound — bit i for the i-th (i < 64; later ones are always bounded) — the
  // others being known to be 0 over the box (from a larger box); on return, bit i set where the
  // i-th may be positive somewhere in the box. Where it is clear, that perturbation's term is 0
  // throughout the box and can be left out of H there (see kAllActive).
  void bound(Interval x, Interval y, Interval z, Interval& value, Interval& slopeZ,
             uint64_t* active = nullptr) const;
  Vec3d toObject(Vec3d q) const { return inverse_.transformPoint(q); }
  // Which of `count` (1…16) equal slabs of [zlo, zhi] the surface may cross over the box x × y:
  // holds[s] ⇔ bound(x, y, slab s) contains 0, slab s being [zlo + (zhi − zlo)·s/count,
  // zlo + (zhi − zlo)·(s + 1)/count]. The same bounds, every slab at once (SIMD, slab_bounds.cpp:
  // the same operations in the same order, so the same answers on every target).
  // `take`: the root's perturbations to bound (the others are known to be 0 over the box, see
  // bound's `active`); `active` (if given): those of them that may be positive in some slab.
  void slabsHolding(Interval x, Interval y, double zlo, double zhi, int count, bool* holds,
                    uint64_t take = kAllActive, uint64_t* active = nullptr) const;
  // Rays (x[i], y[i]), i < count ≤ 16, on each of which H has at most one zero in [zlo, zhi[i]]
  // (a window's bound of ∂H/∂z excludes 0): z[i] is the zero, refined as refineBracket
  // (raycast.cpp) refines it — safeguarded Newton from guess[i] (or the secant point where the
  // guess lies outside, or is NaN), to kRootTolerance — or NaN where H has one sign at both ends
  // (or zhi[i] ≤ zlo). Every ray a SIMD lane (window_rays.cpp), each lane on its own, so every
  // target gives the same z.
  // `active`: the root's perturbations that may be positive over the rays (bound's `active`);
  // the others are left out of H.
  void monotonicCrossings(const double* x, const double* y, double zlo, const double* zhi,
                          int count, const double* guess, double* z,
                          uint64_t active = kAllActive) const;
  // The same for rays whose H may turn in [zlo, zhi[i]] (a window's slope bound holds 0): each
  // ray's span is cut at `pieces` equal steps of [zlo, max zhi] and taken front to back; the
  // ray's own bound (exact per quadric along the ray) over a piece rejects it, or says H is
  // monotonic there — a crossing, if the ends differ in sign, is z[i] — or neither: from[i] is
  // where that piece begins, for the ray's own subdivision (firstCrossing in raycast.cpp) to go on,
  // and z[i] NaN. z[i] and from[i] both NaN: no crossing. Returns the number of ray bounds made.
  int piecewiseCrossings(const double* x, const double* y, double zlo, const double* zhi, int count,
                         int pieces, const double* guess, double* z, double* from,
                         uint64_t active = kAllActive) const;
  // Rays (x[i], y[i]) whose H may turn in [zlo, zhi[i]] but which likely cross near guess[i] (a
  // neighbour's hit): Newton alone from the guess, as monotonicCrossings begins, and a zero it
  // converges to in the span kept only where the ray's own bound (exact per quadric along the ray)
  // over [zlo, zero] shows H monotonic there — then it is the ray's first crossing. z[i] is that
  // zero, or NaN where none was proven (a NaN guess: not tried), for piecewiseCrossings to decide.
  // Returns the number of ray bounds made.
  int provenCrossings(const double* x, const double* y, double zlo, const double* zhi, int count,
                      const double* guess, double* z, uint64_t active = kAllActive) const;
  // Whether H is its quadrics alone where `active` (bound's) holds none of the root's
  // perturbations: the root's quadric and the clips, each a quadratic along any ray of the cube
  // (a projective map keeps a quadric's order, SPEC §12) — so quadricCrossings solves its rays.
  bool quadricsAlone(uint64_t active) const {
    return (active & rootPerturbations_) == 0 && !manyPerturbations_ &&
           clips_.size() <= kMaxClipsSolved;
  }
  // Forms with more clips than this are never their quadrics alone (quadricCrossings holds the
  // quadrics in registers).
  static constexpr size_t kMaxClipsSolved = 7;
  // Rays (x[i], y[i]), i < count (any count), where H is its quadrics alone (quadricsAlone): z[i]
  // is the first crossing of H = min(root, clips) in (zlo, zhi[i]] in closed form — each quadric's
  // roots by the stable quadratic formula, the first that is an entry into every other quadric's
  // inside (an exit from one, where the ray starts inside) — or NaN where there is none (a
  // tangent touch is none). Every ray a SIMD lane, each on its own: the same bits on every target.
  void quadricCrossings(const double* x, const double* y, double zlo, const double* zhi, int count,
                        double* z) const;
  // quadricCrossings for the 8 × 8 rays columns[i] × rows[j] (cube x and y), each over
  // (zlo, min(zhi, the cube depth its pixel holds)], every crossing taken where its window
  // depth, rounded to float, is nearer than the pixel's — into `to`, a row of rays at a time.
  // Returns how many were taken; `last` becomes the cube depth of the last in raster order (left
  // as it is if none).
  int quadricHits(const double* columns, const double* rows, double zlo, double zhi,
                  const HitRows& to, double& last) const;
  // The first crossing of H along the ray (x, y) in [zlo, zhi] — of those `active` holds, the
  // root's perturbations taken — bracketed: spans split into 8 pieces at a time, bounded together
  // (the ray's own bounds, exact per quadric, a piece per SIMD lane), taken depth first and front
  // to back; a piece no bound lets hold a zero is dropped, a monotonic one — or one `narrowest`
  // wide or less — is decided by the signs of H at its ends, others are split again. True if found:
  // bracket = {a, b, H(a), H(b)}, the signs of H(a) and H(b) different (for refining). At most
  // `budget` spans are split; `bounds` gains the pieces bounded. The same on every target.
  bool crossingBracket(double x, double y, double zlo, double zhi, uint64_t active,
                       double narrowest, int budget, double bracket[4], int& bounds) const;
  // bound(x[i], y[i], z, value[i], slope[i], &active[i]) with active[i] = `take` on entry, for
  // up to 16 windows of one depth range, each window a SIMD lane (slab_bounds.cpp): the same
  // operations in the same order, so the same bits, on every target.
  void boundWindows(const Interval* x, const Interval* y, int count, Interval z, uint64_t take,
                    Interval* value, Interval* slope, uint64_t* active) const;
  // H along the ray (x, y) of the cube, into `out` (its storage reused); without the root's
  // perturbations `active` leaves out (known to be 0 along the ray, see bound).
  void ray(double x, double y, RayFunction& out, uint64_t active = kAllActive) const;
  const Mat4d& inverse() const { return inverse_; }

  // The quadrics in preorder: a node's perturbations follow it, its subtree ends at `end`.
  struct Node {
    Quadric q;
    double weight;
    uint32_t end;
  };
  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<Quadric>& clips() const { return clips_; }

 private:
  double evaluateNode(uint32_t i, Vec3d q, double invU4) const;
  Interval boundNode(uint32_t i, Interval x, Interval y, Interval z, Interval invU4) const;
  void boundNodeSlope(uint32_t i, Interval x, Interval y, Interval z, const InversePowers& inv,
                      Interval& value, Interval& slope) const;
  static void flatten(const FreeForm& form, const Mat4d& inverse, std::vector<Node>& out);

  std::vector<Node> nodes_;
  std::vector<Quadric> clips_;  // transformed like the nodes: min(H, u²·C_k) = u²·min(F', C_k)
  Mat4d inverse_;
  uint64_t rootPerturbations_ = 0;  // a bit per root perturbation (the first 64, as `active`)
  bool manyPerturbations_ = false;  // more than 64: the later ones are always in H
};

}  // namespace sv::freeform
