// Based on: SPEC §12 (multi-level ray casting, front to back, masking), §5 (samples), §7 (planar
// texture, footprint level of detail), §8 (Phong, fog).
#include "terrain/terrain_pass.h"

#include <algorithm>
#include <chrono>
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
// The window whose rays are walked together from its start, a packet a sample (castBlock): 4×4
// pixels, 16 lanes.
constexpr int kBlock = 4;
static_assert(kBlock * kBlock == terrain::kPacketRays);
// Steps (cells, or the skip map's squares) each lane of a packet walks at a level of detail before
// the rays it has not finished go on alone (Caster::cast): a lane-masked step is cheaper than a
// ray's march over the pyramid, so the packet walks on — at 4096², 16 cells a lane left 6 % of the
// rays to go on alone and took 119 ms a frame, 256 took 84, 1024 80 (before the skip map;
// docs/terrain.md, "Packets"); the bound keeps a packet's work finite.
constexpr int kPacketCells = 1024;
// The windows whose 4×4 blocks walk as packets from the window's start: the windows' marches
// above them (scalar, a bundle at a time) cost more than the packets' walk over the skip map's
// squares (4096², one thread: 4 px 156 ms a frame, 8 px 143, 16 px 151).
constexpr int kPacketWindow = 8;

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
  // The terms of the tile's rays (EyeRays::direction): per sample plane, its 64 columns' and 64
  // rows'.
  std::vector<Vec3d> column, row;
  // Per pixel, the ray of its first sample that met the ground (where shading looks).
  struct FirstHit {
    Vec3d d;
    double stretch;
    int sample;
  };
  std::vector<FirstHit> first;
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
  double ms = 0;
  for (const WorkerStats& s : stats_) c.add(s.counts), ms += s.ms;
  stats.terrainMs += ms / double(std::max<size_t>(stats_.size(), 1));
  stats.terrains += terrains_.size();
  stats.terrainWindows += c.windows;
  stats.terrainSteps += c.steps;
  stats.terrainSampleRays += c.samples;
  stats.terrainPacketRays += c.lanes;
  stats.terrainRays += c.rays;
  stats.terrainHits += c.hits;
  stats.terrainBytes += groundBytes_;
  stats.terrainLoadMs += loadMs_;
}

void TerrainPass::drawTile(const raster::TileTarget& tile) {
  if (terrains_.empty()) return;
  const auto begin = std::chrono::steady_clock::now();
  drawTerrains(tile);
  stats_[size_t(tile.worker)].ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count();
}

void TerrainPass::drawTerrains(const raster::TileTarget& tile) {
  Scratch& w = *scratch_[size_t(tile.worker)];
  w.counts = &stats_[size_t(tile.worker)].counts;
  w.ox = tile.tileX * kTileSize;
  w.oy = tile.tileY * kTileSize;
  const int s = samples_;
  w.limit.resize(kPlane * size_t(s));
  w.depth.resize(kPlane * size_t(s));
  w.hit.resize(kPlane * size_t(s));
  for (int k = 0; k <= 6; ++k) w.windowLimit[k].resize(size_t(64 >> k) * size_t(64 >> k));
  w.column.resize(size_t(kTileSize) * size_t(s));
  w.row.resize(size_t(kTileSize) * size_t(s));
  for (int k = 0; k < s; ++k)
    for (int i = 0; i < kTileSize; ++i) {
      w.column[size_t(k * kTileSize + i)] = rays_.column(w.ox + i + 0.5 + offsetX_[k]);
      w.row[size_t(k * kTileSize + i)] = rays_.row(w.oy + i + 0.5 + offsetY_[k]);
    }
  w.first.resize(kPlane);
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
  // A block's rays go on together from its start: a march of a smaller footprint first would
  // find little that the walk of their cells does not.
  // Packets walk from 8×8 windows; on a sphere, where the rays are cast one by one, the windows
  // go down to the blocks.
  if (size <= (t.caster->packetsApply() ? kPacketWindow : kBlock)) {
    for (int y = 0; y < size; y += kBlock)
      for (int x = 0; x < size; x += kBlock) castBlock(w, t, x0 + x, y0 + y, s);
    return;
  }
  const int h = size / 2;
  for (int c = 0; c < 4; ++c) castWindow(w, t, x0 + (c & 1) * h, y0 + (c >> 1) * h, h, s);
}

// The 4×4 block at tile position (x0, y0): per sample, its 16 rays walked together from `start`
// (Caster::walkPacket) to the depth each holds, a few cells each; those without a hit and depth
// left go on alone (Caster::cast) from where their walk stopped.
void TerrainPass::castBlock(Scratch& w, const Drawn& t, int x0, int y0, double start) const {
  const Caster& c = *t.caster;
  bool met[kPacketRays] = {};
  const Vec3d base = rays_.base();
  for (int k = 0; k < samples_; ++k) {
    Caster::Packet p;
    p.origin = rays_.eye;
    p.count = kPacketRays;
    // The packet's surfaces: at each depth the coarsest level of detail its rays ask for there
    // (no ray walks cells finer than its footprint) — lodLevel falls as the stretch grows, so
    // that of the longest stretch.
    double stretch = 0, stretches[kPacketRays];
    uint64_t rays = 0;
    size_t at[kPacketRays];
    for (int l = 0; l < kPacketRays; ++l) {
      const int x = x0 + (l & (kBlock - 1)), y = y0 + l / kBlock;
      const int gx = w.ox + x, gy = w.oy + y;
      at[l] = kPlane * size_t(k) + size_t(y * kTileSize + x);
      // rays_.direction(gx + 0.5 + offsetX_[k], gy + 0.5 + offsetY_[k]), from its terms.
      p.dir[l] = (base + w.column[size_t(k * kTileSize + x)]) + w.row[size_t(k * kTileSize + y)];
      if (gx >= width_ || gy >= height_ || !(start < w.limit[at[l]])) {
        p.s0[l] = 1, p.s1[l] = 0;  // beyond the raster, or masked: idle
        continue;
      }
      p.s0[l] = start, p.s1[l] = w.limit[at[l]];
      ++rays;
      stretches[l] = c.stretch(p.dir[l]);
      stretch = std::max(stretch, stretches[l]);
    }
    w.counts->samples += rays;
    c.walkPacketLevels(p, t.pixel, stretch, kPacketCells, *w.counts);
    for (int l = 0; l < kPacketRays; ++l) {
      if (!(p.s0[l] <= p.s1[l])) continue;
      double hs = p.hit[l];
      if (std::isnan(hs) && p.reached[l] < p.s1[l])
        hs = c.cast(rays_.eye, p.dir[l], p.reached[l], p.s1[l], *w.counts, t.pixel);
      if (std::isnan(hs) || !(rays_.sToDepth(hs) < w.depth[at[l]])) continue;
      w.hit[at[l]] = hs;
      if (!met[l]) {  // field by field: a braced temporary's copy stalled on store forwarding
        Scratch::FirstHit& first = w.first[at[l] - kPlane * size_t(k)];
        first.d = p.dir[l], first.stretch = stretches[l], first.sample = k;
      }
      met[l] = true;
    }
  }
  for (int l = 0; l < kPacketRays; ++l)
    if (met[l]) w.pixels.push_back((y0 + l / kBlock) * kTileSize + x0 + (l & (kBlock - 1)));
}

// The draped image's placement (planar, SPEC §7): texture coordinates from map metres by the
// image's bounds.
struct TerrainPass::Drape {
  const texture::Texture* image = nullptr;
  double west = 0, south = 0, east = 1, north = 1, width = 1, height = 1;
  explicit Drape(const Drawn& t)
      : image(t.material.texture),
        west(t.imageBounds[0]),
        south(t.imageBounds[1]),
        east(t.imageBounds[2]),
        north(t.imageBounds[3]),
        width(image ? image->level(0).width : 1),
        height(image ? image->level(0).height : 1) {}
};

// Where a pixel's ray met the ground: its first sample's hit.
struct TerrainPass::PixelHit {
  double sx = 0, sy = 0, s = 0;  // the sample's raster position, the hit's depth
  Vec3d d, point;
  Caster::MapPoint m;
  double gx = 0, gy = 0;  // the hit's grid position, clamped to the table
  int level = 0;          // the level of detail of the surface met
};

void TerrainPass::hitOf(const Scratch& w, const Drawn& t, int p, PixelHit& h) const {
  const Caster& c = *t.caster;
  const HeightField& f = *t.field;
  const int lx = p % kTileSize, ly = p / kTileSize;
  const Scratch::FirstHit& first = w.first[size_t(p)];
  const int k = first.sample;
  h.sx = w.ox + lx + 0.5 + offsetX_[k], h.sy = w.oy + ly + 0.5 + offsetY_[k];
  h.d = first.d;
  h.s = w.hit[kPlane * size_t(k) + size_t(p)];
  h.point = rays_.eye + h.d * h.s;
  h.m = c.toMap(h.point);
  h.gx = std::clamp(h.m.gx, 0.0, double(f.width - 1));
  h.gy = std::clamp(h.m.gy, 0.0, double(f.height - 1));
  h.level = c.lodLevel(h.s, t.pixel, first.stretch);
}

// One pixel's eye position, normal, texture coordinates and detail texture, in double: the
// general case (a sphere's base, a detail texture) of what shadeLanes does.
void TerrainPass::shadePixel(const Drawn& t, const Drape& drape, const PixelHit& h, int i,
                             shade::Fragments& frag, shade::TexCoords& tc) const {
  const Caster& c = *t.caster;
  Vec3d eastDir, northDir;
  // The normal of the surface the ray met: its level of detail's.
  const Vec3d normal = c.normal(h.gx, h.gy, &eastDir, &northDir, h.level);
  const Vec3d rel = h.point - rays_.eye;
  frag.attribute[shade::kEyeX][i] = float(dot(rel, rays_.right));
  frag.attribute[shade::kEyeY][i] = float(dot(rel, rays_.up));
  frag.attribute[shade::kEyeZ][i] = float(-dot(rel, rays_.forward));
  frag.attribute[shade::kNormalX][i] = float(dot(normal, rays_.right));
  frag.attribute[shade::kNormalY][i] = float(dot(normal, rays_.up));
  frag.attribute[shade::kNormalZ][i] = float(-dot(normal, rays_.forward));
  const double u = c.mapU(h.gx), v = c.mapV(h.gy);
  // The footprint (SPEC §7): where the next pixel's rays, right and down, meet the tangent plane
  // at the hit — map metres per pixel along east and north.
  double du[2] = {0, 0}, dv[2] = {0, 0};
  bool finite = true;
  for (int axis = 0; axis < 2; ++axis) {
    const Vec3d dn = rays_.direction(h.sx + (axis == 0), h.sy + (axis == 1));
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
  if (drape.image) {
    const double spanU = drape.east - drape.west, spanV = drape.north - drape.south;
    const double tu = (u - drape.west) / spanU, tv = (drape.north - v) / spanV;
    tc.x0[i] = float(tu * drape.width - 0.5);
    tc.y0[i] = float(tv * drape.height - 0.5);
    tc.lod[i] = t.material.levelZero
                    ? 0.0f
                    : lodOf(du[0] / spanU * drape.width, du[1] / spanU * drape.width,
                            -dv[0] / spanV * drape.height, -dv[1] / spanV * drape.height);
  }
  if (t.detail) {
    const double dw = t.detail->level(0).width, dh = t.detail->level(0).height;
    const double k2 = 1 / t.detailSize;
    const texture::Color4 texel = t.detail->sample(
        texture::Filter::trilinear,
        lodOf(du[0] * k2 * dw, du[1] * k2 * dw, -dv[0] * k2 * dh, -dv[1] * k2 * dh),
        float(std::fmod(u * k2, 1.0) * dw - 0.5), float(std::fmod(-v * k2, 1.0) * dh - 0.5));
    const float rgb[3] = {texel.r, texel.g, texel.b};
    for (int ch = 0; ch < 3; ++ch) frag.color[ch][i] = frag.color[ch][i] * 2 * rgb[ch];
  }
}

// The frame's constants of shadeLanes for terrain `t`.
ShadeFrame TerrainPass::shadeFrame(const Drawn& t, const Drape& drape) const {
  ShadeFrame f;
  const Vec3d d0 = rays_.direction(0, 0);
  const Vec3d dX = rays_.direction(1, 0) - d0, dY = rays_.direction(0, 1) - d0;
  auto put = [](float* out, Vec3d v) {
    out[0] = float(v.x), out[1] = float(v.y), out[2] = float(v.z);
  };
  put(f.d0, d0), put(f.dX, dX), put(f.dY, dY);
  put(f.right, rays_.right), put(f.up, rays_.up), put(f.forward, rays_.forward);
  const HeightField& field = *t.field;
  f.spacingU = float(field.spacingU), f.spacingV = float(field.spacingV);
  f.scale = float(field.scale);
  f.image = drape.image != nullptr;
  f.levelZero = t.material.levelZero;
  const double spanU = drape.east - drape.west, spanV = drape.north - drape.south;
  // texel x = ((originU + gx·spacingU) − west)/spanU·width − ½; y from north likewise.
  f.perMetreX = float(drape.width / spanU), f.perMetreY = float(drape.height / spanV);
  f.texX = float(field.spacingU * drape.width / spanU);
  f.texX0 = float((field.originU - drape.west) * drape.width / spanU - 0.5);
  f.texY = float(field.spacingV * drape.height / spanV);
  f.texY0 = float((drape.north - field.originV) * drape.height / spanV - 0.5);
  return f;
}

// Each pixel that met the ground, shaded once — at its first sample's hit — 16 to a call, and
// written to every sample whose ray met the ground nearer than what the sample held. On the plane
// without a detail texture, the per-pixel work in SIMD lanes (shadeLanes; on the bicubic table,
// the normal from the 4×4 samples around the hit's cell).
void TerrainPass::shadeHits(Scratch& w, const Drawn& t, const raster::TileTarget& tile) const {
  const Caster& c = *t.caster;
  const Drape drape(t);
  const ShadeFrame frame = shadeFrame(t, drape);
  const bool lanesApply = c.placement().radius <= 0 && !t.detail;
  const int n = c.pyramid().gridLevel();
  const int s = samples_;
  for (size_t begin = 0; begin < w.pixels.size(); begin += shade::kMaxFragments) {
    const int count = int(std::min<size_t>(shade::kMaxFragments, w.pixels.size() - begin));
    shade::Fragments frag;
    shade::TexCoords tc;
    frag.count = count;
    for (int i = 0; i < shade::kMaxFragments; ++i) {
      frag.q[i] = 1;
      tc.lod[i] = tc.x0[i] = tc.y0[i] = 0;
      for (int a = 0; a < geometry::kAttributeCount; ++a) frag.attribute[a][i] = 0;
      for (int ch = 0; ch < 3; ++ch) frag.color[ch][i] = 0;
    }
    PixelHit hits[shade::kMaxFragments];
    bool bicubic = false;  // a pixel met the table's bicubic surface
    for (int i = 0; i < count; ++i) {
      hitOf(w, t, w.pixels[begin + size_t(i)], hits[i]);
      bicubic = bicubic || (hits[i].level >= n && t.interp == Interpolation::bicubic);
      Vec3 color{t.color[0], t.color[1], t.color[2]};
      if (!drape.image) {
        const Vec3 r = rampAt(t.ramp, hits[i].m.h);
        color = {color.x * r.x, color.y * r.y, color.z * r.z};
      }
      frag.color[0][i] = color.x, frag.color[1][i] = color.y, frag.color[2][i] = color.z;
    }
    if (lanesApply) {
      ShadeLanes in{};
      in.bicubic = bicubic;
      for (int i = 0; i < count; ++i) {
        const PixelHit& h = hits[i];
        in.px[i] = float(h.sx), in.py[i] = float(h.sy), in.s[i] = float(h.s);
        in.gx[i] = float(h.gx), in.gy[i] = float(h.gy);
        // The cell of the level met around the hit (meanSurface, caster.cpp).
        const Pyramid::MeanLevel m = c.pyramid().mean(h.level);
        const double x = std::clamp(h.gx / m.step, 0.0, double(m.width - 1));
        const double y = std::clamp(h.gy / m.step, 0.0, double(m.height - 1));
        const int ci = std::min(int(x), m.width - 2), cj = std::min(int(y), m.height - 2);
        in.cellU[i] = float(x - ci), in.cellV[i] = float(y - cj);
        in.h00[i] = m.code(ci, cj), in.h10[i] = m.code(ci + 1, cj);
        in.h01[i] = m.code(ci, cj + 1), in.h11[i] = m.code(ci + 1, cj + 1);
        in.step[i] = float(m.step);
        if (bicubic && h.level >= n) {
          // cellSamples, read straight from the rows away from the table's edges.
          const HeightField& f = *t.field;
          in.cubic[i] = 1;
          if (ci >= 1 && cj >= 1 && ci + 2 < f.width && cj + 2 < f.height) {
            for (int r = 0; r < 4; ++r) {
              const uint16_t* row =
                  f.q.data() + size_t(cj - 1 + r) * size_t(f.width) + size_t(ci - 1);
              for (int q = 0; q < 4; ++q) in.patch[4 * r + q][i] = row[q];
            }
          } else {
            double patch[4][4];
            cellSamples(f, ci, cj, patch);
            for (int r = 0; r < 4; ++r)
              for (int q = 0; q < 4; ++q) in.patch[4 * r + q][i] = float(patch[r][q]);
          }
        }
      }
      shadeLanes(frame, in, frag, tc);
    } else {
      for (int i = 0; i < count; ++i) shadePixel(t, drape, hits[i], i, frag, tc);
    }
    alignas(64) float out[4][shade::kMaxFragments];
    shade::shadeFragments(t.material, *environment_, frag, tc, out);
    for (int i = 0; i < count; ++i) {
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
