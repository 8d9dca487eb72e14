// Based on: SPEC §12 (multi-level ray casting, front to back, masking), §5 (samples), §7 (planar
// texture, footprint level of detail), §8 (Phong, fog).
#include "terrain/terrain_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

#include "raster/framebuffer.h"

namespace sv::terrain {
namespace {

using raster::FrameBuffer;
using raster::kTileSize;

constexpr size_t kPlane = size_t(kTileSize) * kTileSize;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The window size whose pixels are cast from its start (TerrainPass::castWindow).
constexpr int kPixelWindow = 2;

}  // namespace

std::vector<scene::TerrainColorStop> defaultRamp(double lo, double hi) {
  const double r = std::max(hi - lo, 1e-9);
  return {{lo, {0.05f, 0.16f, 0.04f}},
          {lo + 0.30 * r, {0.16f, 0.25f, 0.06f}},
          {lo + 0.55 * r, {0.30f, 0.22f, 0.12f}},
          {lo + 0.80 * r, {0.35f, 0.33f, 0.31f}},
          {lo + 0.95 * r, {0.85f, 0.87f, 0.90f}}};
}

Vec3 rampAt(const std::vector<scene::TerrainColorStop>& ramp, double h) {
  if (h <= ramp.front().height) return ramp.front().color;
  for (size_t k = 1; k < ramp.size(); ++k)
    if (h < ramp[k].height) {
      const double t = (h - ramp[k - 1].height) / (ramp[k].height - ramp[k - 1].height);
      const Vec3 a = ramp[k - 1].color, b = ramp[k].color;
      return {float(a.x + (b.x - a.x) * t), float(a.y + (b.y - a.y) * t),
              float(a.z + (b.z - a.z) * t)};
    }
  return ramp.back().color;
}

namespace {

// The level of detail of a footprint with texel Jacobian [a b; c d] per pixel: ½·log2 σ₁², at
// least 0 — shade::textureCoordinates's formula, so ground and polygons filter alike.
float lodOf(double a, double b, double c, double d) {
  const double s = a * a + b * b + c * c + d * d, det = a * d - b * c;
  const double major2 = 0.5 * (s + std::sqrt(std::max(s * s - 4 * det * det, 0.0)));
  if (!(major2 > 1)) return 0;
  return float(std::min(0.5 * std::log2(major2), 63.0));
}

}  // namespace

// Per worker: one tile's samples while it is cast.
struct TerrainPass::Scratch {
  std::vector<float> depth;   // per sample plane and pixel: the window depth already there
  std::vector<double> limit;  // … as eye depth
  std::vector<double> hit;    // … and of the ground where a ray met it nearer (NaN: none)
  // The farthest limit over each window of the screen quadtree: level k holds (64 >> k)² windows
  // of 1 << k pixels (k = 0: pixels).
  std::vector<double> windowLimit[7];
  std::vector<int> pixels;  // the tile's pixels some sample of which met the ground
  CastCounters* counts = nullptr;
  int ox = 0, oy = 0;
};

TerrainPass::TerrainPass() = default;
TerrainPass::~TerrainPass() = default;

void TerrainPass::setTerrains(std::vector<TerrainDraw> terrains, const EyeRays& rays,
                              const shade::Environment& environment) {
  terrains_.clear();
  environment_ = &environment;
  groundBytes_ = 0;
  loadMs_ = 0;
  rays_ = rays;
  for (TerrainDraw& t : terrains) {
    Drawn d;
    static_cast<TerrainDraw&>(d) = std::move(t);
    d.caster =
        std::make_unique<Caster>(*d.field, pyramidOf(*d.field, d.interp), d.interp, d.placement);
    groundBytes_ += groundBytes(*d.field);
    loadMs_ += d.field->loadMs;
    terrains_.push_back(std::move(d));
  }
}

void TerrainPass::prepare(const raster::PassFrame& frame) {
  width_ = rays_.width = frame.width;
  height_ = rays_.height = frame.height;
  samples_ = frame.samples;
  for (int s = 0; s < samples_; ++s) {
    offsetX_[s] = frame.coverage ? frame.coverage->offsetX[s] / 256.0 : 0.0;
    offsetY_[s] = frame.coverage ? frame.coverage->offsetY[s] / 256.0 : 0.0;
  }
  const int workers = frame.pool ? frame.pool->threadCount() : 1;
  while (int(scratch_.size()) < workers) scratch_.push_back(std::make_unique<Scratch>());
  stats_.assign(size_t(workers), WorkerStats{});
}

void TerrainPass::addStats(FrameStats& stats) const {
  CastCounters c;
  for (const WorkerStats& s : stats_) c.add(s.counts);
  stats.terrains += terrains_.size();
  stats.terrainWindows += c.windows;
  stats.terrainSteps += c.steps;
  stats.terrainRays += c.rays;
  stats.terrainHits += c.hits;
  stats.terrainBytes += groundBytes_;
  stats.terrainLoadMs += loadMs_;
}

void TerrainPass::drawTile(const raster::TileTarget& tile) {
  if (terrains_.empty()) return;
  Scratch& w = *scratch_[size_t(tile.worker)];
  w.counts = &stats_[size_t(tile.worker)].counts;
  w.ox = tile.tileX * kTileSize;
  w.oy = tile.tileY * kTileSize;
  const int s = samples_;
  w.limit.resize(kPlane * size_t(s));
  w.depth.resize(kPlane * size_t(s));
  w.hit.resize(kPlane * size_t(s));
  for (int k = 0; k <= 6; ++k) w.windowLimit[k].resize(size_t(64 >> k) * size_t(64 >> k));
  for (const Drawn& t : terrains_) {
    // What the tile holds already (polygons, free forms, earlier terrains), as eye depths; per
    // pixel the farthest of its samples, per window the farthest of its pixels.
    for (int ly = 0; ly < kTileSize; ++ly)
      for (int lx = 0; lx < kTileSize; ++lx) {
        double far = 0;
        for (int k = 0; k < s; ++k) {
          const float z = tile.depth[FrameBuffer::depthOffset(lx, ly, s, k)];
          const double v = rays_.depthToS(z);
          w.depth[kPlane * size_t(k) + size_t(ly * kTileSize + lx)] = z;
          w.limit[kPlane * size_t(k) + size_t(ly * kTileSize + lx)] = v;
          far = std::max(far, v);
        }
        w.windowLimit[0][size_t(ly * kTileSize + lx)] = far;
      }
    for (int k = 1; k <= 6; ++k) {
      const int n = 64 >> k;
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const std::vector<double>& f = w.windowLimit[k - 1];
          const size_t a = size_t(2 * y) * size_t(2 * n) + size_t(2 * x);
          w.windowLimit[k][size_t(y * n + x)] =
              std::max({f[a], f[a + 1], f[a + size_t(2 * n)], f[a + size_t(2 * n) + 1]});
        }
    }
    std::fill(w.hit.begin(), w.hit.end(), kNaN);
    w.pixels.clear();
    castWindow(w, t, 0, 0, kTileSize, rays_.znear);
    shadeHits(w, t, tile);
  }
}

// The window of `size` pixels at tile position (x0, y0), its rays marched from `start` (where its
// parent found the ground possible) to the farthest depth it holds; then its quarters, down to
// pixels, whose samples are cast one ray each.
void TerrainPass::castWindow(Scratch& w, const Drawn& t, int x0, int y0, int size,
                             double start) const {
  const int gx = w.ox + x0, gy = w.oy + y0;
  if (gx >= width_ || gy >= height_) return;
  int level = 0;
  while ((1 << level) < size) ++level;
  const double limit = w.windowLimit[level][size_t((y0 >> level) * (64 >> level) + (x0 >> level))];
  if (!(start < limit)) return;  // masked: what is there already is nearer
  const double x1 = std::min(gx + size, width_), y1 = std::min(gy + size, height_);
  const Bundle b{rays_.eye,
                 {rays_.direction(gx, gy), rays_.direction(x1, gy), rays_.direction(gx, y1),
                  rays_.direction(x1, y1)}};
  // The bundle's width per unit depth, in grid steps (for the pyramid level of its steps).
  const HeightField& f = *t.field;
  const Vec3d d1 = b.corner[3] - b.corner[0], d2 = b.corner[2] - b.corner[1];
  const double footprint =
      std::max(std::hypot(d1.x, d1.z), std::hypot(d2.x, d2.z)) / std::min(f.spacingU, f.spacingV);
  const double s = t.caster->march(b, start, limit, footprint, t.pixel, *w.counts);
  if (!(s < limit)) return;
  // The smallest windows cast their pixels from their own start: a march of a smaller footprint
  // first would find little the pixels' rays do not.
  if (size <= kPixelWindow) {
    for (int y = y0; y < y0 + size; ++y)
      for (int x = x0; x < x0 + size; ++x) castPixel(w, t, x, y, s);
    return;
  }
  const int h = size / 2;
  for (int c = 0; c < 4; ++c) castWindow(w, t, x0 + (c & 1) * h, y0 + (c >> 1) * h, h, s);
}

// Pixel (x, y) of the tile: its samples' rays cast from `start` to the depth each holds.
void TerrainPass::castPixel(Scratch& w, const Drawn& t, int x, int y, double start) const {
  const int gx = w.ox + x, gy = w.oy + y;
  if (gx >= width_ || gy >= height_) return;
  const size_t p = size_t(y * kTileSize + x);
  bool any = false;
  for (int k = 0; k < samples_; ++k) {
    const size_t at = kPlane * size_t(k) + p;
    const double lim = w.limit[at];
    if (!(start < lim)) continue;
    const Vec3d d = rays_.direction(gx + 0.5 + offsetX_[k], gy + 0.5 + offsetY_[k]);
    const double hs = t.caster->cast(rays_.eye, d, start, lim, *w.counts, t.pixel);
    if (std::isnan(hs) || !(rays_.sToDepth(hs) < w.depth[at])) continue;
    w.hit[at] = hs;
    any = true;
  }
  if (any) w.pixels.push_back(int(p));
}

// Each pixel that met the ground, shaded once — at its first sample's hit — 16 to a call, and
// written to every sample whose ray met the ground nearer than what the sample held.
void TerrainPass::shadeHits(Scratch& w, const Drawn& t, const raster::TileTarget& tile) const {
  const Caster& c = *t.caster;
  const HeightField& f = *t.field;
  const texture::Texture* image = t.material.texture;
  const double west = t.imageBounds[0], south = t.imageBounds[1], east = t.imageBounds[2],
               north = t.imageBounds[3];
  const double imageW = image ? image->level(0).width : 1,
               imageH = image ? image->level(0).height : 1;
  const int s = samples_;
  for (size_t begin = 0; begin < w.pixels.size(); begin += shade::kMaxFragments) {
    const int n = int(std::min<size_t>(shade::kMaxFragments, w.pixels.size() - begin));
    shade::Fragments frag;
    shade::TexCoords tc;
    frag.count = n;
    for (int i = 0; i < shade::kMaxFragments; ++i) {
      frag.q[i] = 1;
      tc.lod[i] = tc.x0[i] = tc.y0[i] = 0;
      for (int a = 0; a < geometry::kAttributeCount; ++a) frag.attribute[a][i] = 0;
      for (int ch = 0; ch < 3; ++ch) frag.color[ch][i] = 0;
    }
    for (int i = 0; i < n; ++i) {
      const int p = w.pixels[begin + size_t(i)];
      const int lx = p % kTileSize, ly = p / kTileSize;
      int k = 0;
      while (std::isnan(w.hit[kPlane * size_t(k) + size_t(p)])) ++k;
      const double sx = w.ox + lx + 0.5 + offsetX_[k], sy = w.oy + ly + 0.5 + offsetY_[k];
      const Vec3d d = rays_.direction(sx, sy);
      const double hs = w.hit[kPlane * size_t(k) + size_t(p)];
      const Vec3d point = rays_.eye + d * hs;
      const Caster::MapPoint m = c.toMap(point);
      const double gxc = std::clamp(m.gx, 0.0, double(f.width - 1));
      const double gyc = std::clamp(m.gy, 0.0, double(f.height - 1));
      Vec3d eastDir, northDir;
      // The normal of the surface the ray met: its level of detail's.
      const Vec3d normal =
          c.normal(gxc, gyc, &eastDir, &northDir, c.lodLevel(hs, t.pixel, c.stretch(d)));
      const Vec3d rel = point - rays_.eye;
      frag.attribute[shade::kEyeX][i] = float(dot(rel, rays_.right));
      frag.attribute[shade::kEyeY][i] = float(dot(rel, rays_.up));
      frag.attribute[shade::kEyeZ][i] = float(-dot(rel, rays_.forward));
      frag.attribute[shade::kNormalX][i] = float(dot(normal, rays_.right));
      frag.attribute[shade::kNormalY][i] = float(dot(normal, rays_.up));
      frag.attribute[shade::kNormalZ][i] = float(-dot(normal, rays_.forward));
      const double u = c.mapU(gxc), v = c.mapV(gyc);
      Vec3 color{t.color[0], t.color[1], t.color[2]};
      if (!image) {
        const Vec3 r = rampAt(t.ramp, m.h);
        color = {color.x * r.x, color.y * r.y, color.z * r.z};
      }
      // The footprint (SPEC §7): where the next pixel's rays, right and down, meet the tangent
      // plane at the hit — map metres per pixel along east and north.
      double du[2] = {0, 0}, dv[2] = {0, 0};
      bool finite = true;
      for (int axis = 0; axis < 2; ++axis) {
        const Vec3d dn = rays_.direction(sx + (axis == 0), sy + (axis == 1));
        const double den = dot(normal, dn);
        const double tt = std::fabs(den) > 1e-12 ? dot(normal, rel) / den : -1;
        if (!(tt > 0) || !std::isfinite(tt)) {
          finite = false;
          break;
        }
        const Vec3d delta = dn * tt - rel;
        du[axis] = dot(delta, eastDir);
        dv[axis] = dot(delta, northDir);
      }
      if (!finite) du[0] = du[1] = dv[0] = dv[1] = 1e9;
      if (image) {
        const double tu = (u - west) / (east - west), tv = (north - v) / (north - south);
        tc.x0[i] = float(tu * imageW - 0.5);
        tc.y0[i] = float(tv * imageH - 0.5);
        tc.lod[i] =
            t.material.levelZero
                ? 0.0f
                : lodOf(du[0] / (east - west) * imageW, du[1] / (east - west) * imageW,
                        -dv[0] / (north - south) * imageH, -dv[1] / (north - south) * imageH);
      }
      if (t.detail) {
        const double dw = t.detail->level(0).width, dh = t.detail->level(0).height;
        const double k2 = 1 / t.detailSize;
        const texture::Color4 texel = t.detail->sample(
            texture::Filter::trilinear,
            lodOf(du[0] * k2 * dw, du[1] * k2 * dw, -dv[0] * k2 * dh, -dv[1] * k2 * dh),
            float(std::fmod(u * k2, 1.0) * dw - 0.5), float(std::fmod(-v * k2, 1.0) * dh - 0.5));
        color = {color.x * 2 * texel.r, color.y * 2 * texel.g, color.z * 2 * texel.b};
      }
      frag.color[0][i] = color.x, frag.color[1][i] = color.y, frag.color[2][i] = color.z;
    }
    alignas(64) float out[4][shade::kMaxFragments];
    shade::shadeFragments(t.material, *environment_, frag, tc, out);
    for (int i = 0; i < n; ++i) {
      const int p = w.pixels[begin + size_t(i)];
      const int lx = p % kTileSize, ly = p / kTileSize;
      uint16_t c16[3];
      for (int ch = 0; ch < 3; ++ch)
        c16[ch] = uint16_t(std::lrint(std::clamp(out[ch][i], 0.0f, 1.0f) * 65535.0f));
      for (int k = 0; k < s; ++k) {
        const double hs = w.hit[kPlane * size_t(k) + size_t(p)];
        if (std::isnan(hs)) continue;
        tile.depth[FrameBuffer::depthOffset(lx, ly, s, k)] = rays_.sToDepth(hs);
        for (int ch = 0; ch < 3; ++ch)
          tile.color[FrameBuffer::colorOffset(lx, ly, ch, s, k)] = c16[ch];
      }
    }
  }
}

}  // namespace sv::terrain
