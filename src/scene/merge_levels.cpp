// Hierarchical levels of detail for the traversal stage (SPEC §1: the database prepared so that a
// frame's traversal chooses little): the small far levels of nearby instances merged per cell, so
// that a distant town is a few hundred draws rather than tens of thousands of tiny ones.
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "synthvis/scene.h"

namespace sv::scene {
namespace {

// What the members of one cell share: the band and level they draw alone, what their merged mesh
// is drawn with, and the grid cell of their range points.
struct CellKey {
  int level;
  double from, until;
  int material, priority;
  bool normals, colors, uvs;
  int64_t ix, iy, iz;
  bool operator<(const CellKey& o) const {
    return std::tie(level, from, until, material, priority, normals, colors, uvs, ix, iy, iz) <
           std::tie(o.level, o.from, o.until, o.material, o.priority, o.normals, o.colors, o.uvs,
                    o.ix, o.iy, o.iz);
  }
};

// The grid index of coordinate `x` for cells of side `s`, bounded (a huge coordinate lands in the
// last cell rather than overflowing).
int64_t gridIndex(float x, double s) {
  return int64_t(std::clamp(std::floor(double(x) / s), -1e12, 1e12));
}

void extend(Vec3& lo, Vec3& hi, Vec3 p) {
  lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
  hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
}

}  // namespace

void mergeFarLevels(const Scene& scene, InstanceTree& tree,
                    const std::vector<std::array<Vec3, 2>>& meshBounds) {
  tree.cells.clear();
  tree.members.clear();
  // Each group's range centre in its instances' space, as the traversal measures ranges to it.
  std::vector<Vec3> centres;
  for (const LodGroup& g : scene.lodGroups) {
    Instance probe;
    probe.mesh = g.levels[0].mesh;
    probe.lod = int(&g - scene.lodGroups.data());
    const auto [lo, hi] = instanceBounds(scene, probe, meshBounds);
    centres.push_back(g.center.value_or((lo + hi) * 0.5f));
  }
  std::map<CellKey, std::vector<uint32_t>> found;
  const size_t held = std::min(tree.instanceCount, scene.instances.size());
  for (uint32_t i = 0; i < held; ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.articulated || inst.lod < 0) continue;
    const LodGroup& g = scene.lodGroups[size_t(inst.lod)];
    const Vec3 point = inst.transform.transformPoint(centres[size_t(inst.lod)]);
    for (size_t level = 1; level < g.levels.size(); ++level) {
      const Mesh& mesh = scene.meshes[size_t(g.levels[level].mesh)];
      if (mesh.positions.empty() || mesh.triangleCount() > kMergeTriangles ||
          scene.materialAt(mesh.material).alphaMode == AlphaMode::blend)
        continue;
      // Drawn alone (no dissolve into or out of it) over [previous switch, this switch − fade).
      const double from = g.levels[level - 1].to, until = double(g.levels[level].to) - g.fade;
      if (!(until > from)) continue;
      // A cell's range points must fit in the band with room to move: a quarter of its width; and
      // no more than half its start, so that a cell straddling the view's edge costs little.
      const double side = std::min((until - from) / 4, from / 2);
      if (!(side > 0)) continue;
      found[{int(level), from, until, mesh.material, inst.priority, !mesh.normals.empty(),
             !mesh.colors.empty(), !mesh.uvs.empty(), gridIndex(point.x, side),
             gridIndex(point.y, side), gridIndex(point.z, side)}]
          .push_back(i);
    }
    // Beyond the last level: nothing drawn, from its switch on.
    const double last = g.levels.back().to;
    if (last < 1e29)
      found[{int(g.levels.size()), last, INFINITY, -1, 0, false, false, false,
             gridIndex(point.x, last / 2), gridIndex(point.y, last / 2),
             gridIndex(point.z, last / 2)}]
          .push_back(i);
  }
  size_t vertices = 0;
  for (const auto& entry : found) {
    // Not a structured binding: clang 14 (the libFuzzer build) refuses a lambda capturing one.
    const CellKey& key = entry.first;
    const std::vector<uint32_t>& members = entry.second;
    if (members.size() < 2) continue;  // nothing saved
    InstanceTree::Cell cell;
    cell.beyond = std::isinf(key.until);
    // The level mesh member i draws (none beyond the last level).
    auto levelMesh = [&](uint32_t i) -> const Mesh* {
      const LodGroup& g = scene.lodGroups[size_t(scene.instances[i].lod)];
      return cell.beyond ? nullptr : &scene.meshes[size_t(g.levels[size_t(key.level)].mesh)];
    };
    size_t cellVertices = 0, cellIndices = 0;
    for (uint32_t i : members)
      if (const Mesh* level = levelMesh(i)) {
        cellVertices += level->positions.size();
        cellIndices += level->indices.size();
      }
    if (vertices + cellVertices > kMergeVertices) continue;
    vertices += cellVertices;
    cell.from = key.from;
    cell.until = key.until;
    cell.level = key.level;
    cell.priority = key.priority;
    cell.firstMember = uint32_t(tree.members.size());
    cell.memberCount = uint32_t(members.size());
    Mesh& m = cell.mesh;
    m.name = "merged cell";
    m.material = key.material;
    m.positions.reserve(cellVertices);
    if (key.normals) m.normals.reserve(cellVertices);
    if (key.colors) m.colors.reserve(cellVertices);
    if (key.uvs) m.uvs.reserve(cellVertices);
    m.indices.reserve(cellIndices);
    for (uint32_t i : members) {
      const Instance& inst = scene.instances[i];
      const Vec3 point = inst.transform.transformPoint(centres[size_t(inst.lod)]);
      if (i == members.front()) cell.rangeLo = cell.rangeHi = point;
      extend(cell.rangeLo, cell.rangeHi, point);
      cell.fullTriangles += scene.meshes[size_t(inst.mesh)].triangleCount();
      tree.members.push_back(i);
      const Mesh* level = levelMesh(i);
      if (!level) continue;
      const Mesh& src = *level;
      const auto base = uint32_t(m.positions.size());
      // The vertex stage's own placement: positions by the transform, normals by its normal
      // matrix, renormalized (geometry/vertex_stage.cpp).
      const Mat4 normalMatrix = inst.transform.normalMatrix();
      for (const Vec3& p : src.positions) m.positions.push_back(inst.transform.transformPoint(p));
      for (const Vec3& n : src.normals)
        m.normals.push_back(normalize(normalMatrix.transformDirection(n)));
      m.colors.insert(m.colors.end(), src.colors.begin(), src.colors.end());
      m.uvs.insert(m.uvs.end(), src.uvs.begin(), src.uvs.end());
      for (uint32_t index : src.indices) m.indices.push_back(base + index);
    }
    cell.bounds = m.bounds();
    tree.cells.push_back(std::move(cell));
  }
}

}  // namespace sv::scene
