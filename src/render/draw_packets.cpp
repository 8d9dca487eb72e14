// Based on: SPEC §1 (traversal → projective transform), §4 (the draw order masking needs: priority,
// then nearest first; translucent surfaces last, farthest first).
#include "render/draw_packets.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "geometry/vertex_stage.h"

namespace sv::render {
namespace {

using traversal::InstanceDraw;

// The vertex stage's work, in parallel chunks each writing its own range: a range of one
// instance's vertices, or of its indices (copied offset to the frame's vertex numbering and
// range-checked).
struct VertexJob {
  const Mat4* transform;    // the instance's (a merged cell's: the identity)
  const scene::Mesh* mesh;  // the instance's level of detail, or a merged cell's mesh
  bool indices;  // else vertices
  size_t begin, end, out;
  uint32_t base;  // the instance's first vertex in the frame (indices)
};
constexpr size_t kVertexChunk = 1 << 14, kIndexChunk = 1 << 16, kGroupWork = 4096;

// Every vertex and index the frame draws is checked as the vertex stage reads it, not in a pass of
// its own; the full check runs only to name an offender. (A mesh no instance draws is left to the
// loaders' validation.)
Status invalidVertexData(const scene::Scene& scene) {
  if (Status s = scene::validate(scene, ""); !s) return s;
  return Error{"", "", "invalid vertex data"};  // (validate finds what the stage found)
}

// The mesh's arrays and material as the vertex stage reads them.
geometry::VertexArrays toVertexArrays(const scene::Mesh& mesh) {
  geometry::VertexArrays v;
  v.positions = mesh.positions.data();
  v.count = mesh.positions.size();
  if (!mesh.normals.empty()) v.normals = mesh.normals.data();
  if (!mesh.colors.empty()) v.colors = mesh.colors.data();
  if (!mesh.uvs.empty()) v.uvs = mesh.uvs.data();
  return v;
}
geometry::VertexMaterial toVertexMaterial(const scene::Material& m) {
  return {m.baseColor, m.uvScale, m.unlit, m.phong};
}

// What a draw places where: an instance's level mesh by its transform, or a merged cell's mesh
// (its vertices already in the world) by the identity.
struct DrawSource {
  const Mat4* transform;
  const scene::Mesh* mesh;
  const std::array<Vec3, 2>* bounds;
  int priority;
};
const Mat4 kIdentity{};
DrawSource sourceOf(const scene::Scene& scene, const std::vector<std::array<Vec3, 2>>& boxes,
                    const InstanceDraw& draw) {
  if (draw.cell >= 0) {
    const scene::InstanceTree::Cell& cell = scene.instanceTree->cells[size_t(draw.cell)];
    return {&kIdentity, &cell.mesh, &cell.bounds, cell.priority};
  }
  const scene::Instance& inst = scene.instances[draw.instance];
  return {&inst.transform, &scene.meshes[size_t(draw.mesh)], &boxes[size_t(draw.mesh)],
          inst.priority};
}

// The order the traversal's draws are drawn in (indices into `draws`). Opaque ones: in submission
// order for the Z-buffer; for masking (SPEC §4) by priority, then nearest first — by the smallest
// view depth of their bounding box's corners, which orders objects separated in depth correctly
// (docs/hidden-surfaces.md). Translucent ones, always: farthest first by the view depth of their
// box's centre, so that nearer ones blend over farther ones. Stable: ties keep submission order.
// `boxes`: every mesh's bounds; `sort`: whether either sort applies.
std::vector<uint32_t> drawOrder(const scene::Scene& scene, const std::vector<InstanceDraw>& draws,
                                const Mat4& view, RenderOptions::Hsr hsr,
                                const std::vector<std::array<Vec3, 2>>& boxes, bool sort) {
  std::vector<uint32_t> order(draws.size());
  std::iota(order.begin(), order.end(), 0u);
  if (!sort) return order;
  const bool sortOpaque = hsr != RenderOptions::Hsr::zbuffer;
  // Per draw the view depths of its mesh's box's corners.
  std::vector<float> nearest(order.size()), centre(order.size());
  std::vector<DrawSource> sources;
  sources.reserve(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const DrawSource& source = sources.emplace_back(sourceOf(scene, boxes, draws[i]));
    const auto& [lo, hi] = *source.bounds;
    const Mat4 toEye = view * *source.transform;
    nearest[i] = nearestEyeDepth(toEye, lo, hi);
    centre[i] = -toEye.transformPoint((lo + hi) * 0.5f).z;
  }
  auto translucent = [&](uint32_t i) {
    const int m = sources[i].mesh->material;
    return m >= 0 && scene.materials[size_t(m)].alphaMode == scene::AlphaMode::blend;
  };
  auto priority = [&](uint32_t i) { return sources[i].priority; };
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const bool ta = translucent(a), tb = translucent(b);
    if (ta != tb) return tb;  // opaque first (the passes pick them out again)
    if (ta) return centre[a] > centre[b];
    if (!sortOpaque) return false;
    if (priority(a) != priority(b)) return priority(a) < priority(b);
    return nearest[a] < nearest[b];
  });
  return order;
}

// Every mesh's bounds, for the traversal, the draw order and the objects' screen bounds. False for
// a bound that is not finite where a sort needs it (an infinite position, not yet checked — the
// vertex stage checks them — would give the draw order NaN depths to sort by). `sort`: whether the
// draw order sorts (masking, or some translucent material).
bool meshBounds(const scene::Scene& scene, const RenderOptions& o,
                std::vector<std::array<Vec3, 2>>& boxes, bool& sort) {
  bool anyTranslucent = false;
  for (const scene::Material& m : scene.materials)
    anyTranslucent |= m.alphaMode == scene::AlphaMode::blend;
  sort = o.hsr != RenderOptions::Hsr::zbuffer || anyTranslucent;
  boxes.clear();
  boxes.reserve(scene.meshes.size());
  for (const scene::Mesh& m : scene.meshes) {
    boxes.push_back(m.bounds());
    if (sort)
      for (const Vec3& corner : boxes.back())
        if (!isFinite(corner)) return false;
  }
  return true;
}

// The material a dissolving draw reads: `base` with its door, kept in `p` for the frame (one per
// base and door). Opaque materials become cut-outs (AlphaUse::mask with no alpha threshold):
// pixels outside the door are cut away, and what they would hide stays drawn.
const shade::MaterialShading* doorMaterial(const shade::MaterialShading* base, uint16_t door,
                                           DrawPackets& p) {
  for (const auto& [from, m] : p.doorMaterials)
    if (from == base && m.door == door) return &m;
  shade::MaterialShading m = *base;
  m.door = door;
  if (m.alpha == shade::AlphaUse::opaque) {
    m.alpha = shade::AlphaUse::mask;
    m.alphaCutoff = -1;  // every alpha passes: only the door cuts
  }
  return &p.doorMaterials.emplace_back(base, m).second;
}

}  // namespace

traversal::View traversalView(const FrameCamera& camera) {
  return {camera.view, camera.projection, camera.tanBottom, camera.tanTop};
}

traversal::Options traversalOptions(const RenderOptions& o) {
  return {o.cullInstances, o.lod, o.lodScale, o.mergeCells && o.hsr == RenderOptions::Hsr::zbuffer};
}

namespace {

// The frame's layout: one call per draw the traversal chose, opaque materials first, then
// translucent ones (SPEC §4: blended over what is behind them), each with its vertex and index
// jobs; `stored` gathers the attributes the calls' materials read. Sizes `p`'s vertices and
// indices.
Status layOutCalls(const scene::Scene& scene, const RenderOptions& o, const FrameCamera& camera,
                   const ShadingTables* shading, core::ThreadPool& pool, DrawPackets& p,
                   std::vector<VertexJob>& jobs, unsigned& stored) {
  std::vector<std::array<Vec3, 2>>& boxes = p.meshBounds;
  bool sort = false;
  if (!meshBounds(scene, o, boxes, sort)) return invalidVertexData(scene);
  const bool masking =
      o.hsr != RenderOptions::Hsr::zbuffer && o.debugView != RenderOptions::DebugView::overdraw;
  const Mat4 viewProj = camera.projection * camera.view;
  const geometry::Viewport boundViewport{o.width * o.supersample, o.height * o.supersample};
  traversal::traverse(scene, traversalOptions(o), traversalView(camera), boxes, pool, p.traversal);
  const std::vector<InstanceDraw>& draws = p.traversal.draws;
  const std::vector<uint32_t> order = drawOrder(scene, draws, camera.view, o.hsr, boxes, sort);
  p.doorMaterials.clear();
  size_t vertexCount = 0, indexCount = 0;
  for (const bool translucentPass : {false, true})
    for (const uint32_t d : order) {
      const InstanceDraw& draw = draws[d];
      const DrawSource source = sourceOf(scene, boxes, draw);
      const scene::Mesh& mesh = *source.mesh;
      const scene::Material& mat = scene.materialAt(mesh.material);
      if ((mat.alphaMode == scene::AlphaMode::blend) != translucentPass) continue;
      // Indices are 32-bit; a frame of more vertices or triangles than that cannot be expressed.
      if (vertexCount + mesh.positions.size() > (size_t(1) << 31) ||
          indexCount + mesh.indices.size() > (size_t(1) << 31))
        return Error{"", "", "scene too large for one frame (over 2^31 vertices or indices)"};
      const auto base = static_cast<uint32_t>(vertexCount);
      for (size_t b = 0; b < mesh.positions.size(); b += kVertexChunk)
        jobs.push_back({source.transform, &mesh, false, b, std::min(mesh.positions.size(), b + kVertexChunk),
                        vertexCount + b, base});
      for (size_t b = 0; b < mesh.indices.size(); b += kIndexChunk)
        jobs.push_back({source.transform, &mesh, true, b, std::min(mesh.indices.size(), b + kIndexChunk),
                        indexCount + b, base});
      DrawCall call;
      call.instance = draw.instance;
      call.firstTriangle = static_cast<uint32_t>(indexCount / 3);
      call.triangleCount = static_cast<uint32_t>(mesh.triangleCount());
      call.cull =
          o.cullBackFaces && !mat.doubleSided ? geometry::CullMode::back : geometry::CullMode::none;
      // A dissolving draw is always shaded per pixel: its door cuts pixels there (shading.any is
      // set for a scene with dissolves, so `shading` is given).
      if (shading && (mat.needsPixelShading() || shading->environment.fog || draw.door != 0xFFFF))
        call.material = shading->of(mesh.material, !mesh.normals.empty());
      if (call.material && draw.door != 0xFFFF)
        call.material = doorMaterial(call.material, draw.door, p);
      if (call.material) stored |= shade::attributesUsed(*call.material, shading->environment);
      if (masking)
        call.bounded = geometry::boundObject(viewProj * *source.transform, (*source.bounds)[0],
                                             (*source.bounds)[1], boundViewport, call.bound);
      p.calls.push_back(call);
      vertexCount += mesh.positions.size();
      indexCount += mesh.indices.size();
    }
  p.vertices.resize(vertexCount);
  p.indices.resize(indexCount);
  return {};
}

}  // namespace

void addTraversalCounts(const traversal::Traversal& t, FrameStats& stats) {
  stats.trianglesIn += t.culledTriangles;
  stats.culledOutside += t.culledTriangles;
  stats.culledInstances += t.culledInstances;
  for (int i = 0; i < FrameStats::kLodLevels; ++i) stats.lodDrawn[i] += t.lodDrawn[i];
  stats.lodDissolving += t.lodDissolving;
  stats.mergedCells += t.mergedCells;
  stats.mergedInstances += t.mergedInstances;
  stats.lodBeyond += t.lodBeyond;
}

float nearestEyeDepth(const Mat4& toEye, Vec3 lo, Vec3 hi) {
  float near = std::numeric_limits<float>::infinity();
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
    near = std::min(near, -toEye.transformPoint(corner).z);
  }
  return near;
}

Status buildDrawPackets(const scene::Scene& scene, const RenderOptions& o,
                        const FrameCamera& camera, const ShadingTables* shading,
                        core::ThreadPool& pool, DrawPackets& p) {
  // Vertices, attributes and indices are resized and every one is written by the vertex stage:
  // not cleared first, so that a frame of the same size does not zero megabytes for nothing.
  p.calls.clear();
  std::vector<VertexJob> jobs;
  unsigned stored = 0;  // the attributes some material reads (geometry::AttributeLayout)
  if (Status s = layOutCalls(scene, o, camera, shading, pool, p, jobs, stored); !s) return s;
  // Only the attributes some material reads (geometry::AttributeLayout).
  p.attributeLayout = geometry::AttributeLayout::of(stored);
  const size_t stride = size_t(p.attributeLayout.stride);
  p.attributes.resize(p.vertices.size() * stride);
  geometry::VertexContext context{
      camera.view,
      camera.projection * camera.view,
      {scene.light.direction, scene.light.color, scene.light.ambient, scene.light.enabled},
      {}};
  std::vector<geometry::PointLight> pointLights;
  for (const scene::PointLight& l : scene.pointLights) pointLights.push_back({l.position, l.color});
  context.pointLights = pointLights;
  std::vector<uint8_t> finite(jobs.size());  // positions finite, indices in range
  auto run = [&](size_t j) {
    const VertexJob& job = jobs[j];
    const scene::Mesh& mesh = *job.mesh;
    if (job.indices) {
      uint32_t maxIndex = 0;
      uint32_t* out = p.indices.data() + job.out;
      for (size_t i = job.begin; i < job.end; ++i) {
        maxIndex = std::max(maxIndex, mesh.indices[i]);
        out[i - job.begin] = job.base + mesh.indices[i];
      }
      finite[j] = maxIndex < mesh.positions.size();
      return;
    }
    finite[j] = geometry::transformVertices(
        toVertexArrays(mesh), toVertexMaterial(scene.materialAt(mesh.material)),
        *job.transform, context, job.begin, job.end, p.vertices.data() + job.out,
        stride ? p.attributes.data() + job.out * stride : nullptr, &p.attributeLayout);
  };
  // Small instances' jobs run in groups of consecutive ones (some 4 000 vertices and indices a
  // group), so that a city of thousands of 20-vertex trees is not thousands of dispatches.
  std::vector<size_t>& groups = p.jobGroups;
  groups.assign(1, 0);
  for (size_t j = 0, work = 0; j < jobs.size(); ++j) {
    work += jobs[j].end - jobs[j].begin;
    if (work >= kGroupWork || j + 1 == jobs.size()) {
      groups.push_back(j + 1);
      work = 0;
    }
  }
  pool.parallelFor(groups.size() - 1, [&](size_t g, int) {
    for (size_t j = groups[g]; j < groups[g + 1]; ++j) run(j);
  });
  if (std::find(finite.begin(), finite.end(), 0) != finite.end()) return invalidVertexData(scene);
  return {};
}

}  // namespace sv::render
