// What one frame did: the counts every stage and pass adds to, and its timings. A plain record
// (public API): the renderer fills it, each tile pass adds its own counts (raster/tile_pass.h).
#pragma once

#include <cstdint>
#include <string>

namespace sv {

// What one frame did. Window counts are per quadtree level (64 … 4 pixels, then pixel tests).
struct FrameStats {
  uint64_t trianglesIn = 0;
  uint64_t culledFacing = 0, culledOutside = 0, culledDegenerate = 0, culledInvalid = 0;
  // With masking, in frames of several batches: triangles of objects whose bound lay in windows
  // earlier batches occupied, dropped before setup (object-space culling, SPEC §4).
  uint64_t culledOccluded = 0;
  uint64_t drawn = 0;
  // Instances dropped whole before the vertex stage (RenderOptions::cullInstances); their
  // triangles count in trianglesIn and culledOutside.
  uint64_t culledInstances = 0;
  // Levels of detail (Scene::lodGroups): instances of a group drawn at each level (a dissolving
  // instance counts at both of its levels), those dissolving between two, and those beyond their
  // last level's range (drawn at none; their full-detail triangles count in trianglesIn and
  // culledOutside).
  static constexpr int kLodLevels = 8;
  uint64_t lodDrawn[kLodLevels] = {};
  uint64_t lodDissolving = 0, lodBeyond = 0;
  // Merged cells drawn in place of their members (RenderOptions::mergeCells), and those members
  // (counted in lodDrawn at the cell's level).
  uint64_t mergedCells = 0, mergedInstances = 0;
  uint64_t windows[6] = {};
  uint64_t fullWindows = 0, partialBlocks = 0, fragments = 0;
  uint64_t hiddenFragments = 0;  // fragments of which the depth test passed no sample
  // Hybrid masking: tile passes (a tile per batch) in which it woke — a tile starts as the plain
  // Z-buffer and masks once the depth test has hidden enough (docs/hidden-surfaces.md).
  uint64_t hybridWoken = 0;
  // Deferred pixel shading's passes (one a tile per batch, and one before each translucent
  // triangle): those that found each triangle's pixels from a list of the triangles that won
  // pixels, each with its box, and those that scanned the whole tile (many or large triangles,
  // whose boxes hold more blocks than the scan reads; docs/performance.md).
  uint64_t shadedByList = 0, shadedByScan = 0;
  uint64_t occludedWindows = 0;    // windows triangles were dropped from as occupied (priority)
  uint64_t occludedTriangles = 0;  // triangles dropped whole from a tile (their box occupied)
  uint64_t occludedObjects = 0;    // objects dropped whole from a tile (their bound occupied)
  // Free forms (SPEC §12): objects, screen cells bounded, cells skipped by masking, interval
  // bounds evaluated, pixel (sample) rays solved, and those that took a surface.
  uint64_t freeForms = 0, freeFormCells = 0, freeFormMaskedCells = 0, freeFormBounds = 0,
           freeFormRays = 0, freeFormHits = 0;
  // Terrain (SPEC §11–§12): height fields drawn, screen windows marched in depth, depth steps
  // bounded by the pyramids, the sample rays cast (each once), of them those walked in packets (a
  // 4×4 block's together), rays cast alone (where packets do not apply, and those a packet did
  // not finish), and those that met the ground; the grounds' memory (heights and pyramids) and
  // the time their loading took (once, when the scene was read).
  uint64_t terrains = 0, terrainWindows = 0, terrainSteps = 0, terrainSampleRays = 0,
           terrainPacketRays = 0, terrainRays = 0, terrainHits = 0;
  uint64_t terrainBytes = 0;
  double terrainLoadMs = 0;
  // The terrain pass's time: its tiles' CPU time over the frame's workers (its share of the
  // frame's wall time, the tiles being shared out evenly) — what the IG's governor predicts the
  // terrain's cost from (docs/ig.md).
  double terrainMs = 0;
  // Light points (SPEC §13): lights and stars considered, those drawn (lit, in front of the eye,
  // on screen, bright enough), and the light pass's time (its per-frame preparation plus the
  // busiest worker's tile work).
  uint64_t lightPoints = 0, lightsDrawn = 0;
  double lightsMs = 0;
  // Lines (synthvis/lines.h): segments considered, those drawn (some part in front of the eye,
  // within the far plane and near the screen), and the line pass's time (its preparation plus the
  // busiest worker's tile work).
  uint64_t lines = 0, linesDrawn = 0;
  // The segment pipeline (SPEC §10, RenderOptions::Pipeline::segments): segments sorted, and RUN
  // codes read (a run per change of the visible segment along a line), and lines the overload
  // protection repeated instead of drawing (RenderOptions::SegmentChannel).
  uint64_t segments = 0, segmentRuns = 0, repeatedLines = 0;
  // A channel shared by several processes (synthvis/tile_share.h): the bytes this process sent
  // or received for it (its tiles to part 0, the light points' depth probes), and the time that
  // took, waiting for the other parts included.
  uint64_t shareBytes = 0;
  double shareMs = 0;
  double linesMs = 0;
  // Volumes (the volume pass): volumes in the frame, pixels whose ray met one, samples classified,
  // samples stepped over in empty regions, and rays ended by their transparency (early ray
  // termination); the pass's time as terrainMs is the terrain's (its tiles' CPU time over the
  // frame's workers).
  uint64_t volumes = 0, volumeRays = 0, volumeSamples = 0, volumeSkipped = 0, volumeTerminated = 0;
  uint64_t volumeInterpolated = 0;  // pixels blended from their screen window's corner rays
  uint64_t volumeClosedForm = 0;    // samples composited in closed form (constant bricks)
  double volumeMs = 0;
  // rasterMs: the tile pass, which includes resolving each finished tile into the image.
  double vertexMs = 0, setupMs = 0, rasterMs = 0, totalMs = 0;

  uint64_t culled() const {
    return culledFacing + culledOutside + culledDegenerate + culledInvalid + culledOccluded;
  }
  // Adds another view's counts and times to this one's (the views of one frame: a display's
  // sub-frustum cells); the grounds' memory and load time, the scene's in every view, are the
  // larger of the two.
  FrameStats& operator+=(const FrameStats& o);
  // One line: triangles in / culled / drawn, windows per level, milliseconds.
  std::string summary() const;
  std::string lodSummary() const;  // the summary's levels-of-detail part ("" without any)
};

}  // namespace sv
