#include "render/warped.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>
#include <utility>

#include "core/check.h"
#include "core/timing.h"
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
Cone coneOf(const PlanCone& base, double reach) {
  Cone cone;
  cone.empty = base.empty;
  cone.axis = base.axis;
  if (base.empty || base.everyDirection) return cone;
  const double half = base.halfAngle + 2 * reach * base.pixelAngle;
  if (half < std::numbers::pi) cone.cosHalf = std::cos(half);
  return cone;
}

}  // namespace

PlanCone planCone(const display::SubFrustumPlan& plan, size_t c0, size_t c1) {
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
  PlanCone cone;
  if (corners.empty()) return cone;
  cone.empty = false;
  for (const Vec3d& d : corners) cone.axis = cone.axis + d;
  const double len = std::sqrt(dot(cone.axis, cone.axis));
  if (!(len > 0)) {  // corners all around: every direction
    cone.everyDirection = true;
    return cone;
  }
  cone.axis = cone.axis * (1 / len);
  for (const Vec3d& d : corners)
    cone.halfAngle = std::max(cone.halfAngle, angleBetween(cone.axis, d));
  cone.pixelAngle = pixelAngle;
  return cone;
}

namespace {

// A group's first fitted cell, and how far its map places the directions of the group's cells'
// corners and centres from where their own maps do (pixels, and one more; −1: somewhere behind
// it, or no fitted cell — every cell is then tried).
SubFrustumRenderer::PlanState::Group groupOf(const display::SubFrustumPlan& plan, size_t c0,
                                             size_t c1) {
  SubFrustumRenderer::PlanState::Group g;
  g.first = c0;
  while (g.first < c1 && !plan.cells[g.first].fitted) ++g.first;
  if (g.first == c1) return g;
  const display::SubFrustumCell& rep = plan.cells[g.first];
  double slack = 0;
  for (size_t i = c0; i < c1; ++i) {
    const display::SubFrustumCell& c = plan.cells[i];
    if (!c.fitted) continue;
    const double cx = 0.5 * (c.x0 + c.x1), cy = 0.5 * (c.y0 + c.y1);
    for (const auto& [x, y] :
         {std::pair{double(c.x0), double(c.y0)}, std::pair{double(c.x1), double(c.y0)},
          std::pair{double(c.x0), double(c.y1)}, std::pair{double(c.x1), double(c.y1)},
          std::pair{cx, cy}}) {
      const std::optional<display::PixelPoint> q =
          display::mapDirection(rep, display::mapPixel(c, x, y));
      if (!q) return g;
      slack = std::max({slack, std::abs(q->x - x), std::abs(q->y - y)});
    }
  }
  // The disagreement of two smooth maps grows smoothly between the points measured: twice it,
  // and a pixel, bound it across the cells.
  g.slack = 2 * slack + 1;
  return g;
}

}  // namespace

void SubFrustumRenderer::preparePlan(const display::SubFrustumPlan& plan) {
  const size_t n = plan.cells.size();
  PlanState& st = plan_;
  bool same = st.cells.size() == n && st.width == plan.width && st.height == plan.height;
  for (size_t i = 0; same && i < n; ++i) {
    const display::SubFrustumCell& a = st.cells[i];
    const display::SubFrustumCell& b = plan.cells[i];
    same = a.x0 == b.x0 && a.y0 == b.y0 && a.x1 == b.x1 && a.y1 == b.y1 && a.fitted == b.fitted &&
           std::memcmp(&a.map, &b.map, sizeof(Mat3d)) == 0;
  }
  if (same) return;
  stage_.znear = stage_.zfar = -1;  // made again for this plan
  st.width = plan.width;
  st.height = plan.height;
  st.cells = plan.cells;
  // The light cull's cones.
  const size_t span = kCullGroup * kCullGroups, tops = (n + span - 1) / span;
  st.top.resize(tops);
  st.group.resize((n + kCullGroup - 1) / kCullGroup);
  st.groups.resize(st.group.size());
  pool_.parallelFor(tops, [&](size_t top, int) {
    const size_t t0 = top * span, t1 = std::min(n, t0 + span);
    st.top[top] = planCone(plan, t0, t1);
    for (size_t c0 = t0; c0 < t1; c0 += kCullGroup) {
      const size_t c1 = std::min(t1, c0 + kCullGroup);
      st.group[c0 / kCullGroup] = planCone(plan, c0, c1);
      st.groups[c0 / kCullGroup] = groupOf(plan, c0, c1);
    }
  });
  // The pixels no cell holds (the plan dropped wholly invalid cells), as runs of rows.
  std::vector<uint8_t> covered(size_t(plan.width) * size_t(plan.height), 0);
  for (const display::SubFrustumCell& c : plan.cells)
    for (int y = c.y0; y < c.y1; ++y)
      std::fill_n(&covered[size_t(y) * size_t(plan.width) + size_t(c.x0)], size_t(c.x1 - c.x0),
                  uint8_t(1));
  st.uncovered.clear();
  for (int y = 0; y < plan.height; ++y)
    for (int x = 0; x < plan.width;) {
      if (covered[size_t(y) * size_t(plan.width) + size_t(x)]) {
        ++x;
        continue;
      }
      const int x0 = x;
      while (x < plan.width && !covered[size_t(y) * size_t(plan.width) + size_t(x)]) ++x;
      st.uncovered.push_back({y, x0, x});
    }
}

void SubFrustumRenderer::lightDirections(const scene::Scene& scene, const FrameCamera& base,
                                         Vec3d eye) {
  std::vector<Vec4> positions;
  lights::lightEyePositions(lightInput(scene, base), positions);
  lightDirections_.clear();
  for (size_t l = 0; l < positions.size(); ++l) {
    const Vec4& p = positions[l];
    const Vec3d d{p.x - eye.x * p.w, p.y - eye.y * p.w, p.z - eye.z * p.w};
    const double len = std::sqrt(dot(d, d));
    if (len > 0) lightDirections_.push_back({d * (1 / len), uint32_t(l)});  // at the eye: never
  }
}

double SubFrustumRenderer::lightReach(const scene::Scene& scene) {
  // A splat reaches no pixel farther than its kernel radius from its centre (light_laws.h); a
  // pixel more covers the difference between the pass's float projection and the map's double.
  const scene::LightSettings& ls = scene.lightSettings;
  return lights::splatRadius(std::max(ls.minSize, ls.maxSize)) + 1;
}

void SubFrustumRenderer::cullLights(const scene::Scene& scene, const FrameCamera& base, Vec3d eye,
                                    const display::SubFrustumPlan& plan) {
  lightDirections(scene, base, eye);
  const double reach = lightReach(scene);
  const size_t n = plan.cells.size();
  const size_t span = kCullGroup * kCullGroups;
  cellLights_.resize(n);
  for (std::vector<uint32_t>& list : cellLights_) list.clear();
  // Lights in light order through each level, so every cell's list comes out ascending.
  pool_.parallelFor((n + span - 1) / span, [&](size_t top, int) {
    const size_t t0 = top * span, t1 = std::min(n, t0 + span);
    const Cone outer = coneOf(plan_.top[top], reach);
    if (outer.empty) return;
    std::vector<const LightDirection*> inOuter, inGroup;
    for (const LightDirection& l : lightDirections_)
      if (dot(l.direction, outer.axis) >= outer.cosHalf) inOuter.push_back(&l);
    for (size_t c0 = t0; c0 < t1; c0 += kCullGroup) {
      const size_t c1 = std::min(t1, c0 + kCullGroup);
      const Cone group = coneOf(plan_.group[c0 / kCullGroup], reach);
      if (group.empty) continue;
      inGroup.clear();
      for (const LightDirection* l : inOuter)
        if (dot(l->direction, group.axis) >= group.cosHalf) inGroup.push_back(l);
      // Each light placed once by the group's first map, then tried exactly on the cells whose
      // rectangle that place is near (within the maps' disagreement over the group, slack).
      const PlanState::Group& g = plan_.groups[c0 / kCullGroup];
      for (const LightDirection* l : inGroup) {
        std::optional<display::PixelPoint> q;
        if (g.slack >= 0) q = display::mapDirection(plan.cells[g.first], l->direction);
        const double near = reach + g.slack;
        for (size_t i = c0; i < c1; ++i) {
          const display::SubFrustumCell& c = plan.cells[i];
          if (!c.fitted) continue;
          if (q && !(q->x >= c.x0 - near && q->x <= c.x1 + near && q->y >= c.y0 - near &&
                     q->y <= c.y1 + near))
            continue;
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
                                  FrameStats& stats, SubFrustumStats* cellStats,
                                  const Finish* finish) {
  if (o.debugView != RenderOptions::DebugView::none)
    return Error{"", "", "distortion correction draws images, not debug views"};
  if (plan.width != o.width || plan.height != o.height)
    return Error{"", "",
                 fmt::format("the sub-frustum plan is {} × {} pixels, the channel {} × {}",
                             plan.width, plan.height, o.width, o.height)};
  if (!valid.empty() && valid.size() != size_t(o.width) * size_t(o.height))
    return Error{"", "", "the display's valid-pixel mask does not match its size"};
  const size_t n = plan.cells.size();
  preparePlan(plan);
  // The stage (subfrustum_stage.cpp) where it can run: the tile pipeline, and a flat cover for
  // the plan; else every cell a view of its own.
  const double znear = base.camera.znear, zfar = base.camera.zfar;
  if (stage_.znear != znear || stage_.zfar != zfar) prepareStage(plan, znear, zfar);
  const bool stage = useStage_ && stage_.ok && o.pipeline == RenderOptions::Pipeline::tiles;
  if (stage)
    if (Status s = drawCover(scene, o, base, eye, stats); !s) return s;
  // Every pixel is written: a fitted cell's by its view; an unfitted cell's, and one that is
  // invalid, black. Pixels outside every cell are invalid (the plan's cells hold every valid one):
  // black.
  if (finish) {
    SV_CHECK(finish->gamma && finish->image);
    SV_CHECK(!finish->blend ||
             (finish->blend->width == o.width && finish->blend->height == o.height));
    output::prepareImage(o.width, o.height, *finish->image);
  }
  // Straight into the image (Finish::linear false): the stage's cells, unsupersampled.
  const bool direct = stage && finish && !finish->linear && o.supersample == 1;
  if (!direct) out.resize(o.width, o.height);  // direct: no linear frame is written, or held
  // The cell's rectangle blended and encoded (Finish).
  const auto finishRect = [&](int x0, int y0, int x1, int y1) {
    if (!finish || direct) return;
    if (finish->blend) display::applyBlend(*finish->blend, out.rgb.data(), x0, y0, x1, y1);
    output::encodeRect(out, *finish->gamma, x0, y0, x1, y1, *finish->image);
  };
  // A rectangle black, in whichever frame the cells draw into.
  const auto black = [&](int x0, int y0, int x1, int y1) {
    for (int y = y0; y < y1; ++y)
      if (direct)
        std::fill_n(finish->image->pixel(x0, y), size_t(x1 - x0) * 3, uint8_t(0));
      else
        std::fill_n(&out.rgb[(size_t(y) * size_t(o.width) + size_t(x0)) * 3], size_t(x1 - x0) * 3,
                    uint16_t(0));
    finishRect(x0, y0, x1, y1);
  };
  for (const PlanState::Run& r : plan_.uncovered) black(r.x0, r.y, r.x1, r.y + 1);
  cellStats_.assign(n, FrameStats{});
  cellErrors_.assign(n, Status{});
  const bool lights = !scene.lightPoints.empty() || !scene.stars.stars.empty();
  if (lights) {
    if (stage)
      binLights(scene, base, eye, plan);  // each cell's lights found as it is drawn
    else
      cullLights(scene, base, eye, plan);
    // Every cell looks from the display's eye: the lights' laws (lobes, PAPI, fog, energy) once
    // for all of them, as the channels of one eye share theirs (Renderer::renderChannels).
    FrameCamera moved = base;
    moved.view = Mat4::translation(Vec3{float(-eye.x), float(-eye.y), float(-eye.z)}) * base.view;
    if (!scene.lightPoints.empty()) laws_.compute(lightInput(scene, moved), pool_);
  }
  // Each cell resolves straight into its own rectangle of `out`: the workers never write the same
  // pixel.
  pool_.parallelFor(n, [&](size_t i, int worker) {
    const display::SubFrustumCell& cell = plan.cells[i];
    if (!cell.fitted) {
      black(cell.x0, cell.y0, cell.x1, cell.y1);
      return;
    }
    RenderOptions co = o;
    co.width = cell.x1 - cell.x0;
    co.height = cell.y1 - cell.y0;
    FrameCamera camera = cellCamera(base, cell, eye);
    if (lights && stage) cellLightsOf(i, plan);
    if (lights) camera.lightSubset = &cellLights_[i];
    if (!scene.lightPoints.empty()) camera.lightLaws = &laws_;
    const output::LinearTarget target{&out, cell.x0, cell.y0, co.width, co.height};
    if (direct) {
      CellScratch& scratch = cellScratch_[size_t(worker)];
      cellPackets(i, scratch);
      const display::BlendWeights* blend = finish->blend;
      const output::ImageTarget into{finish->image,
                                     cell.x0,
                                     cell.y0,
                                     co.width,
                                     co.height,
                                     blend ? blend->alpha.data() : nullptr,
                                     blend ? blend->beta.data() : nullptr};
      cellErrors_[i] = workers_[size_t(worker)]->renderPacketsImage(
          scene, co, camera, scratch.packets, shading_, into, cellStats_[i]);
    } else if (stage) {
      CellScratch& scratch = cellScratch_[size_t(worker)];
      cellPackets(i, scratch);
      cellErrors_[i] = workers_[size_t(worker)]->renderPacketsLinear(
          scene, co, camera, scratch.packets, shading_, target, cellStats_[i]);
    } else {
      cellErrors_[i] =
          workers_[size_t(worker)]->renderLinear(scene, co, camera, target, cellStats_[i]);
    }
    // Its invalid pixels black, while they are in this core's cache.
    if (!valid.empty() && cell.validPixels < int64_t(co.width) * co.height)
      for (int y = cell.y0; y < cell.y1; ++y)
        for (int x = cell.x0; x < cell.x1; ++x) {
          const size_t k = size_t(y) * size_t(o.width) + size_t(x);
          if (valid[k]) continue;
          if (direct)
            std::fill_n(finish->image->pixel(x, y), 3, uint8_t(0));
          else
            out.rgb[3 * k] = out.rgb[3 * k + 1] = out.rgb[3 * k + 2] = 0;
        }
    if (cellErrors_[i]) finishRect(cell.x0, cell.y0, cell.x1, cell.y1);
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
  if (cellStats) *cellStats = counts;
  return {};
}

}  // namespace sv::render
