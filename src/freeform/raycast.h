// Multi-level ray casting of free forms (SPEC §12), and the fixed-step ray marcher it is measured
// against.
//
// Based on: SPEC §12 (seed 003: a quadtree over the screen whose leaves are roots of binary trees
// in depth, cells rejected by conservative bounds, multi-level masking front to back); libfive's
// interval subdivision renderer (Keeter 2020) for the shape of the recursion.
//
// Everything happens in the cube [−1, 1]³ the view volume is mapped onto (ProjectedFreeForm): x to
// the right, y up, z from the near plane (−1) to the far one (+1). Pixel (px, py) of a W × H raster
// is the ray x = 2(px + ½)/W − 1, y = 1 − 2(py + ½)/H — the centre sampling of the polygon path —
// and cube depth z is window depth (z + 1)/2, the depth the polygon path stores, so both share one
// depth buffer.
#pragma once

#include <cstdint>
#include <vector>

#include "freeform/freeform.h"

namespace sv::freeform {

inline constexpr uint32_t kNoHit = ~0u;

// The cube coordinates of the ray of pixel column px / row py, moved by a sample offset d
// (pixels; 0: the centre) — the mapping above.
inline double cubeX(int px, int width, double d) { return 2.0 * (px + 0.5 + d) / width - 1; }
inline double cubeY(int py, int height, double d) { return 1 - 2.0 * (py + 0.5 + d) / height; }

// A square window of the raster and its buffers: pixels [x0, x0 + size) × [y0, y0 + size) (clipped
// to the raster), size a power of two up to 64; per pixel, at index (py − y0)·stride + (px − x0):
// window depth (read: a hit must be nearer; written on a hit), the object hit and its exact cube z.
struct CastWindow {
  int width = 0, height = 0;  // the raster
  int x0 = 0, y0 = 0, size = 0;
  float* depth = nullptr;
  uint32_t* object = nullptr;
  double* cubeZ = nullptr;
  // If given, per pixel (same indexing): on a hit, the form's perturbations that may be positive
  // in the ray window it came from (ProjectedFreeForm::bound's `active`) — the others are 0 at
  // the hit, and its shading leaves them out.
  uint64_t* active = nullptr;
  int stride = 0;
  // The rays leave every pixel at this offset from its centre, in pixels: a sample of the
  // anti-aliasing pattern (SPEC §5), or 0 for point sampling.
  double offsetX = 0, offsetY = 0;
};

struct CastStats {
  uint64_t cells = 0;        // screen windows bounded (every level)
  uint64_t maskedCells = 0;  // of those, skipped as hidden behind nearer depths (masking)
  uint64_t depthTests = 0;   // interval bounds evaluated in all
  uint64_t pixels = 0;       // pixel rays solved
  uint64_t hits = 0;         // pixels that took a new nearest surface
  void add(const CastStats& o) {
    cells += o.cells, maskedCells += o.maskedCells, depthTests += o.depthTests;
    pixels += o.pixels, hits += o.hits;
  }
};

struct CastSettings {
  // Masking (SPEC §12 "multi-level masking"): windows whose every pixel already holds a surface
  // nearer than the cell are skipped at every level. Off: every cell is refined (the image is the
  // same; tests compare).
  bool masking = true;
  // With several samples per pixel (FreeFormPass): cast the pixel centres, and every sample only
  // in pixels whose 3×3 neighbourhood of centres does not see one and the same form (silhouettes,
  // forms crossing) or whose polygon samples lie within the form's depth range over the pixel
  // (intersection curves); elsewhere the centre's hit stands for all samples. Off: every sample
  // is a ray (exact for features thinner than a pixel, which centres can miss).
  bool adaptiveSamples = true;
};

// The masking pyramid of a window (SPEC §12, multi-level masking): per square of every level,
// the largest depth its pixels hold. Built from the window's depths; castWindow keeps it up to
// date as its hits lower them, so the forms cast one after another into a window share one
// (nothing else may write the window's depths meanwhile).
class MaskingPyramid {
 public:
  explicit MaskingPyramid(const CastWindow& window);
  int top() const { return top_; }    // the level of the whole window: size = 2^top
  int size() const { return size_; }  // its pixels per row, level 0's nodes per row
  float& node(int level, int x, int y) {
    return nodes_[offset_[size_t(level)] + size_t(y * (size_ >> level) + x)];
  }
  // Recomputes the nodes above the square of 2^level pixels at (lx, ly): every node of it at
  // the levels up to its own, then its single ancestor at each level above.
  void refreshAbove(int level, int lx, int ly);

 private:
  void update(int level, int x, int y);
  int size_ = 0, top_ = 0;
  std::vector<float> nodes_;  // level by level: [offset_[level] + y · (size >> level) + x]
  std::vector<size_t> offset_;
};

// Casts `form` (number `id`) into the window: every pixel whose ray meets the surface at a window
// depth below the one it holds takes the first such hit (the first zero of H along the ray in
// [−1, 1], found to double precision once bracketed). `pyramid`: the window's, shared with the
// forms cast into it before (nullptr: one is built for this call). `active` (if given): the
// form's perturbations that may be positive anywhere in the window (ProjectedFreeForm::bound) —
// the others are 0 at all its hits. Adds to `stats`.
void castWindow(const ProjectedFreeForm& form, uint32_t id, const CastWindow& window,
                const CastSettings& settings, CastStats& stats, MaskingPyramid* pyramid = nullptr,
                uint64_t* active = nullptr);

// One ray of the cube (x, y): the first crossing of `form` beyond cube depth `from` and nearer
// than `depth` (window depth) takes `depth`, `object` (= id) and `cubeZ`. `from`: where the form's
// bounds allow it to begin (−1: the near plane). `hint`: a cube depth near which a crossing is
// likely (a neighbouring ray's), or NaN. `ray` is scratch, reused from call to call.
void castRay(const ProjectedFreeForm& form, uint32_t id, double x, double y, double from,
             double hint, float& depth, uint32_t& object, double& cubeZ, RayFunction& ray,
             CastStats& stats);

// The baseline (issue 7): every pixel of the window marched front to back in `steps` equal steps
// of eye depth from the near plane to the far one (equal steps of cube depth would crowd near the
// eye), the first sign change refined as castWindow refines its brackets.
void marchWindow(const ProjectedFreeForm& form, uint32_t id, const CastWindow& window, int steps,
                 CastStats& stats);

}  // namespace sv::freeform
