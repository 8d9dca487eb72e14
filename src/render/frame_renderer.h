// One frame from clip-space packets to a filled frame buffer: setup and binning in parallel chunks,
// then the tiles in parallel (SPEC §1 stages 3–4, §3.4, §6).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "core/thread_pool.h"
#include "geometry/setup.h"
#include "raster/binner.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"
#include "synthvis/render.h"

namespace sv::render {

// A run of triangles that share a culling mode and a material.
struct DrawCall {
  uint32_t firstTriangle = 0;
  uint32_t triangleCount = 0;
  geometry::CullMode cull = geometry::CullMode::back;
  // Shaded per pixel (FrameSettings::shade = material) with this material, reading `attributes`;
  // nullptr: the interpolated vertex colour.
  const shade::MaterialShading* material = nullptr;
  // With masking: the object the run draws, bounded on screen (object-space culling, SPEC §4) —
  // its triangles are dropped wherever the bound lies in occupied windows. Unbounded: no test.
  bool bounded = false;
  geometry::ObjectBound bound{};
};

// The plain input of a frame: vertices after the projective transform and triangles indexing them.
struct DrawPackets {
  std::vector<geometry::ClipVertex> vertices;
  // For pixel shading, when some call has a material (else empty): per vertex, the attributes
  // `attributeLayout` stores, attributeLayout.stride floats a vertex — the union of those the
  // calls' materials read (shade::attributesUsed).
  std::vector<float> attributes;
  shade::AttributeLayout attributeLayout;
  std::vector<uint32_t> indices;  // 3 per triangle, each < vertices.size()
  std::vector<DrawCall> calls;    // in submission order
};

// The largest batch a frame uses (FrameSettings::batchTriangles is clamped to it).
inline constexpr uint32_t kMaxBatchTriangles = 1u << 24;

struct FrameSettings {
  int width = 0, height = 0;
  float clearColor[3] = {0, 0, 0};  // linear
  raster::ShadeMode shade = raster::ShadeMode::gouraud;
  const shade::Environment* environment = nullptr;  // lights and fog, for ShadeMode::material
  // Samples per pixel: 1 (point sampling at centres) or 4, 8, 16, 64 (anti-aliasing with sub-pixel
  // masks, SPEC §5; Gouraud only). finishTile then receives `samples` sample planes per block.
  int samples = 1;
  // Called once per tile, on the thread that drew it, right after the tile's last triangle, with
  // the tile's depth and colour (laid out as raster/framebuffer.h describes, `samples` per pixel),
  // or — when colour sums are used (`colorSums`) — its sums instead (then depth and colour hold
  // nothing; otherwise `sums` is nullptr). This is the only way out of the frame: the storage is
  // reused for the next tile as soon as the call returns.
  std::function<void(int tile, const float* depth, const uint16_t* color, const int32_t* sums)>
      finishTile;
  // finishTile can take colour sums (it needs no more than each pixel's mean: a box resolve).
  // They are used when the frame allows — anti-aliased priority masking, every triangle opaque,
  // no afterOpaque pass, no occupancy view (raster::TileWork::sums) — and save writing, clearing
  // and summing N sample planes per pixel.
  bool colorSums = false;
  // Triangles per batch (every batch sets up its triangles, then walks the tiles). Frames of one
  // batch draw each tile in a small per-thread buffer that never leaves the core's cache; frames of
  // several keep a whole-frame buffer between batches. Tests lower it to exercise that path.
  uint32_t batchTriangles = 1u << 18;
  // Masking (raster::TileWork::masking): `priority` takes the packets' triangles in priority order,
  // nearest first.
  raster::Masking masking = raster::Masking::none;
  // The occupancy debug view (raster::TileWork::debugOccupancy).
  bool debugOccupancy = false;
  // Called once per tile, on the thread drawing it, when its opaque triangles are drawn and before
  // its translucent ones (raster::TileWork::afterOpaque), with the tile's depth and colour and the
  // worker's number (0 … threads − 1): the free forms' pass. Empty: none.
  std::function<void(int tile, int worker, float* depth, uint16_t* color)> afterOpaque;
};

class FrameRenderer {
 public:
  explicit FrameRenderer(int threads) : pool_(threads) {}

  // Draws `packets`, handing every finished tile to settings.finishTile; adds to `stats`.
  void render(const DrawPackets& packets, const FrameSettings& settings, FrameStats& stats);

  core::ThreadPool& pool() { return pool_; }

 private:
  core::ThreadPool pool_;
  raster::FrameBuffer fb_;  // the whole frame, in frames of several batches
  raster::Binner binner_;
  struct WorkerScratch {
    std::vector<geometry::TriangleSetup> records;  // one chunk's, in submission order
    raster::Binner::Scratch bins;
    raster::FrameBuffer tile;       // 64×64: the tile being drawn, in frames of one batch
    std::vector<uint32_t> visible;  // 64×64 deferred-shading records (TileWork::visible)
    std::unique_ptr<raster::Occupancy> occupancy;  // the tile's, in frames of one batch
    std::vector<uint32_t> objects;  // with masking: the chunk's records' objects (TileWork)
    std::vector<raster::AttributeSetup> attributes;  // pixel shading: the records', in their order
  };
  std::vector<geometry::ObjectBound> objects_;     // with masking: every draw call's bound
  std::vector<raster::Occupancy> frameOccupancy_;  // every tile's, in frames of several batches
  std::vector<geometry::TriangleSetup> setups_;    // the batch's, grouped by tile within each chunk
  std::vector<raster::AttributeSetup>
      attributes_;                      // ShadeMode::material: setups_[i]'s is attributes_[i]
  std::vector<WorkerScratch> scratch_;  // one per pool worker
  std::vector<raster::RasterStats> tileStats_;
  std::vector<uint8_t> opaqueDone_;  // per tile: FrameSettings::afterOpaque has run
};

}  // namespace sv::render
