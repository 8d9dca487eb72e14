// The traversal stage's hierarchy (SPEC §1: the database is walked and culled before the projective
// transform): a bounding-volume tree over the instances' world boxes.
#include <algorithm>
#include <cmath>
#include <memory>

#include "synthvis/scene.h"

namespace sv::scene {
namespace {

constexpr uint32_t kLeafInstances = 8;

struct Box {
  Vec3 lo, hi;
  void add(const Box& b) {
    lo = {std::min(lo.x, b.lo.x), std::min(lo.y, b.lo.y), std::min(lo.z, b.lo.z)};
    hi = {std::max(hi.x, b.hi.x), std::max(hi.y, b.hi.y), std::max(hi.z, b.hi.z)};
  }
};

// The world box of the local box [lo, hi] placed by `m`: its centre moved, its half-extent through
// |m| (exact for an affine m; a projective last row is not something instances use).
Box worldBox(const Mat4& m, Vec3 lo, Vec3 hi) {
  const Vec3 c = m.transformPoint((lo + hi) * 0.5f), e = (hi - lo) * 0.5f;
  Vec3 r;
  float* out[3] = {&r.x, &r.y, &r.z};
  for (int row = 0; row < 3; ++row)
    *out[row] = std::fabs(m.m[0][row]) * e.x + std::fabs(m.m[1][row]) * e.y +
                std::fabs(m.m[2][row]) * e.z;
  return {c - r, c + r};
}

struct Builder {
  const std::vector<Box>& boxes;
  const std::vector<uint64_t>& triangles;
  InstanceTree& tree;

  // Fills node `at` with order[begin, end): a leaf, or two children split at the median centre
  // along the longest axis of the centres' extent.
  void build(uint32_t at, uint32_t begin, uint32_t end) {
    Box box = boxes[tree.order[begin]], centres{};
    uint64_t tris = 0;
    for (uint32_t i = begin; i < end; ++i) {
      const Box& b = boxes[tree.order[i]];
      box.add(b);
      tris += triangles[tree.order[i]];
      const Vec3 c = (b.lo + b.hi) * 0.5f;
      if (i == begin) centres = {c, c};
      centres.add({c, c});
    }
    InstanceTree::Node& node = tree.nodes[at];
    node.lo = box.lo;
    node.hi = box.hi;
    node.triangles = tris;
    if (end - begin <= kLeafInstances) {
      node.first = begin;
      node.count = end - begin;
      return;
    }
    const Vec3 extent = centres.hi - centres.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    auto centre = [&](uint32_t i) {
      const Box& b = boxes[i];
      return axis == 0 ? b.lo.x + b.hi.x : axis == 1 ? b.lo.y + b.hi.y : b.lo.z + b.hi.z;
    };
    const uint32_t mid = begin + (end - begin) / 2;
    // Ties by instance index: the same tree on every machine and run.
    std::nth_element(tree.order.begin() + begin, tree.order.begin() + mid, tree.order.begin() + end,
                     [&](uint32_t a, uint32_t b) {
                       const float ca = centre(a), cb = centre(b);
                       return ca < cb || (ca == cb && a < b);
                     });
    const auto children = uint32_t(tree.nodes.size());
    tree.nodes.resize(tree.nodes.size() + 2);
    tree.nodes[at].first = children;
    tree.nodes[at].count = 0;
    build(children, begin, mid);
    build(children + 1, mid, end);
  }
};

}  // namespace

std::array<Vec3, 2> instanceBounds(const Scene& scene, const Instance& instance,
                                   const std::vector<std::array<Vec3, 2>>& meshBounds) {
  // Around every level that has vertices (a level may be empty: nothing drawn in its range).
  std::optional<std::array<Vec3, 2>> box;
  auto add = [&](int mesh) {
    if (scene.meshes[size_t(mesh)].positions.empty()) return;
    const auto& [lo, hi] = meshBounds[size_t(mesh)];
    if (!box) box = std::array<Vec3, 2>{lo, hi};
    auto& b = *box;
    b[0] = {std::min(b[0].x, lo.x), std::min(b[0].y, lo.y), std::min(b[0].z, lo.z)};
    b[1] = {std::max(b[1].x, hi.x), std::max(b[1].y, hi.y), std::max(b[1].z, hi.z)};
  };
  add(instance.mesh);
  if (instance.lod >= 0)
    for (const LodLevel& level : scene.lodGroups[size_t(instance.lod)].levels) add(level.mesh);
  return box.value_or(meshBounds[size_t(instance.mesh)]);
}

std::vector<std::array<Vec3, 2>> meshBounds(const Scene& scene) {
  std::vector<std::array<Vec3, 2>> bounds;
  bounds.reserve(scene.meshes.size());
  for (const Mesh& m : scene.meshes) bounds.push_back(m.bounds());
  return bounds;
}

void buildInstanceTree(Scene& scene) {
  auto tree = std::make_shared<InstanceTree>();
  const size_t n = scene.instances.size();
  tree->instanceCount = n;
  const std::vector<std::array<Vec3, 2>> bounds = meshBounds(scene);
  if (n > 0) {
    std::vector<Box> boxes(n);
    std::vector<uint64_t> triangles(n);
    for (size_t i = 0; i < n; ++i) {
      const Instance& inst = scene.instances[i];
      const auto [lo, hi] = instanceBounds(scene, inst, bounds);
      boxes[i] = worldBox(inst.transform, lo, hi);
      triangles[i] = scene.meshes[size_t(inst.mesh)].triangleCount();
    }
    // Articulated instances move: they stay out of the tree, culled one by one.
    for (uint32_t i = 0; i < n; ++i)
      (scene.instances[i].articulated ? tree->loose : tree->order).push_back(i);
    const size_t held = tree->order.size();
    if (held > 0) {
      tree->nodes.reserve(2 * (held / kLeafInstances + 1));
      tree->nodes.resize(1);
      Builder{boxes, triangles, *tree}.build(0, 0, uint32_t(held));
    }
  }
  mergeFarLevels(scene, *tree, bounds);
  scene.instanceTree = std::move(tree);
}

}  // namespace sv::scene
