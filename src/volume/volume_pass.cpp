#include "volume/volume_pass.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <climits>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "freeform/raycast.h"
#include "raster/framebuffer.h"
#include "volume/sample_kernel.h"

namespace sv::volume {
namespace {

using raster::FrameBuffer;
using raster::kTileSize;

// The transfer function (synthvis/volumes.h TransferPoint) at `value`: linear between points, the
// end points' beyond them.
std::array<float, 4> classify(const std::vector<scene::TransferPoint>& tf, float value) {
  auto of = [](const scene::TransferPoint& p) {
    return std::array<float, 4>{p.color.x, p.color.y, p.color.z, p.opacity};
  };
  if (!(value > tf.front().value)) return of(tf.front());
  if (!(value < tf.back().value)) return of(tf.back());
  const auto hi = std::upper_bound(tf.begin(), tf.end(), value,
                                   [](float v, const scene::TransferPoint& p) { return v < p.value; });
  const scene::TransferPoint& b = *hi;
  const scene::TransferPoint& a = *(hi - 1);
  const float t = (value - a.value) / (b.value - a.value);
  const auto ca = of(a), cb = of(b);
  return {ca[0] + t * (cb[0] - ca[0]), ca[1] + t * (cb[1] - ca[1]), ca[2] + t * (cb[2] - ca[2]),
          ca[3] + t * (cb[3] - ca[3])};
}

// Per sample of `g`, the direction of its value's gradient (central differences, one-sided at
// the faces) in the grid's own space, scaled to ±127; (0, 0, 0) where the gradient vanishes.
// Four bytes a sample (x, y, z and a pad), for VolumeSettings::precomputedNormals.
std::vector<int8_t> sampleNormals(const scene::VolumeGrid& g) {
  std::vector<int8_t> n(g.codes.size() * 4, 0);
  const int size[3] = {g.nx, g.ny, g.nz};
  const size_t step[3] = {1, size_t(g.nx), size_t(g.nx) * size_t(g.ny)};
  const double spacing[3] = {g.spacing.x, g.spacing.y, g.spacing.z};
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const size_t at = g.at(i, j, k);
        const int index[3] = {i, j, k};
        double d[3], length = 0;
        for (int a = 0; a < 3; ++a) {
          const bool low = index[a] > 0, high = index[a] < size[a] - 1;
          const double up = g.codes[high ? at + step[a] : at], down = g.codes[low ? at - step[a] : at];
          d[a] = (up - down) / ((low + high) * spacing[a]);
          length += d[a] * d[a];
        }
        length = std::sqrt(length);
        if (length > 0)
          for (int a = 0; a < 3; ++a) n[at * 4 + size_t(a)] = int8_t(std::lrint(d[a] / length * 127));
      }
  return n;
}

// The codes of `g` with a border of one sample on every side repeating the faces' samples (the
// sample kernel's central differences read the border where the moved point would be clamped into
// the box), as T (uint8_t only where every code fits), with 4 bytes of slack after them for the
// kernel's 32-bit reads; empty when its bytes would not fit the kernel's 32-bit gather offsets.
template <typename T>
std::vector<T> borderedCodes(const scene::VolumeGrid& g) {
  const size_t px = size_t(g.nx) + 2, py = size_t(g.ny) + 2, pz = size_t(g.nz) + 2;
  if (px * py * pz * sizeof(T) + 16 > size_t(INT32_MAX)) return {};
  std::vector<T> out(px * py * pz + 4 / sizeof(T));
  for (size_t k = 0; k < pz; ++k)
    for (size_t j = 0; j < py; ++j) {
      const int sk = std::clamp(int(k) - 1, 0, g.nz - 1), sj = std::clamp(int(j) - 1, 0, g.ny - 1);
      const uint16_t* row = g.codes.data() + g.at(0, sj, sk);
      T* to = out.data() + (k * py + j) * px;
      to[0] = T(row[0]);
      std::transform(row, row + g.nx, to + 1, [](uint16_t c) { return T(c); });
      to[px - 1] = T(row[g.nx - 1]);
    }
  return out;
}

// The ray o + s·d (own space) against the box [0, e]: its entry and exit s, empty when s0 ≥ s1.
void clipToBox(const double o[3], const double d[3], const double lo[3], const double hi[3],
               double& s0, double& s1) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (o[a] < lo[a] || o[a] > hi[a]) s0 = s1;
      continue;
    }
    double t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    s0 = std::max(s0, t0);
    s1 = std::min(s1, t1);
  }
}

// The ray o + s·d (own space) against the inside (F ≥ 0) of quadric q (A … K, SPEC §11's order):
// [s0, s1] narrowed to the stretch between the first entry and the last exit (a conservative
// hull where the inside is two pieces), or emptied where the ray never enters it.
void clipToQuadric(const std::array<double, 10>& q, const double o[3], const double d[3],
                   double& s0, double& s1) {
  const double A = q[0], B = q[1], C = q[2], D = q[3], E = q[4], F = q[5], G = q[6], H = q[7],
               I = q[8], K = q[9];
  const double a = A * d[0] * d[0] + B * d[1] * d[1] + C * d[2] * d[2] + D * d[0] * d[1] +
                   E * d[0] * d[2] + F * d[1] * d[2];
  const double b = 2 * (A * o[0] * d[0] + B * o[1] * d[1] + C * o[2] * d[2]) +
                   D * (o[0] * d[1] + o[1] * d[0]) + E * (o[0] * d[2] + o[2] * d[0]) +
                   F * (o[1] * d[2] + o[2] * d[1]) + G * d[0] + H * d[1] + I * d[2];
  const double c = A * o[0] * o[0] + B * o[1] * o[1] + C * o[2] * o[2] + D * o[0] * o[1] +
                   E * o[0] * o[2] + F * o[1] * o[2] + G * o[0] + H * o[1] + I * o[2] + K;
  const double scale = std::fabs(a) + std::fabs(b) + std::fabs(c);
  if (!(scale > 0)) return;
  if (std::fabs(a) <= 1e-12 * scale) {  // linear: b·s + c ≥ 0
    if (std::fabs(b) <= 1e-12 * scale) {
      if (c < 0) s0 = s1;
      return;
    }
    const double root = -c / b, margin = 1e-9 * (std::fabs(root) + 1);
    if (b > 0) s0 = std::max(s0, root - margin);
    else s1 = std::min(s1, root + margin);
    return;
  }
  const double disc = b * b - 4 * a * c;
  if (disc < 0) {
    if (a < 0) s0 = s1;  // wholly outside (a > 0: wholly inside)
    return;
  }
  const double sq = std::sqrt(disc);
  const double r0 = std::min((-b - sq) / (2 * a), (-b + sq) / (2 * a)),
               r1 = std::max((-b - sq) / (2 * a), (-b + sq) / (2 * a));
  if (a > 0) return;  // inside beyond both roots: the hull is the whole line
  const double margin = 1e-9 * (std::fabs(r0) + std::fabs(r1) + 1);
  s0 = std::max(s0, r0 - margin);
  s1 = std::min(s1, r1 + margin);
}

// A composite (colour C, transparency T) of one channel over the 16-bit value a sample holds.
inline void compositeOver(uint16_t& out, double C, double T) {
  out = uint16_t(std::lrint(std::clamp(C + T * (out / 65535.0), 0.0, 1.0) * 65535.0));
}

// One pixel's compositing: the running colour and transparency, and per sample of the pixel the
// value they had when the ray reached that sample's depth — and where a translucent surface lies
// in front of some samples' opaque ones, the value at the nearest such surface (the split).
struct PixelComposite {
  double C[3] = {0, 0, 0};
  double T = 1;
  int samples = 1;
  double limit[64];   // per sample: its eye depth (the surface already there)
  bool done[64];
  double snapC[64][3], snapT[64];
  uint64_t split = 0;      // the samples with a translucent surface in front of their opaque one
  double splitAt = 1e300;  // the nearest of those translucent surfaces, as s
  bool splitDone = true;
  double splitC[3] = {0, 0, 0}, splitT = 1;

  double next = -1e300;  // no sample not yet recorded has its surface before this depth
  double last = 0;       // the end of the last sample composited (not transparent), as s

  // Records the samples (and the split) whose surface lies at or before eye depth s.
  void reach(double s) {
    if (s < next) return;
    next = 1e300;
    if (!splitDone) {
      if (splitAt <= s) {
        splitDone = true;
        splitC[0] = C[0], splitC[1] = C[1], splitC[2] = C[2];
        splitT = T;
      } else {
        next = splitAt;
      }
    }
    for (int k = 0; k < samples; ++k) {
      if (!done[k] && limit[k] <= s) {
        done[k] = true;
        snapC[k][0] = C[0], snapC[k][1] = C[1], snapC[k][2] = C[2];
        snapT[k] = T;
      }
      if (!done[k]) next = std::min(next, limit[k]);
    }
  }

  // Starts the composite of pixel (lx, ly) of `tile`, of s samples, each limited by its surface
  // and split at the translucent surfaces in front of them (tile.translucentDepth); returns the
  // eye depth of the farthest sample (no ray goes beyond it).
  [[gnu::always_inline]] double start(const raster::TileTarget& tile, const EyeRays& r, int lx,
                                      int ly, int s) {
    samples = s;
    double farthest = 0;
    for (int k = 0; k < s; ++k) {
      const size_t at = FrameBuffer::depthOffset(lx, ly, s, k);
      limit[k] = r.depthToS(tile.depth[at]);
      done[k] = false;
      farthest = std::max(farthest, limit[k]);
      if (tile.translucentDepth && tile.translucentDepth[at] < tile.depth[at]) {
        split |= uint64_t(1) << k;
        splitAt = std::min(splitAt, r.depthToS(tile.translucentDepth[at]));
        splitDone = false;
      }
    }
    return farthest;
  }

  // Samples the rays did not reach take the whole composite; then each goes over its surface —
  // a split sample only the part behind the split (the part before it is laid over the
  // translucent surfaces later: FrontPixel). A ray that turned opaque (its transparency below ε)
  // at s = `opaqueAt` before a sample's surface hides it: the sample's depth becomes the ray's.
  [[gnu::always_inline]] void writeOver(const raster::TileTarget& tile, const EyeRays& r, int lx,
                                        int ly, double opaqueAt) {
    reach(1e300);
    for (int k = 0; k < samples; ++k) {
      double c[3] = {snapC[k][0], snapC[k][1], snapC[k][2]}, t = snapT[k];
      if (split >> k & 1) {
        // The part behind the split alone: (C − C_f)/T_f and T/T_f. Where T_f vanishes nothing
        // behind shows (the front's T_f multiplies it), so none is composited.
        if (!(splitT > 1e-9)) continue;
        for (int ch = 0; ch < 3; ++ch) c[ch] = (c[ch] - splitC[ch]) / splitT;
        t /= splitT;
      }
      for (int ch = 0; ch < 3; ++ch)
        compositeOver(tile.color[FrameBuffer::colorOffset(lx, ly, ch, samples, k)], c[ch], t);
      if (opaqueAt < limit[k]) {
        float& depth = tile.depth[FrameBuffer::depthOffset(lx, ly, samples, k)];
        depth = std::min(depth, r.sToDepth(opaqueAt));
      }
    }
  }
};

}  // namespace

void VolumePass::setVolumes(const VolumeInput& input) {
  input_ = input;
  const auto& objects = *input.volumes;
  volumes_.resize(objects.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    Prepared& p = volumes_[i];
    const scene::VolumeObject& v = objects[i];
    const bool same = p.grid == v.grid.get() &&
                      p.transfer.size() == v.transfer.size() &&
                      std::equal(p.transfer.begin(), p.transfer.end(), v.transfer.begin(),
                                 [](const scene::TransferPoint& a, const scene::TransferPoint& b) {
                                   return a.value == b.value && a.opacity == b.opacity &&
                                          a.color.x == b.color.x && a.color.y == b.color.y &&
                                          a.color.z == b.color.z;
                                 });
    p.object = &v;
    if (!same) {
      p.held = v.grid;
      p.grid = v.grid.get();
      p.transfer = v.transfer;
      p.normals.clear();
      p.padded.clear();
      p.padded8.clear();
      prepareTables(p);
    }
    if (input.settings.precomputedNormals && v.shaded && p.normals.empty())
      p.normals = sampleNormals(*v.grid);
    if (!input.settings.precomputedNormals) p.normals.clear();
    // The bordered codes: a byte each where every code fits, read for the value lit or not; 16-bit
    // ones only for the gradient of a lit volume.
    const auto& codes = v.grid->codes;
    const bool bytes = std::all_of(codes.begin(), codes.end(), [](uint16_t c) { return c < 256; });
    if (!input.settings.precomputedNormals && p.padded.empty() && p.padded8.empty()) {
      if (bytes)
        p.padded8 = borderedCodes<uint8_t>(*v.grid);
      else if (v.shaded)
        p.padded = borderedCodes<uint16_t>(*v.grid);
    }
    if (input.settings.precomputedNormals) p.padded.clear(), p.padded8.clear();
    if (!v.shaded) p.padded.clear();
    p.shellForm.reset();
    if (v.freeFormShell)
      p.shellForm = freeform::ProjectedFreeForm::make(
          freeform::fromNode(*v.freeFormShell),
          Mat4d::of(input.viewProjection) * Mat4d::of(v.transform));
    // World → own: the inverse of the affine transform, in double (validateVolumes has refused a
    // singular one).
    const bool invertible = affineInverse(v.transform, p.toOwn);
    SV_CHECK(invertible);
    const Mat4& m = v.transform;
    const scene::VolumeGrid& g = *v.grid;
    const Vec3 e = g.extent();
    p.extent[0] = e.x, p.extent[1] = e.y, p.extent[2] = e.z;
    p.inverseSpacing[0] = 1.0 / g.spacing.x;
    p.inverseSpacing[1] = 1.0 / g.spacing.y;
    p.inverseSpacing[2] = 1.0 / g.spacing.z;
    const double smallest = std::min({double(g.spacing.x), double(g.spacing.y), double(g.spacing.z)});
    p.stepOwn = double(input.settings.step) * smallest;
    // The smallest spacing in the world: the shortest image of a voxel's edge.
    double unit = 1e300;
    for (int axis = 0; axis < 3; ++axis) {
      const double sp = axis == 0 ? g.spacing.x : axis == 1 ? g.spacing.y : g.spacing.z;
      const double len = std::sqrt(double(m.m[axis][0]) * m.m[axis][0] +
                                   double(m.m[axis][1]) * m.m[axis][1] +
                                   double(m.m[axis][2]) * m.m[axis][2]) * sp;
      unit = std::min(unit, len);
    }
    p.opacityUnit = v.opacityUnit > 0 ? double(v.opacityUnit) : unit;
    // The transform's scale along the grid's axes: uniform (a similarity) when they agree.
    double lengths[3];
    for (int axis = 0; axis < 3; ++axis)
      lengths[axis] = std::sqrt(double(m.m[axis][0]) * m.m[axis][0] + double(m.m[axis][1]) * m.m[axis][1] +
                                double(m.m[axis][2]) * m.m[axis][2]);
    const double lo = std::min({lengths[0], lengths[1], lengths[2]}),
                 hi = std::max({lengths[0], lengths[1], lengths[2]});
    p.stepOpacity.clear();
    if (hi - lo <= 1e-6 * hi) {
      const double exponent = p.stepOwn * hi / p.opacityUnit;
      const size_t entries = p.table.size() / 4;
      p.stepOpacity.resize(entries);
      for (size_t k = 0; k < entries; ++k) {
        const double o = p.table[k * 4 + 3];
        p.stepOpacity[k] = o >= 1 ? 1.0f : float(1 - std::pow(1 - o, exponent));
      }
    }
  }
}

// The transfer function as a table over the grid's codes, and the map of bricks whose every sample
// it makes transparent. A sample reads the table linearly between the two entries around its code,
// so a brick is transparent when every entry from below its smallest code to above its largest is.
namespace {

// Whether brick (bx, by, bz)'s samples and those within two samples of it (clamped to the grid:
// what its samples' trilinear reads and their gradients' crosses can reach) hold one code.
bool oneCode(const scene::VolumeGrid& g, int bx, int by, int bz) {
  const int b = VolumePass::kBrick;
  const uint16_t code = g.codes[g.at(std::min(bx * b, g.nx - 1), std::min(by * b, g.ny - 1),
                                     std::min(bz * b, g.nz - 1))];
  for (int k = std::max(0, bz * b - 2); k <= std::min(bz * b + b + 2, g.nz - 1); ++k)
    for (int j = std::max(0, by * b - 2); j <= std::min(by * b + b + 2, g.ny - 1); ++j) {
      const uint16_t* row = g.codes.data() + g.at(0, j, k);
      for (int i = std::max(0, bx * b - 2); i <= std::min(bx * b + b + 2, g.nx - 1); ++i)
        if (row[i] != code) return false;
    }
  return true;
}

}  // namespace

void VolumePass::prepareTables(Prepared& p) const {
  const scene::VolumeGrid& g = *p.grid;
  const uint16_t top = g.codes.empty() ? 1 : std::max<uint16_t>(1, *std::max_element(g.codes.begin(), g.codes.end()));
  const int entries = std::min(kTableSize, int(top) + 1);
  p.codeScale = double(entries - 1) / double(top);
  p.table.assign(size_t(entries) * 4, 0.0f);
  std::vector<uint32_t> opaqueBefore(size_t(entries) + 1, 0);  // entries with opacity > 0 before e
  for (int e = 0; e < entries; ++e) {
    const float code = float(double(e) / p.codeScale);
    const auto c = classify(p.transfer, g.offset + g.scale * code);
    for (int k = 0; k < 4; ++k) p.table[size_t(e) * 4 + size_t(k)] = c[size_t(k)];
    opaqueBefore[size_t(e) + 1] = opaqueBefore[size_t(e)] + (c[3] > 0);
  }
  const int n[3] = {g.nx, g.ny, g.nz};
  for (int a = 0; a < 3; ++a) p.bricks[a] = (n[a] - 2) / kBrick + 1;
  p.emptyBrick.assign(size_t(p.bricks[0]) * size_t(p.bricks[1]) * size_t(p.bricks[2]), 0);
  p.constantBrick.assign(p.emptyBrick.size(), 0);
  p.contentBricks.clear();
  for (int bz = 0; bz < p.bricks[2]; ++bz)
    for (int by = 0; by < p.bricks[1]; ++by)
      for (int bx = 0; bx < p.bricks[0]; ++bx) {
        // The brick's cells' corner samples: [8b, 8b + 8] on each axis, within the grid.
        uint16_t lo = 65535, hi = 0;
        for (int k = bz * kBrick; k <= std::min(bz * kBrick + kBrick, g.nz - 1); ++k)
          for (int j = by * kBrick; j <= std::min(by * kBrick + kBrick, g.ny - 1); ++j) {
            const uint16_t* row = g.codes.data() + g.at(0, j, k);
            for (int i = bx * kBrick; i <= std::min(bx * kBrick + kBrick, g.nx - 1); ++i) {
              lo = std::min(lo, row[i]);
              hi = std::max(hi, row[i]);
            }
          }
        // A sample at table position x reads entries ⌊x⌋ and ⌊x⌋ + 1, the second with weight
        // x − ⌊x⌋: so positions in [lo, hi] read entries ⌊lo⌋ … ⌈hi⌉ (a brick of one code reads
        // that code's entry alone: trilinear weights of equal codes give the code exactly).
        const int first = std::max(0, int(std::floor(lo * p.codeScale)));
        const int last = std::min(entries - 1, int(std::ceil(hi * p.codeScale)));
        const size_t index =
            (size_t(bz) * size_t(p.bricks[1]) + size_t(by)) * size_t(p.bricks[0]) + size_t(bx);
        p.emptyBrick[index] = opaqueBefore[size_t(last) + 1] == opaqueBefore[size_t(first)];
        if (!p.emptyBrick[index]) p.contentBricks.push_back(uint32_t(index));
        p.constantBrick[index] = !p.emptyBrick[index] && oneCode(g, bx, by, bz);
      }
}

namespace {

// The pixels and eye depths an own-space box [lo, hi] of a volume placed by `m` may cover: the
// bounding rectangle and depth range of its corners projected. False when a corner lies behind
// the eye (the rectangle is unbounded).
struct Footprint {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300, near = 1e300, far = -1e300;
};
bool footprint(const Mat4& m, const VolumeInput& in, const double lo[3], const double hi[3],
               Footprint& f) {
  const EyeRays& r = in.rays;
  for (int c = 0; c < 8; ++c) {
    const Vec3 own{float((c & 1) ? hi[0] : lo[0]), float((c & 2) ? hi[1] : lo[1]),
                   float((c & 4) ? hi[2] : lo[2])};
    const Vec3 world = m.transformPoint(own);
    const Vec3d rel{world.x - r.eye.x, world.y - r.eye.y, world.z - r.eye.z};
    const double depth = dot(rel, r.axis);
    const Vec4 clip = in.viewProjection * Vec4{world.x, world.y, world.z, 1.0f};
    if (!(depth > 1e-6) || !(clip.w > 1e-6f * std::fabs(clip.x) + 1e-20f)) return false;
    const double px = (clip.x / clip.w + 1) * 0.5 * r.width;
    const double py = (1 - clip.y / clip.w) * 0.5 * r.height;
    f.x0 = std::min(f.x0, px), f.x1 = std::max(f.x1, px);
    f.y0 = std::min(f.y0, py), f.y1 = std::max(f.y1, py);
    f.near = std::min(f.near, depth), f.far = std::max(f.far, depth);
  }
  return true;
}

}  // namespace

// The pixels the volume's box may cover: its corners projected, or the whole raster when one lies
// behind the eye.
void VolumePass::screenBounds(Prepared& p) const {
  const EyeRays& r = input_.rays;
  const double lo[3] = {0, 0, 0};
  Footprint f;
  if (!footprint(p.object->transform, input_, lo, p.extent, f)) {
    p.x0 = p.y0 = 0, p.x1 = r.width, p.y1 = r.height;
    return;
  }
  p.x0 = int(std::clamp(std::floor(f.x0) - 1, 0.0, double(r.width)));
  p.y0 = int(std::clamp(std::floor(f.y0) - 1, 0.0, double(r.height)));
  p.x1 = int(std::clamp(std::ceil(f.x1) + 1, 0.0, double(r.width)));
  p.y1 = int(std::clamp(std::ceil(f.y1) + 1, 0.0, double(r.height)));
}

// Per window, the eye depths between which its rays can meet a brick with content: each such
// brick's eight corners projected give the pixels it may cover (their bounding rectangle, a pixel
// wider: rays pass through pixel centres) and its nearest and farthest eye depth. Every sample
// outside those depths on the window's rays lies in transparent bricks, so starting and ending
// the rays there changes no pixel.
void VolumePass::windowDepths(Prepared& p) const {
  const EyeRays& r = input_.rays;
  p.windowNear.clear();
  p.windowFar.clear();
  if (!input_.settings.skipEmpty) return;
  p.windowsX = (r.width + kWindow - 1) / kWindow;
  const int windowsY = (r.height + kWindow - 1) / kWindow;
  p.windowNear.assign(size_t(p.windowsX) * size_t(windowsY), std::numeric_limits<float>::infinity());
  p.windowFar.assign(p.windowNear.size(), -std::numeric_limits<float>::infinity());
  const scene::VolumeGrid& g = *p.grid;
  const double brick[3] = {kBrick * double(g.spacing.x), kBrick * double(g.spacing.y),
                           kBrick * double(g.spacing.z)};
  for (const uint32_t index : p.contentBricks) {
    const int bx = int(index % uint32_t(p.bricks[0]));
    const int by = int(index / uint32_t(p.bricks[0]) % uint32_t(p.bricks[1]));
    const int bz = int(index / uint32_t(p.bricks[0]) / uint32_t(p.bricks[1]));
    const int b[3] = {bx, by, bz};
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
      lo[a] = std::min(b[a] * brick[a], p.extent[a]), hi[a] = std::min((b[a] + 1) * brick[a], p.extent[a]);
    Footprint fp;
    if (!footprint(p.object->transform, input_, lo, hi, fp)) {
      // Behind the eye: its rectangle is unbounded; the windows are not known this frame.
      p.windowNear.clear();
      p.windowFar.clear();
      return;
    }
    const double x0 = fp.x0, y0 = fp.y0, x1 = fp.x1, y1 = fp.y1, near = fp.near, far = fp.far;
    // (The corners in float through the transform: a margin of a pixel and a part in 10⁴ of
    // depth covers their rounding.)
    const int wx0 = int(std::clamp(std::floor((x0 - 1) / kWindow), 0.0, double(p.windowsX - 1)));
    const int wx1 = int(std::clamp(std::floor((x1 + 1) / kWindow), 0.0, double(p.windowsX - 1)));
    const int wy0 = int(std::clamp(std::floor((y0 - 1) / kWindow), 0.0, double(windowsY - 1)));
    const int wy1 = int(std::clamp(std::floor((y1 + 1) / kWindow), 0.0, double(windowsY - 1)));
    if (x1 < -1 || y1 < -1 || x0 > r.width + 1 || y0 > r.height + 1) continue;
    const float n = float(near * (1 - 1e-4) - 1e-6), f = float(far * (1 + 1e-4) + 1e-6);
    for (int wy = wy0; wy <= wy1; ++wy)
      for (int wx = wx0; wx <= wx1; ++wx) {
        const size_t w = size_t(wy) * size_t(p.windowsX) + size_t(wx);
        p.windowNear[w] = std::min(p.windowNear[w], n);
        p.windowFar[w] = std::max(p.windowFar[w], f);
      }
  }
}

void VolumePass::prepare(const raster::PassFrame& frame) {
  input_.rays.width = frame.width;
  input_.rays.height = frame.height;
  samples_ = frame.samples;
  for (Prepared& p : volumes_) {
    screenBounds(p);
    windowDepths(p);
    // The sample kernel's view of the volume's tables and of the light (sample_kernel.h).
    const scene::VolumeGrid& g = *p.grid;
    SampleSource& k = p.source;
    k.codes = g.codes.data();
    k.nx = g.nx, k.ny = g.ny, k.nz = g.nz;
    const float spacing[3] = {g.spacing.x, g.spacing.y, g.spacing.z};
    for (int a = 0; a < 3; ++a) {
      k.inverseSpacing[a] = float(p.inverseSpacing[a]);
      k.spacing[a] = spacing[a];
      for (int c = 0; c < 3; ++c) k.toWorld[c][a] = float(p.toOwn[a][c]);
    }
    k.table = p.table.data();
    k.entries = int(p.table.size() / 4);
    k.codeScale = float(p.codeScale);
    k.stepOpacity = p.stepOpacity.empty() ? nullptr : p.stepOpacity.data();
    k.normals = p.normals.empty() ? nullptr : p.normals.data();
    k.padded = p.padded.empty() ? nullptr : p.padded.data();
    k.padded8 = p.padded8.empty() ? nullptr : p.padded8.data();
    k.shade = p.object->shaded && input_.lightOn;
    k.toLight[0] = input_.toLight.x, k.toLight[1] = input_.toLight.y, k.toLight[2] = input_.toLight.z;
    k.ambient = input_.ambient;
    k.lightColor[0] = input_.lightColor.x, k.lightColor[1] = input_.lightColor.y,
    k.lightColor[2] = input_.lightColor.z;
  }
  const int workers = frame.pool ? frame.pool->threadCount() : 1;
  counts_.assign(size_t(workers), WorkerCounts{});
  batches_.resize(size_t(workers));
  windows_.resize(size_t(workers));
  tilesX_ = (frame.width + kTileSize - 1) / kTileSize;
  fronts_.resize(size_t(tilesX_) * size_t((frame.height + kTileSize - 1) / kTileSize));
}

void VolumePass::addStats(FrameStats& stats) const {
  VolumeCounts c;
  double ms = 0;
  for (const WorkerCounts& w : counts_) c.add(w.counts), ms += w.ms;
  stats.volumeMs += ms / double(std::max<size_t>(counts_.size(), 1));
  stats.volumes += volumes_.size();
  stats.volumeRays += c.rays;
  stats.volumeSamples += c.samples;
  stats.volumeSkipped += c.skipped;
  stats.volumeTerminated += c.terminated;
  stats.volumeInterpolated += c.interpolated;
  stats.volumeClosedForm += c.closedForm;
}

namespace {

using Prepared = VolumePass::Prepared;
using VolumeList = std::array<const Prepared*, 64>;

// The volumes whose screen bounds meet the tile at (ox, oy) into `listed` (64 at most); their
// number.
int tileVolumes(const std::vector<Prepared>& volumes, int ox, int oy, VolumeList& listed) {
  int count = 0;
  for (const Prepared& p : volumes)
    if (p.x0 < ox + kTileSize && p.x1 > ox && p.y0 < oy + kTileSize && p.y1 > oy && count < 64)
      listed[size_t(count++)] = &p;
  return count;
}

// A volume's stretch of one pixel's ray o + s·dir (its own space). s0, s1: the box's (the sample
// lattice starts at s0); from, to: within the shell and the window's depths. `exact`: [from, to]
// is a piece of a free-form shell, which clips — the sample segments are cut there (a quadric
// shell's stretch only bounds the samples: the segments holding its ends are taken whole).
struct Stretch {
  const Prepared* p;
  double s0, s1, o[3], dir[3], from, to;
  bool exact;  // (no initializer: a ray's list of 64 is not constructed pixel by pixel)
};
using StretchList = std::array<Stretch, 64>;

// The pieces of pixel (px, py)'s ray inside a free-form shell between eye depths from and to, as
// eye depths, into `pieces` (at most 8: the eighth reaches to `to`): the ray's crossings of
// the form one after another from the free forms' caster (freeform/raycast.h castRay), its
// inside at `from` from the form's sign there. Their number.
[[gnu::noinline]] int shellPieces(const freeform::ProjectedFreeForm& form, const EyeRays& r, int px,
                                  int py, double from, double to, freeform::RayFunction& ray,
                                  freeform::RayFunction& scratch, double pieces[8][2]) {
  const double x = freeform::cubeX(px, r.width, 0), y = freeform::cubeY(py, r.height, 0);
  form.ray(x, y, ray);
  const double z0 = std::max(-1.0, ray.cubeDepth(from)), z1 = std::min(1.0, ray.cubeDepth(to));
  if (!(z0 < z1)) return 0;
  bool in = ray.evaluate(z0) >= 0;
  double z = z0, enter = z0;
  int n = 0;
  freeform::CastStats stats;
  while (true) {
    float depth = float(0.5 * (z1 + 1));  // window depth: crossings nearer than z1
    uint32_t object = freeform::kNoHit;
    double hit = 0;
    freeform::castRay(form, 0, x, y, z, std::nan(""), depth, object, hit, scratch, stats);
    if (object == freeform::kNoHit || !(hit < z1)) {
      if (in) pieces[n][0] = enter, pieces[n][1] = z1, ++n;
      break;
    }
    if (in) {
      if (n == 7) {  // the eighth piece reaches to the end
        pieces[n][0] = enter, pieces[n][1] = z1, ++n;
        break;
      }
      pieces[n][0] = enter, pieces[n][1] = hit, ++n;
    } else {
      enter = hit;
    }
    in = !in;
    z = hit + 1e-9;  // beyond the root (refined to 1e-10 of cube depth)
  }
  for (int k = 0; k < n; ++k)
    pieces[k][0] = ray.eyeDepth(pieces[k][0]), pieces[k][1] = ray.eyeDepth(pieces[k][1]);
  return n;
}

// The stretches of the ray of pixel (px, py), world direction d, through the listed volumes
// that can show there, nearest entry first; their number.
[[gnu::always_inline]] inline int rayStretches(const VolumeList& listed, int count,
                                               const EyeRays& r, int px, int py, const Vec3d& d,
                                               StretchList& stretches,
                                               freeform::RayFunction& shellRay,
                                               freeform::RayFunction& castRay) {
  int n = 0;
  for (int v = 0; v < count; ++v) {
    const Prepared& p = *listed[size_t(v)];
    if (px < p.x0 || px >= p.x1 || py < p.y0 || py >= p.y1) continue;
    if (p.object->freeFormShell && !p.shellForm) continue;  // a singular placement: nothing
    // The window's depth interval (windowDepths); empty where no brick with content shows.
    const size_t w = p.windowNear.empty() ? 0
                                          : size_t(py / VolumePass::kWindow) * size_t(p.windowsX) +
                                                size_t(px / VolumePass::kWindow);
    if (!p.windowNear.empty() && !(p.windowNear[w] < p.windowFar[w])) continue;
    Stretch st{&p, r.znear, r.zfar, {}, {}, 0, 0, false};
    for (int a = 0; a < 3; ++a) {
      st.o[a] = p.toOwn[a][0] * r.eye.x + p.toOwn[a][1] * r.eye.y + p.toOwn[a][2] * r.eye.z +
                p.toOwn[a][3];
      st.dir[a] = p.toOwn[a][0] * d.x + p.toOwn[a][1] * d.y + p.toOwn[a][2] * d.z;
    }
    const double lo[3] = {0, 0, 0};
    clipToBox(st.o, st.dir, lo, p.extent, st.s0, st.s1);
    st.from = st.s0, st.to = st.s1;
    if (!p.windowNear.empty()) {
      st.from = std::max(st.from, double(p.windowNear[w]));
      st.to = std::min(st.to, double(p.windowFar[w]));
      if (!(st.from < st.to)) continue;
    }
    for (const auto& q : p.object->shell) clipToQuadric(q, st.o, st.dir, st.from, st.to);
    if (!(st.s0 < st.s1 && st.from < st.to)) continue;
    if (!p.shellForm) {
      stretches[size_t(n++)] = st;
      continue;
    }
    double pieces[8][2];
    const int k = shellPieces(*p.shellForm, r, px, py, st.from, st.to, shellRay, castRay, pieces);
    for (int i = 0; i < k && n < 64; ++i) {
      Stretch piece = st;
      piece.from = std::max(st.from, pieces[i][0]);
      piece.to = std::min(st.to, pieces[i][1]);
      piece.exact = true;
      if (piece.from < piece.to) stretches[size_t(n++)] = piece;
    }
  }
  // Stable (a shell's pieces of one volume keep their order), without std::stable_sort's buffer:
  // insertion, the lists being a few entries long.
  for (int i = 1; i < n; ++i)
    for (int k = i; k > 0 && stretches[size_t(k)].s0 < stretches[size_t(k - 1)].s0; --k)
      std::swap(stretches[size_t(k)], stretches[size_t(k - 1)]);
  return n;
}

// The bricks along a stretch's ray, walked from the first sample's (Amanatides and Woo's grid
// traversal): each the stretch of s up to its exit; the outermost bricks reach to infinity (a
// sample clamps into them).
struct BrickWalk {
  int bi[3], stepAxis[3];    // the brick; per axis the step across its faces, −1, 0 or 1
  double next[3], delta[3];  // per axis: s at the next face crossed; s between its faces

  // Starts at the brick holding the ray's point at s = mid.
  [[gnu::always_inline]] void start(const Stretch& st, const double brickSize[3], double mid) {
    const Prepared& p = *st.p;
    for (int ax = 0; ax < 3; ++ax) {
      const double q = st.o[ax] + mid * st.dir[ax];
      // (Clamped first, the truncation is the floor.)
      bi[ax] = int(std::clamp(q / brickSize[ax], 0.0, double(p.bricks[ax] - 1)));
      stepAxis[ax] = st.dir[ax] > 0 ? 1 : st.dir[ax] < 0 ? -1 : 0;
      const bool edge = stepAxis[ax] == 0 || (stepAxis[ax] > 0 && bi[ax] == p.bricks[ax] - 1) ||
                        (stepAxis[ax] < 0 && bi[ax] == 0);
      delta[ax] = stepAxis[ax] ? brickSize[ax] / std::fabs(st.dir[ax]) : 1e300;
      next[ax] =
          edge ? 1e300 : ((bi[ax] + (stepAxis[ax] > 0)) * brickSize[ax] - st.o[ax]) / st.dir[ax];
    }
  }
  // The s at which the ray leaves the brick.
  [[gnu::always_inline]] double exit() const { return std::min({next[0], next[1], next[2]}); }
  // The brick's index in Prepared::emptyBrick.
  [[gnu::always_inline]] size_t index(const Prepared& p) const {
    return (size_t(bi[2]) * size_t(p.bricks[1]) + size_t(bi[1])) * size_t(p.bricks[0]) +
           size_t(bi[0]);
  }
  // On to the next brick, across the nearest of its faces; false when the brick was the last.
  [[gnu::always_inline]] bool step(const Prepared& p) {
    const int ax = next[0] <= next[1] ? (next[0] <= next[2] ? 0 : 2) : (next[1] <= next[2] ? 1 : 2);
    if (next[ax] >= 1e300) return false;
    bi[ax] += stepAxis[ax];
    const bool edge =
        (stepAxis[ax] > 0 && bi[ax] == p.bricks[ax] - 1) || (stepAxis[ax] < 0 && bi[ax] == 0);
    next[ax] = edge ? 1e300 : next[ax] + delta[ax];
    return true;
  }
};

// SPEC §12's compositing over up to n full steps of one classified sample (a constant brick's:
// opacity w a step, colour c), in closed form — what the samples would sum: after m steps the
// transparency T·a^m (a = 1 − w), the colour T·w·Σ_{k<m} a^k·(c·f_k + fog·(1 − f_k)), the fog's
// f_k = f_0·q^k a geometric series too (no fog: T·c·(1 − a^m)) — stopping, as the samples would,
// at the first step after which the transparency is below ε. `firstMiddle`: the first step's
// middle, s. Returns the steps composited, negative when the ray ended there.
int64_t compositeConstant(double w, const double c[3], int64_t n, double firstMiddle, double ds,
                          double worldPerS, const VolumeInput& in, PixelComposite& pc) {
  const double a = 1 - w, epsilon = in.settings.termination;
  int64_t m = n;
  bool ended = false;
  if (epsilon > 0 && pc.T * std::pow(a, double(n)) < epsilon) {
    // The first m ≥ 1 with T·a^m < ε (the logarithm's guess, made exact).
    m = a <= 0
            ? 1
            : std::clamp<int64_t>(int64_t(std::ceil(std::log(epsilon / pc.T) / std::log(a))), 1, n);
    while (m > 1 && pc.T * std::pow(a, double(m - 1)) < epsilon) --m;
    while (m < n && !(pc.T * std::pow(a, double(m)) < epsilon)) ++m;
    ended = true;
  }
  auto series = [&](double x) {  // Σ_{k<m} x^k
    return std::fabs(1 - x) < 1e-12 ? double(m) : (1 - std::pow(x, double(m))) / (1 - x);
  };
  const double am = std::pow(a, double(m));
  if (in.fogBeta > 0) {
    const double f0 = std::exp2(-double(in.fogBeta) * firstMiddle * worldPerS);  // SPEC §8
    const double q = std::exp2(-double(in.fogBeta) * ds * worldPerS);
    const double fogged = series(a * q), plain = series(a);
    const double fc[3] = {in.fogColor.x, in.fogColor.y, in.fogColor.z};
    for (int k = 0; k < 3; ++k)
      pc.C[k] += pc.T * w * (c[k] * f0 * fogged + fc[k] * (plain - f0 * fogged));
  } else {
    for (int k = 0; k < 3; ++k) pc.C[k] += pc.T * c[k] * (1 - am);
  }
  pc.T *= am;
  return ended ? -m : m;
}

// Composites a classified batch (sample j: segment start[j], length[j]) front to back into `pc`,
// each sample's opacity corrected for its length (SPEC §12) and fogged by its distance (SPEC §8);
// false once the transparency fell below ε (the ray ends there).
[[gnu::always_inline]] inline bool compositeBatch(const SampleBatch& batch, const double* start,
                                                  const double* length, int waiting, double ds,
                                                  double worldPerS, const Prepared& p,
                                                  const VolumeInput& in, PixelComposite& pc,
                                                  VolumeCounts& counts) {
  const double epsilon = in.settings.termination;
  // The running composite in locals through the loop (registers, not the composite's memory:
  // its chain T·(1 − w) is the loop's latency), written back where a snapshot reads it.
  double C[3] = {pc.C[0], pc.C[1], pc.C[2]}, T = pc.T, last = pc.last;
  auto store = [&] { pc.C[0] = C[0], pc.C[1] = C[1], pc.C[2] = C[2], pc.T = T, pc.last = last; };
  for (int j = 0; j < waiting; ++j) {
    if (start[j] >= pc.next) store(), pc.reach(start[j]);
    const float opacity = batch.opacity[j];
    if (!(opacity > 0)) continue;
    // SPEC §12: the opacity of a sample of length l is 1 − (1 − W)^(l / unit) — for a full
    // step tabled under a uniform scale, else taken in the kernel's lanes for the ray's step.
    const bool full = length[j] == ds;
    const double w = full && (p.source.stepOpacity || batch.exponent > 0) ? double(batch.w[j])
                     : opacity >= 1
                         ? 1.0
                         : 1 - std::pow(1 - double(opacity), length[j] * worldPerS / p.opacityUnit);
    double color[3] = {batch.r[j], batch.g[j], batch.b[j]};
    if (in.fogBeta > 0) {
      const double mid = start[j] + 0.5 * length[j];
      const double fog = std::exp2(-double(in.fogBeta) * mid * worldPerS);  // SPEC §8
      const double fc[3] = {in.fogColor.x, in.fogColor.y, in.fogColor.z};
      for (int c = 0; c < 3; ++c) color[c] = color[c] * fog + fc[c] * (1 - fog);
    }
    for (int c = 0; c < 3; ++c) C[c] += T * w * color[c];
    T *= 1 - w;
    last = start[j] + length[j];
    if (T < epsilon) {
      counts.samples += uint64_t(j + 1);
      ++counts.terminated;
      store();
      return false;
    }
  }
  counts.samples += uint64_t(waiting);
  store();
  return true;
}

// Casts the ray through one stretch (SPEC §12): its samples, up to the farthest surface of the
// pixel, classified a batch at a time (sample_kernel.h) and composited front to back into `pc`.
// True once the ray's transparency fell below ε (the ray ends there).
[[gnu::always_inline]] inline bool castStretch(const Stretch& st, double farthest, double worldPerS,
                                               const VolumeInput& in, SampleBatch& batch,
                                               PixelComposite& pc, VolumeCounts& counts) {
  const Prepared& p = *st.p;
  const scene::VolumeGrid& g = *p.grid;
  const double dirLength =
      std::sqrt(st.dir[0] * st.dir[0] + st.dir[1] * st.dir[1] + st.dir[2] * st.dir[2]);
  const double ds = p.stepOwn / dirLength;  // a step in s
  const double end = std::min(st.s1, farthest);
  const double brickSize[3] = {VolumePass::kBrick * double(g.spacing.x),
                               VolumePass::kBrick * double(g.spacing.y),
                               VolumePass::kBrick * double(g.spacing.z)};
  // The samples waiting in `batch`, in ray order: their segments' starts and lengths in s.
  double start[kBatch], length[kBatch];
  batch.exponent = p.source.stepOpacity ? 0.0f : float(ds * worldPerS / p.opacityUnit);
  int pending = 0;
  // Classifies the waiting samples together (sample_kernel.h), then composites them in
  // order: false once the ray's transparency fell below ε.
  auto flush = [&]() -> bool {
    classifySamples(p.source, pending, batch);
    const int waiting = pending;
    pending = 0;
    return compositeBatch(batch, start, length, waiting, ds, worldPerS, p, in, pc, counts);
  };
  // Segments [s0 + i·ds, s0 + (i + 1)·ds) ∩ [s0, end), each sampled at its middle.
  // From the segment holding the shell's entry to the one holding its exit: the samples
  // outside the shell are transparent (its promise), the lattice the box's.
  const int64_t first = int64_t(std::max(0.0, std::floor((st.from - st.s0) / ds)));
  const double perS = 1 / ds;
  const double lastSegment = std::ceil((end - st.s0) * perS) - 1;
  // Brick by brick: a brick every sample of which the transfer function makes transparent is
  // stepped over whole (its samples' cells' corners all lie in it), a brick with content sampled
  // without looking again.
  BrickWalk walk;
  walk.start(st, brickSize, st.s0 + (double(first) + 0.5) * ds);
  for (int64_t i = first; double(i) <= lastSegment && st.s0 + double(i) * ds <= st.to;) {
    // Segment j's middle is s0 + (j + ½)·ds; those with it below the exit are in the brick.
    // (⌈x⌉ of x capped first, by truncation: the baseline target has no rounding
    // instruction, and std::ceil is a call.)
    const double x = std::clamp((walk.exit() - st.s0) * perS - 0.5, -1.0, lastSegment + 1);
    const double cut = double(int64_t(x));
    const double through = std::min((cut < x ? cut + 1 : cut) - 1, lastSegment);
    if (through >= double(i)) {
      const int64_t last = int64_t(std::min(through, 1e15));
      if (in.settings.skipEmpty && p.emptyBrick[walk.index(p)]) {
        counts.skipped += uint64_t(last - i + 1);
      } else {
        int64_t j = i;
        if (in.settings.closedForm && p.constantBrick[walk.index(p)] &&
            (!st.exact || st.s0 + double(j) * ds >= st.from)) {
          // The brick's full steps within the stretch's end and the shell's exit, in closed form
          // — where no sample of the pixel has its surface among them.
          const double stop = st.exact ? std::min(end, st.to) : end;
          int64_t upTo = last;
          while (upTo >= j &&
                 (st.s0 + double(upTo) * ds + ds > stop || st.s0 + double(upTo) * ds > st.to))
            --upTo;
          pc.reach(st.s0 + double(j) * ds);
          if (upTo > j && pc.next > st.s0 + double(upTo) * ds) {
            if (pending > 0 && !flush()) return true;
            const double middle = st.s0 + (double(j) + 0.5) * ds;
            batch.x[0] = float(st.o[0] + middle * st.dir[0]);
            batch.y[0] = float(st.o[1] + middle * st.dir[1]);
            batch.z[0] = float(st.o[2] + middle * st.dir[2]);
            classifySamples(p.source, 1, batch);
            ++counts.samples;
            if (batch.opacity[0] > 0) {
              const double color[3] = {batch.r[0], batch.g[0], batch.b[0]};
              const int64_t m =
                  compositeConstant(batch.w[0], color, upTo - j + 1, middle, ds, worldPerS, in, pc);
              const int64_t steps = m < 0 ? -m : m;
              counts.closedForm += uint64_t(steps);
              pc.last = st.s0 + double(j + steps) * ds;
              if (m < 0) {
                ++counts.terminated;
                return true;
              }
            }
            j = upTo + 1;
          }
        }
        // Samples j … last, up to the stretch's end and the shell's exit; the segment a split
        // (a translucent surface) crosses is cut there, each part composited on its side.
        auto sample = [&](double a, double b, bool full) {
          const double middle = 0.5 * (a + b);
          start[pending] = a;
          length[pending] = full ? ds : b - a;
          batch.x[pending] = float(st.o[0] + middle * st.dir[0]);
          batch.y[pending] = float(st.o[1] + middle * st.dir[1]);
          batch.z[pending] = float(st.o[2] + middle * st.dir[2]);
          return ++pending < kBatch || flush();
        };
        // (Most runs have neither a piece's ends nor a split to cut at: their own loop.)
        const bool plain = !st.exact && !pc.split;
        for (; plain && j <= last; ++j) {
          const double a = st.s0 + double(j) * ds;
          if (!(a < end) || a > st.to) break;
          const bool full = a + ds <= end;
          if (!sample(a, full ? a + ds : end, full)) return true;
        }
        for (; !plain && j <= last; ++j) {
          double a = st.s0 + double(j) * ds;
          if (!(a < end) || a > st.to) break;
          bool full = a + ds <= end;
          double b = full ? a + ds : end;
          if (st.exact) {  // a free-form shell's piece: the segment cut to it
            if (!(a < st.to)) break;
            full = full && a >= st.from && b <= st.to;
            a = std::max(a, st.from), b = std::min(b, st.to);
            if (!(a < b)) continue;
          }
          if (pc.split && a < pc.splitAt && pc.splitAt < b) {
            if (!sample(a, pc.splitAt, false) || !sample(pc.splitAt, b, false)) return true;
          } else if (!sample(a, b, full)) {
            return true;
          }
        }
      }
      i = last + 1;
    }
    if (!walk.step(p)) break;
  }
  return pending > 0 && !flush();
}

// Steps 2–4 for one pixel of a tile: its ray through the listed volumes, nearest first,
// composited front to back — each of the pixel's samples stopping at its surface, until the
// transparency falls below ε — and written over what each sample holds.
struct PixelCaster {
  const raster::TileTarget& tile;
  const EyeRays& r;
  const VolumeInput& in;
  int samples;
  const VolumeList& listed;
  int count;
  SampleBatch& batch;
  freeform::RayFunction &shellRay, &castRay;  // scratch for free-form shells
  VolumeCounts& counts;
  std::vector<FrontPixel>* fronts;  // the tile's split pixels, with tile.translucentDepth

  WindowPixel cast(int lx, int ly) const {
    WindowPixel out;
    out.state = WindowPixel::cast;
    const int px = tile.tileX * kTileSize + lx, py = tile.tileY * kTileSize + ly;
    const Vec3d d = r.direction(px + 0.5, py + 0.5);
    const double worldPerS = std::sqrt(dot(d, d));
    StretchList stretches;
    const int n = rayStretches(listed, count, r, px, py, d, stretches, shellRay, castRay);
    if (n == 0) return out;
    PixelComposite pc;
    const double farthest = pc.start(tile, r, lx, ly, samples);
    ++counts.rays;
    // Where the ray's composite ends of itself: its transparency below ε, or its last stretch's
    // end. Complete: every sample's surface lies beyond it (no surface cut the ray short).
    double ended = 0, opaqueAt = 1e300;
    for (int v = 0; v < n; ++v) {
      const Stretch& st = stretches[size_t(v)];
      ended = std::max(ended, std::min(st.s1, st.to));
      if (castStretch(st, farthest, worldPerS, in, batch, pc, counts)) {
        ended = opaqueAt = pc.last;
        out.opaque = true;
        break;
      }
    }
    out.met = true;
    out.complete = pc.split == 0;
    for (int k = 0; k < samples; ++k) out.complete = out.complete && pc.limit[k] >= ended;
    for (int c = 0; c < 3; ++c) out.C[c] = float(pc.C[c]);
    out.T = float(pc.T);
    // Rounded up: a pixel blended must lie beyond it.
    out.last = std::nextafter(float(pc.last), 3.0e38f);
    pc.writeOver(tile, r, lx, ly, opaqueAt);
    if (pc.split && pc.splitT < 1) {
      FrontPixel f;
      f.pixel = uint16_t(ly * kTileSize + lx);
      f.samples = pc.split;
      for (int c = 0; c < 3; ++c) f.C[c] = float(pc.splitC[c]);
      f.T = float(pc.splitT);
      fronts->push_back(f);
    }
    return out;
  }

  // The nearest of the pixel's samples' surfaces, as s.
  double nearest(int lx, int ly) const {
    double s = 1e300;
    for (int k = 0; k < samples; ++k)
      s = std::min(s, r.depthToS(tile.depth[FrameBuffer::depthOffset(lx, ly, samples, k)]));
    return s;
  }

  // Whether a translucent surface lies in front of one of the pixel's samples' opaque ones (its
  // ray is split there: cast, never blended).
  bool translucent(int lx, int ly) const {
    if (!tile.translucentDepth) return false;
    for (int k = 0; k < samples; ++k) {
      const size_t at = FrameBuffer::depthOffset(lx, ly, samples, k);
      if (tile.translucentDepth[at] < tile.depth[at]) return true;
    }
    return false;
  }

  // The composite (C, T) over every sample of the pixel; where it turned opaque at s = opaqueAt
  // (every corner's ray did), the samples beyond take that depth (PixelComposite::writeOver).
  void write(int lx, int ly, const double C[3], double T, double opaqueAt) const {
    for (int k = 0; k < samples; ++k) {
      for (int c = 0; c < 3; ++c)
        compositeOver(tile.color[FrameBuffer::colorOffset(lx, ly, c, samples, k)], C[c], T);
      if (opaqueAt >= 1e300) continue;  // (most blended pixels: no depth to write)
      float& depth = tile.depth[FrameBuffer::depthOffset(lx, ly, samples, k)];
      if (opaqueAt < r.depthToS(depth)) depth = std::min(depth, r.sToDepth(opaqueAt));
    }
  }
};

// SPEC §12's screen subdivision down to the pixel (VolumeSettings::windowTolerance): the tile's
// windows of kRefineWindow pixels (4 × 4: 8 × 8 lost the cloud's lit ripples, docs/volumes.md)
// have their corner rays cast; a window whose corners all met a volume, ended their composites
// before their surfaces, and differ by at most `tolerance` in colour and transparency is a leaf,
// any other is split in four (its edges' and centre's rays cast) down to windows without inner
// pixels. Then each leaf's pixels not cast take the bilinear blend of its corners — where the
// pixel's nearest surface lies beyond the corners' last samples (else its ray is cast). The tile
// alone decides (no ray of another tile is read): the same bits for any number of threads.
void refineWindows(const PixelCaster& caster, int w, int h, float tolerance,
                   WindowScratch& scratch) {
  std::vector<WindowPixel>& window = scratch.window;
  window.resize(size_t(kTileSize) * kTileSize);
  for (int y = 0; y < h; ++y)
    std::fill_n(window.begin() + ptrdiff_t(y) * kTileSize, w, WindowPixel{});
  auto at = [&](int x, int y) -> WindowPixel& { return window[size_t(y) * kTileSize + size_t(x)]; };
  auto ensure = [&](int x, int y) -> WindowPixel& {
    WindowPixel& p = at(x, y);
    if (p.state == WindowPixel::none) p = caster.cast(x, y);
    return p;
  };
  using Leaf = WindowRect;
  std::vector<Leaf>& leaves = scratch.leaves;
  leaves.clear();
  auto similar = [&](const Leaf& c) {
    const WindowPixel* q[4] = {&at(c.x0, c.y0), &at(c.x1, c.y0), &at(c.x0, c.y1), &at(c.x1, c.y1)};
    double lo[4], hi[4];
    for (int k = 0; k < 4; ++k) lo[k] = 1e300, hi[k] = -1e300;
    for (const WindowPixel* p : q) {
      if (!p->met || !p->complete) return false;
      const double v[4] = {p->C[0], p->C[1], p->C[2], p->T};
      for (int k = 0; k < 4; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
    }
    for (int k = 0; k < 4; ++k)
      if (hi[k] - lo[k] > tolerance) return false;
    return true;
  };
  // Windows in the order of a stack, each with its corners cast.
  std::vector<Leaf>& stack = scratch.stack;
  stack.clear();
  for (int y0 = 0; y0 < h - 1; y0 += VolumePass::kRefineWindow)
    for (int x0 = 0; x0 < w - 1; x0 += VolumePass::kRefineWindow)
      stack.push_back({x0, y0, std::min(x0 + VolumePass::kRefineWindow, w - 1),
                       std::min(y0 + VolumePass::kRefineWindow, h - 1)});
  for (const Leaf& c : stack)
    ensure(c.x0, c.y0), ensure(c.x1, c.y0), ensure(c.x0, c.y1), ensure(c.x1, c.y1);
  // A single row or column has no window: its pixels cast as they are.
  if (w == 1 || h == 1)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) ensure(x, y);
  while (!stack.empty()) {
    const Leaf c = stack.back();
    stack.pop_back();
    if (c.x1 - c.x0 <= 1 && c.y1 - c.y0 <= 1) continue;  // no inner pixel
    if (similar(c)) {
      leaves.push_back(c);
      continue;
    }
    // Split where the window has inner pixels: in four, or in two along its longer side.
    const bool alongX = c.x1 - c.x0 > 1, alongY = c.y1 - c.y0 > 1;
    const int xm = alongX ? (c.x0 + c.x1) / 2 : c.x0, ym = alongY ? (c.y0 + c.y1) / 2 : c.y0;
    for (const int y : {c.y0, ym, c.y1})
      for (const int x : {c.x0, xm, c.x1}) ensure(x, y);
    const Leaf halves[4] = {{c.x0, c.y0, alongX ? xm : c.x1, alongY ? ym : c.y1},
                            {xm, c.y0, c.x1, alongY ? ym : c.y1},
                            {c.x0, ym, alongX ? xm : c.x1, c.y1},
                            {xm, ym, c.x1, c.y1}};
    stack.push_back(halves[0]);
    if (alongX) stack.push_back(halves[1]);
    if (alongY) stack.push_back(halves[2]);
    if (alongX && alongY) stack.push_back(halves[3]);
  }
  for (const Leaf& c : leaves) {
    const WindowPixel *a = &at(c.x0, c.y0), *b = &at(c.x1, c.y0), *e = &at(c.x0, c.y1),
                      *f = &at(c.x1, c.y1);
    const double last = double(std::max({a->last, b->last, e->last, f->last}));
    for (int y = c.y0; y <= c.y1; ++y)
      for (int x = c.x0; x <= c.x1; ++x) {
        WindowPixel& p = at(x, y);
        if (p.state != WindowPixel::none) continue;
        if (!(caster.nearest(x, y) > last) || caster.translucent(x, y)) {
          p = caster.cast(x, y);
          continue;
        }
        const double u = c.x1 > c.x0 ? double(x - c.x0) / (c.x1 - c.x0) : 0;
        const double v = c.y1 > c.y0 ? double(y - c.y0) / (c.y1 - c.y0) : 0;
        const double wa = (1 - u) * (1 - v), wb = u * (1 - v), we = (1 - u) * v, wf = u * v;
        double C[3];
        for (int ch = 0; ch < 3; ++ch)
          C[ch] = wa * double(a->C[ch]) + wb * double(b->C[ch]) + we * double(e->C[ch]) +
                  wf * double(f->C[ch]);
        const double T =
            wa * double(a->T) + wb * double(b->T) + we * double(e->T) + wf * double(f->T);
        const bool opaque = a->opaque && b->opaque && e->opaque && f->opaque;
        caster.write(x, y, C, T, opaque ? last : 1e300);
        p.state = WindowPixel::interpolated;
        ++caster.counts.interpolated;
      }
  }
}

}  // namespace

void VolumePass::drawTile(const raster::TileTarget& tile) {
  if (volumes_.empty()) return;
  const auto begin = std::chrono::steady_clock::now();
  drawVolumes(tile);
  counts_[size_t(tile.worker)].ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count();
}

bool VolumePass::wantsTranslucentDepth(int tileX, int tileY) const {
  VolumeList listed;
  return tileVolumes(volumes_, tileX * kTileSize, tileY * kTileSize, listed) > 0;
}

void VolumePass::drawVolumes(const raster::TileTarget& tile) {
  VolumeCounts& counts = counts_[size_t(tile.worker)].counts;
  const EyeRays& r = input_.rays;
  const int ox = tile.tileX * kTileSize, oy = tile.tileY * kTileSize;
  std::vector<FrontPixel>& fronts = fronts_[size_t(tile.tileY * tilesX_ + tile.tileX)];
  fronts.clear();
  // Step 1: the volumes this tile may show, by their screen bounds.
  VolumeList listed{};
  const int count = tileVolumes(volumes_, ox, oy, listed);
  if (count == 0) return;
  WorkerBatch& scratch = batches_[size_t(tile.worker)];
  const PixelCaster caster{tile,
                           r,
                           input_,
                           samples_,
                           listed,
                           count,
                           scratch.batch,
                           scratch.shellRay,
                           scratch.castRay,
                           counts,
                           &fronts};
  const int w = std::min(kTileSize, r.width - ox), h = std::min(kTileSize, r.height - oy);
  if (input_.settings.windowTolerance > 0) {
    refineWindows(caster, w, h, input_.settings.windowTolerance, windows_[size_t(tile.worker)]);
    return;
  }
  for (int ly = 0; ly < h; ++ly)
    for (int lx = 0; lx < w; ++lx) caster.cast(lx, ly);
}

// The split pixels' parts before the translucent surfaces, over what those surfaces left.
void VolumePass::overTranslucent(const raster::TileTarget& tile) {
  if (volumes_.empty()) return;
  std::vector<FrontPixel>& fronts = fronts_[size_t(tile.tileY * tilesX_ + tile.tileX)];
  for (const FrontPixel& f : fronts) {
    const int lx = f.pixel % kTileSize, ly = f.pixel / kTileSize;
    for (int k = 0; k < samples_; ++k)
      if (f.samples >> k & 1)
        for (int c = 0; c < 3; ++c)
          compositeOver(tile.color[FrameBuffer::colorOffset(lx, ly, c, samples_, k)], f.C[c], f.T);
  }
  fronts.clear();
}

}  // namespace sv::volume
