// Free-form surfaces as the scene records them (SPEC §11): perturbed quadrics, plain records
// (public API) shared by the scene's free-form objects and the volumes' shells
// (synthvis/volumes.h), drawn by the free forms' caster (src/freeform).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace sv::scene {

// A free-form surface (SPEC §11; docs/scene-format.md "Free forms"): the quadric
// F = Ax² + By² + Cz² + Dxy + Exz + Fyz + Gx + Hy + Iz + K (coefficients in this order; inside
// F ≥ 0) plus, for each perturbation, weight·max(0, Q)³ with Q itself a free form.
inline constexpr int kMaxFreeFormQuadrics = 256;  // per free-form object, perturbations included
inline constexpr int kMaxFreeFormDepth = 16;      // nesting of perturbations
inline constexpr size_t kMaxFreeFormObjects = 65536;

struct FreeFormNode {
  std::array<double, 10> quadric{};
  double weight = 1;  // where this node perturbs its parent: R = weight·Q³
  std::vector<FreeFormNode> perturbations;
  // At the root only: the form is min(F', C_1, …) — cut to the insides of these plain quadrics
  // (set-theoretic intersection, e.g. a cylinder capped by two planes).
  std::vector<std::array<double, 10>> clips;
  // This node's, its clips' and all its perturbations', recursively.
  int quadricCount() const {
    int n = 1 + int(clips.size());
    for (const FreeFormNode& p : perturbations) n += p.quadricCount();
    return n;
  }
};

}  // namespace sv::scene
