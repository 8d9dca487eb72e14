// BENCH.md `layers`: depth complexity D as D parallel screen-filling layers.
//
// Layer i of D faces the camera at view distance 2 + 18·i/(D−1) (2 … 20; 2 when D = 1) and fills
// the screen exactly: a grid of cells of about 20×20 px split into two triangles each (mean area
// ≈ 200 px), its interior vertices jittered by up to ±30 % of a cell (no fold-overs), its border
// vertices on the screen's edges — so every pixel is covered D times. Vertex colours as in `tris`.
// Submission order: random (all layers' triangles shuffled), f2b (nearest layer first) or b2f.
// Texture and fog (BENCH.md) come with their issues; the geometry is final.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "generators/generator_common.h"
#include "synthvis/generators.h"

namespace sv::generators {

Scene generateLayers(const LayersParams& p, TrisStats* stats) {
  std::mt19937_64 rng(p.seed);
  auto uniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  const double w = p.width, h = p.height, aspect = w / h;
  const double tanHalf = std::tan(30.0 * std::numbers::pi / 180.0);
  const int cols = std::max(1, int(std::lround(w / 20))),
            rows = std::max(1, int(std::lround(h / 20)));
  const double cellW = w / cols, cellH = h / rows;

  // UVs from a generator of their own, so that the geometry and colours are those of earlier
  // versions for the same seed: per layer an offset and a density in texels per pixel.
  std::mt19937_64 uvRng(p.seed ^ 0x5DEECE66Dull);
  auto uvUniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(uvRng);
  };
  struct Tri {
    Vec3 v[3];
    Vec4 c[3];
    Vec2 uv[3];
    int layer;
  };
  std::vector<Tri> tris;
  tris.reserve(size_t(p.layers) * cols * rows * 2);
  double totalArea = 0;
  for (int layer = 0; layer < p.layers; ++layer) {
    const double z = p.layers == 1 ? 2.0 : 2.0 + 18.0 * layer / (p.layers - 1);
    // Pixel (px, py) at view distance z (camera at the origin looking down −Z).
    auto world = [&](double px, double py) {
      return Vec3{float((2 * px / w - 1) * z * tanHalf * aspect),
                  float((1 - 2 * py / h) * z * tanHalf), float(-z)};
    };
    const double uvPerPixel = std::exp2(uvUniform(-1, 2)) / 1024.0;  // BENCH.md's 1024² texture
    const double u0 = uvUniform(0, 1), v0 = uvUniform(0, 1);
    std::vector<double> gx(size_t(cols + 1) * (rows + 1)), gy(gx.size());
    for (int j = 0; j <= rows; ++j)
      for (int i = 0; i <= cols; ++i) {
        double px = i * cellW, py = j * cellH;
        if (i > 0 && i < cols) px += uniform(-0.3, 0.3) * cellW;
        if (j > 0 && j < rows) py += uniform(-0.3, 0.3) * cellH;
        gx[size_t(j) * (cols + 1) + i] = px;
        gy[size_t(j) * (cols + 1) + i] = py;
      }
    for (int j = 0; j < rows; ++j)
      for (int i = 0; i < cols; ++i) {
        const size_t a = size_t(j) * (cols + 1) + i, b = a + 1, c = a + cols + 1, d = c + 1;
        for (const auto& t : {std::array<size_t, 3>{a, b, d}, std::array<size_t, 3>{a, d, c}}) {
          Tri tri;
          tri.layer = layer;
          for (int k = 0; k < 3; ++k) {
            tri.v[k] = world(gx[t[k]], gy[t[k]]);
            tri.uv[k] = {float(u0 + gx[t[k]] * uvPerPixel), float(v0 + gy[t[k]] * uvPerPixel)};
            tri.c[k] = detail::randomBenchColor(rng);
          }
          totalArea += 0.5 * std::fabs((gx[t[1]] - gx[t[0]]) * (gy[t[2]] - gy[t[0]]) -
                                       (gx[t[2]] - gx[t[0]]) * (gy[t[1]] - gy[t[0]]));
          tris.push_back(tri);
        }
      }
  }
  switch (p.order) {
    case SubmitOrder::random:
      std::shuffle(tris.begin(), tris.end(), rng);
      break;
    case SubmitOrder::frontToBack:
      break;  // generated nearest first
    case SubmitOrder::backToFront:
      std::stable_sort(tris.begin(), tris.end(),
                       [](const Tri& a, const Tri& b) { return a.layer > b.layer; });
      break;
  }

  Mesh m;
  m.name = "layers";
  m.material = 0;
  for (const Tri& t : tris)
    for (int k = 0; k < 3; ++k) {
      m.indices.push_back(uint32_t(m.positions.size()));
      m.positions.push_back(t.v[k]);
      m.colors.push_back(t.c[k]);
      m.uvs.push_back(t.uv[k]);
    }
  Scene s = benchCameraScene("layers");
  s.meshes.push_back(std::move(m));
  if (p.textured) addBenchTexture(s);
  if (p.fog) addBenchFog(s);
  if (stats) {
    stats->meanArea = tris.empty() ? 0 : totalArea / double(tris.size());
    stats->depthComplexity = totalArea / (w * h);
  }
  return s;
}

}  // namespace sv::generators
