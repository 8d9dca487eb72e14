// Curved-screen displays (SPEC §9, §12's distortion correction; docs/display.md): projectors on a
// curved screen, each pixel showing its own direction from the design eye, drawn pre-distorted and
// edge-blended by Renderer::renderDisplay, as display channels are by Renderer::renderChannels.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "synthvis/result.h"

namespace sv {

namespace render {
struct DisplaySetup;  // src/render/correction.h: the projectors' direction tables and blends
}

// A display: its projectors, each with a name, a size in pixels, the direction each of its pixels
// shows (its display mapping) and, where the projectors overlap, its blend weights. Immutable and
// cheap to copy (copies share the tables).
class Display {
 public:
  // Issue 34's demo rig: three projectors of `width` × `height` on a cylinder, overlapping by
  // `overlapDegrees`, with their exact directions and alpha maps (docs/display.md).
  static Display cylinder(int width, int height, double overlapDegrees = 10);
  // An MPCDI file's regions (the 3d profile: each region's frustum and warp give its directions,
  // its alpha and beta maps its blend), named by their ids. Errors name the file and the problem.
  static Result<Display> readMpcdi(const std::string& path);
  // The rig as an MPCDI file (3d profile, level 2: a region per projector, its frustum the
  // projector's covering flat view, a warp per pixel, its alpha map). Only an analytic rig
  // (cylinder) can be written; an error says so for a display read from a file.
  Status writeMpcdi(const std::string& path) const;

  int projectorCount() const;
  const std::string& projectorName(int projector) const;
  int projectorWidth(int projector) const;
  int projectorHeight(int projector) const;
  // Whether the screen's geometry is known (an analytic rig): what Renderer::viewerImage and a
  // moved eye's refitted correction (DisplayView::eyeOffset) need.
  bool hasGeometry() const;
  // The display at 1/r of its projectors' resolution, each ⌈w/r⌉ × ⌈h/r⌉ pixels: the same screen,
  // lenses and blend (an image generator's half-resolution quality level, each pixel shown r × r
  // times). r ≥ 1.
  Display scaled(int r) const;

  const render::DisplaySetup& setup() const { return *setup_; }  // the renderer's view of it

 private:
  explicit Display(std::shared_ptr<const render::DisplaySetup> setup);
  std::shared_ptr<const render::DisplaySetup> setup_;
};

// What Renderer::renderDisplay draws a frame for.
struct DisplayView {
  // The eye moved from the display's design eye, metres in the camera's eye frame (x right, y up,
  // z back): head tracking, or a design eye the host moves. A display whose screen is known
  // (hasGeometry) refits its sub-frusta's maps for the moved eye whenever it moves (about 1.5 ms
  // for a 1920×1080 projector, docs/display.md); one read from a file keeps its design eye's
  // correction and moves the viewpoint alone. Finite.
  float eyeOffset[3] = {0, 0, 0};
  // Only these projectors, by index (an image generator's share of them under MPI); the others'
  // images are left as they were. Empty: every one.
  std::vector<int> projectors;
  // The frames kept in linear light for Renderer::viewerImage. False (an image generator's
  // frames): each projector's cells resolve through the gamma table straight into its image,
  // blended as they are drawn — the frame's fastest path — and viewerImage refuses the frame.
  bool keepLinear = true;
};

// How a projector's frame was made (Renderer::renderDisplay), in milliseconds and counts.
struct DisplayStats {
  // Sub-frusta (RenderOptions::Correction::subFrusta): the plan, made from the display mapping
  // (once per frame today), its cells and the largest residual of their projective maps.
  double planMs = 0;
  // For an eye moved from the design eye (DisplayView::eyeOffset, a display whose screen is
  // known): the maps refitted for it — 0 ms when the eye has not moved since the last frame — and
  // the cells that had to be planned again from their pixels.
  double refitMs = 0;
  int replannedCells = 0;
  int cells = 0;
  double maxResidualPixels = 0;
  // Resampling (bilinear, bicubic): the warp (once per frame today), the flat view's size, the
  // resampling, and the valid pixels the flat view missed (black).
  double warpMs = 0;
  int flatWidth = 0, flatHeight = 0;
  double resampleMs = 0;
  int64_t outside = 0;
  double renderMs = 0;  // the cells, or the flat view
  double blendMs = 0;
};

}  // namespace sv
