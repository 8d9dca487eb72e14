// A pass of the frame over each tile's shared buffers (docs/ARCHITECTURE.md, "Passes").
//
// A tile's work is an ordered list of passes over the same depth and colour samples: the opaque
// polygons (the tile kernel's own), then the ray-cast surfaces (free forms, terrain), then
// volumes, then the translucent polygons (the kernel again), then light points. Every primitive
// besides polygons is one TilePass; render composes the frame's list, and the tile kernel and the
// frame runner call each pass where its stage says, knowing nothing else of it.
#pragma once

#include <cstdint>

#include "core/thread_pool.h"
#include "raster/coverage_masks.h"
#include "synthvis/frame_stats.h"
#include "synthvis/result.h"
#include "synthvis/tile_share.h"

namespace sv::raster {

// Where a pass runs in a tile's order. Passes of one stage run in the order the list gives them.
enum class PassStage : uint8_t {
  surfaces,  // after the opaque polygons: opaque surfaces ray cast into the depth (free forms)
  volumes,   // after the surfaces, before the translucent polygons: composited front to back
  lights,    // last, once the other passes of the tile and the eight around it are done
};

// What every pass learns of the frame before its tiles are drawn.
struct PassFrame {
  int width = 0, height = 0;  // the raster, pixels (64 × 64 tiles; the last row and column partial)
  int samples = 1;            // per pixel
  const CoverageTables* coverage = nullptr;  // with samples > 1: their positions (pattern)
  core::ThreadPool* pool = nullptr;          // the frame's workers; prepare may use them
  // In a shared frame, for passes of stage `lights`: the whole frame's buffer, its drawn tiles'
  // depth final when exchange is called (what the pass reads of them to exchange). Else nullptr.
  const class FrameBuffer* frame = nullptr;
  // A frame shared by several processes (synthvis/tile_share.h): drawTile is called for this
  // part's tiles only, and the others' samples are never drawn here.
  TileShare share = {};
};

// One tile's shared buffers, as raster/framebuffer.h lays them out: `samples` depth and colour
// planes per 4×4 block. `worker` (0 … pool threads − 1) names the calling thread, for scratch
// memory; no two calls with the same worker run at once.
struct TileTarget {
  int tileX = 0, tileY = 0;  // the tile's pixel origin is (64·tileX, 64·tileY)
  float* depth = nullptr;
  uint16_t* color = nullptr;
  int worker = 0;
  // For passes run before the tile's first translucent polygon, where one asked for it
  // (TilePass::wantsTranslucentDepth): per sample, laid out as `depth`, the nearest translucent
  // surface the tile's batch will blend in front of its opaque one — or that one's depth where
  // none will (a sample has a translucent surface iff translucentDepth < depth). Else nullptr.
  const float* translucentDepth = nullptr;
};

// The contract (docs/ARCHITECTURE.md): a pass may read and write the tile's depth and colour
// samples — and nothing else of the frame — through `drawTile` (a pass of stage lights may also
// keep what it reads of a tile's depth in `seeTile`, for the tiles around it); it leaves depth as the nearest
// surface drawn so far for every sample it writes (passes after it test against it), colour in
// linear 16-bit light, and samples it does not touch as it found them. The tile's occupancy
// (masking) is the polygons' alone: a pass does not read it. Output is the same for any thread
// count: what a tile gets depends on the tile, never on the worker.
class TilePass {
 public:
  virtual ~TilePass() = default;

  virtual PassStage stage() const = 0;
  // Once per frame, before any tile, on the frame's thread (may run work on frame.pool).
  virtual void prepare(const PassFrame& frame) = 0;
  // In a shared frame, for passes of stage lights: once this part's tiles are drawn, before
  // drawTile — where a pass that reads beyond its tile fetches what the other parts drew
  // (PassFrame::share's exchange). Every part calls it for the same passes in the same order.
  virtual Status exchange() { return {}; }
  // For passes of stage lights, whose work in a tile reads the depth of the tiles around it (a
  // light's splat reaches up to 33 px from its centre pixel, whose depth and its neighbours'
  // decide whether it is seen): once per tile and frame, on `tile.worker`, when the tile's depth
  // is final — its other passes done — and before drawTile of it or of any of the eight around
  // it. The pass keeps what it needs of the depth: it may be gone by drawTile (tile.depth then
  // nullptr). drawTile of a tile follows seeTile of every tile around it.
  virtual void seeTile(const TileTarget& /*tile*/) {}
  // Draws the pass into one tile, once per tile and frame, on worker `tile.worker`.
  virtual void drawTile(const TileTarget& tile) = 0;
  // For passes of stage surfaces and volumes: whether drawTile of tile (tileX, tileY) wants
  // TileTarget::translucentDepth — a pass that composites without occluding (volumes) splits its
  // work there, so that translucent polygons take their place in depth among its samples.
  virtual bool wantsTranslucentDepth(int /*tileX*/, int /*tileY*/) const { return false; }
  // For passes of stage surfaces and volumes: once the tile's translucent polygons are all drawn
  // (its last batch), on a worker of its own (its scratch), before the passes of stage lights —
  // where a pass lays what it kept back in front of the translucent surfaces over them.
  virtual void overTranslucent(const TileTarget& /*tile*/) {}
  // Once per frame, after every tile: adds what the pass did to the frame's statistics.
  virtual void addStats(FrameStats& stats) const = 0;
};

}  // namespace sv::raster
