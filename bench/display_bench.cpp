// Kernel benchmarks of distortion correction at an IG's rate (issue 61's cost model,
// docs/display.md "At an IG's rate"), on BENCH.md's display figure — scenes/airport.json on the
// demo cylinder's centre projector at 1920×1080 — on one thread (/1), so that a figure is ns of a
// core, and on two (/2, the figure):
//   BM_UnwarpedFrame: the scene camera's view, through the gamma table    → ms a frame
//   BM_SubFrustaFrame: the same through the projector's sub-frusta (the plan made once), each
//     cell resolved through the table into the image, as the IG draws it → ms a frame
//   BM_SubFrustaOverUnwarped/threads/mode: the two alternating in one run, their medians, ratio
//     and (sub-frusta − unwarped) / cells in µs of the threads' time; mode 0 both in linear
//     light, 1 as `bench --renderer display` times them (the figure), 2 the display
//     frame in linear light against the unwarped one through the table
//   BM_RefitPlan: the plan refitted for a (2, 1, −1) cm move (the cells fixed) → ms, /904 a cell
// The budget: ≤ 3 µs of a core a cell for the frame (the 1.3× target), ≤ 4 µs a cell for the
// refit (2 ms on 2 threads). Run: build/bench/sv_display_bench (SV_BENCH_TARGET=avx2 for the AVX2
// kernels on an AVX-512 machine).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>

#include "bench_target.h"
#include "display/subfrustum.h"
#include "render/camera.h"
#include "render/correction.h"
#include "render/view_renderer.h"
#include "render/warped.h"
#include "synthvis/formats.h"

namespace {

constexpr int kWidth = 1920, kHeight = 1080;

struct DisplayCase {
  sv::scene::Scene scene;
  sv::RenderOptions options;
  sv::render::DisplaySetup display = sv::render::cylinderDisplay(kWidth, kHeight);
  sv::display::SubFrustumPlan plan;
  sv::render::FrameCamera base;

  DisplayCase() {
    const std::string path = std::string(SV_SOURCE_DIR) + "/scenes/airport.json";
    auto loaded = sv::formats::loadScene(path);
    if (!loaded.ok()) {
      std::fprintf(stderr, "sv_display_bench: %s (scripts/demo unpacks its star catalogue)\n",
                   loaded.error().str().c_str());
      std::exit(1);
    }
    scene = std::move(loaded.value());
    options.threads = 1;
    options.width = kWidth;
    options.height = kHeight;
    base = sv::render::chooseCamera(scene, options).value();
    sv::display::SubFrustumOptions so;
    so.znear = base.camera.znear;
    so.zfar = base.camera.zfar;
    plan = sv::display::planSubFrusta(centre().table, so);
  }
  const sv::render::ProjectorSetup& centre() const { return display.projectors[1]; }
};

DisplayCase& theCase() {
  static DisplayCase c;
  return c;
}

void BM_UnwarpedFrame(benchmark::State& state) {
  DisplayCase& c = theCase();
  sv::RenderOptions o = c.options;
  o.threads = int(state.range(0));
  sv::render::ViewRenderer renderer(o);
  sv::Image image;
  for (auto _ : state) {
    sv::FrameStats stats;
    if (!renderer.render(c.scene, o, c.base, image, stats)) state.SkipWithError("render");
  }
}
BENCHMARK(BM_UnwarpedFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SubFrustaFrame(benchmark::State& state) {
  DisplayCase& c = theCase();
  sv::RenderOptions o = c.options;
  o.threads = int(state.range(0));
  sv::render::SubFrustumRenderer renderer(o);
  sv::output::LinearImage out;
  // As an image generator draws it: through the gamma table straight into the image.
  const sv::output::GammaTable gamma = sv::output::GammaTable::srgb();
  sv::Image image;
  const sv::render::SubFrustumRenderer::Finish finish{nullptr, &gamma, &image, false};
  for (auto _ : state) {
    sv::FrameStats stats;
    if (!renderer.render(c.scene, o, c.base, c.display.eye, c.plan, c.centre().table.valid, out,
                         stats, nullptr, &finish))
      state.SkipWithError("render");
  }
  state.counters["cells"] = double(c.plan.cells.size());
}
BENCHMARK(BM_SubFrustaFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The two frames alternating, each timed (BENCH.md: ratios from the same run): the medians and
// their ratio, and (sub-frusta − unwarped) / cells in µs of the threads' time.
void BM_SubFrustaOverUnwarped(benchmark::State& state) {
  DisplayCase& c = theCase();
  sv::RenderOptions o = c.options;
  o.threads = int(state.range(0));
  sv::render::ViewRenderer flat(o);
  sv::render::SubFrustumRenderer cells(o);
  sv::output::LinearImage a, b;
  std::vector<double> flatMs, cellsMs;
  const auto ms = [](auto t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  // /…/1: as `bench --renderer display` times them — the unwarped view resolved to 8 bits, the
  // display's frame (render::renderCorrected, the plan given) and its gamma table.
  const bool encoded = state.range(1) != 0;
  sv::render::CorrectionRenderer corrected(o);
  sv::render::CorrectedView view;
  view.table = &c.centre().table;
  view.plan = &c.plan;
  view.eye = c.display.eye;
  sv::Image image, encodedImage;
  for (auto _ : state) {
    sv::FrameStats stats;
    auto t0 = std::chrono::steady_clock::now();
    if (encoded) {
      if (!flat.render(c.scene, o, c.base, image, stats)) state.SkipWithError("render");
    } else if (!flat.renderLinear(c.scene, o, c.base, a, stats)) {
      state.SkipWithError("render");
    }
    flatMs.push_back(ms(t0));
    t0 = std::chrono::steady_clock::now();
    if (encoded) {
      sv::DisplayStats cs;
      if (!sv::render::renderCorrected(corrected, c.scene, o, c.base, view, b, stats, cs,
                                       state.range(1) == 1 ? &encodedImage : nullptr, false))
        state.SkipWithError("render");
    } else if (!cells.render(c.scene, o, c.base, c.display.eye, c.plan, c.centre().table.valid, b,
                             stats)) {
      state.SkipWithError("render");
    }
    cellsMs.push_back(ms(t0));
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  const double f = median(flatMs), s = median(cellsMs);
  state.counters["unwarped_ms"] = f;
  state.counters["subfrusta_ms"] = s;
  state.counters["ratio"] = f > 0 ? s / f : 0;
  state.counters["us_a_cell"] = (s - f) * 1000 * o.threads / double(c.plan.cells.size());
}
BENCHMARK(BM_SubFrustaOverUnwarped)
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Args({2, 2})
    ->Iterations(30)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_RefitPlan(benchmark::State& state) {
  DisplayCase& c = theCase();
  const sv::display::DisplayGeometry design = c.display.rig->geometry(1);
  const sv::display::PlanScreenPoints points =
      sv::display::planScreenPoints(c.plan, c.centre().table, design);
  sv::display::DisplayGeometry moved = design;
  // A head's motion, as `bench --renderer display` moves it: (2, 1, −1) cm.
  moved.eye = moved.eye + sv::Vec3{0.02f, 0.01f, -0.01f};
  sv::display::RefitStats st;
  for (auto _ : state) {
    sv::display::SubFrustumPlan p = sv::display::refitPlan(c.plan, points, moved, {}, &st);
    benchmark::DoNotOptimize(p.cells.data());
  }
  state.counters["replanned"] = st.replanned;
  state.counters["cells"] = double(c.plan.cells.size());
}
BENCHMARK(BM_RefitPlan)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) { return sv::bench::runBenchmarks(argc, argv, "sv_display_bench"); }
