// The volume pass's samples, classified and shaded a batch at a time in SIMD lanes (Highway,
// dispatched at run time): the samples of one ray are independent until they are composited, so
// the pass gathers up to kBatch of them (in order) and classifies them together.
//
// Based on: SPEC §11 (classification by the transfer function; the normal from the gradient of
// the value, taken while traversing or precomputed per sample), §12 (trilinear samples, opacity
// corrected for the sample length), §8 (Phong weighting, two-sided for a volume's gradient).
#pragma once

#include <cstdint>

namespace sv::volume {

// One volume as the kernel reads it (VolumePass::Prepared's tables). Positions are in the grid's
// own space; everything is float, each lane's arithmetic in the same order on every target, so a
// sample gets the same bits whichever target runs it and whichever batch it falls in.
struct SampleSource {
  const uint16_t* codes = nullptr;  // nx·ny·nz, x fastest; fewer than 2^30
  int nx = 0, ny = 0, nz = 0;
  float inverseSpacing[3] = {1, 1, 1};
  float spacing[3] = {1, 1, 1};  // the central differences' half-span, own units
  const float* table = nullptr;  // entries × (r, g, b, opacity)
  int entries = 1;
  float codeScale = 1;  // table position of code c: c · codeScale
  // The corrected opacity of a full step, per entry (read linearly like the table); null: the
  // caller corrects every sample itself.
  const float* stepOpacity = nullptr;
  // Per sample 4 bytes (x, y, z gradient direction of ±127, pad); null: central differences of
  // the interpolated value, one sample spacing each way.
  const int8_t* normals = nullptr;
  // The codes with a border of one sample on every side repeating the faces' samples,
  // (nx + 2)·(ny + 2)·(nz + 2): the central differences read the cross of cells about a sample's
  // cell from it (16 gathers for the value and its gradient instead of 28), the border standing
  // for the clamping at the faces. Null (or with normals): the differences are six trilinear
  // reads at the moved points, clamped into the box.
  const uint16_t* padded = nullptr;
  // The same bordered codes a byte each, when every code is below 256 (8-bit data): half the
  // memory, and a row's four codes about the cell in one 32-bit gather (twelve gathers for the
  // value and its gradient). Read instead of `padded` when given — and for the value alone where
  // the volume is unlit; 4 bytes of slack at the end.
  const uint8_t* padded8 = nullptr;
  bool shade = false;
  float toWorld[3][3] = {};  // own → world for gradients: the rows of world → own, transposed
  float toLight[3] = {0, 0, 1};  // world, unit
  float ambient = 0.25f;
  float lightColor[3] = {1, 1, 1};
};

inline constexpr int kBatch = 16;

// Positions in, classification out; the kernel reads and writes whole batches (lanes past
// `count` are computed on copies of valid positions and ignored).
struct SampleBatch {
  alignas(64) float x[kBatch], y[kBatch], z[kBatch];
  alignas(64) float opacity[kBatch];  // the transfer function's, uncorrected
  // Corrected for a full step: from SampleSource::stepOpacity when given, else — where
  // `exponent` is positive — 1 − (1 − opacity)^exponent in the lanes.
  alignas(64) float w[kBatch];
  // A full step's length over the opacity unit, l / unit, for the batch's ray (under a transform
  // that is not a similarity each ray's steps have their own length in the world); 0: none.
  float exponent = 0;
  alignas(64) float r[kBatch], g[kBatch], b[kBatch];  // shaded colour
};

// Classifies and shades samples [0, count) of `batch` (count ≤ kBatch). A sample the transfer
// function makes wholly transparent gets colour (0, 0, 0) (its gradient is not taken where a whole
// vector of samples is transparent).
void classifySamples(const SampleSource& source, int count, SampleBatch& batch);

}  // namespace sv::volume
