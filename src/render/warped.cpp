#include "render/warped.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>

#include "lights/light_laws.h"
#include "render/passes.h"

namespace sv::render {

FrameCamera cellCamera(const FrameCamera& base, const display::SubFrustumCell& cell, Vec3d eye) {
  FrameCamera c = base;
  c.view = Mat4::translation(Vec3{float(-eye.x), float(-eye.y), float(-eye.z)}) * base.view;
  // The camera's depth range, not the plan's. Mat4d is row-major, Mat4 column-major.
  const Mat4d p = display::cellProjection(cell, base.camera.znear, base.camera.zfar);
  for (size_t r = 0; r < 4; ++r)
    for (size_t k = 0; k < 4; ++k) c.projection.m[k][r] = float(p.m[r][k]);
  c.projective = true;
  return c;
}

namespace {

// The light cull's hierarchy: groups of kCullGroup consecutive cells, and of kCullGroups such
// groups — consecutive cells of the plan's quadtree order lie together, so their directions fit
// a narrow cone.
constexpr size_t kCullGroup = 16, kCullGroups = 4;

// A cone from the eye: unit axis, cosine of the half angle (−2: every direction).
struct Cone {
  Vec3d axis;
  double cosHalf = -2;
  bool empty = true;  // no fitted cell
};

// The cone of cells [c0, c1) of the plan: about the mean of their corner directions, out to the
// farthest corner (a cell's directions form a convex spherical quadrilateral, inside the cap of
// its corners), widened by `reach` pixels at twice the coarsest pixel angle at a cell's centre (a
// cell's pixel angle varies by far less across it).
Cone coneOf(const display::SubFrustumPlan& plan, size_t c0, size_t c1, double reach) {
  std::vector<Vec3d> corners;
  double pixelAngle = 0;
  for (size_t i = c0; i < c1; ++i) {
    const display::SubFrustumCell& c = plan.cells[i];
    if (!c.fitted) continue;
    for (const auto& [x, y] : {std::pair{c.x0, c.y0}, std::pair{c.x1, c.y0}, std::pair{c.x0, c.y1},
                               std::pair{c.x1, c.y1}})
      corners.push_back(display::mapPixel(c, x, y));
    const double cx = 0.5 * (c.x0 + c.x1), cy = 0.5 * (c.y0 + c.y1);
    const Vec3d centre = display::mapPixel(c, cx, cy);
    pixelAngle = std::max({pixelAngle, angleBetween(centre, display::mapPixel(c, cx + 1, cy)),
                           angleBetween(centre, display::mapPixel(c, cx, cy + 1))});
  }
  Cone cone;
  if (corners.empty()) return cone;
  cone.empty = false;
  for (const Vec3d& d : corners) cone.axis = cone.axis + d;
  const double len = std::sqrt(dot(cone.axis, cone.axis));
  if (!(len > 0)) return cone;  // corners all around: every direction
  cone.axis = cone.axis * (1 / len);
  double half = 0;
  for (const Vec3d& d : corners) half = std::max(half, angleBetween(cone.axis, d));
  half += 2 * reach * pixelAngle;
  if (half < std::numbers::pi) cone.cosHalf = std::cos(half);
  return cone;
}

}  // namespace

void SubFrustumRenderer::cullLights(const scene::Scene& scene, const FrameCamera& base, Vec3d eye,
                                    const display::SubFrustumPlan& plan) {
  std::vector<Vec4> positions;
  lights::lightEyePositions(lightInput(scene, base), positions);
  lightDirections_.clear();
  for (size_t l = 0; l < positions.size(); ++l) {
    const Vec4& p = positions[l];
    const Vec3d d{p.x - eye.x * p.w, p.y - eye.y * p.w, p.z - eye.z * p.w};
    const double len = std::sqrt(dot(d, d));
    if (len > 0) lightDirections_.push_back({d * (1 / len), uint32_t(l)});  // at the eye: never
  }
  // A splat reaches no pixel farther than its kernel radius from its centre (light_laws.h); a
  // pixel more covers the difference between the pass's float projection and the map's double.
  const scene::LightSettings& ls = scene.lightSettings;
  const double reach = lights::splatRadius(std::max(ls.minSize, ls.maxSize)) + 1;
  const size_t n = plan.cells.size();
  const size_t span = kCullGroup * kCullGroups;
  cellLights_.resize(n);
  for (std::vector<uint32_t>& list : cellLights_) list.clear();
  // Lights in light order through each level, so every cell's list comes out ascending.
  pool_.parallelFor((n + span - 1) / span, [&](size_t top, int) {
    const size_t t0 = top * span, t1 = std::min(n, t0 + span);
    const Cone outer = coneOf(plan, t0, t1, reach);
    if (outer.empty) return;
    std::vector<const LightDirection*> inOuter, inGroup;
    for (const LightDirection& l : lightDirections_)
      if (dot(l.direction, outer.axis) >= outer.cosHalf) inOuter.push_back(&l);
    for (size_t c0 = t0; c0 < t1; c0 += kCullGroup) {
      const size_t c1 = std::min(t1, c0 + kCullGroup);
      const Cone group = coneOf(plan, c0, c1, reach);
      if (group.empty) continue;
      inGroup.clear();
      for (const LightDirection* l : inOuter)
        if (dot(l->direction, group.axis) >= group.cosHalf) inGroup.push_back(l);
      for (size_t i = c0; i < c1; ++i) {
        const display::SubFrustumCell& c = plan.cells[i];
        if (!c.fitted) continue;
        for (const LightDirection* l : inGroup) {
          const std::optional<display::PixelPoint> p = display::mapDirection(c, l->direction);
          if (p && p->x >= c.x0 - reach && p->x <= c.x1 + reach && p->y >= c.y0 - reach &&
              p->y <= c.y1 + reach)
            cellLights_[i].push_back(l->index);
        }
      }
    }
  });
}

SubFrustumRenderer::SubFrustumRenderer(const RenderOptions& options)
    : pool_(resolveThreads(options.threads)) {
  RenderOptions single = options;
  single.threads = 1;
  for (int i = 0; i < pool_.threadCount(); ++i)
    workers_.push_back(std::make_unique<ViewRenderer>(single));
}

Status SubFrustumRenderer::render(const scene::Scene& scene, const RenderOptions& o,
                                  const FrameCamera& base, Vec3d eye,
                                  const display::SubFrustumPlan& plan,
                                  const std::vector<uint8_t>& valid, output::LinearImage& out,
                                  FrameStats& stats, SubFrustumStats* cellStats) {
  if (o.debugView != RenderOptions::DebugView::none)
    return Error{"", "", "distortion correction draws images, not debug views"};
  if (plan.width != o.width || plan.height != o.height)
    return Error{"", "",
                 fmt::format("the sub-frustum plan is {} × {} pixels, the channel {} × {}",
                             plan.width, plan.height, o.width, o.height)};
  if (!valid.empty() && valid.size() != size_t(o.width) * size_t(o.height))
    return Error{"", "", "the display's valid-pixel mask does not match its size"};
  out.resize(o.width, o.height);
  const size_t n = plan.cells.size();
  // Every pixel is written: a fitted cell's by its view; an unfitted cell's, and one that is
  // invalid, black. Pixels outside every cell are invalid (the plan's cells hold every valid one):
  // without a mask to say so, the frame starts black.
  int64_t covered = 0;
  for (const display::SubFrustumCell& c : plan.cells)
    covered += int64_t(c.x1 - c.x0) * int64_t(c.y1 - c.y0);
  if (valid.empty() && covered != int64_t(o.width) * int64_t(o.height))
    std::fill(out.rgb.begin(), out.rgb.end(), uint16_t(0));
  cellStats_.assign(n, FrameStats{});
  cellErrors_.assign(n, Status{});
  const bool lights = !scene.lightPoints.empty() || !scene.stars.stars.empty();
  if (lights) cullLights(scene, base, eye, plan);
  // Each cell resolves straight into its own rectangle of `out`: the workers never write the same
  // pixel.
  pool_.parallelFor(n, [&](size_t i, int worker) {
    const display::SubFrustumCell& cell = plan.cells[i];
    if (!cell.fitted) {
      for (int y = cell.y0; y < cell.y1; ++y)
        std::fill_n(&out.rgb[(size_t(y) * size_t(o.width) + size_t(cell.x0)) * 3],
                    size_t(cell.x1 - cell.x0) * 3, uint16_t(0));
      return;
    }
    RenderOptions co = o;
    co.width = cell.x1 - cell.x0;
    co.height = cell.y1 - cell.y0;
    FrameCamera camera = cellCamera(base, cell, eye);
    if (lights) camera.lightSubset = &cellLights_[i];
    cellErrors_[i] = workers_[size_t(worker)]->renderLinear(
        scene, co, camera, output::LinearTarget{&out, cell.x0, cell.y0, co.width, co.height},
        cellStats_[i]);
  });
  SubFrustumStats counts;
  counts.unfittedPixels = plan.unfittedPixels;
  counts.maxResidualPixels = plan.maxResidualPixels;
  for (size_t i = 0; i < n; ++i) {
    if (!cellErrors_[i]) return cellErrors_[i];
    if (!plan.cells[i].fitted) continue;
    stats += cellStats_[i];
    ++counts.cells;
  }
  if (!valid.empty())
    for (size_t i = 0; i < valid.size(); ++i)
      if (!valid[i]) out.rgb[3 * i] = out.rgb[3 * i + 1] = out.rgb[3 * i + 2] = 0;
  if (cellStats) *cellStats = counts;
  return {};
}

}  // namespace sv::render
