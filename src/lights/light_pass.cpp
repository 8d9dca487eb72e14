// Based on: SPEC §13 (light points: tiny, bright, anti-aliased, attenuated by distance and fog,
// directional and blinking, depth-tested), §5 (the frame's samples), §8 (fog, linear light).
#include "lights/light_pass.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/eye_rays.h"
#include "core/timing.h"
#include "lights/light_laws.h"
#include "lights/splat_blocks.h"
#include "raster/framebuffer.h"

namespace sv::lights {
namespace {

using raster::FrameBuffer;
using raster::kTileLog2;
using raster::kTileSize;

// Lights are projected in chunks of this many (fixed: the splats' order never depends on the
// thread count).
constexpr size_t kChunk = 4096;

// The equatorial x, y and z axes in the world at the input's time (light_laws.h: starDirection).
void starAxesOf(const LightInput& in, Vec3 axes[3]) {
  const scene::StarField& f = *in.stars;
  axes[0] = starDirection({1, 0, 0}, f.latitude, f.siderealTime, in.time);
  axes[1] = starDirection({0, 1, 0}, f.latitude, f.siderealTime, in.time);
  axes[2] = starDirection({0, 0, 1}, f.latitude, f.siderealTime, in.time);
}

// A star's direction in the world from its equatorial direction.
Vec3 starWorld(const Vec3 axes[3], Vec3 e) { return axes[0] * e.x + axes[1] * e.y + axes[2] * e.z; }

// A tile's border as seeTile keeps it: its outermost pixels (the outer ring: 252) with every
// sample, then the ring inside them (244) with the first. A light centred on the outer ring reads
// its centre's samples and the first sample of the eight around it — on the two rings, or on the
// next tile's outer ring; one centred inside reads its own tile only.
constexpr int kOuterRing = 4 * kTileSize - 4, kInnerRing = 4 * (kTileSize - 2) - 4;
size_t borderFloats(int samples) { return size_t(kOuterRing) * size_t(samples) + kInnerRing; }
bool onOuterRing(int lx, int ly) {
  return lx == 0 || ly == 0 || lx == kTileSize - 1 || ly == kTileSize - 1;
}
// Per tile-local pixel (row-major): its slot on the outer ring (0 … 251), on the inner one
// (252 … 495), or −1.
const int16_t* borderSlots() {
  static const auto slots = [] {
    std::array<int16_t, raster::kTilePixels> s;
    int16_t outer = 0, inner = kOuterRing;
    for (int ly = 0; ly < kTileSize; ++ly)
      for (int lx = 0; lx < kTileSize; ++lx) {
        const bool onInner = lx == 1 || ly == 1 || lx == kTileSize - 2 || ly == kTileSize - 2;
        int16_t& slot = s[size_t(ly * kTileSize + lx)];
        slot = onOuterRing(lx, ly) ? outer++ : onInner ? inner++ : int16_t(-1);
      }
    return s;
  }();
  return slots.data();
}

// A point's laws seen from `eye`: off (energy < 0) when its group is off, it is blinked out or at
// the eye; else its on-screen energy and colour.
LightLaws::Point pointLaw(const LightInput& in, const scene::LightPoint& p, Vec3 eye,
                          const LobeTangents& tangents) {
  LightLaws::Point law;
  float dim = 1;
  if (p.group >= 0) {
    const scene::LightGroup& g = in.groups[size_t(p.group)];
    if (!g.on) return law;
    dim = g.dim;
  }
  const scene::LightAppearance& a = in.appearances[p.appearance];
  if (!blinkOn(a.blink, p.phase, in.time)) return law;
  const Vec3 toEye = eye - p.position;
  const float d = length(toEye);
  if (!(d > 0)) return law;
  const Vec3 color = appearanceColor(a, lobeAxis(a, p.phase, in.time), toEye * (1 / d), tangents);
  const float transmission = fogTransmission(in.fogBeta, in.settings.punchThrough, d);
  law.energy = screenEnergy(in.settings.exposure, a.intensity * dim, transmission, d);
  law.r = color.x, law.g = color.y, law.b = color.z;
  return law;
}

std::vector<LobeTangents> lobeTangentsOf(const LightInput& in) {
  std::vector<LobeTangents> t;
  for (const scene::LightAppearance& a : in.appearances)
    t.push_back(lobeTangents(a.horizontalLobe, a.verticalLobe));
  return t;
}

}  // namespace

Vec3 viewEye(const Mat4& v) {
  Vec3 eye;
  for (int j = 0; j < 3; ++j) {
    double e = 0;
    for (int i = 0; i < 3; ++i) e -= double(v.m[j][i]) * double(v.m[3][i]);
    (j == 0 ? eye.x : j == 1 ? eye.y : eye.z) = float(e);
  }
  return eye;
}

void lightEyePositions(const LightInput& in, std::vector<Vec4>& out) {
  out.clear();
  out.reserve(in.points.size() + (in.stars ? in.stars->stars.size() : 0));
  for (const scene::LightPoint& p : in.points)
    out.push_back(in.view * Vec4{p.position.x, p.position.y, p.position.z, 1});
  if (!in.stars) return;
  Vec3 axes[3];
  starAxesOf(in, axes);
  for (const scene::Star& star : in.stars->stars) {
    const Vec3 w = starWorld(axes, star.direction);
    out.push_back(in.view * Vec4{w.x, w.y, w.z, 0});
  }
}

void LightLaws::compute(const LightInput& in, core::ThreadPool& pool) {
  eye_ = viewEye(in.view);
  const std::vector<LobeTangents> tangents = lobeTangentsOf(in);
  points_.resize(in.points.size());
  const size_t chunks = (points_.size() + kChunk - 1) / kChunk;
  pool.parallelFor(chunks, [&](size_t c, int) {
    for (size_t i = c * kChunk; i < std::min(points_.size(), (c + 1) * kChunk); ++i) {
      const scene::LightPoint& p = in.points[i];
      points_[i] = pointLaw(in, p, eye_, tangents[p.appearance]);
    }
  });
}

void LightPass::setLights(const LightInput& input) { in_ = input; }

float LightPass::eyeDepthOf(float windowDepth) const {
  if (!(windowDepth < 1.0f)) return zfar_;
  return m32_ / (2 * windowDepth - 1 + m22_);
}

bool LightPass::projectPoint(size_t index, SizeBatch& batch, int i) const {
  const scene::LightPoint& p = in_.points[index];
  const LightLaws::Point law =
      in_.laws ? in_.laws->point(index) : pointLaw(in_, p, eye_, lobeTangents_[p.appearance]);
  if (law.energy < 0) return false;
  const Vec4 eye = in_.view * Vec4{p.position.x, p.position.y, p.position.z, 1};
  const Vec4 c = in_.projection * eye;
  if (!(c.w > 0) || !(c.z >= -c.w) || !(c.z <= c.w)) return false;  // behind, near, beyond far
  const float invW = 1 / c.w;
  batch.x[i] = (c.x * invW + 1) * 0.5f * float(frame_.width);
  batch.y[i] = (1 - c.y * invW) * 0.5f * float(frame_.height);
  batch.eyeDepth[i] = c.w;  // −eye.z for a window, bit for bit; a sub-frustum cell's axis depth
  batch.energy[i] = law.energy;
  batch.r[i] = law.r, batch.g[i] = law.g, batch.b[i] = law.b;
  return true;
}

bool LightPass::projectStar(const scene::Star& star, SizeBatch& batch, int i) const {
  const scene::StarField& f = *in_.stars;
  if (star.magnitude > f.limit) return false;
  const Vec3 w = starWorld(starAxes_, star.direction);
  const Vec4 eye = in_.view * Vec4{w.x, w.y, w.z, 0};  // a direction: at infinity
  const Vec4 c = in_.projection * eye;
  if (!(c.w > 0)) return false;
  const float invW = 1 / c.w;
  batch.x[i] = (c.x * invW + 1) * 0.5f * float(frame_.width);
  batch.y[i] = (1 - c.y * invW) * 0.5f * float(frame_.height);
  batch.eyeDepth[i] = 0;
  batch.energy[i] = f.brightness * std::exp2(-0.4f * std::log2(10.0f) * star.magnitude);
  batch.r[i] = star.color.x, batch.g[i] = star.color.y, batch.b[i] = star.color.z;
  return true;
}

void LightPass::projectRange(size_t begin, size_t end, std::vector<Splat>& out) const {
  out.clear();
  const size_t points = in_.points.size();
  // Projected one at a time (their laws branch by kind), sized and weighed 16 at a time.
  SizeBatch batch;
  uint32_t light[SizeBatch::kLights];
  int count = 0;
  auto size = [&] {
    sizeSplats(sizeLaws_, count, batch);
    for (int j = 0; j < count; ++j) {
      if (!batch.drawn[j]) continue;
      Splat& s = out.emplace_back();
      s.x = batch.x[j], s.y = batch.y[j], s.eyeDepth = batch.eyeDepth[j];
      s.radius = batch.radius[j];
      s.rgb[0] = batch.red[j], s.rgb[1] = batch.green[j], s.rgb[2] = batch.blue[j];
      s.frontDepth = batch.frontDepth[j];
      s.firstX = batch.firstX[j], s.firstY = batch.firstY[j];
      s.spanX = batch.spanX[j], s.spanY = batch.spanY[j];
      for (int k = 0; k < Splat::kKeptSpan; ++k) s.kx[k] = batch.kx[k][j], s.ky[k] = batch.ky[k][j];
      s.light = light[j];
    }
    count = 0;
  };
  for (size_t k = begin; k < end; ++k) {
    const size_t i = in_.subset ? (*in_.subset)[k] : k;
    const bool projected = i < points ? projectPoint(i, batch, count)
                                      : projectStar(in_.stars->stars[i - points], batch, count);
    if (!projected) continue;
    light[count] = uint32_t(k);
    if (++count == SizeBatch::kLights) size();
  }
  size();
}

template <class F>
void LightPass::forTiles(const Splat& s, F&& f) const {
  const int tilesY = int(tiles_ / size_t(tilesX_));
  const int tx0 = std::max(0, floorToInt(s.x - s.radius) >> kTileLog2);
  const int tx1 = std::min(tilesX_ - 1, floorToInt(s.x + s.radius) >> kTileLog2);
  const int ty0 = std::max(0, floorToInt(s.y - s.radius) >> kTileLog2);
  const int ty1 = std::min(tilesY - 1, floorToInt(s.y + s.radius) >> kTileLog2);
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) f(size_t(ty) * size_t(tilesX_) + size_t(tx));
}

void LightPass::prepare(const raster::PassFrame& frame) {
  const auto t0 = core::Clock::now();
  frame_ = frame;
  exchangeMs_ = 0;
  probes_.clear();
  eye_ = in_.laws ? in_.laws->eye() : viewEye(in_.view);
  if (!in_.laws) lobeTangents_ = lobeTangentsOf(in_);
  m22_ = float(depthP22(in_.projection));  // m[2][2] for a window
  m32_ = in_.projection.m[3][2];
  zfar_ = m32_ / (1 + m22_);
  const scene::LightSettings& ls = in_.settings;
  sizeLaws_ = SizeLaws{
      ls.minSize, ls.maxSize, float(frame.width), float(frame.height), ls.depthBias, m22_, m32_};
  const size_t stars = in_.stars ? in_.stars->stars.size() : 0;
  if (stars) starAxesOf(in_, starAxes_);
  const size_t total = in_.subset ? in_.subset->size() : in_.points.size() + stars;
  candidates_ = total;
  // Chunks of a size fixed by the light count alone (never the thread count), at most 64 of them,
  // so that the per-chunk tile counts stay small.
  const size_t chunk = std::max(kChunk, (total + 63) / 64);
  const size_t chunks = (total + chunk - 1) / chunk;
  chunks_.resize(chunks);
  tilesX_ = (frame_.width + kTileSize - 1) >> kTileLog2;
  tiles_ = size_t(tilesX_) * size_t((frame_.height + kTileSize - 1) >> kTileLog2);
  tileSplats_.build(
      chunks_, tiles_, *frame.pool,
      [&](size_t c, std::vector<Splat>& out) {
        projectRange(c * chunk, std::min(total, (c + 1) * chunk), out);
      },
      [&](const Splat& s, auto&& f) { forTiles(s, f); });
  workerMs_.assign(size_t(frame.pool->threadCount()), 0.0);
  // Every drawn splat's visibility is written (seeTile, exchange) before it is read.
  visible_.resize(total);
  entryVisible_.resize(tileSplats_.size());
  if (!frame.share.shared()) borders_.resize(tiles_ * borderFloats(frame.samples));
  prepareMs_ = core::msSince(t0);
}

std::vector<Splat> LightPass::splats() const {
  std::vector<Splat> all;
  for (const std::vector<Splat>& c : chunks_) all.insert(all.end(), c.begin(), c.end());
  return all;
}

float LightPass::visibilityFromBorders(const Splat& s) const {
  const int n = frame_.samples;
  const size_t stride = borderFloats(n);
  const int16_t* slots = borderSlots();
  return visibilityFrom(s, [&](int x, int y, int k) {
    const size_t tile = size_t((y >> kTileLog2) * tilesX_ + (x >> kTileLog2));
    const int slot = slots[(y & (kTileSize - 1)) * kTileSize + (x & (kTileSize - 1))];
    const float* border = &borders_[tile * stride];
    // Only the outer ring keeps more than the first sample (visibilityFrom reads the others at
    // the centre alone).
    return slot < kOuterRing ? border[slot * n + k] : border[kOuterRing * n + slot - kOuterRing];
  });
}

float LightPass::visibilityFromProbes(const Splat& s) const {
  // The probes exchange() fetched, in the order it stored them.
  const float* probe = &probes_[probeAt_[s.light]];
  const int cx = std::clamp(floorToInt(s.x), 0, frame_.width - 1);
  const int cy = std::clamp(floorToInt(s.y), 0, frame_.height - 1);
  return visibilityFrom(s, [&](int x, int y, int k) {
    if (x == cx && y == cy) return probe[k];
    const int neighbour = (y - cy + 1) * 3 + (x - cx + 1);  // 0 … 8, the centre 4
    return probe[frame_.samples + neighbour - (neighbour > 4)];
  });
}

// Visibility (docs/lights.md): the fraction of the centre pixel's samples that do not hide the
// light. A sample hides a light when its surface is nearer than the light by more than the
// depth bias plus the surface's own spread — the largest depth difference between the centre
// pixel and the eight around it: ground seen at a grazing angle changes depth steeply from pixel
// to pixel, so a light standing on it stays lit; a wall facing the eye does not, and hides what
// is behind it (but within a pixel of a silhouette a light behind shows). A star is seen only
// where nothing was drawn.
template <class DepthAt>
float LightPass::visibilityFrom(const Splat& s, DepthAt&& depthAt) const {
  const int cx = std::clamp(floorToInt(s.x), 0, frame_.width - 1);
  const int cy = std::clamp(floorToInt(s.y), 0, frame_.height - 1);
  const int n = frame_.samples;
  int visible = 0;
  if (s.eyeDepth == 0) {
    for (int k = 0; k < n; ++k) visible += !(depthAt(cx, cy, k) < 1.0f);
    return float(visible) / float(n);
  }
  // Every sample at least as far as the light less the bias (the common case: a light in front
  // of what is behind it): visible, without the spread.
  float nearestSample = 1.0f;
  for (int k = 0; k < n; ++k) nearestSample = std::min(nearestSample, depthAt(cx, cy, k));
  if (!(nearestSample < s.frontDepth)) return 1.0f;
  const float centre = eyeDepthOf(depthAt(cx, cy, 0));
  float spread = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = cx + dx, y = cy + dy;
      if (x < 0 || y < 0 || x >= frame_.width || y >= frame_.height) continue;
      spread = std::max(spread, std::fabs(eyeDepthOf(depthAt(x, y, 0)) - centre));
    }
  const float limit = s.eyeDepth - in_.settings.depthBias - spread;
  for (int k = 0; k < n; ++k) visible += !(eyeDepthOf(depthAt(cx, cy, k)) < limit);
  return float(visible) / float(n);
}

// SPEC §3.4, issue 36: a part of a shared frame has drawn only its own tiles, and a light's
// visibility reads the depth around its centre, which another part may have drawn. Every part
// fills the probes it drew and leaves the others at −∞; their maximum is the whole frame's.
Status LightPass::exchange() {
  if (!frame_.share.shared()) return {};
  const auto t0 = core::Clock::now();
  const int n = frame_.samples;
  const size_t stride = size_t(n + kNeighbourProbes);
  size_t drawn = 0;
  for (const std::vector<Splat>& c : chunks_) drawn += c.size();
  probes_.assign(drawn * stride, -std::numeric_limits<float>::infinity());
  probeAt_.assign(size_t(candidates_), 0);
  const auto depthAt = [&](int x, int y, int k, float& out) {
    if (x < 0 || y < 0 || x >= frame_.width || y >= frame_.height) return;
    const int tx = x >> kTileLog2, ty = y >> kTileLog2;
    if (!frame_.share.owns(tx, ty)) return;
    out = frame_.frame->tileDepth(ty * tilesX_ + tx)[FrameBuffer::depthOffset(x, y, n, k)];
  };
  size_t slot = 0;
  for (const std::vector<Splat>& c : chunks_)
    for (const Splat& s : c) {
      float* probe = &probes_[slot * stride];
      probeAt_[s.light] = uint32_t(slot * stride);
      ++slot;
      const int cx = std::clamp(floorToInt(s.x), 0, frame_.width - 1);
      const int cy = std::clamp(floorToInt(s.y), 0, frame_.height - 1);
      for (int k = 0; k < n; ++k) depthAt(cx, cy, k, probe[k]);
      int at = n;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (dx != 0 || dy != 0) depthAt(cx + dx, cy + dy, 0, probe[at++]);
    }
  const Status s = frame_.share.exchange->maxAll(probes_);
  if (s)
    for (const std::vector<Splat>& c : chunks_)
      for (const Splat& splat : c) visible_[splat.light] = visibilityFromProbes(splat);
  std::fill(entryVisible_.begin(), entryVisible_.end(), -1.0f);  // drawTile reads visible_
  exchangeMs_ = core::msSince(t0);
  return s;
}

void LightPass::seeTile(const raster::TileTarget& tile) {
  if (frame_.share.shared()) return;  // exchange() saw every splat
  const auto t0 = core::Clock::now();
  const int n = frame_.samples;
  const size_t t = size_t(tile.tileY * tilesX_ + tile.tileX);
  // The border, for the lights of the tiles around that are centred on it (drawTile): the outer
  // ring's pixels are the rows 0 and 63 and the columns 0 and 63; the inner ring's inside them.
  float* border = &borders_[t * borderFloats(n)];
  const int16_t* slots = borderSlots();
  const auto keep = [&](int lx, int ly) {
    const int slot = slots[ly * kTileSize + lx];
    if (slot < kOuterRing)
      for (int k = 0; k < n; ++k)
        border[slot * n + k] = tile.depth[FrameBuffer::depthOffset(lx, ly, n, k)];
    else
      border[kOuterRing * n + slot - kOuterRing] = tile.depth[FrameBuffer::depthOffset(lx, ly, n)];
  };
  for (const int ly : {0, 1, kTileSize - 2, kTileSize - 1})
    for (int lx = 0; lx < kTileSize; ++lx) keep(lx, ly);
  for (int ly = 2; ly < kTileSize - 2; ++ly)
    for (const int lx : {0, 1, kTileSize - 2, kTileSize - 1}) keep(lx, ly);
  // The visibility of the tile's splats centred inside its border: every splat reaches the tile
  // of its centre pixel (clamped into the frame, as visibilityFrom clamps it).
  const std::span<const Splat> splats = tileSplats_.tile(t);
  float* entry = entryVisible_.data() + tileSplats_.first(t);
  const auto inTile = [](float c, float r, int tileAt) {
    return floorToInt(c - r) >> kTileLog2 == tileAt && floorToInt(c + r) >> kTileLog2 == tileAt;
  };
  const auto depthAt = [&](int x, int y, int k) {
    return tile.depth[FrameBuffer::depthOffset(x, y, n, k)];
  };
  for (size_t i = 0; i < splats.size(); ++i) {
    const Splat& s = splats[i];
    const int cx = std::clamp(floorToInt(s.x), 0, frame_.width - 1);
    const int cy = std::clamp(floorToInt(s.y), 0, frame_.height - 1);
    entry[i] = -1;
    if ((cx >> kTileLog2) != tile.tileX || (cy >> kTileLog2) != tile.tileY ||
        onOuterRing(cx & (kTileSize - 1), cy & (kTileSize - 1)))
      continue;
    entry[i] = visibilityFrom(s, depthAt);
    if (!inTile(s.x, s.radius, tile.tileX) || !inTile(s.y, s.radius, tile.tileY))
      visible_[s.light] = entry[i];
  }
  workerMs_[size_t(tile.worker)] += core::msSince(t0);
}

void LightPass::drawTile(const raster::TileTarget& tile) {
  const auto t0 = core::Clock::now();
  const size_t t = size_t(tile.tileY * tilesX_ + tile.tileX);
  const int ox = tile.tileX * kTileSize, oy = tile.tileY * kTileSize;
  const int xEnd = std::min(ox + kTileSize, frame_.width);
  const int yEnd = std::min(oy + kTileSize, frame_.height);
  const int n = frame_.samples;
  const std::span<const Splat> splats = tileSplats_.tile(t);
  if (splats.empty()) return;
  // The tile's colour may have left the caches while the tiles around it were drawn: stream it
  // back in order (the lights then touch it at random).
  const char* color = reinterpret_cast<const char*>(tile.color);
  for (size_t b = 0; b < size_t(raster::kTilePixels) * size_t(n) * 6; b += 64)
    __builtin_prefetch(color + b, 1);
  const float* entry = entryVisible_.data() + tileSplats_.first(t);
  for (size_t i = 0; i < splats.size(); ++i) {
    const Splat& s = splats[i];
    float v = entry[i];
    if (v < 0) {
      const int cx = std::clamp(floorToInt(s.x), 0, frame_.width - 1);
      const int cy = std::clamp(floorToInt(s.y), 0, frame_.height - 1);
      v = !frame_.share.shared() && onOuterRing(cx & (kTileSize - 1), cy & (kTileSize - 1))
              ? visibilityFromBorders(s)
              : visible_[s.light];
    }
    if (!(v > 0)) continue;
    SplatInTile part;
    float kx[kMaxSplatSpan], ky[kMaxSplatSpan];
    if (s.spanX <= Splat::kKeptSpan && s.spanY <= Splat::kKeptSpan) {
      part.kx = s.kx;
      part.ky = s.ky;
    } else {
      int first;
      splatAxis(s.x, s.radius, kx, first);
      splatAxis(s.y, s.radius, ky, first);
      part.kx = kx;
      part.ky = ky;
    }
    part.kernelX = s.firstX - ox;
    part.kernelY = s.firstY - oy;
    part.x0 = std::max(0, part.kernelX);
    part.x1 = std::min(xEnd - ox, part.kernelX + s.spanX) - 1;
    part.y0 = std::max(0, part.kernelY);
    part.y1 = std::min(yEnd - oy, part.kernelY + s.spanY) - 1;
    for (int ch = 0; ch < 3; ++ch) part.rgb[ch] = s.rgb[ch] * v;
    if (part.x0 <= part.x1 && part.y0 <= part.y1) addSplat(tile.color, n, part);
  }
  workerMs_[size_t(tile.worker)] += core::msSince(t0);
}

void LightPass::addStats(FrameStats& stats) const {
  stats.lightPoints += candidates_;
  uint64_t drawn = 0;
  for (const std::vector<Splat>& c : chunks_) drawn += c.size();
  stats.lightsDrawn += drawn;
  stats.lightsMs +=
      prepareMs_ + exchangeMs_ + *std::max_element(workerMs_.begin(), workerMs_.end());
  stats.shareMs += exchangeMs_;
  stats.shareBytes += probes_.size() * sizeof(float);
}

}  // namespace sv::lights
