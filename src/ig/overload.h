// Overload protection (seed 002: the picture never breaks under overload; docs/ig.md, "Overload"):
// every frame has a deadline, a share of the frame period. Before each frame the governor predicts
// the frame's time at the current quality level from the previous frames' times at that level,
// scaled by the coming frame's work (triangles and light points against those the times were
// measured with), and when the prediction overruns it steps down to the first level whose
// prediction fits. It steps back up one level at a time, only after `holdFrames` frames in a row
// predicted to fit the level above with a quarter of the budget to spare (hysteresis: no
// oscillation between two levels). A frame that overran despite the prediction steps down at once.
// The estimates of levels not drawn lately drift down toward what the drawn level's measurements
// imply for them, so that one passing overload does not keep the quality down for good.
//
// Levels, in the order quality is given up (level 0 is the configuration's quality):
//   anti-aliasing samples, one step at a time (64 → 16 → 8 → 4 → 1);
//   texture filtering, trilinear or anisotropic → bilinear;
//   the star field off;
//   terrain interpolation bicubic → bilinear;
//   half resolution: channels drawn at half their width and height, each pixel shown 2 × 2 times
//   (pixel replication, as CIGI's View Definition names it).
#pragma once

#include <string>
#include <vector>

#include "synthvis/render.h"

namespace sv::ig {

struct QualityLevel {
  RenderOptions options;
  bool stars = true;
  int replication = 1;  // channels drawn at 1/r of their size, each pixel shown r × r times
  std::string change;  // what this level gave up against the one before ("aa 4", "no stars")
};

// The levels from full quality `full` down, each one reduction more than the last; with
// `levelsOfDetail` (the database has level-of-detail groups) one that switches every group's
// levels at half their ranges, before half resolution.
std::vector<QualityLevel> qualityLevels(const RenderOptions& full, bool levelsOfDetail = false);

class OverloadGovernor {
 public:
  OverloadGovernor(std::vector<QualityLevel> levels, double budgetMs, int holdFrames = 30);

  // The level to draw the coming frame at, whose work is `work` (triangles + light points).
  int choose(double work);
  // What the frame at `level` took, drawing `work`.
  void record(int level, double work, double ms);
  // Before the clock starts: what a frame at `level` takes, measured once for every level, so
  // that the levels' costs against each other are known rather than guessed (prior()).
  void calibrate(int level, double work, double ms);

  int level() const { return level_; }
  int levels() const { return int(levels_.size()); }
  const QualityLevel& at(int level) const { return levels_[size_t(level)]; }
  double budgetMs() const { return budgetMs_; }
  // The predicted time of a frame of `work` at `level`, ms (0 before any measurement).
  double predict(int level, double work) const;

 private:
  struct Estimate {
    double msPerWork = 0;   // exponentially weighted; 0: never measured
    double calibrated = 0;  // calibrate()'s measurement; 0: none
  };
  // A level's cost against the one above it: as calibrated, or else a prior guess.
  double prior(int level) const;

  std::vector<QualityLevel> levels_;
  std::vector<Estimate> estimates_;
  double budgetMs_;
  int hold_;
  int level_ = 0;
  int fitting_ = 0;  // frames in a row the level above was predicted to fit
};

}  // namespace sv::ig
