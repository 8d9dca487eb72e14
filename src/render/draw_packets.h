// The frame's draw packets (SPEC §1 stages 2–3): every instance's triangles in draw order, their
// vertices through the vertex stage — the plain input of setup and the tiles.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <vector>

#include "core/thread_pool.h"
#include "geometry/setup.h"
#include "render/camera.h"
#include "render/shading_tables.h"
#include "traversal/traversal.h"

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
  uint32_t instance = 0;  // the scene instance drawn (an index into Scene::instances)
};

// The plain input of a frame: vertices after the projective transform and triangles indexing them.
struct DrawPackets {
  std::vector<geometry::ClipVertex> vertices;
  // For pixel shading, when some call has a material (else empty): per vertex, the attributes
  // `attributeLayout` stores, attributeLayout.stride floats a vertex — the union of those the
  // calls' materials read (shade::attributesUsed).
  std::vector<float> attributes;
  geometry::AttributeLayout attributeLayout;
  std::vector<uint32_t> indices;  // 3 per triangle, each < vertices.size()
  std::vector<DrawCall> calls;    // in draw order (buildDrawPackets)
  // What the traversal chose (its draws, what it culled and the levels of detail drawn), and the
  // frame's meshes' bounds.
  traversal::Traversal traversal;
  std::vector<std::array<Vec3, 2>> meshBounds;
  // The materials of dissolving draws (each a scene material's with a door), for the frame.
  std::deque<std::pair<const shade::MaterialShading*, shade::MaterialShading>> doorMaterials;
  std::vector<size_t> jobGroups;  // the vertex stage's groups of jobs (their first, and the end)
};

// Builds `out` for the scene seen by `camera`: one call per draw the traversal chose (traverse:
// instances culled to the view, at their levels of detail) in draw order (drawOrder:
// opaque ones first — by priority and distance under masking — then translucent ones, farthest
// first), each with its culling mode, its material when `shading` is given (pixel shading; else
// nullptr: vertex colours only) and, under masking, its object bound; every vertex transformed and
// every index range-checked in parallel chunks on `pool`. `out`'s storage is reused from frame to
// frame. An error names invalid vertex data (non-finite positions, indices out of range) or a
// frame of over 2^31 vertices or indices.
Status buildDrawPackets(const scene::Scene& scene, const RenderOptions& options,
                        const FrameCamera& camera, const ShadingTables* shading,
                        core::ThreadPool& pool, DrawPackets& out);

// The traversal's view and options for a frame of `camera` under `options` (merged cells only
// under the Z-buffer: masking draws objects nearest first, which a merged cell is not).
traversal::View traversalView(const FrameCamera& camera);
traversal::Options traversalOptions(const RenderOptions& options);

// What a traversal chose and culled, added to a frame's counts (the triangles it culled among
// those in).
void addTraversalCounts(const traversal::Traversal& t, FrameStats& stats);

// The smallest view depth of the corners of the box [lo, hi] placed by `toEye`.
float nearestEyeDepth(const Mat4& toEye, Vec3 lo, Vec3 hi);

}  // namespace sv::render
