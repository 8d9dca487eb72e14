// The per-pixel work before shading a terrain's hits, 16 pixels at a time in SIMD lanes (Highway,
// per target, float): the normal of the surface met, the hit in eye space, and the draped image's
// texture coordinates and level of detail from the pixel's footprint (SPEC §7) — what
// TerrainPass::shadeHits does per pixel, for the plane base: the normal of a bilinear surface (a
// mean level, or the table's bilinear interpolation) from its cell's corners, of the table's
// Catmull–Rom surface from the 4×4 samples around the cell. The lanes are independent, and only Add, Mul, Div and
// Sqrt are used (no fused multiply-add, no library functions), so every target gives the same
// bits.
//
// Based on: SPEC §7 (seed 001's planar texture, the footprint's level of detail), §8 (Phong's
// normal), §11 (bilinear interpolation).
#pragma once

#include "shade/shading.h"

namespace sv::terrain {

// What is constant over a frame and a terrain.
struct ShadeFrame {
  // The ray through raster point (px, py): d0 + dX·px + dY·py (EyeRays::direction, linear).
  float d0[3], dX[3], dY[3];
  float right[3], up[3], forward[3];  // the eye space's axes (forward = −z)
  // Map metres east and north of a grid step: spacingU, spacingV; heights: scale (metres a code).
  float spacingU = 1, spacingV = 1, scale = 1;
  // The draped image: texel x = gx·texX + texX0, y = gy·texY + texY0 (level 0, texel centres at
  // +½), and its texels per map metre east and north (the footprint's scale).
  bool image = false, levelZero = false;
  float texX = 0, texX0 = 0, texY = 0, texY0 = 0, perMetreX = 1, perMetreY = 1;
};

// The pixels: their inputs (made per pixel by shadeHits: the hit's grid position clamped to the
// table, and the four samples of the cell of the surface met around it) and results.
struct ShadeLanes {
  alignas(64) float px[shade::kMaxFragments], py[shade::kMaxFragments];  // the sample's ray
  alignas(64) float s[shade::kMaxFragments];                             // the hit's depth
  alignas(64) float gx[shade::kMaxFragments], gy[shade::kMaxFragments];  // grid, clamped
  // The cell of the level met: the position in it (0 … 1), its corners' codes and its size in
  // grid steps.
  alignas(64) float cellU[shade::kMaxFragments], cellV[shade::kMaxFragments];
  alignas(64) float h00[shade::kMaxFragments], h10[shade::kMaxFragments];
  alignas(64) float h01[shade::kMaxFragments], h11[shade::kMaxFragments];
  alignas(64) float step[shade::kMaxFragments];
  // Where `bicubic` is set, the pixels whose `cubic` is 1 met the table's Catmull–Rom surface:
  // the 4×4 codes around their cell (cellSamples, patch[4·y + x]) instead of its corners.
  bool bicubic = false;
  alignas(64) float cubic[shade::kMaxFragments];
  alignas(64) float patch[16][shade::kMaxFragments];
};

// Fills the eye position and normal attributes of `frag` (its count lanes) and, with an image,
// `tc`'s coordinates and levels of detail.
void shadeLanes(const ShadeFrame& frame, const ShadeLanes& lanes, shade::Fragments& frag,
                shade::TexCoords& tc);

}  // namespace sv::terrain
