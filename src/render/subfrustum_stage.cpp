// The sub-frusta as a stage of the frame (issue 61 item 1; docs/display.md, "At an IG's rate"):
// a cell is not a view of its own. The display's traversal, shading tables and vertex stage run
// once a frame, in the clip space of a flat cover view that holds every cell; each triangle is
// binned to the cells its box meets; a cell takes its triangles to its own clip space by one 4 × 4
// map and sets them up and draws them through its own raster, as before.
//
// Why one map does it: a cell's projection P_c and the cover's P acts on the same homogeneous
// eye-frame points, so P_c·x = (P_c·P⁻¹)·(P·x) — linear on clip coordinates, before any divide or
// clipping: a vertex behind the cover's eye plane maps as exactly as one in front.
#include <algorithm>
#include <cmath>

#include "core/quadric.h"
#include "core/timing.h"
#include "render/warped.h"

namespace sv::render {
namespace {

// A column-major float Mat4 of a row-major double one.
Mat4 toFloat(const Mat4d& d) {
  Mat4 m;
  for (size_t r = 0; r < 4; ++r)
    for (size_t c = 0; c < 4; ++c) m.m[c][r] = float(d.m[r][c]);
  return m;
}

// glFrustum's matrix for the window [l, r] × [b, t] of tangents at unit depth, looking along −z.
Mat4d frustum(double l, double r, double b, double t, double n, double f) {
  Mat4d p;
  p.m = {};
  p.m[0][0] = 2 / (r - l);
  p.m[0][2] = (r + l) / (r - l);
  p.m[1][1] = 2 / (t - b);
  p.m[1][2] = (t + b) / (t - b);
  p.m[2][2] = -(f + n) / (f - n);
  p.m[2][3] = -2 * f * n / (f - n);
  p.m[3][2] = -1;
  return p;
}

}  // namespace

std::array<int16_t, 4> SubFrustumRenderer::Stage::bins(const std::array<float, 4>& b) const {
  const float sx = kBins / (grid[2] - grid[0]), sy = kBins / (grid[3] - grid[1]);
  // Clamped before the conversion: a place far off the grid is a bin at its edge.
  const auto bin = [](float v) {
    return int16_t(std::floor(std::clamp(v, 0.0f, float(kBins - 1))));
  };
  return {bin((b[0] - grid[0]) * sx), bin((b[1] - grid[1]) * sy), bin((b[2] - grid[0]) * sx),
          bin((b[3] - grid[1]) * sy)};
}

void SubFrustumRenderer::prepareStage(const display::SubFrustumPlan& plan, double znear,
                                      double zfar) {
  Stage& st = stage_;
  st = Stage{};
  st.znear = znear, st.zfar = zfar;
  // The cover: along the mean of the cells' corner directions, its window the tangent box of
  // every corner widened by 2 %. Every cell's rectangle is a convex quadrilateral there (a
  // homography's image), inside the box of its corners.
  std::vector<Vec3d> corners;
  for (const display::SubFrustumCell& c : plan.cells) {
    if (!c.fitted) continue;
    for (const auto& [x, y] : {std::pair{c.x0 - 2, c.y0 - 2}, std::pair{c.x1 + 2, c.y0 - 2},
                               std::pair{c.x0 - 2, c.y1 + 2}, std::pair{c.x1 + 2, c.y1 + 2}})
      corners.push_back(display::mapPixel(c, x, y));
  }
  if (corners.empty()) return;
  Vec3d f{0, 0, 0};
  for (const Vec3d& d : corners) f = f + d;
  if (!(dot(f, f) > 0)) return;
  f = normalize(f);
  const Vec3d upWorld = std::abs(f.y) < 0.9 ? Vec3d{0, 1, 0} : Vec3d{1, 0, 0};
  const Vec3d right = normalize(cross(f, upWorld)), up = cross(right, f);
  double l = 1e300, r = -1e300, b = 1e300, t = -1e300;
  for (const Vec3d& d : corners) {
    const double depth = dot(d, f);
    if (!(depth > 0.1)) return;  // beyond 84° of the mean: no flat cover (a dome's projector)
    const double x = dot(d, right) / depth, y = dot(d, up) / depth;
    l = std::min(l, x), r = std::max(r, x), b = std::min(b, y), t = std::max(t, y);
  }
  const double mx = 0.02 * (r - l), my = 0.02 * (t - b);
  Mat4d rotation;  // eye frame → the cover's frame (x right, y up, looking along −z)
  rotation.m = {{{right.x, right.y, right.z, 0}, {up.x, up.y, up.z, 0}, {-f.x, -f.y, -f.z, 0},
                 {0, 0, 0, 1}}};
  // Its near plane the cells' znear. A nearer one, znear·cos θ for the farthest corner θ, would
  // keep every instance a cell's near plane keeps (a point at depth ≥ znear along a cell's axis
  // lies at ≥ znear·cos θ along the cover's), but it cost the airport's frame 4 % (sv_display_bench,
  // the same run); so an instance wholly within that sliver beside the eye is culled by the
  // cover's traversal, where a view of its own per cell drew it.
  const Mat4d cover = frustum(l - mx, r + mx, b - my, t + my, znear, zfar) * rotation;
  const std::optional<Mat4d> inverse = cover.inverse();
  if (!inverse) return;
  st.cover = toFloat(cover);
  const size_t n = plan.cells.size();
  st.toCell.resize(n);
  st.box.assign(n, {0, 0, 0, 0});
  st.grid[0] = st.grid[1] = 1;
  st.grid[2] = st.grid[3] = -1;
  for (size_t i = 0; i < n; ++i) {
    const display::SubFrustumCell& c = plan.cells[i];
    if (!c.fitted) continue;
    st.toCell[i] = toFloat(display::cellProjection(c, znear, zfar) * *inverse);
    std::array<float, 4>& box = st.box[i];
    box = {1e30f, 1e30f, -1e30f, -1e30f};
    // Two pixels beyond the rectangle: an anti-aliased triangle reaches the pixels its square
    // touches, and the float maps differ by far less.
    for (const auto& [x, y] : {std::pair{c.x0 - 2, c.y0 - 2}, std::pair{c.x1 + 2, c.y0 - 2},
                               std::pair{c.x0 - 2, c.y1 + 2}, std::pair{c.x1 + 2, c.y1 + 2}}) {
      const Vec3d d = display::mapPixel(c, x, y);
      const Vec4d q = cover * Vec4d{{d.x, d.y, d.z, 1}};
      const float nx = float(q[0] / q[3]), ny = float(q[1] / q[3]);
      box = {std::min(box[0], nx), std::min(box[1], ny), std::max(box[2], nx), std::max(box[3], ny)};
    }
    st.grid[0] = std::min(st.grid[0], box[0]), st.grid[1] = std::min(st.grid[1], box[1]);
    st.grid[2] = std::max(st.grid[2], box[2]), st.grid[3] = std::max(st.grid[3], box[3]);
  }
  st.ok = st.grid[0] < st.grid[2] && st.grid[1] < st.grid[3];
  lightReach_ = -1;
}

void SubFrustumRenderer::binLights(const scene::Scene& scene, const FrameCamera& base, Vec3d eye,
                                   const display::SubFrustumPlan& plan) {
  lightDirections(scene, base, eye);
  const double reach = lightReach(scene);
  const size_t n = plan.cells.size();
  const Stage& st = stage_;
  const Mat4d cover = Mat4d::of(st.cover);
  if (reach != lightReach_) {
    // Each cell's rectangle widened by the reach and two pixels, as a box of the cover's NDC.
    lightReach_ = reach;
    lightBox_.assign(n, {0, 0, 0, 0});
    const double r = std::ceil(reach) + 2;
    for (size_t i = 0; i < n; ++i) {
      const display::SubFrustumCell& c = plan.cells[i];
      if (!c.fitted) continue;
      std::array<float, 4>& box = lightBox_[i];
      box = {1e30f, 1e30f, -1e30f, -1e30f};
      for (const auto& [x, y] : {std::pair{c.x0 - r, c.y0 - r}, std::pair{c.x1 + r, c.y0 - r},
                                 std::pair{c.x0 - r, c.y1 + r}, std::pair{c.x1 + r, c.y1 + r}}) {
        const Vec3d d = display::mapPixel(c, x, y);
        const Vec4d q = cover * Vec4d{{d.x, d.y, d.z, 1}};
        const float nx = float(q[0] / q[3]), ny = float(q[1] / q[3]);
        box = {std::min(box[0], nx), std::min(box[1], ny), std::max(box[2], nx),
               std::max(box[3], ny)};
      }
    }
  }
  // Every light's place on the cover's grid (the triangles' grid: a light beyond it is beyond
  // every cell's box widened by less than two pixels; its bins clamp the rest), in light order.
  const size_t lights = lightDirections_.size();
  lightPlace_.resize(lights);
  std::vector<int32_t> binOf(lights, -1);
  lightBinStart_.assign(size_t(kBins) * kBins + 1, 0);
  const Mat4& m = st.cover;
  for (size_t k = 0; k < lights; ++k) {
    const Vec3d& d = lightDirections_[k].direction;
    const Vec4 q = m * Vec4{float(d.x), float(d.y), float(d.z), 1};
    // Beyond 90° of the cover's axis, or so near it that its place is off the grid by a
    // thousand widths: no cell is within reach.
    if (!(q.w > 1e-3f * (std::abs(q.x) + std::abs(q.y)))) continue;
    const float x = q.x / q.w, y = q.y / q.w;
    lightPlace_[k] = {x, y};
    const std::array<int16_t, 4> b = st.bins({x, y, x, y});
    binOf[k] = b[1] * kBins + b[0];
    ++lightBinStart_[size_t(binOf[k]) + 1];
  }
  for (size_t b = 1; b < lightBinStart_.size(); ++b) lightBinStart_[b] += lightBinStart_[b - 1];
  lightBinLights_.resize(lightBinStart_.back());
  std::vector<uint32_t> cursor(lightBinStart_.begin(), lightBinStart_.end() - 1);
  for (size_t k = 0; k < lights; ++k)
    if (binOf[k] >= 0) lightBinLights_[cursor[size_t(binOf[k])]++] = uint32_t(k);
  cellLights_.resize(n);
}

void SubFrustumRenderer::cellLightsOf(size_t i, const display::SubFrustumPlan& plan) {
  const Stage& st = stage_;
  const display::SubFrustumCell& c = plan.cells[i];
  std::vector<uint32_t>& list = cellLights_[i];
  list.clear();
  const std::array<float, 4>& box = lightBox_[i];
  const std::array<int16_t, 4> cb = st.bins(box);
  const int bx0 = cb[0], by0 = cb[1], bx1 = cb[2], by1 = cb[3];
  const double reach = lightReach_;
  for (int y = by0; y <= by1; ++y)
    for (int x = bx0; x <= bx1; ++x) {
      const size_t b = size_t(y * kBins + x);
      for (uint32_t k = lightBinStart_[b]; k < lightBinStart_[b + 1]; ++k) {
        const uint32_t l = lightBinLights_[k];
        const std::array<float, 2>& q = lightPlace_[l];
        if (q[0] < box[0] || q[0] > box[2] || q[1] < box[1] || q[1] > box[3]) continue;
        // The exact test, as cullLights': where the cell's own map puts the light.
        const std::optional<display::PixelPoint> p =
            display::mapDirection(c, lightDirections_[l].direction);
        if (p && p->x >= c.x0 - reach && p->x <= c.x1 + reach && p->y >= c.y0 - reach &&
            p->y <= c.y1 + reach)
          list.push_back(l);
      }
    }
  // In light order (the bins hold each light once); then the lights' own indices.
  std::sort(list.begin(), list.end());
  for (uint32_t& l : list) l = lightDirections_[l].index;
}

Status SubFrustumRenderer::drawCover(const scene::Scene& scene, const RenderOptions& o,
                                     const FrameCamera& base, Vec3d eye, FrameStats& stats) {
  const auto t0 = core::Clock::now();
  FrameCamera cover = base;
  cover.view = Mat4::translation(Vec3{float(-eye.x), float(-eye.y), float(-eye.z)}) * base.view;
  cover.projection = stage_.cover;
  cover.projective = true;
  buildShading(scene, o, cover.view, shading_);
  if (Status s =
          buildDrawPackets(scene, o, cover, shading_.any ? &shading_ : nullptr, pool_, cover_);
      !s)
    return s;
  binTriangles();
  cellScratch_.resize(workers_.size());
  stats.vertexMs += core::msSince(t0);
  addTraversalCounts(cover_.traversal, stats);
  return {};
}

void SubFrustumRenderer::binTriangles() {
  const Stage& st = stage_;
  const size_t triangles = cover_.indices.size() / 3;
  triangleBox_.resize(triangles);
  triangleBins_.resize(triangles);
  everywhere_.clear();
  binStart_.assign(size_t(kBins) * kBins + 1, 0);
  for (size_t t = 0; t < triangles; ++t) {
    std::array<float, 4> box{1e30f, 1e30f, -1e30f, -1e30f};
    bool front = true;
    for (int k = 0; k < 3; ++k) {
      const geometry::ClipVertex& v = cover_.vertices[cover_.indices[3 * t + size_t(k)]];
      // A vertex near or behind the eye plane has no place on the cover: every cell tries the
      // triangle (its setup clips it).
      if (!(v.w > 1e-6f * (std::abs(v.x) + std::abs(v.y)) && v.w > 0)) {
        front = false;
        break;
      }
      const float x = v.x / v.w, y = v.y / v.w;
      box = {std::min(box[0], x), std::min(box[1], y), std::max(box[2], x), std::max(box[3], y)};
    }
    triangleBox_[t] = box;
    if (!front) {
      triangleBins_[t] = {0, 0, -1, -1};  // in no bin
      everywhere_.push_back(uint32_t(t));
      continue;
    }
    if (box[2] < st.grid[0] || box[0] > st.grid[2] || box[3] < st.grid[1] || box[1] > st.grid[3]) {
      triangleBins_[t] = {0, 0, -1, -1};  // beyond every cell: no bin
      continue;
    }
    const std::array<int16_t, 4> b = st.bins(box);
    triangleBins_[t] = b;
    for (int y = b[1]; y <= b[3]; ++y)
      for (int x = b[0]; x <= b[2]; ++x) ++binStart_[size_t(y * kBins + x) + 1];
  }
  for (size_t k = 1; k < binStart_.size(); ++k) binStart_[k] += binStart_[k - 1];
  binTriangles_.resize(binStart_.back());
  std::vector<uint32_t> cursor(binStart_.begin(), binStart_.end() - 1);
  for (size_t t = 0; t < triangles; ++t) {
    const std::array<int16_t, 4>& b = triangleBins_[t];
    for (int y = b[1]; y <= b[3]; ++y)
      for (int x = b[0]; x <= b[2]; ++x) binTriangles_[cursor[size_t(y * kBins + x)]++] = uint32_t(t);
  }
}

void SubFrustumRenderer::cellPackets(size_t i, CellScratch& s) {
  const Stage& st = stage_;
  const std::array<float, 4>& box = st.box[i];
  const std::array<int16_t, 4> cb = st.bins(box);
  const int bx0 = cb[0], by0 = cb[1], bx1 = cb[2], by1 = cb[3];
  // The triangles whose boxes meet the cell's, each once: from the first of the cell's bins it
  // lies in.
  s.triangles.assign(everywhere_.begin(), everywhere_.end());
  for (int y = by0; y <= by1; ++y)
    for (int x = bx0; x <= bx1; ++x) {
      const size_t b = size_t(y * kBins + x);
      for (uint32_t k = binStart_[b]; k < binStart_[b + 1]; ++k) {
        const uint32_t t = binTriangles_[k];
        const std::array<int16_t, 4>& tb = triangleBins_[t];
        if (x != std::max(bx0, int(tb[0])) || y != std::max(by0, int(tb[1]))) continue;
        const std::array<float, 4>& q = triangleBox_[t];
        if (q[2] < box[0] || q[0] > box[2] || q[3] < box[1] || q[1] > box[3]) continue;
        s.triangles.push_back(t);
      }
    }
  std::sort(s.triangles.begin(), s.triangles.end());  // the draw order
  // Their vertices through the cell's map, each once; their calls, in order.
  DrawPackets& p = s.packets;
  p.vertices.clear();
  p.attributes.clear();
  p.indices.clear();
  p.calls.clear();
  p.attributeLayout = cover_.attributeLayout;
  const size_t stride = size_t(cover_.attributeLayout.stride);
  if (s.stamp.size() != cover_.vertices.size() || ++s.generation == 0) {
    s.stamp.assign(cover_.vertices.size(), 0);
    s.remap.resize(cover_.vertices.size());
    s.generation = 1;
  }
  const Mat4& m = st.toCell[i];
  size_t call = 0, lastCall = 0;
  for (const uint32_t t : s.triangles) {
    while (cover_.calls[call].firstTriangle + cover_.calls[call].triangleCount <= t) ++call;
    if (p.calls.empty() || lastCall != call) {
      DrawCall c = cover_.calls[call];
      c.firstTriangle = uint32_t(p.indices.size() / 3);
      c.triangleCount = 0;
      c.bounded = false;  // its screen bound is the cover's, not the cell's
      p.calls.push_back(c);
      lastCall = call;
    }
    ++p.calls.back().triangleCount;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = cover_.indices[3 * size_t(t) + size_t(k)];
      if (s.stamp[v] != s.generation) {
        s.stamp[v] = s.generation;
        s.remap[v] = uint32_t(p.vertices.size());
        const geometry::ClipVertex& a = cover_.vertices[v];
        const Vec4 q = m * Vec4{a.x, a.y, a.z, a.w};
        p.vertices.push_back({q.x, q.y, q.z, q.w, a.r, a.g, a.b, a.a});
        if (stride)
          p.attributes.insert(p.attributes.end(), cover_.attributes.begin() + long(v * stride),
                              cover_.attributes.begin() + long((v + 1) * stride));
      }
      p.indices.push_back(s.remap[v]);
    }
  }
}

}  // namespace sv::render
