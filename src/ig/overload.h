// Overload protection (seed 002: the picture never breaks under overload; docs/ig.md, "Overload"):
// every frame has a deadline, a share of the frame period. Before each frame the governor predicts
// the frame's time at the current quality level, pass by pass, from what each pass cost per unit
// of its own work in the previous frames at that level: the polygons and light points by the
// coming frame's triangles and lights, the terrain by the share of the frame's samples whose rays
// meet the ground (the last frame's, which a flight changes little from frame to frame). When the
// prediction overruns it steps down to the first level whose prediction fits. It steps back up one
// level at a time, only after `holdFrames` frames in a row predicted to fit the level above with a
// quarter of the budget to spare (hysteresis: no oscillation between two levels). A frame that
// overran despite the prediction steps down at once. The estimates of levels not drawn lately
// drift down toward what the drawn level's measurements imply for them, so that one passing
// overload does not keep the quality down for good.
//
// Levels, in the order quality is given up (level 0 is the configuration's quality):
//   anti-aliasing samples, one step at a time (64 → 16 → 8 → 4 → 1);
//   texture filtering, trilinear or anisotropic → bilinear;
//   the star field off;
//   with terrain, in the order of their measured gain: interpolation bicubic → bilinear (where
//   some terrain is bicubic), then the ground one level of detail coarser;
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
  std::string change;   // what this level gave up against the one before ("aa 4", "no stars")
};

// What the database's ray-cast passes allow the governor to give up.
struct PassLevels {
  bool terrain = false;  // the database has terrain
  bool bicubic = false;  // some terrain is drawn bicubic at full quality
  bool volumes = false;  // the database has volumes
  float volumeWindowTolerance = 0;  // theirs at full quality (VolumeSettings::windowTolerance)
};

// The levels from full quality `full` down, each one reduction more than the last; with volumes,
// their screen windows blended at twice the tolerance (at least 0.05); with terrain, its
// reductions (bicubic → bilinear where some terrain is bicubic, then the ground a level of detail
// coarser: the order of their measured gain, docs/ig.md); with `levelsOfDetail` (the database has
// level-of-detail groups) one that switches every group's levels at half their ranges, before
// half resolution.
std::vector<QualityLevel> qualityLevels(const RenderOptions& full, bool levelsOfDetail = false,
                                        const PassLevels& passes = {});

// What a frame draws, by the work each pass's cost is predicted from.
struct FrameWork {
  double geometry = 1;  // triangles and light points: the coming frame's, from the scene
  double terrain = 0;  // the share of the frame's samples whose rays met the ground: the last one's
};
// What a drawn frame took: all of it, and the terrain pass's part (FrameStats::terrainMs).
struct FrameCost {
  double ms = 0;
  double terrainMs = 0;
};

class OverloadGovernor {
 public:
  OverloadGovernor(std::vector<QualityLevel> levels, double budgetMs, int holdFrames = 30);

  // The level to draw the coming frame at, whose work is `work`.
  int choose(const FrameWork& work);
  // What the frame at `level` took, drawing `work`.
  void record(int level, const FrameWork& work, const FrameCost& cost);
  // Before the clock starts: what a frame at `level` takes, measured once for every level, so
  // that the levels' costs against each other are known rather than guessed (prior()).
  void calibrate(int level, const FrameWork& work, const FrameCost& cost);

  int level() const { return level_; }
  int levels() const { return int(levels_.size()); }
  const QualityLevel& at(int level) const { return levels_[size_t(level)]; }
  double budgetMs() const { return budgetMs_; }
  // The predicted time of a frame of `work` at `level`, ms (0 before any measurement).
  double predict(int level, const FrameWork& work) const;

 private:
  struct Estimate {
    // Exponentially weighted ms per unit of each pass's work; measured: ever recorded.
    double perGeometry = 0, perTerrain = 0;
    bool measured = false;
    double calibrated = 0;  // calibrate()'s frame time; 0: none
    double predict(const FrameWork& w) const {
      return perGeometry * w.geometry + perTerrain * w.terrain;
    }
  };
  // A measurement into `e`, with weight `weight` (1: replaces it).
  static void update(Estimate& e, const FrameWork& work, const FrameCost& cost, double weight);
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
