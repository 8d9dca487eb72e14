// The traversal stage (SPEC §1 stage 2): which instances a view draws, and at which level of
// detail — the instance tree culled against the view volume, levels chosen by range with
// screen-door dissolves across each switch — before any vertex is transformed. Between the
// database and the vertex stage: it reads the scene, and the renderer calls it once a view
// (render/draw_packets.cpp); no stage after it sees it.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/thread_pool.h"
#include "synthvis/frame_stats.h"
#include "synthvis/scene.h"

namespace sv::traversal {

// The view a traversal culls against and measures ranges in.
struct View {
  Mat4 view;        // world → eye
  Mat4 projection;  // eye → clip
  // The vertical extent of the view window at unit eye depth (FrameCamera's): ranges are scaled
  // by it, so that a zoomed view switches levels where the projected size is the same.
  double tanBottom = -1, tanTop = 1;
};

// How a traversal chooses (the renderer's options: RenderOptions).
struct Options {
  bool cullInstances = true;  // drop instances wholly outside the view volume
  bool lod = true;            // levels of detail by range (else level 0 everywhere)
  float lodScale = 1;         // multiplies every range
  bool mergeCells = true;     // draw merged cells (InstanceTree::Cell) where they stand in
};

// One draw the traversal chose: an instance's mesh at one level of detail.
struct InstanceDraw {
  uint32_t instance = 0;  // into Scene::instances (a merged cell's: its first member)
  int mesh = 0;           // the level's mesh (into Scene::meshes; a merged cell's: −1)
  // The pixels of every screen-aligned 4×4 block it draws (bit x + 4y; 0xFFFF: all): two levels
  // dissolving into each other draw complementary patterns (ordered dither, Bayer 4×4).
  uint16_t door = 0xFFFF;
  int cell = -1;  // a merged cell drawn for its members (into InstanceTree::cells), or −1
};

struct Traversal {
  // What a range of instances chose and counted.
  struct Chunk {
    std::vector<InstanceDraw> draws;  // in instance order, a dissolving instance's levels adjacent
    // Instances dropped outside the view volume, and their full-detail triangles.
    uint64_t culledInstances = 0, culledTriangles = 0;
    // As FrameStats' (lodDrawn, lodDissolving, lodBeyond); beyond's triangles are in
    // culledTriangles.
    uint64_t lodDrawn[FrameStats::kLodLevels] = {};
    uint64_t lodDissolving = 0, lodBeyond = 0;
  };
  // The whole view's: its draws (the merged cells', then the instances' in instance order), and
  // its counts.
  std::vector<InstanceDraw> draws;
  uint64_t culledInstances = 0, culledTriangles = 0;
  uint64_t mergedCells = 0, mergedInstances = 0;  // cells drawn, and their members
  uint64_t lodDrawn[FrameStats::kLodLevels] = {};
  uint64_t lodDissolving = 0, lodBeyond = 0;
  std::vector<uint8_t> state;  // per instance, the walk's scratch
  std::vector<Chunk> chunks;   // per job, kept from frame to frame
};

// Fills `out` for `view`: every instance not wholly outside its view volume (with
// options.cullInstances; the scene's instance tree first, then instance by instance as setup's
// outcodes would cull every triangle — so the image is the same as with no culling), at the level
// of detail its range chooses (options.lod; scene.h LodGroup) — drawn by its merged cell where
// every member of the cell draws that level alone (options.mergeCells; InstanceTree::Cell).
// `meshBounds`: every mesh's bounds.
// The instances are visited in parallel chunks on `pool`; the result does not depend on its
// threads.
void traverse(const scene::Scene& scene, const Options& options, const View& view,
              const std::vector<std::array<Vec3, 2>>& meshBounds, core::ThreadPool& pool,
              Traversal& out);

// The screen-door pattern that draws `k` of 16 pixels of each 4×4 block (0 … 16), by the Bayer
// ordered-dither matrix: doorPattern(k) and ~doorPattern(k) split every block between two draws.
uint16_t doorPattern(int k);

// Whether the box [lo, hi] placed by `mvp` lies wholly beyond one plane of the view volume, or
// wholly behind the eye (then setup culls every triangle inside it).
bool outsideView(const Mat4& mvp, Vec3 lo, Vec3 hi);

}  // namespace sv::traversal
