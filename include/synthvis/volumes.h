// Voxel volumes (the volume pass, src/volume): plain records (public API), shared by the scene
// (which holds them) and the pass (which draws them); docs/scene-format.md, "Volumes", says how.
//
// Based on: SPEC §11 (voxel arrays are 3D textures in their own coordinate system, classified by a
// transfer function), §12 (ray cast front to back, composited, opacity corrected for the sample
// length).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "synthvis/free_forms.h"
#include "synthvis/math.h"

namespace sv::scene {

// Most samples one volume may hold (2 GiB of 16-bit codes); loaders refuse more before allocating.
inline constexpr size_t kMaxVolumeSamples = size_t(1) << 30;
inline constexpr int kMaxVolumeSide = 8192;  // samples along one axis

// A 3D grid of samples: sample (i, j, k) lies at (i·spacing.x, j·spacing.y, k·spacing.z) in the
// volume's own space, values in between are trilinear. Stored as 16-bit codes, x fastest: the
// value of code c is offset + scale·c — exact for 8- and 16-bit data; float data is quantized to
// 65 536 steps over its range.
struct VolumeGrid {
  int nx = 0, ny = 0, nz = 0;  // each ≥ 2
  std::vector<uint16_t> codes;  // nx·ny·nz
  float offset = 0, scale = 1;  // scale > 0
  Vec3 spacing{1, 1, 1};        // > 0

  size_t at(int i, int j, int k) const { return (size_t(k) * size_t(ny) + size_t(j)) * size_t(nx) + size_t(i); }
  float value(uint16_t code) const { return offset + scale * float(code); }
  // The box the samples span in the volume's own space: [0, (n − 1)·spacing].
  Vec3 extent() const {
    return {float(nx - 1) * spacing.x, float(ny - 1) * spacing.y, float(nz - 1) * spacing.z};
  }
};

// One point of a transfer function: at `value`, colour (linear RGB) and opacity — the share of
// light a slab `VolumeObject::opacityUnit` thick absorbs, in [0, 1]. Between points, linear;
// below the first and above the last, the end points'.
struct TransferPoint {
  float value = 0;
  Vec3 color{1, 1, 1};
  float opacity = 0;
};

// How volumes are cast (docs/scene-format.md, "Volumes").
struct VolumeSettings {
  // The samples along a ray, in voxels of the grid's smallest spacing (0.05 … 8).
  float step = 0.5f;
  // A ray stops once its transparency Π(1 − W) falls below this (0: never; early ray termination).
  float termination = 1.0f / 512;
  // Regions of the grid whose values the transfer function makes wholly transparent are stepped
  // over (empty-space skipping); false: every sample is taken (the reference).
  bool skipEmpty = true;
  // SPEC §11's two ways to light a sample: false, the gradient of the interpolated value taken
  // while traversing (six more reads a lit sample); true, each grid sample's gradient direction
  // precomputed once (4 bytes a sample) and interpolated — faster, more memory, a little softer.
  bool precomputedNormals = false;
  // SPEC §12's screen subdivision taken to the pixel: a window's corner rays are cast first, and
  // where no two of them differ by more than this in colour or transparency (and every corner's
  // composite ended before its surfaces) the pixels within are interpolated from them; elsewhere
  // the window is split in four, down to single pixels. 0: every pixel's ray cast.
  float windowTolerance = 0;
  // A brick whose samples, and those about it its gradients read, hold one code is composited in
  // closed form over its length (Beer–Lambert: 1 − (1 − w)^n, fog a geometric series) instead
  // of sample by sample — the same result up to rounding; false: every sample taken.
  bool closedForm = true;
};

// A volume placed in the world.
struct VolumeObject {
  std::string name;
  std::shared_ptr<const VolumeGrid> grid;
  Mat4 transform;  // the volume's own space → world (invertible, affine)
  std::vector<TransferPoint> transfer;  // 1 … 256 points, values increasing
  // The thickness, in world units, at which a sample's opacity is the transfer function's; a
  // sample step of length l has opacity 1 − (1 − W)^(l / opacityUnit). 0: the grid's smallest
  // spacing in the world.
  float opacityUnit = 0;
  // Lit by the scene's light (Phong of the value's gradient), or the transfer function's colour
  // as it is.
  bool shaded = true;
  // A bounding shell (SPEC §11–§12: a free form bounding the volume, so that rays start where it
  // begins rather than at the box): quadrics in the volume's own space, A … K as FreeFormNode's,
  // whose common inside (F ≥ 0) holds every sample the transfer function does not make
  // transparent. Rays are cast only within it, on the same sample lattice, so a true shell changes
  // no pixel. Empty: the box alone.
  std::vector<std::array<double, 10>> shell;
  // A free-form shell (seed 003 places volumes inside free forms): a perturbed quadric (R = w·Q³)
  // with clips, in the volume's own space. It clips the volume: each ray is cast only within the
  // pieces of it inside the form — entry and exit from the free forms' caster, the sample
  // segments cut there. Unset: none.
  std::optional<FreeFormNode> freeFormShell;
};

}  // namespace sv::scene
