#include "synthvis/ground_truth.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/thread_pool.h"
#include "render/draw_packets.h"

namespace sv::reference {
namespace {

// One triangle in 2D homogeneous form: with V_k = (x_k, y_k, w_k) in clip space and p = (X, Y, 1)
// in normalized device coordinates, λ_k(p) = adj_k · p / det are β_k / w_P (3D barycentrics over
// the point's w), so "all λ_k ≥ 0" is "inside and in front of the eye", z_ndc = Σ λ_k z_k and a
// vertex attribute interpolates perspective-correctly as Σ λ_k f_k / Σ λ_k.
struct Tri {
  double adj[3][3];  // rows adj_k / det
  double z[3];
  double color[3][3];
  int x0, y0, x1, y1;  // pixel box to sample (inclusive), clipped to the raster
};

double linearFromSrgb(uint8_t v) {
  const double s = v / 255.0;
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

uint8_t srgbFromLinear(double l) {
  l = std::clamp(l, 0.0, 1.0);
  const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
  return uint8_t(std::lround(e * 255.0));
}

// Stratified samples: one per cell of an n×n grid, jittered inside it by a hash of the pixel,
// cell and axis (deterministic). A regular grid would favour the regular patterns it is used to
// judge — its own error is correlated with theirs: against a regular 16×16 truth, 4×4
// supersampling looked 1.5× better than 16 n-rooks samples on mixed.json, against this one they
// are level (docs/quality.md). One sample per pixel stays at the centre (point sampling).
double jitter(int n, int x, int y, int sx, int sy, int axis) {
  if (n == 1) return 0.5;
  uint64_t h = (uint64_t(uint32_t(x)) << 32 | uint32_t(y)) * 0x9E3779B97F4A7C15ull ^
               (uint64_t(sx) << 24 | uint64_t(sy) << 8 | uint64_t(axis));
  h ^= h >> 31;  // splitmix64 finalizer
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 31;
  return (double(h >> 11) + 0.5) / 9007199254740992.0;  // (0, 1)
}

// Triangle c's 2D homogeneous form and pixel box on a W × H raster, or nothing when it is not
// finite, degenerate, culled as a back face, or off the raster.
std::optional<Tri> homogeneousTriangle(const geometry::ClipVertex* const c[3], bool cullBack, int W,
                                       int H) {
  double V[3][3];
  bool finite = true;
  for (int k = 0; k < 3; ++k) {
    V[k][0] = c[k]->x;
    V[k][1] = c[k]->y;
    V[k][2] = c[k]->w;
    finite &= std::isfinite(c[k]->x) && std::isfinite(c[k]->y) && std::isfinite(c[k]->z) &&
              std::isfinite(c[k]->w);
  }
  if (!finite) return std::nullopt;
  Tri tri;
  double adj[3][3];
  for (int k = 0; k < 3; ++k) {
    const double* a = V[(k + 1) % 3];
    const double* b = V[(k + 2) % 3];
    adj[k][0] = a[1] * b[2] - a[2] * b[1];
    adj[k][1] = a[2] * b[0] - a[0] * b[2];
    adj[k][2] = a[0] * b[1] - a[1] * b[0];
  }
  const double det = V[0][0] * adj[0][0] + V[0][1] * adj[0][1] + V[0][2] * adj[0][2];
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) return std::nullopt;
  // Counter-clockwise in normalized device coordinates is the front (det > 0).
  if (cullBack && det < 0) return std::nullopt;
  for (int k = 0; k < 3; ++k) {
    for (int q = 0; q < 3; ++q) tri.adj[k][q] = adj[k][q] / det;
    tri.z[k] = c[k]->z;
    tri.color[k][0] = c[k]->r;
    tri.color[k][1] = c[k]->g;
    tri.color[k][2] = c[k]->b;
  }
  // The box: from the projected vertices when all are in front of the eye, else everything.
  tri.x0 = 0, tri.y0 = 0, tri.x1 = W - 1, tri.y1 = H - 1;
  if (c[0]->w > 0 && c[1]->w > 0 && c[2]->w > 0) {
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (int k = 0; k < 3; ++k) {
      const double px = (c[k]->x / double(c[k]->w) + 1) * 0.5 * W;
      const double py = (1 - c[k]->y / double(c[k]->w)) * 0.5 * H;
      lo[0] = std::min(lo[0], px), hi[0] = std::max(hi[0], px);
      lo[1] = std::min(lo[1], py), hi[1] = std::max(hi[1], py);
    }
    tri.x0 = int(std::clamp(std::floor(lo[0]), 0.0, double(W - 1)));
    tri.x1 = int(std::clamp(std::floor(hi[0]), 0.0, double(W - 1)));
    tri.y0 = int(std::clamp(std::floor(lo[1]), 0.0, double(H - 1)));
    tri.y1 = int(std::clamp(std::floor(hi[1]), 0.0, double(H - 1)));
    if (hi[0] < 0 || lo[0] > W || hi[1] < 0 || lo[1] > H) return std::nullopt;
  }
  return tri;
}

// Every sample of rows [yb0, yb1) (`S` a pixel, n per side): depth test "less" against the
// triangles in order, the winner's perspective-correct colour (`color`, 3 a sample, starting as
// the background) and index (`id`, −1 for the background).
void sampleBand(const std::vector<Tri>& tris, int W, int H, int n, int yb0, int yb1,
                std::vector<float>& color, std::vector<int32_t>& id) {
  const int S = n * n;
  std::vector<float> depth(id.size(), std::numeric_limits<float>::infinity());
  for (size_t ti = 0; ti < tris.size(); ++ti) {
    const Tri& t = tris[ti];
    const int ty0 = std::max(t.y0, yb0), ty1 = std::min(t.y1, yb1 - 1);
    for (int y = ty0; y <= ty1; ++y)
      for (int x = t.x0; x <= t.x1; ++x)
        for (int sy = 0; sy < n; ++sy)
          for (int sx = 0; sx < n; ++sx) {
            const double X = 2 * (x + (sx + jitter(n, x, y, sx, sy, 0)) / n) / W - 1;
            const double Y = 1 - 2 * (y + (sy + jitter(n, x, y, sx, sy, 1)) / n) / H;
            double l[3], sum = 0;
            bool inside = true;
            for (int k = 0; k < 3; ++k) {
              l[k] = t.adj[k][0] * X + t.adj[k][1] * Y + t.adj[k][2];
              inside &= l[k] >= 0;
              sum += l[k];
            }
            if (!inside || !(sum > 0)) continue;
            const double z = l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2];  // z / w
            if (z < -1 || z > 1) continue;                                   // near, far
            const size_t s = (size_t(y - yb0) * W + x) * S + size_t(sy * n + sx);
            const float zf = float(0.5 * (z + 1));
            if (!(zf < depth[s])) continue;
            depth[s] = zf;
            id[s] = int32_t(ti);
            for (int ch = 0; ch < 3; ++ch)
              color[s * 3 + ch] = float(std::clamp(
                  (l[0] * t.color[0][ch] + l[1] * t.color[1][ch] + l[2] * t.color[2][ch]) / sum,
                  0.0, 1.0));
          }
  }
}

}  // namespace

Result<Image> renderGroundTruth(const scene::Scene& scene, const GroundTruthOptions& g,
                                Image* edges) {
  RenderOptions o = g.options;
  if (Status s = validate(o); !s) return s.error();
  if (Status s = scene::validate(scene, ""); !s) return s.error();
  if (g.samplesPerSide < 1 || g.samplesPerSide > 32)
    return Error{"", "",
                 fmt::format("{} samples per side is out of range (1…32)", g.samplesPerSide)};
  const int W = o.width, H = o.height, n = g.samplesPerSide, S = n * n;
  core::ThreadPool pool(o.threads > 0 ? o.threads : 1);

  // The same clip-space vertices and lit colours as synthvis's vertex stage: the render stage's
  // draw packets (vertex colours only), their calls taken in the scene's order of instances — the
  // truth has no translucency, and drawn in that order a depth tie goes to the earlier instance.
  o.hsr = RenderOptions::Hsr::zbuffer;
  const Result<render::FrameCamera> camera = render::chooseCamera(scene, o);
  if (!camera.ok()) return camera.error();
  render::DrawPackets packets;
  if (Status s = render::buildDrawPackets(scene, o, camera.value(), nullptr, pool, packets); !s)
    return s.error();
  std::stable_sort(
      packets.calls.begin(), packets.calls.end(),
      [](const render::DrawCall& a, const render::DrawCall& b) { return a.instance < b.instance; });
  std::vector<Tri> tris;
  for (const render::DrawCall& call : packets.calls)
    for (uint32_t t = call.firstTriangle; t < call.firstTriangle + call.triangleCount; ++t) {
      const uint32_t* index = &packets.indices[size_t(t) * 3];
      const geometry::ClipVertex* c[3] = {&packets.vertices[index[0]], &packets.vertices[index[1]],
                                          &packets.vertices[index[2]]};
      if (auto tri = homogeneousTriangle(c, call.cull == geometry::CullMode::back, W, H))
        tris.push_back(*tri);
    }

  // Bands of rows in parallel; each keeps its samples' depth and colour, then box-filters its
  // pixels in linear light and marks the edges.
  constexpr int kBand = 4;
  const int bands = (H + kBand - 1) / kBand;
  std::vector<double> linear(size_t(W) * H * 3);
  std::vector<uint8_t> edge(size_t(W) * H);
  const float background[3] = {scene.background.x, scene.background.y, scene.background.z};
  pool.parallelFor(size_t(bands), [&](size_t band, int) {
    const int yb0 = int(band) * kBand, yb1 = std::min(H, yb0 + kBand);
    const size_t samples = size_t(yb1 - yb0) * W * S;
    std::vector<float> color(samples * 3);
    std::vector<int32_t> id(samples, -1);  // the triangle each sample shows; −1: background
    for (size_t i = 0; i < samples; ++i)
      for (int ch = 0; ch < 3; ++ch) color[i * 3 + ch] = background[ch];
    sampleBand(tris, W, H, n, yb0, yb1, color, id);
    for (int y = yb0; y < yb1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t base = (size_t(y - yb0) * W + x) * S;
        bool mixed = false;
        for (int s = 1; s < S; ++s) mixed |= id[base + size_t(s)] != id[base];
        edge[size_t(y) * W + x] = mixed;
        for (int ch = 0; ch < 3; ++ch) {
          double acc = 0;
          for (int s = 0; s < S; ++s) acc += color[(base + size_t(s)) * 3 + ch];
          linear[(size_t(y) * W + x) * 3 + ch] = acc / S;
        }
      }
  });
  Image image;
  image.width = W;
  image.height = H;
  image.rgb.resize(linear.size());
  for (size_t i = 0; i < linear.size(); ++i) image.rgb[i] = srgbFromLinear(linear[i]);
  if (edges) {
    edges->width = W;
    edges->height = H;
    edges->rgb.assign(size_t(W) * H * 3, 0);
    for (size_t i = 0; i < edge.size(); ++i)
      if (edge[i]) std::fill_n(edges->rgb.begin() + ptrdiff_t(i * 3), 3, uint8_t(255));
  }
  return image;
}

Result<ImageDifference> compareImages(const Image& a, const Image& b, const Image* mask) {
  if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size())
    return Error{"", "",
                 fmt::format("the images differ in size ({}x{} and {}x{})", a.width, a.height,
                             b.width, b.height)};
  if (mask && (mask->width != a.width || mask->height != a.height))
    return Error{"", "",
                 fmt::format("the edge mask is {}x{}, the images {}x{}", mask->width, mask->height,
                             a.width, a.height)};
  if (a.rgb.empty()) return Error{"", "", "the images are empty"};
  double lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = linearFromSrgb(uint8_t(i));
  ImageDifference d;
  double sum = 0, edgeSum = 0;
  const int W = a.width, H = a.height;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = (size_t(y) * W + x) * 3;
      bool edge = mask && (mask->rgb[i] | mask->rgb[i + 1] | mask->rgb[i + 2]) != 0;
      for (int dy = -1; dy <= 1 && !edge && !mask; ++dy)
        for (int dx = -1; dx <= 1 && !edge; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
          const size_t j = (size_t(ny) * W + nx) * 3;
          for (int ch = 0; ch < 3; ++ch)
            edge |= std::abs(int(b.rgb[i + ch]) - int(b.rgb[j + ch])) > 1;
        }
      double e = 0;
      for (int ch = 0; ch < 3; ++ch) {
        const double diff = lut[a.rgb[i + ch]] - lut[b.rgb[i + ch]];
        e += diff * diff;
      }
      sum += e;
      if (edge) {
        edgeSum += e;
        ++d.edgePixels;
      }
    }
  d.pixels = size_t(W) * H;
  auto psnr = [](double rmse) {
    return rmse > 0 ? 20 * std::log10(1.0 / rmse) : std::numeric_limits<double>::infinity();
  };
  d.rmse = std::sqrt(sum / double(d.pixels * 3));
  d.psnrDb = psnr(d.rmse);
  d.edgeRmse = d.edgePixels ? std::sqrt(edgeSum / double(d.edgePixels * 3)) : 0;
  d.edgePsnrDb = psnr(d.edgeRmse);
  return d;
}

}  // namespace sv::reference
