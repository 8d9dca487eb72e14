// Based on: SPEC §12 (multi-level ray casting, leaf shading), §5 (samples), §8 (Phong, fog).
#include "freeform/freeform_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "raster/framebuffer.h"

namespace sv::freeform {
namespace {

using raster::FrameBuffer;
using raster::kBlockSize;
using raster::kTileSize;

constexpr size_t kPlane = size_t(kTileSize) * kTileSize;  // a tile's pixels: one sample plane

// What a pixel's samples take under CastSettings::adaptiveSamples (castAdaptive): nothing (no
// form at any of its 3×3 centres); the centre's hit or their own (kBand: one form at all of them,
// each sample wholly in front of or behind its depth band over the pixel); or a ray each (kRays).
enum PixelState : uint8_t { kNothing, kBand, kRays };

// The centres with a ring of one pixel around the tile: kRing wide, row-major.
constexpr int kRing = kTileSize + 2;

// Block `block` of a tile (its index in block-major order): its top-left pixel.
int blockX(int block) { return (block % raster::kBlocksPerTileSide) * kBlockSize; }
int blockY(int block) { return (block / raster::kBlocksPerTileSide) * kBlockSize; }

}  // namespace

struct FreeFormPass::TileJob {
  int ox, oy;  // the tile's pixel origin
  float* depth;
  uint16_t* color;
  const std::vector<uint32_t>& listed;  // the forms it casts, nearest first
  const std::vector<double>& nearest;   // … and the nearest cube depth each may take
  Scratch& scratch;
  CastStats& stats;
  int samples;
  // Every sample is cast by the windows (not adaptively, not marched): each hit keeps its
  // window's perturbations that may be positive (CastWindow::active), and shading leaves out the
  // rest — a form's few bumps are each in few windows (on BENCH.md's freeform 0.2 of a form's 3.1
  // perturbations per window, against 2.9 over a tile).
  bool pixelMasks;

  // Sample plane k of the scratch buffers: depth, object, cube z (row-major, kTileSize wide).
  float* depthPlane(int k) const { return scratch.depth.data() + kPlane * size_t(k); }
  uint32_t* objectPlane(int k) const { return scratch.object.data() + kPlane * size_t(k); }
  double* cubeZPlane(int k) const { return scratch.cubeZ.data() + kPlane * size_t(k); }
};

void FreeFormPass::setForms(std::vector<ShadedForm> forms, const shade::Environment* environment,
                            const CastSettings& settings, int marchSteps) {
  forms_ = std::move(forms);
  surfaces_.clear();
  for (const ShadedForm& f : forms_)
    surfaces_.emplace_back(f.form, f.projected.inverse(), f.objectToEye, f.normalToEye,
                           f.uvScale[0], f.uvScale[1]);
  environment_ = environment;
  settings_ = settings;
  marchSteps_ = marchSteps;
}

void FreeFormPass::prepare(const raster::PassFrame& frame) {
  width_ = frame.width;
  height_ = frame.height;
  samples_ = frame.samples;
  for (int s = 0; s < samples_; ++s) {
    offsetX_[s] = frame.coverage ? frame.coverage->offsetX[s] / 256.0 : 0.0;
    offsetY_[s] = frame.coverage ? frame.coverage->offsetY[s] / 256.0 : 0.0;
  }
  const int workers = frame.pool ? frame.pool->threadCount() : 1;
  scratch_.resize(size_t(workers));
  stats_.assign(size_t(workers), WorkerStats{});
  tilesX_ = (width_ + kTileSize - 1) / kTileSize;
  tilesY_ = (height_ + kTileSize - 1) / kTileSize;
  tileForms_.assign(size_t(tilesX_) * size_t(tilesY_), {});
  tileNearest_.assign(tileForms_.size(), {});
  int size = kTileSize;
  while (size < width_ || size < height_) size *= 2;
  // Each form's tiles found on its own (in parallel), then listed in the order of the forms.
  marks_.resize(forms_.size());
  const auto mark = [&](size_t f, int) {
    marks_[f].clear();
    markTiles(uint32_t(f), 0, 0, size, -1, 1, marks_[f]);
  };
  if (frame.pool)
    frame.pool->parallelFor(forms_.size(), mark);
  else
    for (size_t f = 0; f < forms_.size(); ++f) mark(f, 0);
  for (uint32_t f = 0; f < forms_.size(); ++f)
    for (const Mark& m : marks_[f]) {
      tileForms_[m.tile].push_back(f);
      tileNearest_[m.tile].push_back(m.nearest);
    }
  sortTileLists();
}

// Each tile's forms nearest first; ties in the order of the scene (stable), so the frame never
// depends on more than the scene.
void FreeFormPass::sortTileLists() {
  for (size_t t = 0; t < tileForms_.size(); ++t) {
    std::vector<uint32_t>& list = tileForms_[t];
    const std::vector<double>& nearest = tileNearest_[t];
    std::vector<uint32_t> order(list.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return nearest[a] < nearest[b]; });
    std::vector<uint32_t> sorted(list.size());
    std::vector<double> sortedNearest(list.size());
    for (size_t i = 0; i < order.size(); ++i) {
      sorted[i] = list[order[i]];
      sortedNearest[i] = nearest[order[i]];
    }
    list = std::move(sorted);
    tileNearest_[t] = std::move(sortedNearest);
  }
}

void FreeFormPass::addStats(FrameStats& stats) const {
  CastStats cast;
  for (const WorkerStats& s : stats_) cast.add(s.counts);
  stats.freeForms += forms_.size();
  stats.freeFormCells += cast.cells;
  stats.freeFormMaskedCells += cast.maskedCells;
  stats.freeFormBounds += cast.depthTests;
  stats.freeFormRays += cast.pixels;
  stats.freeFormHits += cast.hits;
}

// Step 0 of a frame, per form: the screen quadtree from the whole raster down to tiles, with the
// eight-slab depth tree (the caster uses sixteen), over whole pixel squares (every sample of a
// pixel lies in its square).
void FreeFormPass::markTiles(uint32_t f, int x0, int y0, int size, double zlo, double zhi,
                             std::vector<Mark>& marks) const {
  if (x0 >= width_ || y0 >= height_) return;
  const int x1 = std::min(x0 + size, width_), y1 = std::min(y0 + size, height_);
  const Interval x{2.0 * x0 / width_ - 1, 2.0 * x1 / width_ - 1};
  const Interval y{1 - 2.0 * y1 / height_, 1 - 2.0 * y0 / height_};
  constexpr int kSlabs = 8;
  bool holds[kSlabs];
  forms_[f].projected.slabsHolding(x, y, zlo, zhi, kSlabs, holds);
  int first = -1, last = -1;
  for (int s = 0; s < kSlabs; ++s) {
    if (!holds[s]) continue;
    if (first < 0) first = s;
    last = s;
  }
  if (first < 0) return;
  if (size == kTileSize) {
    marks.push_back({uint32_t(y0 / kTileSize) * uint32_t(tilesX_) + uint32_t(x0 / kTileSize),
                     zlo + (zhi - zlo) * first / kSlabs});
    return;
  }
  const double nlo = zlo + (zhi - zlo) * first / kSlabs;
  const double nhi = last + 1 == kSlabs ? zhi : zlo + (zhi - zlo) * (last + 1) / kSlabs;
  const int h = size / 2;
  for (int c = 0; c < 4; ++c) markTiles(f, x0 + (c & 1) * h, y0 + (c >> 1) * h, h, nlo, nhi, marks);
}

void FreeFormPass::drawTile(const raster::TileTarget& tile) {
  const size_t index = size_t(tile.tileY) * size_t(tilesX_) + size_t(tile.tileX);
  const std::vector<uint32_t>& listed = tileForms_[index];
  if (listed.empty()) return;
  const int s = samples_;
  TileJob job{tile.tileX * kTileSize,
              tile.tileY * kTileSize,
              tile.depth,
              tile.color,
              listed,
              tileNearest_[index],
              scratch_[size_t(tile.worker)],
              stats_[size_t(tile.worker)].counts,
              s,
              marchSteps_ == 0 && (s == 1 || !settings_.adaptiveSamples)};
  // Step 1: per sample, the tile's depths row by row; every listed form cast into them — into
  // all samples, or (CastSettings::adaptiveSamples) into the pixel centres, then into the samples
  // of the pixels where the centres do not tell.
  readDepths(job);
  // Per listed form, the perturbations that may be positive at its hits in the tile: the union
  // over the casts; all of them where rays are marched or samples cast ray by ray (beyond the
  // windows' bounds).
  job.scratch.active.assign(listed.size(), marchSteps_ > 0 ? kAllActive : 0);
  if (job.pixelMasks) job.scratch.pixelActive.resize(kPlane * size_t(s));
  if (s == 1 || !settings_.adaptiveSamples || marchSteps_ > 0)
    castEverySample(job);
  else
    castAdaptive(job);
  // Step 2: shading, once per pixel and form that took some of its samples — at the first such
  // sample's hit (the centre with one sample) — 16 fragments of one form to a call; their surface
  // points and normals 16 at a time (SurfacePoints).
  listPixels(job);
  for (size_t place = 0; place < listed.size(); ++place) shadeForm(job, place);
}

// The tile's depth, sample plane by sample plane, into the scratch rows.
void FreeFormPass::readDepths(TileJob& job) const {
  const int s = job.samples;
  job.scratch.depth.resize(kPlane * size_t(s));
  job.scratch.object.assign(kPlane * size_t(s), kNoHit);
  job.scratch.cubeZ.resize(kPlane * size_t(s));
  for (int k = 0; k < s; ++k) {
    float* d = job.depthPlane(k);
    // Block by block: a block's sample plane is 4 rows of 4 in a row (FrameBuffer's layout).
    for (int by = 0; by < kTileSize; by += kBlockSize)
      for (int bx = 0; bx < kTileSize; bx += kBlockSize) {
        const float* block = job.depth + FrameBuffer::depthOffset(bx, by, s, k);
        for (int r = 0; r < kBlockSize; ++r)
          std::copy_n(block + r * kBlockSize, kBlockSize, d + (by + r) * kTileSize + bx);
      }
  }
}

// The whole tile as one window (freeform::castWindow) of buffers `depth`, `object`, `cubeZ` and (if given) `active`
// (row-major, kTileSize wide), its rays at sample offset (dx, dy); every listed form cast into it.
void FreeFormPass::castTile(TileJob& job, float* depth, uint32_t* object, double* cubeZ,
                            uint64_t* active, double dx, double dy) const {
  CastWindow w;
  w.width = width_;
  w.height = height_;
  w.x0 = job.ox;
  w.y0 = job.oy;
  w.size = kTileSize;
  w.depth = depth;
  w.object = object;
  w.cubeZ = cubeZ;
  w.active = active;
  w.stride = kTileSize;
  w.offsetX = dx;
  w.offsetY = dy;
  if (marchSteps_ > 0) {
    for (uint32_t f : job.listed) marchWindow(forms_[f].projected, f, w, marchSteps_, job.stats);
    return;
  }
  MaskingPyramid pyramid(w);  // one for all the forms
  for (size_t i = 0; i < job.listed.size(); ++i) {
    uint64_t formActive;
    castWindow(forms_[job.listed[i]].projected, job.listed[i], w, settings_, job.stats, &pyramid,
               &formActive);
    job.scratch.active[i] |= formActive;
  }
}

void FreeFormPass::castEverySample(TileJob& job) const {
  for (int k = 0; k < job.samples; ++k)
    castTile(job, job.depthPlane(k), job.objectPlane(k), job.cubeZPlane(k),
             job.pixelMasks ? job.scratch.pixelActive.data() + kPlane * size_t(k) : nullptr,
             offsetX_[k], offsetY_[k]);
}

// CastSettings::adaptiveSamples: the pixel centres, then every sample only where the centres do
// not tell.
void FreeFormPass::castAdaptive(TileJob& job) const {
  job.scratch.active.assign(job.listed.size(), kAllActive);
  castCentresWithRing(job);
  classifyPixels(job);
  // The kBand pixels: the centre's hit for every sample it is nearer than.
  Scratch& scratch = job.scratch;
  const uint32_t* co = scratch.ringObject.data();
  const float* cd = scratch.ringDepth.data();
  for (int k = 0; k < job.samples; ++k) {
    float* d = job.depthPlane(k);
    uint32_t* obj = job.objectPlane(k);
    double* z = job.cubeZPlane(k);
    for (int ly = 0; ly < kTileSize; ++ly)
      for (int lx = 0; lx < kTileSize; ++lx) {
        const size_t p = size_t(ly) * kTileSize + size_t(lx);
        if (scratch.pixelState[p] != kBand) continue;
        const size_t r = size_t(ly + 1) * kRing + size_t(lx + 1);
        if (!(cd[r] < d[p])) continue;
        d[p] = cd[r];
        obj[p] = co[r];
        z[p] = scratch.centreZ[p];
      }
  }
  castSampleRays(job);
}

// The centres cast against the farthest of each pixel's samples (a polygon covering part of the
// pixel must not hide the form from the whole of it), then copied into the ring (ringObject,
// ringDepth) whose border pixels get rays of their own — which see the forms alone (the
// neighbouring tiles' polygons are not here; off the raster, nothing).
void FreeFormPass::castCentresWithRing(TileJob& job) const {
  Scratch& scratch = job.scratch;
  scratch.centreDepth.resize(kPlane);
  scratch.centreObject.assign(kPlane, kNoHit);
  scratch.centreZ.resize(kPlane);
  // Plane by plane: the planes lie 16 KB apart, and a pixel's samples read one after another
  // fall in one cache set (docs/performance.md, "Free forms").
  std::copy_n(scratch.depth.data(), kPlane, scratch.centreDepth.data());
  for (int k = 1; k < job.samples; ++k)
    for (size_t p = 0; p < kPlane; ++p)
      scratch.centreDepth[p] =
          std::max(scratch.centreDepth[p], scratch.depth[kPlane * size_t(k) + p]);
  castTile(job, scratch.centreDepth.data(), scratch.centreObject.data(), scratch.centreZ.data(),
           nullptr, 0, 0);
  scratch.ringObject.assign(size_t(kRing) * kRing, kNoHit);
  scratch.ringDepth.assign(size_t(kRing) * kRing, 1.0f);
  uint32_t* co = scratch.ringObject.data();
  float* cd = scratch.ringDepth.data();
  for (int ly = 0; ly < kTileSize; ++ly)
    for (int lx = 0; lx < kTileSize; ++lx) {
      co[size_t(ly + 1) * kRing + size_t(lx + 1)] =
          scratch.centreObject[size_t(ly) * kTileSize + size_t(lx)];
      cd[size_t(ly + 1) * kRing + size_t(lx + 1)] =
          scratch.centreDepth[size_t(ly) * kTileSize + size_t(lx)];
    }
  CastStats local;
  double ignored;
  for (int ry = 0; ry < kRing; ++ry)
    for (int rx = 0; rx < kRing; rx += (ry == 0 || ry == kRing - 1) ? 1 : kRing - 1) {
      const int px = job.ox + rx - 1, py = job.oy + ry - 1;
      if (px < 0 || py < 0 || px >= width_ || py >= height_) continue;
      const size_t r = size_t(ry) * kRing + size_t(rx);
      for (size_t i = 0; i < job.listed.size(); ++i)
        castRay(forms_[job.listed[i]].projected, job.listed[i], cubeX(px, width_, 0),
                cubeY(py, height_, 0), job.nearest[i], std::numeric_limits<double>::quiet_NaN(),
                cd[r], co[r], ignored, scratch.ray, local);
    }
  job.stats.add(local);
}

// Per pixel, what its samples take (PixelState). Worked out plane by plane where the samples are
// read (castCentresWithRing).
void FreeFormPass::classifyPixels(TileJob& job) const {
  Scratch& scratch = job.scratch;
  const uint32_t* co = scratch.ringObject.data();
  const float* cd = scratch.ringDepth.data();
  scratch.pixelState.assign(kPlane, kNothing);
  scratch.bandLo.resize(kPlane);
  scratch.bandHi.resize(kPlane);
  for (int ly = 0; ly < kTileSize && job.oy + ly < height_; ++ly)
    for (int lx = 0; lx < kTileSize && job.ox + lx < width_; ++lx) {
      const size_t p = size_t(ly) * kTileSize + size_t(lx);
      const size_t r = size_t(ly + 1) * kRing + size_t(lx + 1);
      const uint32_t o = co[r];
      // Uniform: a pixel whose 3×3 centres all see form o (or all none).
      bool uniform = true;
      for (int j = -1; j <= 1 && uniform; ++j)
        for (int i = -1; i <= 1 && uniform; ++i)
          uniform = co[size_t(ptrdiff_t(r) + j * kRing + i)] == o;
      if (uniform && o == kNoHit) continue;
      if (!uniform) {
        scratch.pixelState[p] = kRays;
        continue;
      }
      // The form's depth over the pixel: the centre's ± the largest step to a neighbour's.
      const float zc = cd[r];
      float dz = 0;
      for (const int n : {-1, 1, -kRing, kRing})
        dz = std::max(dz, std::fabs(cd[size_t(ptrdiff_t(r) + n)] - zc));
      scratch.pixelState[p] = kBand;
      scratch.bandLo[p] = zc - dz;
      scratch.bandHi[p] = zc + dz;
    }
  for (int k = 0; k < job.samples; ++k) {
    const float* held = job.depthPlane(k);
    for (size_t p = 0; p < kPlane; ++p)
      if (scratch.pixelState[p] == kBand &&
          !(held[p] > scratch.bandHi[p] || held[p] < scratch.bandLo[p]))
        scratch.pixelState[p] = kRays;  // a sample within the band: polygons cross the form
  }
}

// The kRays pixels — silhouettes, forms crossing each other or the polygons: every sample its own
// ray, for the forms the 3×3 centres saw (nearest first, as listed), each started near the depth
// a centre saw it at.
void FreeFormPass::castSampleRays(TileJob& job) const {
  Scratch& scratch = job.scratch;
  const uint32_t* co = scratch.ringObject.data();
  const float* cd = scratch.ringDepth.data();
  for (int ly = 0; ly < kTileSize && job.oy + ly < height_; ++ly)
    for (int lx = 0; lx < kTileSize && job.ox + lx < width_; ++lx) {
      const size_t p = size_t(ly) * kTileSize + size_t(lx);
      if (scratch.pixelState[p] != kRays) continue;
      const size_t r = size_t(ly + 1) * kRing + size_t(lx + 1);
      uint32_t seen[9];
      double hint[9], from[9];
      int count = 0;
      for (size_t l = 0; l < job.listed.size(); ++l)
        for (int j = -1; j <= 1; ++j)
          for (int i = -1; i <= 1; ++i) {
            const uint32_t f = job.listed[l];
            const size_t q = size_t(ptrdiff_t(r) + j * kRing + i);
            if (co[q] != f || (count > 0 && seen[count - 1] == f)) continue;
            seen[count] = f;
            from[count] = job.nearest[l];
            hint[count++] = q == r ? scratch.centreZ[p] : 2.0 * double(cd[q]) - 1;
          }
      CastStats local;
      for (int k = 0; k < job.samples; ++k) {
        const double x = cubeX(job.ox + lx, width_, offsetX_[k]);
        const double y = cubeY(job.oy + ly, height_, offsetY_[k]);
        for (int c = 0; c < count; ++c)
          castRay(forms_[seen[c]].projected, seen[c], x, y, from[c], hint[c], job.depthPlane(k)[p],
                  job.objectPlane(k)[p], job.cubeZPlane(k)[p], scratch.ray, local);
      }
      job.stats.add(local);
    }
}

// The pixels to shade, per listed form (by its place in the list), in one pass over the tile's
// 4×4 blocks: a block all of whose samples one form took is shaded as one batch and written back
// whole (the frame buffer holds a block's samples together); the others pixel by pixel. Then the
// cube x of every column and y of every row, per sample (the rays' own).
void FreeFormPass::listPixels(TileJob& job) const {
  Scratch& scratch = job.scratch;
  const std::vector<uint32_t>& listed = job.listed;
  const int s = job.samples;
  scratch.pending.resize(std::max(scratch.pending.size(), listed.size()));
  scratch.wholeBlocks.resize(std::max(scratch.wholeBlocks.size(), listed.size()));
  scratch.place.resize(forms_.size());
  scratch.lastPixel.assign(listed.size(), -1);
  for (size_t i = 0; i < listed.size(); ++i) {
    scratch.pending[i].clear();
    scratch.wholeBlocks[i].clear();
    scratch.place[listed[i]] = uint32_t(i);
  }
  const int ox = job.ox, oy = job.oy;
  for (int by = 0; by < kTileSize && oy + by < height_; by += kBlockSize)
    for (int bx = 0; bx < kTileSize && ox + bx < width_; bx += kBlockSize) {
      const uint32_t first = scratch.object[size_t(by * kTileSize + bx)];
      bool whole =
          first != kNoHit && oy + by + kBlockSize <= height_ && ox + bx + kBlockSize <= width_;
      for (int k = 0; k < s && whole; ++k)
        for (int r = 0; r < kBlockSize && whole; ++r) {
          const uint32_t* row = job.objectPlane(k) + size_t((by + r) * kTileSize + bx);
          for (int c = 0; c < kBlockSize; ++c) whole &= row[c] == first;
        }
      if (whole) {
        scratch.wholeBlocks[scratch.place[first]].push_back(
            (by / kBlockSize) * raster::kBlocksPerTileSide + bx / kBlockSize);
        continue;
      }
      for (int ly = by; ly < by + kBlockSize && oy + ly < height_; ++ly)
        for (int lx = bx; lx < bx + kBlockSize && ox + lx < width_; ++lx) {
          const int p = ly * kTileSize + lx;
          for (int k = 0; k < s; ++k) {
            const uint32_t o = scratch.object[kPlane * size_t(k) + size_t(p)];
            if (o == kNoHit) continue;
            const uint32_t i = scratch.place[o];
            if (scratch.lastPixel[i] == p) continue;  // shaded at an earlier sample of the pixel
            scratch.lastPixel[i] = p;
            scratch.pending[i].push_back({lx, ly, k});
          }
        }
    }
  scratch.columnX.resize(size_t(kTileSize) * size_t(s));
  scratch.rowY.resize(size_t(kTileSize) * size_t(s));
  for (int k = 0; k < s; ++k)
    for (int i = 0; i < kTileSize; ++i) {
      scratch.columnX[size_t(k * kTileSize + i)] = cubeX(ox + i, width_, offsetX_[k]);
      scratch.rowY[size_t(k * kTileSize + i)] = cubeY(oy + i, height_, offsetY_[k]);
    }
}

static_assert(int(shade::kU) == SurfaceLanes::kU && int(shade::kV) == SurfaceLanes::kV &&
                  int(shade::kNormalX) == SurfaceLanes::kNormal &&
                  int(shade::kEyeX) == SurfaceLanes::kEye &&
                  int(shade::kEyeZ) + 1 == SurfaceLanes::kFloats,
              "SurfaceLanes::floats are shading's attributes from kU on, in its order");
static_assert(shade::kMaxFragments == 16, "fragments are SurfaceLanes' 16 lanes");
static_assert(shade::kMaxFragments == raster::kBlockPixels, "a whole block is one batch");

// The listed form at `place`: its whole blocks, then its other pixels, 16 to a batch.
void FreeFormPass::shadeForm(TileJob& job, size_t place) const {
  const ShadedForm& form = forms_[job.listed[place]];
  const std::vector<Scratch::Pending>& pending = job.scratch.pending[place];
  const std::vector<int>& wholeBlocks = job.scratch.wholeBlocks[place];
  if (pending.empty() && wholeBlocks.empty()) return;
  // What all the form's fragments share, set once: attributes given as themselves (w = 1), the
  // form's colour, opaque. (Every lane set: a batch of fewer than 16 leaves the rest as they are,
  // and shading and the write-back's rounding run over all 16.)
  shade::Fragments frag;
  std::fill_n(&frag.attribute[0][0], shade::kAttributeCount * shade::kMaxFragments, 0.0f);
  std::fill_n(frag.q, shade::kMaxFragments, 1.0f);
  for (int ch = 0; ch < 3; ++ch) std::fill_n(frag.color[ch], shade::kMaxFragments, form.color[ch]);
  std::fill_n(frag.attribute[shade::kAlpha], shade::kMaxFragments, 1.0f);
  // Textured forms are shaded a pixel at a time (shadeBatch).
  const bool textured = form.material.texture != nullptr;
  for (const int block : wholeBlocks) {
    if (!textured) {
      shadeBatch(job, place, frag, nullptr, shade::kMaxFragments, block);
      continue;
    }
    // Textured, pixel by pixel: the block's pixels in its lane order, at their first samples.
    Scratch::Pending batch[shade::kMaxFragments];
    for (int i = 0; i < shade::kMaxFragments; ++i)
      batch[i] = {blockX(block) + i % kBlockSize, blockY(block) + i / kBlockSize, 0};
    shadeBatch(job, place, frag, batch, shade::kMaxFragments, -1);
  }
  for (size_t begin = 0; begin < pending.size(); begin += shade::kMaxFragments)
    shadeBatch(job, place, frag, pending.data() + begin,
               int(std::min<size_t>(shade::kMaxFragments, pending.size() - begin)), -1);
}

// A batch of `count` pixels of the listed form at `place`: batch[0 … count), or (untextured forms
// only) whole block `block` ≥ 0, batch unused. Textured forms are shaded a pixel at a time: each
// has its own footprint (Fragments carries one gradient per call — a triangle's, constant over
// it).
void FreeFormPass::shadeBatch(TileJob& job, size_t place, shade::Fragments& frag,
                              const Scratch::Pending* batch, int count, int block) const {
  Scratch& scratch = job.scratch;
  const uint32_t f = job.listed[place];
  const ShadedForm& form = forms_[f];
  // Per fragment: its sample's cube point (the worker's arrays: lanes past `count` are read, not
  // used); the perturbations that may be positive at any.
  double* qx = scratch.cubeX;
  double* qy = scratch.cubeY;
  double* qz = scratch.cubeZPoint;
  uint64_t active = job.pixelMasks ? 0 : scratch.active[place];
  if (block >= 0) {  // a whole block: its first samples, row by row
    const int bx = blockX(block), by = blockY(block);
    for (int r = 0; r < kBlockSize; ++r) {
      const size_t at = size_t((by + r) * kTileSize + bx);
      std::copy_n(scratch.columnX.data() + bx, kBlockSize, qx + r * kBlockSize);
      std::fill_n(qy + r * kBlockSize, kBlockSize, scratch.rowY[size_t(by + r)]);
      std::copy_n(scratch.cubeZ.data() + at, kBlockSize, qz + r * kBlockSize);
      if (job.pixelMasks)
        for (int c = 0; c < kBlockSize; ++c) active |= scratch.pixelActive[at + size_t(c)];
    }
  } else {
    for (int i = 0; i < count; ++i) {
      const Scratch::Pending& p = batch[i];
      const size_t at = kPlane * size_t(p.sample) + size_t(p.ly * kTileSize + p.lx);
      qx[i] = scratch.columnX[size_t(p.sample * kTileSize + p.lx)];
      qy[i] = scratch.rowY[size_t(p.sample * kTileSize + p.ly)];
      qz[i] = scratch.cubeZ[at];
      if (job.pixelMasks) active |= scratch.pixelActive[at];
    }
  }
  SurfaceLanes& hit = scratch.surface;
  alignas(64) float out[4][shade::kMaxFragments];  // shadeFragments stores whole vectors
  if (form.material.texture == nullptr) {
    surfaces_[f].at(qx, qy, qz, count, hit, active, frag.attribute + shade::kU);
    frag.count = count;
    shade::shadeFragments(form.material, *environment_, frag, out);
    writeBack(job, f, batch, 0, count, block, out);
    return;
  }
  surfaces_[f].at(qx, qy, qz, count, hit, active);
  for (int first = 0; first < count; ++first) {
    frag.count = 1;
    for (int a = 0; a < SurfaceLanes::kFloats; ++a)
      frag.attribute[shade::kU + a][0] = hit.floats[a][first];
    // The footprint (SPEC §7): where the next pixel's rays, right and down, meet the tangent
    // plane at the hit — the texture coordinates' derivatives per pixel.
    const Vec3d point{hit.point[0][first], hit.point[1][first], hit.point[2][first]};
    const Vec3d gradient{hit.gradient[0][first], hit.gradient[1][first], hit.gradient[2][first]};
    const double z = qz[first];
    const Scratch::Pending& p = batch[first];
    const double sx = job.ox + p.lx + 0.5 + offsetX_[p.sample];  // the sample, in pixels
    const double sy = job.oy + p.ly + 0.5 + offsetY_[p.sample];
    auto onTangentPlane = [&](double px, double py, double& u, double& v) {
      const Vec3d a = form.projected.toObject({2 * px / width_ - 1, 1 - 2 * py / height_, z});
      const Vec3d b = form.projected.toObject(
          {2 * px / width_ - 1, 1 - 2 * py / height_, std::min(1.0, z + 1e-3 * (1 - z))});
      const double den = dot(gradient, b - a);
      const double t = std::fabs(den) > 1e-300 ? dot(gradient, point - a) / den : 0;
      const Vec3d x = a + (b - a) * std::clamp(t, -1e6, 1e6);
      u = x.x * form.uvScale[0];
      v = x.z * form.uvScale[1];
    };
    double ux, vx, uy, vy;
    onTangentPlane(sx + 1, sy, ux, vx);
    onTangentPlane(sx, sy + 1, uy, vy);
    frag.udx = float(ux - point.x * form.uvScale[0]);
    frag.vdx = float(vx - point.z * form.uvScale[1]);
    frag.udy = float(uy - point.x * form.uvScale[0]);
    frag.vdy = float(vy - point.z * form.uvScale[1]);
    shade::shadeFragments(form.material, *environment_, frag, out);
    writeBack(job, f, batch, first, 1, -1, out);
  }
}

// Step 3: depth and colour to every sample of the pixels form `form` took — fragments [0, n) of
// `out`, the pixels batch[first …]; `block` ≥ 0: the batch is that whole block, lanes in its
// order, written plane by plane.
void FreeFormPass::writeBack(TileJob& job, uint32_t form, const Scratch::Pending* batch, int first,
                             int n, int block, const float (*out)[shade::kMaxFragments]) const {
  const int s = job.samples;
  // To 16 bits, to nearest (ties to even, as lrint): adding 2^23 leaves the rounded value in the
  // float's low bits. shadeFragments's colours lie in [0, 1] already; with no clamp the loop is
  // one the compiler vectorizes.
  alignas(64) uint16_t c16[3][shade::kMaxFragments];
  for (int ch = 0; ch < 3; ++ch)
    for (int j = 0; j < shade::kMaxFragments; ++j) {
      const float v = out[ch][j] * 65535.0f + 8388608.0f;
      uint32_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      c16[ch][j] = uint16_t(bits);
    }
  if (block >= 0) {
    const int bx = blockX(block), by = blockY(block);
    for (int k = 0; k < s; ++k) {
      float* d = job.depth + FrameBuffer::depthOffset(bx, by, s, k);
      for (int r = 0; r < kBlockSize; ++r)
        std::copy_n(job.depthPlane(k) + size_t((by + r) * kTileSize + bx), kBlockSize,
                    d + r * kBlockSize);
      std::copy_n(&c16[0][0], raster::kColorPerBlock,
                  job.color + FrameBuffer::colorOffset(bx, by, 0, s, k));
    }
    return;
  }
  for (int j = 0; j < n; ++j) {
    const Scratch::Pending& p = batch[first + j];
    for (int k = p.sample; k < s; ++k) {
      const size_t at = kPlane * size_t(k) + size_t(p.ly * kTileSize + p.lx);
      if (job.scratch.object[at] != form) continue;
      job.depth[FrameBuffer::depthOffset(p.lx, p.ly, s, k)] = job.scratch.depth[at];
      for (int ch = 0; ch < 3; ++ch)
        job.color[FrameBuffer::colorOffset(p.lx, p.ly, ch, s, k)] = c16[ch][j];
    }
  }
}

}  // namespace sv::freeform
