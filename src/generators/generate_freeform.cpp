// BENCH.md `freeform` and `freeform-one`: perturbed quadrics (SPEC §11) for multi-level ray casting
// (SPEC §12) and its baselines.
#include <cmath>
#include <numbers>
#include <random>

#include "core/quadric.h"
#include "generators/generator_common.h"
#include "synthvis/generators.h"

namespace sv::generators {
namespace {

// A perturbation: a small sphere or ellipsoid centred on `at`, a bump (w > 0) or a dent (w < 0).
FreeFormNode perturbation(Vec3d at, double radius, bool ellipsoid, double weight) {
  FreeFormNode n;
  n.quadric = ellipsoid ? Quadric::ellipsoid(at, {radius * 1.3, radius * 0.7, radius}).c
                        : Quadric::sphere(at, radius).c;
  n.weight = weight;
  return n;
}

void addBenchLight(Scene& s) {
  s.light.enabled = true;
  s.light.direction = {-0.5f, -1.0f, -0.6f};
  s.light.color = {1.0f, 0.97f, 0.92f};
  s.light.ambient = 0.3f;
}

}  // namespace

Scene generateFreeForms(const FreeFormParams& p) {
  std::mt19937_64 rng(p.seed);
  auto uniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  Scene s;
  s.background = {0.55f, 0.62f, 0.72f};
  addBenchLight(s);
  s.fog = {true, {0.55f, 0.62f, 0.72f}, 0.04f};
  s.cameras.push_back(detail::benchCamera({0, 0, 0}, {0, 0, -1}, 60, 0.5f, 100));
  // Eight Phong materials of random colours.
  for (int m = 0; m < 8; ++m) {
    Material mat;
    mat.name = "freeform" + std::to_string(m);
    mat.baseColor = {float(uniform(0.2, 0.9)), float(uniform(0.2, 0.9)), float(uniform(0.2, 0.9)),
                     1};
    mat.phong = true;
    mat.specular = float(uniform(0.1, 0.5));
    mat.shininess = float(uniform(10, 60));
    s.materials.push_back(mat);
  }
  const double tanHalf = std::tan(std::numbers::pi / 6), aspect = double(p.width) / p.height;
  for (int i = 0; i < p.count; ++i) {
    FreeFormObject o;
    o.name = "freeform" + std::to_string(i);
    o.material = int(uniform(0, 8));
    // Placement: depth 5 … 25 m, anywhere in the view; the size grows with depth, so that near and
    // far objects cover similar areas and overlap in part.
    const double depth = 5 * std::pow(5.0, uniform(0, 1));
    const double r = 0.55 * std::sqrt(depth / 5) * uniform(0.7, 1.3);
    const Vec3 centre{float(uniform(-0.95, 0.95) * depth * tanHalf * aspect),
                      float(uniform(-0.95, 0.95) * depth * tanHalf), float(-depth)};
    const Vec3 axis =
        normalize(Vec3{float(uniform(-1, 1)), float(uniform(-1, 1)), float(uniform(-1, 1))});
    o.transform =
        Mat4::translation(centre) * Mat4::rotation(axis, float(uniform(0, 2 * std::numbers::pi)));
    // The base: sphere, ellipsoid, capped cylinder or capped paraboloid, about the origin.
    const int kind = int(uniform(0, 4));
    Vec3d radii{r, r, r};
    if (kind == 0) {
      o.form.quadric = Quadric::sphere({0, 0, 0}, r).c;
    } else if (kind == 1) {
      radii = {r * uniform(0.6, 1.4), r * uniform(0.6, 1.4), r * uniform(0.6, 1.4)};
      o.form.quadric = Quadric::ellipsoid({0, 0, 0}, radii).c;
    } else if (kind == 2) {
      const double h = r * uniform(0.6, 1.5);
      o.form.quadric = Quadric::cylinder({0, 0, 0}, {0, 1, 0}, 0.7 * r).c;
      o.form.clips = {Quadric::halfSpace({0, 1, 0}, h).c, Quadric::halfSpace({0, -1, 0}, h).c};
      radii = {0.7 * r, h, 0.7 * r};
    } else {
      const double h = r * uniform(0.8, 1.4);
      o.form.quadric = Quadric::paraboloid({0, -h, 0}, {0, 1, 0}, 2 * h / (r * r)).c;
      o.form.clips = {Quadric::halfSpace({0, 1, 0}, h).c};
      radii = {r, h, r};
    }
    // 1 … 5 perturbations on the surface: mostly bumps, some dents.
    const int perturbations = 1 + int(uniform(0, 5));
    for (int k = 0; k < perturbations; ++k) {
      Vec3d d{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
      const double l = std::sqrt(dot(d, d)) + 1e-9;
      const Vec3d at{d.x / l * radii.x, d.y / l * radii.y, d.z / l * radii.z};
      const double weight = uniform(0, 1) < 0.7 ? uniform(0.5, 3) : -uniform(0.5, 2);
      o.form.perturbations.push_back(
          perturbation(at, r * uniform(0.25, 0.5), uniform(0, 1) < 0.5, weight));
    }
    s.freeForms.push_back(std::move(o));
  }
  return s;
}

Scene generateFreeFormOne() {
  Scene s;
  s.background = {0.08f, 0.09f, 0.12f};
  addBenchLight(s);
  s.cameras.push_back(detail::benchCamera({0, 0.9f, 3.6f}, {0, 0, 0}, 45, 0.5f, 20));
  Material clay;
  clay.name = "clay";
  clay.baseColor = {0.75f, 0.45f, 0.3f, 1};
  clay.phong = true;
  clay.specular = 0.35f;
  clay.shininess = 40;
  s.materials.push_back(clay);
  // A unit sphere with six perturbations on its surface, at the six axis points: alternately a
  // bump and a dent, alternately a sphere and an ellipsoid.
  FreeFormObject o;
  o.name = "freeform-one";
  o.material = 0;
  o.form.quadric = Quadric::sphere({0, 0, 0}, 1).c;
  const Vec3d axes[6] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  for (int k = 0; k < 6; ++k)
    o.form.perturbations.push_back(
        perturbation(axes[k], 0.45, k % 2 == 1, k % 2 == 0 ? 2.5 : -2.5));
  s.freeForms.push_back(std::move(o));
  return s;
}

}  // namespace sv::generators
