// Lines in the frame: the scene's line segments (synthvis/lines.h) drawn as strips a fixed number
// of pixels wide facing the eye — a tile pass (raster/tile_pass.h, stage `surfaces`), after the
// opaque polygons and the ray-cast surfaces, before the translucent polygons.
//
// A strip is sampled like a polygon (SPEC §5): each of the frame's samples inside it, and nearer
// than the depth already there, takes its depth and colour, so a line is anti-aliased by the same
// sample pattern and resolve as the polygons' edges, hidden by what is in front of it and hiding
// what is behind (the translucent polygons and light points after it test against it). Its colour
// is its own (lines are not lit), fogged by the true distance like a surface (SPEC §8).
//
// Per frame (prepare, in parallel over chunks of segments): each segment clipped to the near and far
// planes, projected, clipped to the screen, drawn a little nearer the eye (LineSettings::depthBias,
// so a line lying on a surface shows over it), and listed for every tile its strip reaches, in
// segment order. Per tile (drawTile): each listed strip row by row over the pixels its rectangle
// reaches. What a tile gets depends on the tile alone: the same image for any thread count.
#pragma once

#include <span>
#include <vector>

#include "raster/tile_lists.h"
#include "raster/tile_pass.h"
#include "synthvis/lines.h"

namespace sv::lines {

// What the pass needs of the scene and the frame's camera (the span must outlive the frame).
struct LineInput {
  std::span<const scene::LineSegment> lines;
  scene::LineSettings settings;
  Mat4 view;        // world → eye
  Mat4 projection;  // eye → clip (OpenGL conventions: window depth ½(−m22 + m32 / s) + ½)
  bool fog = false;
  Vec3 fogColor{0, 0, 0};  // linear
  float fogBeta = 0;       // per scene unit (Scene::fog)
};

// One segment as the frame draws it: its part in front of the eye and near the screen.
struct Strip {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // raster endpoints, pixels (pixel centres at i + ½)
  float dx = 1, dy = 0;                  // the unit direction from end 0 to end 1 (x for a dot)
  float length = 0;                      // pixels
  // Affine along the strip on screen: window depth (biased), 1/w, and the eye-space point over w
  // (the true point, for fog, is their quotient).
  float z0 = 0, z1 = 0, q0 = 1, q1 = 1;
  Vec3 e0, e1;
  Vec3 color;
  float corners[4][2] = {};  // the rectangle, ½ width around the segment and past its ends
  float yMin = 0, yMax = 0;  // the rectangle's rows
};

class LinePass final : public raster::TilePass {
 public:
  void setLines(const LineInput& input);

  raster::PassStage stage() const override { return raster::PassStage::surfaces; }
  void prepare(const raster::PassFrame& frame) override;
  void drawTile(const raster::TileTarget& tile) override;
  void addStats(FrameStats& stats) const override;

 private:
  bool project(const scene::LineSegment& segment, Strip& s) const;
  // Calls f(tile index) for every tile the strip's rectangle reaches.
  template <class F>
  void forTiles(const Strip& s, F&& f) const;
  void drawStrip(const Strip& s, const raster::TileTarget& tile) const;

  LineInput in_;
  raster::PassFrame frame_;
  float offsetX_[64] = {}, offsetY_[64] = {};  // the sample pattern, pixels from the centre
  std::vector<std::vector<Strip>> chunks_;     // the drawn strips, chunk by chunk, in order
  int tilesX_ = 0, tilesY_ = 0;
  size_t tiles_ = 0;
  raster::TileLists<Strip> tileStrips_;      // every tile's strips, in segment order
  std::vector<double> workerMs_;
  double prepareMs_ = 0;
};

}  // namespace sv::lines
