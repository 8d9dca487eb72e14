// Test support: triangles placed in pixel coordinates, the renderer under test driven directly
// with clip-space packets, and an independent brute-force reference rasterizer.
#pragma once

#include <cstdint>
#include <vector>

#include "render/frame_renderer.h"

namespace sv::test {

// A clip-space vertex that lands on raster position (x, y) (pixels, y down) with window depth z,
// scaled by w (w > 0 leaves the projection unchanged; w < 0 puts the vertex behind the eye).
geometry::ClipVertex pixelVertex(double x, double y, int width, int height, float z = 0.5f,
                                 float w = 1.0f, float r = 1, float g = 1, float b = 1);

// Random triangles of every size class (legs 1 … 4096 px, random depths and colours, every third
// back-face culled); `wild` puts some vertices behind the eye and beyond the near and far planes
// (homogeneous edges, near/far edges, int64 stepping). Seeded: the same scene every time.
render::DrawPackets randomScene(int width, int height, int count, unsigned seed, bool wild);

// Adds a triangle (no culling) to `p`.
void addTriangle(render::DrawPackets& p, const geometry::ClipVertex& a,
                 const geometry::ClipVertex& b, const geometry::ClipVertex& c,
                 geometry::CullMode cull = geometry::CullMode::none);

// What a frame holds, in plain row-major arrays.
struct Frame {
  int width = 0, height = 0, samples = 1;
  std::vector<float> depth;     // per sample: index (y·width + x)·samples + s
  std::vector<uint16_t> color;  // 3 per sample
  uint16_t channel(int x, int y, int ch, int s = 0) const {
    return color[((size_t(y) * width + x) * samples + s) * 3 + ch];
  }
  // The mean of the pixel's samples, as the box resolve computes it (rounded).
  uint16_t resolved(int x, int y, int ch) const;
  bool operator==(const Frame&) const = default;
};

// Renders with the quadtree rasterizer and copies the frame buffer out.
Frame renderQuadtree(const render::DrawPackets& p, const render::FrameSettings& s, int threads = 1,
                     FrameStats* stats = nullptr);

// Renders and box-resolves: each pixel's 3 channels, the rounded mean of its samples (row-major),
// from the tiles' sample planes or — when the frame renderer hands them over (s.colorSums) — their
// colour sums; `usedSums` (optional) says whether every tile came as sums.
std::vector<uint16_t> renderResolved(const render::DrawPackets& p, const render::FrameSettings& s,
                                     int threads = 1, bool* usedSums = nullptr);

// The brute-force reference (RASTER-NOTES "hierarchy = flat"): for every pixel and every triangle
// in submission order, test the pixel centre against each edge function directly, then the same
// depth test and colour expressions as the kernel, in scalar code. With s.samples > 1 the pixel's
// mask is the AND of EdgeMaskTable::mask over the edges (in double, independent of the kernel's
// integer cell index), and depth is tested per sample.
Frame renderReference(const render::DrawPackets& p, const render::FrameSettings& s);

}  // namespace sv::test
