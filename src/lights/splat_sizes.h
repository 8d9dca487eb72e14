// Light points' splats sized and weighed 16 at a time in SIMD lanes (Highway, dispatched per
// call): the clamped size from the on-screen energy, the culling of dark and off-screen ones, the
// kernel's axis weights and their sum, the colour scaled so that the weights carry the energy, and
// the depth at the depth bias in front of the light — light_laws.h's laws, the same bits as one
// light at a time (sizeSplat below, the reference every target is tested against).
//
// Based on: SPEC §13 (tiny, bright, anti-aliased light points of conserved energy), docs/lights.md.
#pragma once

#include <cstdint>

#include "synthvis/math.h"

namespace sv::lights {

// What sizing reads of the frame and the scene's light settings.
struct SizeLaws {
  float minSize = 1.5f, maxSize = 8;  // LightSettings: the diameters' clamp, pixels
  float width = 0, height = 0;        // the raster, pixels
  float depthBias = 0;                // LightSettings::depthBias
  float m22 = 0, m32 = 1;             // the projection's depth row (window depth of an eye depth)
};

// Up to kLights lights, structure of arrays: positions, energy and colour in; the splat out.
struct SizeBatch {
  static constexpr int kLights = 16;
  // In: raster position (pixels), on-screen energy Φ, colour, eye depth (0: a star).
  alignas(64) float x[kLights], y[kLights], energy[kLights];
  alignas(64) float r[kLights], g[kLights], b[kLights], eyeDepth[kLights];
  // Out: drawn (1) or culled (0) — dark, or wholly off the raster — and for the drawn ones their
  // kernel radius, a weight-1 pixel's 16-bit additions, the window depth depthBias in front, the
  // kernel's first pixel centre and span per axis, and the first four axis weights kept for
  // drawing (where both spans are at most four; else 0).
  alignas(64) int32_t drawn[kLights];
  alignas(64) float radius[kLights], red[kLights], green[kLights], blue[kLights];
  alignas(64) float frontDepth[kLights];
  alignas(64) int32_t firstX[kLights], firstY[kLights], spanX[kLights], spanY[kLights];
  alignas(64) float kx[4][kLights], ky[4][kLights];
};

// Sizes lights [0, count) of `batch` (count ≤ kLights; lanes past it are computed on copies of
// the first and ignored).
void sizeSplats(const SizeLaws& laws, int count, SizeBatch& batch);

// One light as sizeSplats sizes lane i: the reference (tests compare every target with it).
// Returns whether it is drawn; fills the outputs of lane i.
bool sizeSplat(const SizeLaws& laws, SizeBatch& batch, int i);

}  // namespace sv::lights
