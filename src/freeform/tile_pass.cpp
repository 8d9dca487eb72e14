// Based on: SPEC §12 (multi-level ray casting, leaf shading), §5 (samples), §8 (Phong, fog).
#include "freeform/tile_pass.h"

#include <algorithm>
#include <cmath>

#include "raster/framebuffer.h"

namespace sv::freeform {
namespace {

using raster::kBlockPixels;
using raster::kBlockSize;
using raster::kColorPerBlock;
using raster::kTileSize;

// Sample s of tile-local pixel (lx, ly) in the tile's block-major buffers (raster/framebuffer.h).
size_t depthIndex(int lx, int ly, int samples, int s) {
  return (raster::tileBlock(lx, ly) * size_t(samples) + size_t(s)) * kBlockPixels +
         size_t((ly & (kBlockSize - 1)) * kBlockSize + (lx & (kBlockSize - 1)));
}
size_t colorIndex(int lx, int ly, int samples, int s, int channel) {
  return (raster::tileBlock(lx, ly) * size_t(samples) + size_t(s)) * kColorPerBlock +
         size_t(channel * kBlockPixels + (ly & (kBlockSize - 1)) * kBlockSize +
                (lx & (kBlockSize - 1)));
}

Vec3d apply3(const Mat4d& m, Vec3d v) {  // the 3×3 part
  return {m.m[0][0] * v.x + m.m[0][1] * v.y + m.m[0][2] * v.z,
          m.m[1][0] * v.x + m.m[1][1] * v.y + m.m[1][2] * v.z,
          m.m[2][0] * v.x + m.m[2][1] * v.y + m.m[2][2] * v.z};
}

}  // namespace

void FreeFormFrame::prepare(std::vector<ShadedForm> forms, int width, int height, int samples,
                            const int32_t* sampleOffsetX, const int32_t* sampleOffsetY,
                            const shade::Environment* environment, const CastSettings& settings,
                            int marchSteps) {
  forms_ = std::move(forms);
  width_ = width;
  height_ = height;
  samples_ = samples;
  for (int s = 0; s < samples; ++s) {
    offsetX_[s] = sampleOffsetX ? sampleOffsetX[s] / 256.0 : 0.0;
    offsetY_[s] = sampleOffsetY ? sampleOffsetY[s] / 256.0 : 0.0;
  }
  environment_ = environment;
  settings_ = settings;
  marchSteps_ = marchSteps;
  tilesX_ = (width + kTileSize - 1) / kTileSize;
  tilesY_ = (height + kTileSize - 1) / kTileSize;
  tileForms_.assign(size_t(tilesX_) * size_t(tilesY_), {});
  tileNearest_.assign(tileForms_.size(), {});
  int size = kTileSize;
  while (size < width || size < height) size *= 2;
  for (uint32_t f = 0; f < forms_.size(); ++f) markTiles(f, 0, 0, size, -1, 1);
  // Nearest first; ties in the order of the scene (stable), so the frame never depends on more
  // than the scene.
  for (size_t t = 0; t < tileForms_.size(); ++t) {
    std::vector<uint32_t>& list = tileForms_[t];
    const std::vector<double>& nearest = tileNearest_[t];
    std::vector<uint32_t> order(list.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return nearest[a] < nearest[b]; });
    std::vector<uint32_t> sorted(list.size());
    for (size_t i = 0; i < order.size(); ++i) sorted[i] = list[order[i]];
    list = std::move(sorted);
  }
  tileNearest_.clear();
}

// Step 0 of a frame, per form: the screen quadtree from the whole raster down to tiles, with the
// eight-slab depth tree of the caster, over whole pixel squares (every sample of a pixel lies in
// its square).
void FreeFormFrame::markTiles(uint32_t f, int x0, int y0, int size, double zlo, double zhi) {
  if (x0 >= width_ || y0 >= height_) return;
  const int x1 = std::min(x0 + size, width_), y1 = std::min(y0 + size, height_);
  const Interval x{2.0 * x0 / width_ - 1, 2.0 * x1 / width_ - 1};
  const Interval y{1 - 2.0 * y1 / height_, 1 - 2.0 * y0 / height_};
  constexpr int kSlabs = 8;
  int first = -1, last = -1;
  for (int s = 0; s < kSlabs; ++s) {
    const double z0 = zlo + (zhi - zlo) * s / kSlabs, z1 = zlo + (zhi - zlo) * (s + 1) / kSlabs;
    if (!forms_[f].projected.bound(x, y, {z0, z1}).containsZero()) continue;
    if (first < 0) first = s;
    last = s;
  }
  if (first < 0) return;
  if (size == kTileSize) {
    const size_t t = size_t(y0 / kTileSize) * size_t(tilesX_) + size_t(x0 / kTileSize);
    tileForms_[t].push_back(f);
    tileNearest_[t].push_back(zlo + (zhi - zlo) * first / kSlabs);
    return;
  }
  const double nlo = zlo + (zhi - zlo) * first / kSlabs;
  const double nhi = last + 1 == kSlabs ? zhi : zlo + (zhi - zlo) * (last + 1) / kSlabs;
  const int h = size / 2;
  for (int c = 0; c < 4; ++c) markTiles(f, x0 + (c & 1) * h, y0 + (c >> 1) * h, h, nlo, nhi);
}

void FreeFormFrame::drawTile(int tileX, int tileY, float* depth, uint16_t* color,
                             Scratch& scratch, CastStats& stats) const {
  const std::vector<uint32_t>& listed = tileForms_[size_t(tileY) * size_t(tilesX_) + size_t(tileX)];
  if (listed.empty()) return;
  const int s = samples_;
  const size_t plane = size_t(kTileSize) * kTileSize;
  scratch.depth.resize(plane * size_t(s));
  scratch.object.assign(plane * size_t(s), kNoHit);
  scratch.cubeZ.resize(plane * size_t(s));
  const int ox = tileX * kTileSize, oy = tileY * kTileSize;

  // Step 1: per sample, the tile's depths row by row, and every listed form cast into them.
  for (int k = 0; k < s; ++k) {
    float* d = scratch.depth.data() + plane * size_t(k);
    for (int ly = 0; ly < kTileSize; ++ly)
      for (int lx = 0; lx < kTileSize; ++lx)
        d[ly * kTileSize + lx] = depth[depthIndex(lx, ly, s, k)];
    CastWindow w;
    w.width = width_;
    w.height = height_;
    w.x0 = ox;
    w.y0 = oy;
    w.size = kTileSize;
    w.depth = d;
    w.object = scratch.object.data() + plane * size_t(k);
    w.cubeZ = scratch.cubeZ.data() + plane * size_t(k);
    w.stride = kTileSize;
    w.offsetX = offsetX_[k];
    w.offsetY = offsetY_[k];
    for (uint32_t f : listed) {
      if (marchSteps_ > 0)
        marchWindow(forms_[f].projected, f, w, marchSteps_, stats);
      else
        castWindow(forms_[f].projected, f, w, settings_, stats);
    }
  }

  // Step 2: shading, once per pixel and form that took some of its samples — at the first such
  // sample's hit (the centre with one sample) — 16 fragments of one form to a call.
  struct Pending {
    int lx, ly, sample;
  };
  for (uint32_t f : listed) {
    const ShadedForm& form = forms_[f];
    std::vector<Pending> pending;
    for (int ly = 0; ly < kTileSize && oy + ly < height_; ++ly)
      for (int lx = 0; lx < kTileSize && ox + lx < width_; ++lx)
        for (int k = 0; k < s; ++k)
          if (scratch.object[plane * size_t(k) + size_t(ly * kTileSize + lx)] == f) {
            pending.push_back({lx, ly, k});
            break;
          }
    for (size_t begin = 0; begin < pending.size(); begin += shade::kMaxFragments) {
      const int count = int(std::min<size_t>(shade::kMaxFragments, pending.size() - begin));
      shade::Fragments frag;
      frag.count = count;
      for (int i = 0; i < count; ++i) {
        const Pending& p = pending[begin + size_t(i)];
        const size_t at = plane * size_t(p.sample) + size_t(p.ly * kTileSize + p.lx);
        const Vec3d q{2.0 * (ox + p.lx + 0.5 + offsetX_[p.sample]) / width_ - 1,
                      1 - 2.0 * (oy + p.ly + 0.5 + offsetY_[p.sample]) / height_,
                      scratch.cubeZ[at]};
        const Vec3d point = form.projected.toObject(q);
        // Inside is F ≥ 0, so the outward normal is −∇F.
        const Vec3d n = normalize(apply3(form.normalToEye, form.form.gradient(point) * -1.0));
        const Vec3d eye = form.objectToEye.transformPoint(point);
        frag.q[i] = 1;  // attributes are given as themselves (w = 1)
        for (int ch = 0; ch < 3; ++ch) frag.color[ch][i] = form.color[ch];
        frag.attribute[shade::kU][i] = frag.attribute[shade::kV][i] = 0;
        frag.attribute[shade::kNormalX][i] = float(n.x);
        frag.attribute[shade::kNormalY][i] = float(n.y);
        frag.attribute[shade::kNormalZ][i] = float(n.z);
        frag.attribute[shade::kEyeX][i] = float(eye.x);
        frag.attribute[shade::kEyeY][i] = float(eye.y);
        frag.attribute[shade::kEyeZ][i] = float(eye.z);
        frag.attribute[shade::kAlpha][i] = 1;
      }
      float out[4][shade::kMaxFragments];
      shade::shadeFragments(form.material, *environment_, frag, out);
      // Step 3: depth and colour to every sample of the pixel this form took.
      for (int i = 0; i < count; ++i) {
        const Pending& p = pending[begin + size_t(i)];
        uint16_t c16[3];
        for (int ch = 0; ch < 3; ++ch)
          c16[ch] = uint16_t(std::lrint(std::clamp(out[ch][i], 0.0f, 1.0f) * 65535.0f));
        for (int k = p.sample; k < s; ++k) {
          const size_t at = plane * size_t(k) + size_t(p.ly * kTileSize + p.lx);
          if (scratch.object[at] != f) continue;
          depth[depthIndex(p.lx, p.ly, s, k)] = scratch.depth[at];
          for (int ch = 0; ch < 3; ++ch) color[colorIndex(p.lx, p.ly, s, k, ch)] = c16[ch];
        }
      }
    }
  }
}

}  // namespace sv::freeform
