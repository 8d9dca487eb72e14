#include "support/raster_harness.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <random>

#include "core/check.h"

namespace sv::test {

geometry::ClipVertex pixelVertex(double x, double y, int width, int height, float z, float w,
                                 float r, float g, float b) {
  // Inverse of setup's X = (x_clip + w)·width/2, Y = (w − y_clip)·height/2.
  const double xc = (2.0 * x / width - 1.0) * w;
  const double yc = (1.0 - 2.0 * y / height) * w;
  const double zc = (2.0 * z - 1.0) * w;
  return {float(xc), float(yc), float(zc), w, r, g, b, 1};
}

void addTriangle(render::DrawPackets& p, const geometry::ClipVertex& a,
                 const geometry::ClipVertex& b, const geometry::ClipVertex& c,
                 geometry::CullMode cull) {
  const uint32_t base = uint32_t(p.vertices.size());
  p.vertices.insert(p.vertices.end(), {a, b, c});
  p.indices.insert(p.indices.end(), {base, base + 1, base + 2});
  const uint32_t tri = uint32_t(p.indices.size() / 3 - 1);
  if (!p.calls.empty() && p.calls.back().cull == cull &&
      p.calls.back().firstTriangle + p.calls.back().triangleCount == tri) {
    ++p.calls.back().triangleCount;
  } else {
    p.calls.push_back({tri, 1, cull});
  }
}

render::DrawPackets randomScene(int width, int height, int count, unsigned seed, bool wild) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  render::DrawPackets p;
  for (int t = 0; t < count; ++t) {
    const double size = std::pow(2.0, 12 * u01(rng));  // 1 … 4096 px legs
    const double cx = u01(rng) * width, cy = u01(rng) * height;
    geometry::ClipVertex v[3];
    for (auto& vert : v) {
      const float w =
          wild && u01(rng) < 0.15 ? float(u01(rng) * 2 - 0.5) : float(0.5 + u01(rng) * 3);
      const float z = wild ? float(u01(rng) * 1.4 - 0.2) : float(u01(rng));
      vert = pixelVertex(cx + (u01(rng) - 0.5) * size, cy + (u01(rng) - 0.5) * size, width, height,
                         z, w, float(u01(rng)), float(u01(rng)), float(u01(rng)));
      if (wild && vert.w <= 0) {
        // pixelVertex scales by w; for w ≤ 0 give the vertex an arbitrary clip position instead.
        vert.x = float(u01(rng) * 4 - 2);
        vert.y = float(u01(rng) * 4 - 2);
        vert.z = float(u01(rng) * 2 - 1);
      }
    }
    addTriangle(p, v[0], v[1], v[2],
                t % 3 == 0 ? geometry::CullMode::back : geometry::CullMode::none);
  }
  return p;
}

Frame renderQuadtree(const render::DrawPackets& p, const render::FrameSettings& s, int threads,
                     FrameStats* stats) {
  render::FrameRenderer r(threads);
  const int n = s.samples;
  Frame f{s.width, s.height, n, {}, {}};
  f.depth.resize(size_t(s.width) * s.height * n);
  f.color.resize(f.depth.size() * 3);
  render::FrameSettings settings = s;
  const int tilesX = (s.width + raster::kTileSize - 1) >> raster::kTileLog2;
  // Tiles are copied out as they are finished (concurrently: each writes its own pixels).
  settings.finishTile = [&](int tile, const float* depth, const uint16_t* color, const int32_t*) {
    const int x0 = (tile % tilesX) * raster::kTileSize, y0 = (tile / tilesX) * raster::kTileSize;
    for (int y = y0; y < std::min(s.height, y0 + raster::kTileSize); ++y)
      for (int x = x0; x < std::min(s.width, x0 + raster::kTileSize); ++x) {
        for (int k = 0; k < n; ++k) {
          const size_t i = (size_t(y) * s.width + x) * n + k;
          if (depth) f.depth[i] = depth[raster::FrameBuffer::depthOffset(x, y, n, k)];
          for (int ch = 0; ch < 3; ++ch)
            f.color[i * 3 + ch] = color[raster::FrameBuffer::colorOffset(x, y, ch, n, k)];
        }
      }
  };
  FrameStats local;
  SV_CHECK(r.render(p, settings, stats ? *stats : local).ok());  // unshared: never fails
  return f;
}

std::vector<uint16_t> renderResolved(const render::DrawPackets& p, const render::FrameSettings& s,
                                     int threads, bool* usedSums) {
  render::FrameRenderer r(threads);
  const uint32_t n = uint32_t(s.samples);
  std::vector<uint16_t> rgb(size_t(s.width) * s.height * 3);
  std::atomic<int> sumTiles{0}, planeTiles{0};
  render::FrameSettings settings = s;
  const int tilesX = (s.width + raster::kTileSize - 1) >> raster::kTileLog2;
  settings.finishTile = [&](int tile, const float*, const uint16_t* color, const int32_t* sums) {
    ++(sums ? sumTiles : planeTiles);
    const int x0 = (tile % tilesX) * raster::kTileSize, y0 = (tile / tilesX) * raster::kTileSize;
    for (int y = y0; y < std::min(s.height, y0 + raster::kTileSize); ++y)
      for (int x = x0; x < std::min(s.width, x0 + raster::kTileSize); ++x)
        for (int ch = 0; ch < 3; ++ch) {
          uint32_t sum = 0;
          if (sums) {
            // A sum sits where sample 0 of a one-sample plane would (raster/framebuffer.h).
            sum = uint32_t(sums[raster::FrameBuffer::colorOffset(x, y, ch)]);
          } else {
            for (uint32_t k = 0; k < n; ++k)
              sum += color[raster::FrameBuffer::colorOffset(x, y, ch, int(n), int(k))];
          }
          rgb[(size_t(y) * s.width + x) * 3 + ch] = uint16_t((sum + n / 2) / n);
        }
  };
  FrameStats stats;
  SV_CHECK(r.render(p, settings, stats).ok());
  if (usedSums) *usedSums = sumTiles > 0 && planeTiles == 0;  // every tile, or none
  return rgb;
}

uint16_t Frame::resolved(int x, int y, int ch) const {
  uint32_t sum = 0;
  for (int k = 0; k < samples; ++k) sum += channel(x, y, ch, k);
  return uint16_t((sum + uint32_t(samples) / 2) / uint32_t(samples));
}

Frame renderReference(const render::DrawPackets& p, const render::FrameSettings& s) {
  const bool count = s.shade == raster::ShadeMode::overdraw;
  const int n = s.samples;
  const raster::SamplePattern* pattern = raster::samplePattern(n);
  const raster::EdgeMaskTable table(*pattern);
  Frame f{s.width, s.height, n, {}, {}};
  f.depth.assign(size_t(s.width) * s.height * n, 1.0f);
  f.color.resize(f.depth.size() * 3);
  for (size_t i = 0; i < f.depth.size(); ++i)
    for (int ch = 0; ch < 3; ++ch)
      f.color[i * 3 + ch] =
          count ? 0 : uint16_t(std::lround(std::clamp(s.clearColor[ch], 0.0f, 1.0f) * 65535.0f));
  const geometry::Viewport vp{s.width, s.height, n > 1};
  size_t callIndex = 0;
  for (uint32_t tri = 0; tri < p.indices.size() / 3; ++tri) {
    while (callIndex < p.calls.size() &&
           tri >= p.calls[callIndex].firstTriangle + p.calls[callIndex].triangleCount)
      ++callIndex;
    const geometry::CullMode cull =
        callIndex < p.calls.size() ? p.calls[callIndex].cull : geometry::CullMode::none;
    geometry::TriangleSetup t;
    const uint32_t* idx = &p.indices[size_t(tri) * 3];
    if (geometry::setupTriangle(p.vertices[idx[0]], p.vertices[idx[1]], p.vertices[idx[2]], vp,
                                cull, t) != geometry::SetupOutcome::drawn)
      continue;
    float sampleDepth[64];
    for (int k = 0; k < n; ++k)
      sampleDepth[k] = t.depth.dx * float(pattern->offsets[size_t(k)][0]) +
                       t.depth.dy * float(pattern->offsets[size_t(k)][1]);
    // Every pixel of the raster, not just the bounding box: the box is part of what is tested.
    // With anti-aliasing the box is part of the definition: near a vertex the AND of area masks
    // (coverage_masks.h) can claim samples beyond the triangle's extent, and the box — every
    // pixel square the triangle reaches, tested in setup_test — bounds them.
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        if (n > 1 && (x < t.minX || x > t.maxX || y < t.minY || y > t.maxY)) continue;
        uint64_t mask = table.allSamples();
        for (int k = 0; k < t.edgeCount && mask; ++k) {
          const geometry::EdgeFunction& e = t.edges[k];
          const int64_t value = e.c + e.stepX() * x + e.stepY() * y;
          if (n == 1) {
            mask = value >= 0;
          } else {
            // The geometric value: setup folds the fill rule in as −1 on edges not owning ties.
            const bool owns = e.a > 0 || (e.a == 0 && e.b > 0);
            mask &= table.mask(e.a, e.b, double(value + (owns ? 0 : 1)) / 256.0);
          }
        }
        if (!mask) continue;
        const size_t i = size_t(y) * s.width + x;
        if (count) {
          ++f.color[i * 3];
          continue;
        }
        const float zCentre = geometry::planeAtPixel(t.depth, x, y, t.minX, t.minY);
        // Colour at the centre, or with anti-aliasing for a partly covered pixel at the centroid
        // of its covered samples: (Σ offsets in 1/256 px) · (1 / (count · 256)).
        float cx = 0, cy = 0;
        const int covered = std::popcount(mask);
        if (n > 1 && covered < n && raster::CoverageTables::forCount(n)->centroid) {
          int sx = 0, sy = 0;
          for (int k = 0; k < n; ++k)
            if (mask >> k & 1) {
              sx += int(std::lround(pattern->offsets[size_t(k)][0] * 256));
              sy += int(std::lround(pattern->offsets[size_t(k)][1] * 256));
            }
          const float scale = 1.0f / (float(covered) * 256.0f);
          cx = float(sx) * scale;
          cy = float(sy) * scale;
        }
        auto at = [&](const geometry::Plane& plane) {
          return geometry::planeAtPixel(plane, x, y, t.minX, t.minY) +
                 (plane.dx * cx + plane.dy * cy);
        };
        const float invW =
            n > 1 ? at(t.invW) : geometry::planeAtPixel(t.invW, x, y, t.minX, t.minY);
        const float w = 1.0f / (n > 1 ? std::max(invW, 1e-30f) : invW);
        uint16_t c16[3];
        const geometry::Plane* planes[3] = {&t.red, &t.green, &t.blue};
        for (int ch = 0; ch < 3; ++ch) {
          const float v =
              n > 1 ? at(*planes[ch]) : geometry::planeAtPixel(*planes[ch], x, y, t.minX, t.minY);
          // NaN → 0, as the kernels' Max(v·w, 0) gives on every SIMD target (it returns the
          // other operand); std::max returns its first operand when the two are unordered.
          const float c = std::min(std::max(0.0f, v * w), 1.0f);
          c16[ch] = uint16_t(std::nearbyint(c * 65535.0f));  // ties to even
        }
        for (int k = 0; k < n; ++k) {
          if (!(mask >> k & 1)) continue;
          const size_t j = i * n + k;
          const float z = n > 1 ? zCentre + sampleDepth[k] : zCentre;
          if (!(z < f.depth[j])) continue;
          f.depth[j] = z;
          for (int ch = 0; ch < 3; ++ch) f.color[j * 3 + ch] = c16[ch];
        }
      }
  }
  return f;
}

}  // namespace sv::test
