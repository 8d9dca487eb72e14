// Rasterization of set-up triangles into one screen tile by recursive 2×2 subdivision.
//
// Based on: SPEC §3.1–§3.3 (seed 000 eqs. 1–9, seed 004 eqs. 8–14), §3.5 (levels unrolled, the four
// children tested together in SIMD lanes), §4 (Z-buffer).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>

#include "geometry/setup.h"
#include "raster/binner.h"
#include "raster/coverage_masks.h"
#include "raster/occupancy.h"
#include "raster/tile_pass.h"
#include "shade/shading.h"

namespace sv::raster {

// Windows are counted by size: 64, 32, 16, 8, 4 pixels, and 1 (pixel centres tested in leaves).
inline constexpr int kStatLevels = 6;

struct RasterStats {
  uint64_t windows[kStatLevels] = {};  // windows tested per level (each child of a split counts)
  uint64_t fullWindows = 0;            // covered windows filled without further subdivision
  uint64_t occludedWindows = 0;        // windows a triangle was dropped from as occupied (SPEC §4)
  uint64_t occludedTriangles = 0;      // triangles dropped whole in a tile: their box was occupied
  uint64_t occludedObjects = 0;        // objects dropped whole in a tile: their bound was occupied
  uint64_t partialBlocks = 0;          // 4×4 leaves tested pixel by pixel
  uint64_t fragments = 0;              // pixels that passed coverage (some sample, with
                                       // anti-aliasing) and reached the depth test
  uint64_t hiddenFragments = 0;        // … of which the depth test passed none
  uint64_t hybridWoken = 0;            // tile passes in which hybrid masking woke (drawLists)
  uint64_t shadedByList = 0;  // deferred shading passes that read the tile kernel's WinnerList
  uint64_t shadedByScan = 0;  // … that scanned the tile

  void add(const RasterStats& o) {
    for (int i = 0; i < kStatLevels; ++i) windows[i] += o.windows[i];
    fullWindows += o.fullWindows;
    occludedWindows += o.occludedWindows;
    occludedTriangles += o.occludedTriangles;
    occludedObjects += o.occludedObjects;
    partialBlocks += o.partialBlocks;
    fragments += o.fragments;
    hiddenFragments += o.hiddenFragments;
    hybridWoken += o.hybridWoken;
    shadedByList += o.shadedByList;
    shadedByScan += o.shadedByScan;
  }
};

// Hidden-surface removal besides the Z-buffer (SPEC §4): multi-level priority masking, which
// trusts the submission order (nearest first), or its combination with depth, which does not.
enum class Masking : uint8_t { none, priority, hybrid };

// Object-space culling (SPEC §4, seed 004): whether an object bounded by `bound` can show nothing
// in tile (tileX, tileY) — its bound misses the tile, or lies there in windows the occupancy holds
// occupied (priority) or full and nearer than all of it (hybrid).
inline bool objectHidden(const Occupancy& occupancy, const geometry::ObjectBound& bound, int tileX,
                         int tileY, Masking masking) {
  const int x0 = std::max(bound.minX - tileX * kTileSize, 0);
  const int y0 = std::max(bound.minY - tileY * kTileSize, 0);
  const int x1 = std::min(bound.maxX - tileX * kTileSize, kTileSize - 1);
  const int y1 = std::min(bound.maxY - tileY * kTileSize, kTileSize - 1);
  if (x0 > x1 || y0 > y1) return true;
  return masking == Masking::hybrid ? occupancy.rectHidden(x0, y0, x1, y1, bound.zmin)
                                    : occupancy.rectFull(x0, y0, x1, y1);
}
inline constexpr uint32_t kNoObject = ~0u;

// What a covered pixel does.
enum class ShadeMode : uint8_t {
  gouraud,   // depth test "less", perspective-correct Gouraud colour (SPEC §4, §8)
  overdraw,  // no depth test; the red channel counts the triangles covering the pixel
  // Depth test "less"; the red channel records where the winning triangle's subdivision stopped:
  // 1 for a pixel tested in a 4×4 leaf, else log2 of the window it was filled in (2…6).
  levels,
  // Depth test "less"; triangles with an AttributeSetup material are shaded per pixel by
  // shade::shadeFragments (texture, Phong, fog) and written opaque, cut out (alpha mask) or blended
  // over the pixel without writing depth (translucent); the others as `gouraud`.
  material,
};

// Pixel shading's record for one triangle (ShadeMode::material): its attribute planes in
// shade::Attribute order, with the same origin as its TriangleSetup's planes, and its material.
struct alignas(64) AttributeSetup {
  const shade::MaterialShading* material =
      nullptr;  // nullptr: Gouraud colour, as ShadeMode::gouraud
  geometry::Plane planes[shade::kAttributeCount];
  // The record is two cache lines; the first holds the material and the first planes (a
  // textured material's u and v). Whether shading reads the second, by attributesUsed's bits:
  static constexpr size_t kLineBytes = 64;
  static constexpr int kFirstLinePlanes =
      int((kLineBytes - sizeof(void*)) / sizeof(geometry::Plane));
  static bool readsSecondLine(unsigned used) { return (used >> kFirstLinePlanes) != 0; }
};

// One tile's work: triangles in submission order, given as lists of indices into `setups`.
struct TileWork {
  int tileX = 0, tileY = 0;  // tile coordinates (pixel origin = 64·tileX, 64·tileY)
  float* depth = nullptr;    // the tile's buffers, laid out as FrameBuffer describes
  uint16_t* color = nullptr;
  // Colour sums instead of sample planes (FrameBuffer, "colour sums"): anti-aliased priority
  // masking where every triangle is opaque and nothing reads the tile but the resolve, so each
  // sample is written once. The kernel adds coverage × colour per pixel, tests sample depth only
  // against the clear depth, and leaves `depth` and `color` untouched. nullptr: sample planes.
  int32_t* sums = nullptr;
  bool clear = false;  // clear the tile before drawing
  float clearDepth = 1.0f;
  uint16_t clearColor[3] = {0, 0, 0};
  const geometry::TriangleSetup* setups = nullptr;
  const uint32_t* const* lists = nullptr;  // listCount lists, drawn one after the other
  const uint32_t* listSizes = nullptr;
  int listCount = 0;
  ShadeMode shade = ShadeMode::gouraud;
  // Anti-aliasing (SPEC §5): N = coverage->samples samples per pixel, each triangle's sub-pixel
  // mask per pixel from the tables, depth tested per sample, colour shaded once per pixel at its
  // centre. The triangles must be set up with Viewport::pixelAperture and the buffers hold N sample
  // planes (framebuffer.h). nullptr: point sampling at pixel centres. Gouraud only.
  const CoverageTables* coverage = nullptr;
  // ShadeMode::material: setups[i]'s pixel-shading record is attributes[i].
  const AttributeSetup* attributes = nullptr;
  const shade::Environment* environment = nullptr;
  // ShadeMode::material at one sample: kTilePixels entries of scratch, all ~0u on entry and left
  // so (which triangle won each pixel: its shading is deferred until the tile's lists are drawn).
  uint32_t* visible = nullptr;
  // Masking (SPEC §4; not with ShadeMode::overdraw), with the tile's occupancy — emptied with the
  // tile (`clear`) and kept across calls for later batches. `priority`: the lists are in priority
  // order, nearest first, and opaque triangles are dropped from windows nearer ones occupy.
  // `hybrid`: any order; they are dropped from full windows whose depth bound they do not beat,
  // and the image is the Z-buffer's. The depth test stays on either way, so that translucent
  // triangles (drawn after the opaque ones) are hidden behind nearer opaque ones.
  Masking masking = Masking::none;
  Occupancy* occupancy = nullptr;
  // Object-space culling with masking: per list, each entry's object — an index into `objects`,
  // or kNoObject (unbounded, or translucent) — or nullptr for none. An object's run of entries is
  // skipped where objectHidden says so, before any of its records is read.
  const uint32_t* const* listObjects = nullptr;
  const geometry::ObjectBound* objects = nullptr;
  // Priority masking where no triangle is translucent: per list, each entry's bounding box
  // (Binner::Box), or nullptr. A triangle whose box lies in occupied windows is dropped before
  // its records — setup and pixel shading's — are read (in a deep stack of layers, most are).
  const Binner::Box* const* listBoxes = nullptr;
  // The passes that run once the tile's opaque triangles are all drawn (and shaded) — before its
  // first translucent one, or after its last triangle in the frame's last batch — in order, into
  // the tile's buffers as they stand (PassStage surfaces and volumes: free forms, tile_pass.h), on
  // `worker`. `opaqueDone` is set when they have run (kept across batches by the caller).
  std::span<TilePass* const> afterOpaque;
  // Scratch for TileTarget::translucentDepth (the tile's depth planes drawn again with its
  // batch's translucent triangles alone, colour thrown away), laid out as depth and color; or
  // nullptr, when no pass gets it.
  float* translucentDepth = nullptr;
  uint16_t* translucentColor = nullptr;
  int worker = 0;
  uint8_t* opaqueDone = nullptr;
  bool lastBatch = true;
  // After the tile's triangles: its colour replaced by the occupancy view — the red channel 0
  // where nothing is occupied, 1 for an occupied pixel, else log2 of the largest full window.
  bool debugOccupancy = false;
};

// Draws the tile's triangles as `work.shade` says. Runs the best SIMD
// target the CPU has (Highway runtime dispatch, chosen once per call).
void rasterizeTile(const TileWork& work, RasterStats& stats);

}  // namespace sv::raster
