// Based on: SPEC §5 (the frame's samples: a strip is covered sample by sample, like a polygon),
// §8 (fog 2^(−β·r) by the true distance, linear light), §1 (one more pass over the tile buffers).
#include "lines/line_pass.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/timing.h"
#include "raster/framebuffer.h"

namespace sv::lines {
namespace {

using raster::FrameBuffer;
using raster::kTileLog2;
using raster::kTileSize;

// Segments are projected in chunks of this many (fixed: the strips' order never depends on the
// thread count).
constexpr size_t kChunk = 4096;

// ⌊x⌋ for the clipped raster coordinates (within a few widths of the screen).
int floorToInt(float x) { return int(std::floor(x)); }

// The x extent of convex polygon `c` (4 corners) between rows y = ya and y = yb: false when the
// polygon does not reach the band.
bool bandRange(const float (&c)[4][2], float ya, float yb, float& xmin, float& xmax) {
  xmin = std::numeric_limits<float>::infinity();
  xmax = -xmin;
  for (int e = 0; e < 4; ++e) {
    const float* p = c[e];
    const float* q = c[(e + 1) & 3];
    const float dy = q[1] - p[1];
    float t0 = 0, t1 = 1;
    if (dy == 0) {
      if (p[1] < ya || p[1] > yb) continue;
    } else {
      float ta = (ya - p[1]) / dy, tb = (yb - p[1]) / dy;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) continue;
    }
    const float xa = p[0] + t0 * (q[0] - p[0]), xb = p[0] + t1 * (q[0] - p[0]);
    xmin = std::min({xmin, xa, xb});
    xmax = std::max({xmax, xa, xb});
  }
  return xmin <= xmax;
}

// What is interpolated along a segment: clip-space position, eye-space position.
struct End {
  Vec4 clip;
  Vec3 eye;
};

End lerp(const End& a, const End& b, double t) {
  auto mix = [t](float u, float v) { return float(u + t * (double(v) - double(u))); };
  return {{mix(a.clip.x, b.clip.x), mix(a.clip.y, b.clip.y), mix(a.clip.z, b.clip.z),
           mix(a.clip.w, b.clip.w)},
          {mix(a.eye.x, b.eye.x), mix(a.eye.y, b.eye.y), mix(a.eye.z, b.eye.z)}};
}

// Clips [t0, t1] of the segment from a to b to the half-space where da + t·(db − da) ≥ 0.
bool clipTo(double da, double db, double& t0, double& t1) {
  if (da < 0 && db < 0) return false;
  if (da < 0) t0 = std::max(t0, da / (da - db));
  else if (db < 0) t1 = std::min(t1, da / (da - db));
  return t0 <= t1;
}

}  // namespace

void LinePass::setLines(const LineInput& input) { in_ = input; }

bool LinePass::project(const scene::LineSegment& segment, Strip& s) const {
  End ends[2];
  const Vec3 p[2] = {segment.a, segment.b};
  for (int k = 0; k < 2; ++k) {
    const Vec4 e = in_.view * Vec4{p[k].x, p[k].y, p[k].z, 1};
    ends[k] = {in_.projection * e, {e.x, e.y, e.z}};
  }
  // The near (z ≥ −w) and far (z ≤ w) planes, in clip space, where positions are linear.
  double t0 = 0, t1 = 1;
  const Vec4 &a = ends[0].clip, &b = ends[1].clip;
  if (!clipTo(double(a.z) + a.w, double(b.z) + b.w, t0, t1) ||
      !clipTo(double(a.w) - a.z, double(b.w) - b.z, t0, t1))
    return false;
  const End e0 = lerp(ends[0], ends[1], t0), e1 = lerp(ends[0], ends[1], t1);
  if (!(e0.clip.w > 0) || !(e1.clip.w > 0)) return false;
  // On screen: position, window depth drawn depthBias·s nearer (the eye point scaled by 1 − k
  // keeps its ray, and its ndc depth gains k/(1 − k)·m32/w), 1/w and the eye point over w, all
  // affine along the strip.
  const float k = in_.settings.depthBias;
  const float m32 = in_.projection.m[3][2];
  const float W = float(frame_.width), H = float(frame_.height);
  double sx[2], sy[2], attr[2][5];
  const End* e[2] = {&e0, &e1};
  for (int i = 0; i < 2; ++i) {
    const Vec4& c = e[i]->clip;
    const double q = 1.0 / c.w;
    sx[i] = (c.x * q + 1) * 0.5 * W;
    sy[i] = (1 - c.y * q) * 0.5 * H;
    const double ndc = c.z * q + k / (1 - k) * m32 * q;
    attr[i][0] = std::max(0.0, 0.5 * ndc + 0.5);
    attr[i][1] = q;
    attr[i][2] = e[i]->eye.x * q, attr[i][3] = e[i]->eye.y * q, attr[i][4] = e[i]->eye.z * q;
  }
  // The screen, a margin wider than the strip: positions stay small, and the attributes, affine on
  // screen, follow the clipped ends (Liang–Barsky).
  const double margin = in_.settings.width + 2;
  double u0 = 0, u1 = 1;
  const double ddx = sx[1] - sx[0], ddy = sy[1] - sy[0];
  if (!clipTo(sx[0] + margin, sx[1] + margin, u0, u1) ||
      !clipTo(W + margin - sx[0], W + margin - sx[1], u0, u1) ||
      !clipTo(sy[0] + margin, sy[1] + margin, u0, u1) ||
      !clipTo(H + margin - sy[0], H + margin - sy[1], u0, u1))
    return false;
  auto at = [&](int i, double u) { return attr[0][i] + u * (attr[1][i] - attr[0][i]); };
  s.x0 = float(sx[0] + u0 * ddx), s.y0 = float(sy[0] + u0 * ddy);
  s.x1 = float(sx[0] + u1 * ddx), s.y1 = float(sy[0] + u1 * ddy);
  s.z0 = float(at(0, u0)), s.z1 = float(at(0, u1));
  s.q0 = float(at(1, u0)), s.q1 = float(at(1, u1));
  s.e0 = {float(at(2, u0)), float(at(3, u0)), float(at(4, u0))};
  s.e1 = {float(at(2, u1)), float(at(3, u1)), float(at(4, u1))};
  s.color = segment.color;
  // The rectangle: ½ width either side, and past either end (square caps, so that the segments of
  // a polyline meet without a notch). A segment seen end-on is a square (a dot).
  const float lx = s.x1 - s.x0, ly = s.y1 - s.y0;
  s.length = std::sqrt(lx * lx + ly * ly);
  if (s.length > 1e-6f) s.dx = lx / s.length, s.dy = ly / s.length;
  else s.dx = 1, s.dy = 0, s.length = 0;
  const float h = 0.5f * in_.settings.width;
  const float ax = s.dx * h, ay = s.dy * h;  // along
  const float nx = -ay, ny = ax;             // across
  const float c[4][2] = {{s.x0 - ax - nx, s.y0 - ay - ny},
                         {s.x1 + ax - nx, s.y1 + ay - ny},
                         {s.x1 + ax + nx, s.y1 + ay + ny},
                         {s.x0 - ax + nx, s.y0 - ay + ny}};
  std::copy(&c[0][0], &c[0][0] + 8, &s.corners[0][0]);
  s.yMin = std::min({c[0][1], c[1][1], c[2][1], c[3][1]});
  s.yMax = std::max({c[0][1], c[1][1], c[2][1], c[3][1]});
  return true;
}

template <class F>
void LinePass::forTiles(const Strip& s, F&& f) const {
  const int ty0 = std::max(0, floorToInt(s.yMin) >> kTileLog2);
  const int ty1 = std::min(tilesY_ - 1, floorToInt(s.yMax) >> kTileLog2);
  for (int ty = ty0; ty <= ty1; ++ty) {
    float xmin, xmax;
    if (!bandRange(s.corners, float(ty * kTileSize), float((ty + 1) * kTileSize), xmin, xmax))
      continue;
    const int tx0 = std::max(0, floorToInt(xmin) >> kTileLog2);
    const int tx1 = std::min(tilesX_ - 1, floorToInt(xmax) >> kTileLog2);
    for (int tx = tx0; tx <= tx1; ++tx) f(size_t(ty) * size_t(tilesX_) + size_t(tx));
  }
}

void LinePass::prepare(const raster::PassFrame& frame) {
  const auto t0 = core::Clock::now();
  frame_ = frame;
  for (int k = 0; k < frame.samples; ++k) {
    offsetX_[k] = frame.coverage ? float(frame.coverage->offsetX[k]) / 256 : 0.0f;
    offsetY_[k] = frame.coverage ? float(frame.coverage->offsetY[k]) / 256 : 0.0f;
  }
  const size_t total = in_.lines.size();
  // Chunks of a size fixed by the segment count alone (never the thread count), at most 64.
  const size_t chunk = std::max(kChunk, (total + 63) / 64);
  const size_t chunks = (total + chunk - 1) / chunk;
  chunks_.resize(chunks);
  tilesX_ = (frame_.width + kTileSize - 1) >> kTileLog2;
  tilesY_ = (frame_.height + kTileSize - 1) >> kTileLog2;
  tiles_ = size_t(tilesX_) * size_t(tilesY_);
  tileStrips_.build(
      chunks_, tiles_, *frame.pool,
      [&](size_t c, std::vector<Strip>& out) {
        out.clear();
        for (size_t i = c * chunk; i < std::min(total, (c + 1) * chunk); ++i) {
          Strip s;
          if (project(in_.lines[i], s)) out.push_back(s);
        }
      },
      [&](const Strip& s, auto&& f) { forTiles(s, f); });
  workerMs_.assign(size_t(frame.pool->threadCount()), 0.0);
  prepareMs_ = core::msSince(t0);
}

// The strip over the tile's pixels, row by row: a sample inside the rectangle and nearer than the
// depth there takes the strip's depth (affine along it) and colour (at the pixel centre's place
// along it, fogged).
void LinePass::drawStrip(const Strip& s, const raster::TileTarget& tile) const {
  const int n = frame_.samples;
  const int ox = tile.tileX * kTileSize, oy = tile.tileY * kTileSize;
  const int xEnd = std::min(ox + kTileSize, frame_.width) - 1;
  const int yEnd = std::min(oy + kTileSize, frame_.height) - 1;
  const float h = 0.5f * in_.settings.width;
  const float invLength = s.length > 0 ? 1 / s.length : 0;
  for (int py = std::max(oy, floorToInt(s.yMin)); py <= std::min(yEnd, floorToInt(s.yMax)); ++py) {
    float xmin, xmax;
    if (!bandRange(s.corners, float(py), float(py + 1), xmin, xmax)) continue;
    for (int px = std::max(ox, floorToInt(xmin)); px <= std::min(xEnd, floorToInt(xmax)); ++px) {
      uint64_t covered = 0;
      for (int k = 0; k < n; ++k) {
        const float rx = float(px) + 0.5f + offsetX_[k] - s.x0;
        const float ry = float(py) + 0.5f + offsetY_[k] - s.y0;
        const float along = rx * s.dx + ry * s.dy, across = ry * s.dx - rx * s.dy;
        if (!(std::fabs(across) <= h) || along < -h || along > s.length + h) continue;
        const float u = std::clamp(along * invLength, 0.0f, 1.0f);
        const float z = s.z0 + u * (s.z1 - s.z0);
        float& d = tile.depth[FrameBuffer::depthOffset(px, py, n, k)];
        if (!(z < d)) continue;
        d = z;
        covered |= uint64_t(1) << k;
      }
      if (!covered) continue;
      // The pixel centre's place along the strip; its eye point for the fog's distance.
      const float rx = float(px) + 0.5f - s.x0, ry = float(py) + 0.5f - s.y0;
      const float u = std::clamp((rx * s.dx + ry * s.dy) * invLength, 0.0f, 1.0f);
      Vec3 c = s.color;
      if (in_.fog) {
        const float q = s.q0 + u * (s.q1 - s.q0);
        const Vec3 e = (s.e0 + (s.e1 - s.e0) * u) * (1 / q);
        const float f = std::exp2(-in_.fogBeta * length(e));
        c = c * f + in_.fogColor * (1 - f);
      }
      const float rgb[3] = {c.x, c.y, c.z};
      uint16_t c16[3];
      for (int ch = 0; ch < 3; ++ch)
        c16[ch] = uint16_t(std::lrint(std::clamp(rgb[ch], 0.0f, 1.0f) * 65535.0f));
      for (int k = 0; k < n; ++k)
        if (covered >> k & 1)
          for (int ch = 0; ch < 3; ++ch)
            tile.color[FrameBuffer::colorOffset(px, py, ch, n, k)] = c16[ch];
    }
  }
}

void LinePass::drawTile(const raster::TileTarget& tile) {
  const auto t0 = core::Clock::now();
  const size_t t = size_t(tile.tileY * tilesX_ + tile.tileX);
  const std::span<const Strip> strips = tileStrips_.tile(t);
  if (strips.empty()) return;
  for (const Strip& s : strips) drawStrip(s, tile);
  workerMs_[size_t(tile.worker)] += core::msSince(t0);
}

void LinePass::addStats(FrameStats& stats) const {
  stats.lines += in_.lines.size();
  uint64_t drawn = 0;
  for (const std::vector<Strip>& c : chunks_) drawn += c.size();
  stats.linesDrawn += drawn;
  stats.linesMs += prepareMs_ + *std::max_element(workerMs_.begin(), workerMs_.end());
}

}  // namespace sv::lines
