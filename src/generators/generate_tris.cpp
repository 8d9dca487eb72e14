// BENCH.md `tris`: random triangles of a given mean projected area.
//
// Per triangle (BENCH.md): target area A·U(0.5, 1.5); view distance U(2, 20); centroid uniform over
// the region; a plane tilted up to 60° from the view direction with a random azimuth; a roughly
// equilateral triangle (vertices at 120° ± 20° steps, radius U(0.75, 1.25)) scaled so that its
// projected area meets the target; vertex colours uniform in [64, 255] (sRGB-encoded display
// values, stored linear); UVs giving 0.5–4 texels per pixel on a 1024² texture.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

#include "generators/generator_common.h"
#include "synthvis/generators.h"
#include "texture/texture.h"

namespace sv::generators {
namespace {

constexpr double kYFov = 60.0 * std::numbers::pi / 180.0;

}  // namespace

Result<SubmitOrder> parseSubmitOrder(const std::string& text) {
  if (text == "random") return SubmitOrder::random;
  if (text == "f2b") return SubmitOrder::frontToBack;
  if (text == "b2f") return SubmitOrder::backToFront;
  return Error{"", "", "unknown order '" + text + "' (random, f2b or b2f)"};
}

const char* submitOrderName(SubmitOrder order) {
  switch (order) {
    case SubmitOrder::frontToBack:
      return "f2b";
    case SubmitOrder::backToFront:
      return "b2f";
    default:
      return "random";
  }
}

void addBenchTexture(Scene& s) {
  // BENCH.md's textured scenes: a 1024 × 1024 texture (grey noise, so every texel differs),
  // repeated, modulating the vertex colours.
  texture::Level level = texture::generateTexture(texture::Pattern::noise, 1024,
                                                  {0.2f, 0.2f, 0.2f, 1}, {1, 1, 1, 1}, 1);
  s.textures.push_back(
      {"bench-noise", std::make_shared<texture::Texture>(std::move(level), texture::Wrap::repeat,
                                                         texture::Wrap::repeat)});
  for (Material& m : s.materials) m.texture = 0;
}

void addBenchFog(Scene& s) {
  s.fog.enabled = true;
  s.fog.color = {0.5f, 0.55f, 0.6f};
  s.fog.beta = 0.1f;
}

Scene benchCameraScene(const std::string& name) {
  Scene s;
  Material mat;
  mat.name = name;
  mat.unlit = true;
  mat.doubleSided = true;
  s.materials.push_back(mat);
  s.instances.push_back({0, Mat4{}});
  s.cameras.push_back(detail::benchCamera({0, 0, 0}, {0, 0, -1}, 60, 0.1f, 100));
  s.light.enabled = false;
  s.background = {0, 0, 0};
  return s;
}

Scene generateTris(const TrisParams& p, TrisStats* stats) {
  std::mt19937_64 rng(p.seed);
  auto uniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };

  const double w = p.width, h = p.height, aspect = w / h;
  const double tanHalf = std::tan(kYFov / 2);
  // Pixel → eye-space direction at depth 1 (camera at the origin looking down −Z).
  auto rayAt = [&](double px, double py) {
    return Vec3d{(2 * px / w - 1) * tanHalf * aspect, (1 - 2 * py / h) * tanHalf, -1};
  };
  auto project = [&](Vec3d q, double& px, double& py) {
    px = (q.x / (-q.z) / (tanHalf * aspect) + 1) * 0.5 * w;
    py = (1 - q.y / (-q.z) / tanHalf) * 0.5 * h;
  };

  // The region the centroids fall in: a centred rectangle of the screen's aspect.
  double regionW = w, regionH = h;
  if (p.depth > 0) {
    const double area = std::min(w * h, p.count * p.area / p.depth);
    regionW = std::sqrt(area * aspect);
    regionH = area / regionW;
  }

  // UVs from a generator of their own, so that the geometry and colours are those of earlier
  // versions for the same seed.
  std::mt19937_64 uvRng(p.seed ^ 0x5DEECE66Dull);
  auto uvUniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(uvRng);
  };
  struct Tri {
    Vec3d v[3];
    float uv[3][2];
    float c[3][3];
    double distance;
    double area;
  };
  std::vector<Tri> tris(size_t(std::max(p.count, 0)));
  for (Tri& t : tris) {
    const double target = p.area * uniform(0.5, 1.5);
    const double distance = uniform(2, 20);
    const double sx = w / 2 + (uniform(0, 1) - 0.5) * regionW;
    const double sy = h / 2 + (uniform(0, 1) - 0.5) * regionH;
    const Vec3d dir = normalize(rayAt(sx, sy));
    const Vec3d centre = dir * (distance / -dir.z);  // at view depth `distance`
    // Plane normal: the direction back to the eye, tilted by up to 60° about a random axis.
    const Vec3d back = dir * -1.0;
    Vec3d helper = std::fabs(back.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    const Vec3d a1 = normalize(cross(back, helper)), a2 = cross(back, a1);
    const double tilt = uniform(0, 60) * std::numbers::pi / 180,
                 azimuth = uniform(0, 2 * std::numbers::pi);
    const Vec3d axis = a1 * std::cos(azimuth) + a2 * std::sin(azimuth);
    const Vec3d n = back * std::cos(tilt) + cross(axis, back) * std::sin(tilt);
    const Vec3d e1 = normalize(cross(n, helper)), e2 = cross(n, e1);
    // A roughly equilateral triangle of unit scale in that plane.
    double angle = uniform(0, 2 * std::numbers::pi);
    Vec3d local[3];
    for (int k = 0; k < 3; ++k) {
      const double r = uniform(0.75, 1.25);
      local[k] = e1 * (r * std::cos(angle)) + e2 * (r * std::sin(angle));
      angle += (120 + uniform(-20, 20)) * std::numbers::pi / 180;
    }
    // Scale to the target projected area (projection is nearly linear at this size: two passes).
    double scale = distance * 0.01;
    double area = 0;
    for (int pass = 0; pass < 3; ++pass) {
      double px[3], py[3];
      for (int k = 0; k < 3; ++k) {
        t.v[k] = centre + local[k] * scale;
        project(t.v[k], px[k], py[k]);
      }
      area = 0.5 * std::fabs((px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]));
      if (pass < 2 && area > 0) scale *= std::sqrt(target / area);
    }
    t.area = area;
    t.distance = distance;
    // BENCH.md: ρ = 0.5 … 4 texels per pixel on a 1024-texel texture. A pixel at this distance
    // spans 2·tan(fov/2)·distance/h world units (ignoring tilt), so uv per world unit is
    // ρ / (1024 · pixel size); the in-plane coordinates (e1, e2) give u and v.
    {
      constexpr double kTextureSide = 1024;
      const double rho = std::exp2(uvUniform(-1, 2));
      const double pixelWorld = 2 * tanHalf * distance / h;
      const double uvPerWorld = rho / (kTextureSide * pixelWorld);
      const double u0 = uvUniform(0, 1), v0 = uvUniform(0, 1);
      for (int k = 0; k < 3; ++k) {
        const Vec3d d = local[k] * scale;
        t.uv[k][0] = float(u0 + dot(d, e1) * uvPerWorld);
        t.uv[k][1] = float(v0 + dot(d, e2) * uvPerWorld);
      }
    }
    for (auto& c : t.c) {
      const Vec4 v = detail::randomBenchColor(rng);
      c[0] = v.x, c[1] = v.y, c[2] = v.z;
    }
  }
  if (p.order != SubmitOrder::random) {
    std::stable_sort(tris.begin(), tris.end(), [&](const Tri& a, const Tri& b) {
      return p.order == SubmitOrder::frontToBack ? a.distance < b.distance
                                                 : a.distance > b.distance;
    });
  }

  Scene s = benchCameraScene("tris");
  Mesh m;
  m.name = "tris";
  m.material = 0;
  m.positions.reserve(tris.size() * 3);
  m.colors.reserve(tris.size() * 3);
  m.uvs.reserve(tris.size() * 3);
  m.indices.reserve(tris.size() * 3);
  double totalArea = 0;
  for (const Tri& t : tris) {
    for (int k = 0; k < 3; ++k) {
      m.indices.push_back(uint32_t(m.positions.size()));
      m.positions.push_back({float(t.v[k].x), float(t.v[k].y), float(t.v[k].z)});
      m.colors.push_back({t.c[k][0], t.c[k][1], t.c[k][2], 1});
      m.uvs.push_back({t.uv[k][0], t.uv[k][1]});
    }
    totalArea += t.area;
  }
  s.meshes.push_back(std::move(m));
  if (p.textured) addBenchTexture(s);
  if (p.fog) addBenchFog(s);
  if (stats) {
    stats->meanArea = tris.empty() ? 0 : totalArea / double(tris.size());
    stats->depthComplexity = totalArea / (regionW * regionH);
  }
  return s;
}

}  // namespace sv::generators
