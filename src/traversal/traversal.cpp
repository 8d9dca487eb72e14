// Based on: SPEC §1 (the traversal stage: the database walked, culled to the view and its levels
// of detail chosen before the projective transform).
#include "traversal/traversal.h"

#include <algorithm>
#include <cmath>

namespace sv::traversal {
namespace {

// kMerged: drawn by its merged cell (or culled with it), not on its own.
enum State : uint8_t { kCulled, kTest, kInside, kMerged };
constexpr size_t kTraversalChunk = 4096;  // instances a job

// The view volume's six planes in world space: a point p is inside plane k where
// plane[k]·(p, 1) ≥ 0 — the clip-space conditions w ± x, w ± y, w ± z ≥ 0 of setup's outcodes.
struct Planes {
  double p[6][4];
  explicit Planes(const Mat4& m) {
    for (int k = 0; k < 6; ++k) {
      const int row = k / 2;
      const double sign = k % 2 ? -1 : 1;
      for (int c = 0; c < 4; ++c) p[k][c] = double(m.m[c][3]) + sign * double(m.m[c][row]);
    }
  }
  // Outside when the box lies wholly beyond one plane, inside when wholly within all six, else
  // kTest. Decided in double with a margin of 1e-4 of the terms' size, so that a box called outside
  // is outside by far more than the rounding of the float test instance by instance (outsideView)
  // — the tree never drops what that test, and setup, would keep.
  State classify(Vec3 lo, Vec3 hi) const {
    bool inside = true;
    for (const auto& q : p) {
      double most = q[3], least = q[3], size = std::fabs(q[3]);
      const float l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
      for (int a = 0; a < 3; ++a) {
        const double x = q[a] * l[a], y = q[a] * h[a];
        most += std::max(x, y);
        least += std::min(x, y);
        size += std::max(std::fabs(x), std::fabs(y));
      }
      const double margin = 1e-4 * size;
      if (most < -margin) return kCulled;
      inside = inside && least > margin;
    }
    return inside ? kInside : kTest;
  }
};

// Marks every instance the tree holds: outside, inside, or to be tested one by one.
void walk(const scene::InstanceTree& tree, const Planes& planes, std::vector<uint8_t>& state) {
  if (tree.nodes.empty()) return;
  std::vector<std::pair<uint32_t, State>> stack{{0u, kTest}};
  while (!stack.empty()) {
    auto [at, parent] = stack.back();
    stack.pop_back();
    const scene::InstanceTree::Node& node = tree.nodes[at];
    const State s = parent == kTest ? planes.classify(node.lo, node.hi) : parent;
    if (node.count) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) state[tree.order[i]] = s;
      continue;
    }
    stack.push_back({node.first + 1, s});
    stack.push_back({node.first, s});
  }
}

// The smallest and largest distance from `eye` to the box [lo, hi], in double.
std::array<double, 2> distanceRange(Vec3 eye, Vec3 lo, Vec3 hi) {
  const double e[3] = {eye.x, eye.y, eye.z}, l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
  double nearest = 0, farthest = 0;
  for (int a = 0; a < 3; ++a) {
    const double below = l[a] - e[a], above = e[a] - h[a];
    const double in = std::max({below, above, 0.0});
    const double out = std::max(std::fabs(e[a] - l[a]), std::fabs(h[a] - e[a]));
    nearest += in * in;
    farthest += out * out;
  }
  return {std::sqrt(nearest), std::sqrt(farthest)};
}

// The merged cells whose members all draw the cell's level alone this frame: each drawn as one
// (or culled whole) and its members marked kMerged, counted at that level; or all beyond their
// last level, marked kMerged and counted beyond. A cell with a member
// switched off is left to its members. Ranges as the visit's (the distance to each member's range
// point, which lies in the cell's range box), with a relative margin of 1e-5 for the rounding of
// the visit's float differences.
void drawMergedCells(const scene::InstanceTree& tree, const scene::Scene& scene, const Options& o,
                     const Mat4& viewProj, Vec3 eye, double rangeScale, Traversal& out) {
  for (const scene::InstanceTree::Cell& cell : tree.cells) {
    const auto [nearest, farthest] = distanceRange(eye, cell.rangeLo, cell.rangeHi);
    if (!(nearest * rangeScale * (1 - 1e-5) >= cell.from &&
          farthest * rangeScale * (1 + 1e-5) < cell.until))
      continue;
    const uint32_t* members = tree.members.data() + cell.firstMember;
    if (!std::all_of(members, members + cell.memberCount,
                     [&](uint32_t i) { return scene.instances[i].visible; }))
      continue;
    if (cell.beyond) {
      // As the visit would count them, without visiting them: those outside the view culled, the
      // others beyond; the triangles of both not drawn.
      uint32_t culled = 0;
      for (uint32_t k = 0; k < cell.memberCount; ++k) {
        culled += out.state[members[k]] == kCulled;
        out.state[members[k]] = kMerged;
      }
      out.culledInstances += culled;
      out.lodBeyond += cell.memberCount - culled;
      out.culledTriangles += cell.fullTriangles;
      continue;
    }
    if (o.cullInstances && outsideView(viewProj, cell.bounds[0], cell.bounds[1])) {
      // Left to the visit as culled, which counts them as it would have.
      for (uint32_t k = 0; k < cell.memberCount; ++k) out.state[members[k]] = kCulled;
      continue;
    }
    for (uint32_t k = 0; k < cell.memberCount; ++k) out.state[members[k]] = kMerged;
    const auto index = int(&cell - tree.cells.data());
    out.draws.push_back({members[0], -1, 0xFFFF, index});
    out.lodDrawn[std::min<size_t>(size_t(cell.level), FrameStats::kLodLevels - 1)] +=
        cell.memberCount;
    ++out.mergedCells;
    out.mergedInstances += cell.memberCount;
  }
}

// The Bayer 4×4 ordered-dither thresholds, pixel (x, y) at x + 4y.
constexpr uint8_t kBayer[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};

}  // namespace

uint16_t doorPattern(int k) {
  uint16_t door = 0;
  for (int i = 0; i < 16; ++i)
    if (kBayer[i] < k) door = uint16_t(door | 1u << i);
  return door;
}

bool outsideView(const Mat4& mvp, Vec3 lo, Vec3 hi) {
  // With a margin of 1e-5·|w|, so that rounding between the corners' transform and the vertices'
  // can never drop a triangle setup would have kept; the planes are linear in the box's points,
  // so what holds for its corners holds inside. Never for a box that is not finite.
  unsigned common = 63;
  bool allBehind = true;
  for (int c = 0; c < 8; ++c) {
    const Vec4 v = mvp * Vec4{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z, 1};
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || !std::isfinite(v.w))
      return false;
    const float m = v.w + 1e-5f * std::fabs(v.w);
    unsigned code = 0;
    if (v.x < -m) code |= 1;
    if (v.x > m) code |= 2;
    if (v.y < -m) code |= 4;
    if (v.y > m) code |= 8;
    if (v.z < -m) code |= 16;
    if (v.z > m) code |= 32;
    common &= code;
    allBehind = allBehind && v.w < 0;
  }
  return common != 0 || allBehind;
}

void traverse(const scene::Scene& scene, const Options& o, const View& camera,
              const std::vector<std::array<Vec3, 2>>& meshBounds, core::ThreadPool& pool,
              Traversal& out) {
  out.draws.clear();
  out.culledInstances = out.culledTriangles = out.lodDissolving = out.lodBeyond = 0;
  out.mergedCells = out.mergedInstances = 0;
  std::fill(std::begin(out.lodDrawn), std::end(out.lodDrawn), 0);
  const size_t n = scene.instances.size();
  const Mat4 viewProj = camera.projection * camera.view;
  out.state.assign(n, o.cullInstances ? kTest : kInside);
  if (o.cullInstances && scene.instanceTree) walk(*scene.instanceTree, Planes(viewProj), out.state);

  // Ranges (scene.h LodGroup): from the eye, scaled to the view's field of view and lodScale.
  const auto& v = camera.view.m;
  const Vec3 t{v[3][0], v[3][1], v[3][2]};
  const Vec3 eye{-(v[0][0] * t.x + v[0][1] * t.y + v[0][2] * t.z),
                 -(v[1][0] * t.x + v[1][1] * t.y + v[1][2] * t.z),
                 -(v[2][0] * t.x + v[2][1] * t.y + v[2][2] * t.z)};
  const double rangeScale =
      0.5 * (camera.tanTop - camera.tanBottom) / std::tan(M_PI / 6) * double(o.lodScale);
  const std::vector<uint8_t>& state = out.state;
  std::vector<std::array<Vec3, 2>> groupBounds;
  if (o.lod)
    for (const scene::LodGroup& g : scene.lodGroups) {
      scene::Instance probe;
      probe.mesh = g.levels[0].mesh;
      probe.lod = int(&g - scene.lodGroups.data());
      groupBounds.push_back(scene::instanceBounds(scene, probe, meshBounds));
    }

  if (o.lod && o.mergeCells && scene.instanceTree)
    drawMergedCells(*scene.instanceTree, scene, o, viewProj, eye, rangeScale, out);

  // Instance i into `part`: culled, beyond its levels, or its draws.
  auto visit = [&](size_t i, Traversal::Chunk& part) {
    const scene::Instance& inst = scene.instances[i];
    if (!inst.visible || state[i] == kMerged) return;  // switched off, or drawn by its cell
    const uint64_t fullTriangles = scene.meshes[size_t(inst.mesh)].triangleCount();
    auto cull = [&] {
      ++part.culledInstances;
      part.culledTriangles += fullTriangles;
    };
    if (state[i] == kCulled) {
      cull();
      return;
    }
    // The level (or two levels) drawn, with their doors.
    InstanceDraw draw[2];
    size_t levels[2] = {0, 0};
    int draws = 1;
    draw[0] = {uint32_t(i), inst.mesh, 0xFFFF};
    if (o.lod && inst.lod >= 0) {
      const scene::LodGroup& g = scene.lodGroups[size_t(inst.lod)];
      const auto& [lo, hi] = groupBounds[size_t(inst.lod)];
      const Vec3 d = inst.transform.transformPoint(g.center.value_or((lo + hi) * 0.5f)) - eye;
      const double range =
          std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z) * rangeScale;
      size_t level = 0;
      while (level < g.levels.size() && !(range < double(g.levels[level].to))) ++level;
      if (level == g.levels.size()) {
        ++part.lodBeyond;
        part.culledTriangles += fullTriangles;
        return;
      }
      draw[0].mesh = g.levels[level].mesh;
      levels[0] = level;
      const double start = double(g.levels[level].to) - double(g.fade);
      if (g.fade > 0 && range >= start) {
        // k of 16 pixels already belong to the next level (or to nothing after the last).
        const int k = std::clamp(int((range - start) / double(g.fade) * 16 + 0.5), 0, 16);
        if (k > 0) {
          ++part.lodDissolving;
          draw[0].door = uint16_t(~doorPattern(k));
          if (level + 1 < g.levels.size()) {
            draw[1] = {uint32_t(i), g.levels[level + 1].mesh, doorPattern(k)};
            levels[1] = level + 1;
            draws = 2;
          }
        }
      }
    }
    bool drawn = false;
    for (int k = 0; k < draws; ++k) {
      if (draw[k].door == 0) continue;
      const auto& [lo, hi] = meshBounds[size_t(draw[k].mesh)];
      if (state[i] == kTest && outsideView(viewProj * inst.transform, lo, hi)) continue;
      part.draws.push_back(draw[k]);
      if (inst.lod >= 0 && o.lod)
        ++part.lodDrawn[std::min<size_t>(levels[k], FrameStats::kLodLevels - 1)];
      drawn = true;
    }
    if (!drawn) cull();
  };
  // The instances in chunks on the pool, each with its own draws and counts, joined in order.
  const size_t chunks = (n + kTraversalChunk - 1) / kTraversalChunk;
  out.chunks.resize(std::max(out.chunks.size(), chunks));
  pool.parallelFor(chunks, [&](size_t c, int) {
    Traversal::Chunk& part = out.chunks[c];
    part = Traversal::Chunk{std::move(part.draws)};
    part.draws.clear();
    for (size_t i = c * kTraversalChunk; i < std::min(n, (c + 1) * kTraversalChunk); ++i)
      visit(i, part);
  });
  for (size_t c = 0; c < chunks; ++c) {
    const Traversal::Chunk& part = out.chunks[c];
    out.draws.insert(out.draws.end(), part.draws.begin(), part.draws.end());
    out.culledInstances += part.culledInstances;
    out.culledTriangles += part.culledTriangles;
    for (int l = 0; l < FrameStats::kLodLevels; ++l) out.lodDrawn[l] += part.lodDrawn[l];
    out.lodDissolving += part.lodDissolving;
    out.lodBeyond += part.lodBeyond;
  }
}

}  // namespace sv::traversal
