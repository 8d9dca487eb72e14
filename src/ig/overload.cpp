// Based on: seed 002 (overload protection: a frame that never breaks), seed 004 (a real-time system).
#include "ig/overload.h"

#include <fmt/format.h>

#include <algorithm>

namespace sv::ig {
namespace {

// A level never measured is predicted from the one above it scaled by this prior: anti-aliasing
// costs about in proportion to the samples' share of the work; the other reductions a little.
constexpr double kPriorOther = 0.9;
// The weight of a new measurement in the running estimate.
constexpr double kSmoothing = 0.2;
// How fast a level's stale estimate drifts toward the one implied by a level below it, a frame.
constexpr double kStaleDrift = 0.05;

}  // namespace

std::vector<QualityLevel> qualityLevels(const RenderOptions& full, bool levelsOfDetail,
                                        const PassLevels& passes) {
  std::vector<QualityLevel> levels{{full, true, 1, "full quality"}};
  auto next = [&](const char* what, auto&& change) {
    QualityLevel l = levels.back();
    change(l);
    l.change = what;
    levels.push_back(l);
  };
  for (const int to : {16, 8, 4, 1})
    if (levels.back().options.samples > to) {
      const std::string what = fmt::format("aa {}", to);
      next(what.c_str(), [to](QualityLevel& l) { l.options.samples = to; });
    }
  if (full.textureFilter == scene::TextureFilter::trilinear ||
      full.textureFilter == scene::TextureFilter::anisotropic ||
      full.textureFilter == scene::TextureFilter::trilinearThreePoint)
    next("bilinear textures",
         [](QualityLevel& l) { l.options.textureFilter = scene::TextureFilter::bilinear; });
  next("no stars", [](QualityLevel& l) { l.stars = false; });
  // Volumes: their screen windows blended more widely (docs/volumes.md: at 0.05 the cloud layer
  // casts 15 % of its rays, 54 dB from the exact cast).
  if (passes.volumes) {
    const float own =
        full.volumeWindowTolerance >= 0 ? full.volumeWindowTolerance : passes.volumeWindowTolerance;
    const float wider = std::min(1.0f, std::max(0.05f, 2 * own));
    next("coarser volume windows",
         [wider](QualityLevel& l) { l.options.volumeWindowTolerance = wider; });
  }
  // The terrain's reductions, the larger gain first (docs/ig.md: bicubic costs several times
  // bilinear; a level of detail coarser saves a part of the cells walked).
  const bool bicubic =
      full.terrainFilter == RenderOptions::TerrainFilter::bicubic ||
      (full.terrainFilter == RenderOptions::TerrainFilter::scene && passes.bicubic);
  if (passes.terrain && bicubic)
    next("bilinear terrain",
         [](QualityLevel& l) { l.options.terrainFilter = RenderOptions::TerrainFilter::bilinear; });
  if (passes.terrain && full.terrainLod)
    next("coarser terrain", [](QualityLevel& l) { ++l.options.terrainLodBias; });
  // Geometry: every level of detail switched at half its range (RenderOptions::lodScale).
  if (levelsOfDetail && full.lod)
    next("coarser levels of detail", [](QualityLevel& l) { l.options.lodScale *= 2; });
  next("half resolution", [](QualityLevel& l) { l.replication = 2; });
  return levels;
}

OverloadGovernor::OverloadGovernor(std::vector<QualityLevel> levels, double budgetMs,
                                   int holdFrames)
    : levels_(std::move(levels)),
      estimates_(levels_.size()),
      budgetMs_(budgetMs),
      hold_(holdFrames) {}

void OverloadGovernor::update(Estimate& e, const FrameWork& work, const FrameCost& cost,
                              double weight) {
  // The terrain's part by the ground's share of the samples, the rest by triangles and lights.
  const double terrainMs = std::clamp(cost.terrainMs, 0.0, cost.ms);
  const double geometry = (std::max(cost.ms, 1e-3) - terrainMs) / std::max(work.geometry, 1.0);
  if (!e.measured) weight = 1;
  e.perGeometry += weight * (geometry - e.perGeometry);
  if (work.terrain > 1e-6) e.perTerrain += weight * (terrainMs / work.terrain - e.perTerrain);
  e.measured = true;
}

void OverloadGovernor::calibrate(int level, const FrameWork& work, const FrameCost& cost) {
  Estimate& e = estimates_[size_t(level)];
  e.measured = false;
  update(e, work, cost, 1);
  e.calibrated = std::max(cost.ms, 1e-3);
}

double OverloadGovernor::prior(int level) const {
  const Estimate &a = estimates_[size_t(level - 1)], &b = estimates_[size_t(level)];
  if (a.calibrated > 0 && b.calibrated > 0) return b.calibrated / a.calibrated;
  const int from = levels_[size_t(level - 1)].options.samples,
            to = levels_[size_t(level)].options.samples;
  if (levels_[size_t(level)].replication != levels_[size_t(level - 1)].replication)
    return 0.3;  // a quarter of the pixels, and the per-frame work that does not shrink
  return from != to ? std::max(0.25, double(to) / double(from)) : kPriorOther;
}

double OverloadGovernor::predict(int level, const FrameWork& work) const {
  // The nearest measured level at or above this one, scaled down by the priors in between.
  double scale = 1;
  for (int l = level; l >= 0; --l) {
    if (estimates_[size_t(l)].measured) return estimates_[size_t(l)].predict(work) * scale;
    if (l > 0) scale *= prior(l);
  }
  return 0;
}

int OverloadGovernor::choose(const FrameWork& work) {
  if (predict(level_, work) > budgetMs_) {
    // Down to the first level predicted to fit (or the last).
    while (level_ + 1 < levels() && predict(level_, work) > budgetMs_) ++level_;
    fitting_ = 0;
    return level_;
  }
  if (level_ > 0 && predict(level_ - 1, work) <= 0.75 * budgetMs_) {
    if (++fitting_ >= hold_) {
      --level_;
      fitting_ = 0;
    }
  } else {
    fitting_ = 0;
  }
  return level_;
}

void OverloadGovernor::record(int level, const FrameWork& work, const FrameCost& cost) {
  Estimate& e = estimates_[size_t(level)];
  update(e, work, cost, kSmoothing);
  // The levels above were last measured when they were drawn, perhaps in a passing overload (the
  // machine busy, a heavy view): their estimates drift down toward what this level's measurement
  // implies for them, so that a stale figure cannot keep the quality down for good.
  double implied = std::max(cost.ms, 1e-3);
  for (int l = level; l > 0; --l) {
    implied /= prior(l);
    Estimate& above = estimates_[size_t(l - 1)];
    const double theirs = above.predict(work);
    if (above.measured && theirs > implied) {
      const double shrink = 1 + kStaleDrift * (implied / theirs - 1);
      above.perGeometry *= shrink, above.perTerrain *= shrink;
    }
  }
  // An overrun the prediction missed: down a level at once, and start the hold again.
  if (cost.ms > budgetMs_ && level == level_ && level_ + 1 < levels()) {
    ++level_;
    fitting_ = 0;
  }
}

}  // namespace sv::ig
