#include <algorithm>
#include <chrono>

#include "synthvis/bench.h"

namespace sv {
namespace {
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
}  // namespace

Result<FrameTimings> timeFrames(const scene::Scene& scene, const RenderOptions& options, int frames,
                                int warmup) {
  if (Status s = validate(options); !s) return s.error();
  if (frames < 1 || frames > 100000 || warmup < 0 || warmup > 100000)
    return Error{"", "", "frames must be 1…100000 and warmup 0…100000"};
  Renderer renderer(options);
  FrameTimings t;
  std::vector<double> raster;
  for (int i = 0; i < warmup + frames; ++i) {
    FrameStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    if (Status s = renderer.render(scene, t.image, &stats); !s) return s.error();
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (i < warmup) continue;
    t.frameMs.push_back(ms);
    raster.push_back(stats.setupMs + stats.rasterMs);
    t.stats = stats;
  }
  t.medianMs = median(t.frameMs);
  t.minMs = *std::min_element(t.frameMs.begin(), t.frameMs.end());
  t.maxMs = *std::max_element(t.frameMs.begin(), t.frameMs.end());
  t.medianRasterMs = median(raster);
  return t;
}

}  // namespace sv
