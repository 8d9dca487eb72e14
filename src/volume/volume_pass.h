// Voxel volumes in the frame: a tile pass (raster/tile_pass.h, stage `volumes`) that casts a ray
// per pixel through each volume after the opaque surfaces, classifies its samples by the volume's
// transfer function, shades them by the gradient and composites them front to back over what the
// pixel's samples already hold, each ray ending at its sample's depth (an aircraft inside a cloud).
//
// Based on: SPEC §11 (voxel arrays in their own coordinate system; classified while traversing:
// opacity from the value, normal from its gradient), §12 (inner voxels are not discarded: the ray
// continues through the object accumulating colour front to back, P = Σ I_n W_n Π_{m<n} (1 − W_m),
// until the volume is exhausted or the transparency falls below ε; empty regions skipped without
// descending to their samples; opacity corrected for the sample's length), §8 (Phong weighting,
// fog by distance).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/eye_rays.h"
#include "freeform/freeform.h"
#include "raster/tile_pass.h"
#include "synthvis/volumes.h"
#include "volume/sample_kernel.h"

namespace sv::volume {

// What the pass needs of the scene and the view. The volumes must outlive the frame.
struct VolumeInput {
  const std::vector<scene::VolumeObject>* volumes = nullptr;
  scene::VolumeSettings settings;
  EyeRays rays;            // the view's (its raster is set by prepare)
  Mat4 viewProjection;     // world → clip, for the volumes' screen bounds
  bool lightOn = false;    // the scene's directional light, in the world
  Vec3 toLight{0, 0, 1};   // unit, toward the light
  Vec3 lightColor{1, 1, 1};
  float ambient = 0.25f;   // Q_amb (SPEC §8); Q_diff = 1 − Q_amb
  float fogBeta = 0;       // 0: no fog
  Vec3 fogColor{0, 0, 0};
};

// Counts of one frame's casts (FrameStats' volume fields).
struct VolumeCounts {
  uint64_t rays = 0;            // pixels whose ray met a volume's box
  uint64_t samples = 0;         // samples classified
  uint64_t skipped = 0;         // samples stepped over in empty regions
  uint64_t terminated = 0;      // rays ended by their transparency falling below ε
  uint64_t interpolated = 0;    // pixels blended from their window's corner rays, not cast
  uint64_t closedForm = 0;      // samples composited in closed form over a constant brick
  void add(const VolumeCounts& o) {
    rays += o.rays, samples += o.samples, skipped += o.skipped, terminated += o.terminated;
    interpolated += o.interpolated, closedForm += o.closedForm;
  }
};

// A pixel of a tile in the screen-window refinement (VolumeSettings::windowTolerance): whether
// its ray was cast or its composite blended from its window's corners, and what a cast gave.
struct WindowPixel {
  enum State : uint8_t { none, cast, interpolated } state = none;
  bool met = false;       // its ray composited something of a volume
  bool complete = false;  // ... and ended before every one of its samples' surfaces
  bool opaque = false;    // ... and ended by its transparency falling below ε
  // What the cast gave, kept in float (24 bytes a pixel: a tile's 4 096 reset per tile).
  float C[3] = {0, 0, 0}, T = 1;
  float last = 0;  // the end of its last sample composited, as s (eye depth)
};
// A pixel whose ray was split at the nearest translucent surface in front of its samples'
// opaque ones (raster::TileTarget::translucentDepth): the part behind it composited over those
// samples at once, the part before it (C, T) kept here until the tile's translucent polygons are
// drawn, then laid over them (VolumePass::overTranslucent).
struct FrontPixel {
  uint16_t pixel = 0;    // in the tile: y·64 + x
  uint64_t samples = 0;  // the samples split (bit k: sample k)
  float C[3] = {0, 0, 0}, T = 1;
};

// A screen window of the refinement: pixels [x0, x1] × [y0, y1] of a tile, corners included.
struct WindowRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};
// A worker's screen-window refinement: the tile's pixels, the windows still to look at, and the
// leaves (windows whose pixels are blended from their corners).
struct WindowScratch {
  std::vector<WindowPixel> window;
  std::vector<WindowRect> stack, leaves;
};

class VolumePass final : public raster::TilePass {
 public:
  // The frame's volumes; call before prepare. Classification tables and the empty-region map are
  // made once per volume grid and transfer function and kept from frame to frame.
  void setVolumes(const VolumeInput& input);

  raster::PassStage stage() const override { return raster::PassStage::volumes; }
  void prepare(const raster::PassFrame& frame) override;
  void drawTile(const raster::TileTarget& tile) override;
  bool wantsTranslucentDepth(int tileX, int tileY) const override;
  void overTranslucent(const raster::TileTarget& tile) override;
  void addStats(FrameStats& stats) const override;

  // The edge of the cubes of grid cells the empty-region map is made of.
  static constexpr int kBrick = 8;
  // The edge, in pixels, of the screen windows whose rays share their depth interval.
  static constexpr int kWindow = 8;
  // The edge of the largest windows of the screen-window refinement (windowTolerance).
  static constexpr int kRefineWindow = 4;
  // Entries of the transfer function's table over the grid's codes (fewer for 8-bit data: one per
  // code).
  static constexpr int kTableSize = 4096;

  // One volume as the pass casts it.
  struct Prepared {
    const scene::VolumeObject* object = nullptr;
    const scene::VolumeGrid* grid = nullptr;
    // Held while its tables are: a grid freed and another made at its address would otherwise
    // be taken for it.
    std::shared_ptr<const scene::VolumeGrid> held;
    std::vector<scene::TransferPoint> transfer;  // what the tables were made for
    double toOwn[3][4] = {};   // world → the volume's own space (affine rows)
    double extent[3] = {};     // the grid's box in its own space: [0, extent]
    double inverseSpacing[3] = {};
    double stepOwn = 0.5;      // sample step, own units
    double opacityUnit = 1;    // world units
    // The transfer function at table entry e (code e / codeScale): red, green, blue, opacity.
    std::vector<float> table;
    double codeScale = 1;      // table position of code c: c · codeScale
    // Under a transform of uniform scale every full step has the same length in the world, so its
    // corrected opacity 1 − (1 − W)^(l / unit) is tabled per entry (read linearly like the table);
    // empty: not uniform, every sample corrects its own.
    std::vector<float> stepOpacity;
    // VolumeSettings::precomputedNormals: per sample its gradient's direction, 4 bytes (x, y, z,
    // pad) of ±127; empty: the gradient is taken while traversing.
    std::vector<int8_t> normals;
    // Gradients taken while traversing: the codes with a one-sample border (sample_kernel.h),
    // 2 bytes a sample; empty with precomputed normals, unlit, or beyond 2^31 bytes.
    std::vector<uint16_t> padded;
    // The same a byte a sample, instead, where every code fits — lit or not (the value's reads
    // too); empty with precomputed normals.
    std::vector<uint8_t> padded8;
    // The free-form shell (VolumeObject::freeFormShell) carried into the view's cube (SPEC §12)
    // this frame: the rays' pieces inside it from the free forms' caster. Unset: none, or its
    // placement singular (then the volume shows nothing).
    std::optional<freeform::ProjectedFreeForm> shellForm;
    int bricks[3] = {};
    std::vector<uint8_t> emptyBrick;  // per brick (x fastest): every sample it holds transparent
    // Per brick: not empty, and every code within two samples of it the same (its samples'
    // trilinear values and their gradients' reads): composited in closed form.
    std::vector<uint8_t> constantBrick;
    std::vector<uint32_t> contentBricks;  // the bricks not wholly transparent, by index
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the pixels its box may cover this frame, [x0, x1)
    // SPEC §12's screen subdivision at one level: per window of kWindow² pixels this frame, the
    // eye depths [near, far] between which its rays can meet a brick with content (its bricks'
    // corners projected): a ray starts and ends there, and a window no such brick covers casts
    // none. Empty: not known this frame (a brick reaches behind the eye, or skipping is off).
    std::vector<float> windowNear, windowFar;
    int windowsX = 0;
    SampleSource source;  // the above as the sample kernel reads it (set by prepare)
  };

 private:
  struct alignas(64) WorkerCounts {
    VolumeCounts counts;
    double ms = 0;  // the worker's time in the pass's tiles
  };
  void drawVolumes(const raster::TileTarget& tile);
  void prepareTables(Prepared& p) const;
  void screenBounds(Prepared& p) const;
  void windowDepths(Prepared& p) const;

  VolumeInput input_;
  std::vector<Prepared> volumes_;
  int samples_ = 1;
  std::vector<WorkerCounts> counts_;
  struct WorkerBatch {
    SampleBatch batch;
    freeform::RayFunction shellRay, castRay;  // a free-form shell's, along a pixel's ray
  };
  std::vector<WorkerBatch> batches_;  // per worker: its ray's samples waiting to be classified
  std::vector<WindowScratch> windows_;  // per worker
  std::vector<std::vector<FrontPixel>> fronts_;  // per tile (y·tiles across + x): its split pixels
  int tilesX_ = 0;
};

}  // namespace sv::volume
