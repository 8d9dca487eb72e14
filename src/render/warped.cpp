#include "render/warped.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

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

SubFrustumRenderer::SubFrustumRenderer(const RenderOptions& options)
    : pool_(resolveThreads(options.threads)) {
  RenderOptions single = options;
  single.threads = 1;
  for (int i = 0; i < pool_.threadCount(); ++i)
    workers_.push_back(std::make_unique<ViewRenderer>(single));
  cellImages_.resize(size_t(pool_.threadCount()));
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
  std::fill(out.rgb.begin(), out.rgb.end(), uint16_t(0));
  const size_t n = plan.cells.size();
  cellStats_.assign(n, FrameStats{});
  cellErrors_.assign(n, Status{});
  // Each cell writes its own rectangle of `out`: the workers never write the same pixel.
  pool_.parallelFor(n, [&](size_t i, int worker) {
    const display::SubFrustumCell& cell = plan.cells[i];
    if (!cell.fitted) return;
    RenderOptions co = o;
    co.width = cell.x1 - cell.x0;
    co.height = cell.y1 - cell.y0;
    output::LinearImage& image = cellImages_[size_t(worker)];
    cellErrors_[i] = workers_[size_t(worker)]->renderLinear(scene, co, cellCamera(base, cell, eye),
                                                            image, cellStats_[i]);
    if (!cellErrors_[i]) return;
    for (int y = 0; y < co.height; ++y)
      std::memcpy(&out.rgb[(size_t(cell.y0 + y) * size_t(o.width) + size_t(cell.x0)) * 3],
                  &image.rgb[size_t(y) * size_t(co.width) * 3], size_t(co.width) * 6);
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
