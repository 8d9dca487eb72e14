// The city benchmark scene (BENCH.md `city`; issue 32): a generated town of instanced buildings and
// trees with levels of detail, for the traversal stage (SPEC §1) — culling and levels of detail
// are what make it drawable at all.
#include <algorithm>
#include <cmath>
#include <random>

#include "formats/primitives.h"
#include "generators/generator_common.h"
#include "synthvis/generators.h"

namespace sv::generators {
namespace {

constexpr float kBlock = 40;  // metres from one block's centre to the next
constexpr float kFloorHeight = 3.2f;
constexpr int kBuildingKinds = 8;
constexpr int kTreeKinds = 3;

// `c`'s colour times `f` plus `add`, opaque.
Vec4 scaled(Vec4 c, float f, float add) { return {c.x * f + add, c.y * f + add, c.z * f + add, 1}; }

// Appends `part` to `into`, placed by `t`, every vertex coloured `color`.
void append(Mesh& into, const Mesh& part, const Mat4& t, Vec4 color) {
  const auto base = uint32_t(into.positions.size());
  for (size_t i = 0; i < part.positions.size(); ++i) {
    into.positions.push_back(t.transformPoint(part.positions[i]));
    into.normals.push_back(normalize(t.transformDirection(part.normals[i])));
    into.colors.push_back(color);
  }
  for (uint32_t index : part.indices) into.indices.push_back(base + index);
}

// One axis-aligned quad with its own four vertices: corner `o`, edges `u` and `v` (counter-
// clockwise seen from the side `u × v` points to).
void quad(Mesh& m, Vec3 o, Vec3 u, Vec3 v, Vec4 color) {
  const auto base = uint32_t(m.positions.size());
  const Vec3 n = normalize(cross(u, v));
  for (const Vec3& p : {o, o + u, o + u + v, o + v}) {
    m.positions.push_back(p);
    m.normals.push_back(n);
    m.colors.push_back(color);
  }
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

// A building of `floors` storeys on a width × depth footprint centred on the origin: every wall a
// grid of wall strips and `columns` windows per floor (each its own quad), and a flat roof.
Mesh detailedBuilding(float width, float depth, int floors, int columns, Vec4 wall) {
  Mesh m;
  m.name = "building";
  const Vec4 glass{0.10f, 0.13f, 0.18f, 1};
  const float height = float(floors) * kFloorHeight;
  const float x0 = -width / 2, z0 = -depth / 2;
  // The four walls: origin, direction along the wall, its length (outward normal = along × up).
  const struct {
    Vec3 origin, along;
    float length;
  } walls[4] = {{{x0, 0, -z0}, {1, 0, 0}, width},
                {{-x0, 0, -z0}, {0, 0, -1}, depth},
                {{-x0, 0, z0}, {-1, 0, 0}, width},
                {{x0, 0, z0}, {0, 0, 1}, depth}};
  for (const auto& w : walls) {
    // Columns: wall, window, wall, …, wall (2·columns + 1 cells, windows 60 % of a bay).
    const float bay = w.length / float(columns);
    std::vector<float> xs{0};
    for (int c = 0; c < columns; ++c) {
      xs.push_back(float(c) * bay + 0.2f * bay);
      xs.push_back(float(c) * bay + 0.8f * bay);
    }
    xs.push_back(w.length);
    std::vector<float> ys{0};
    for (int f = 0; f < floors; ++f) {
      ys.push_back(float(f) * kFloorHeight + 0.9f);
      ys.push_back(float(f) * kFloorHeight + 2.6f);
    }
    ys.push_back(height);
    for (size_t i = 0; i + 1 < xs.size(); ++i)
      for (size_t j = 0; j + 1 < ys.size(); ++j)
        quad(m, w.origin + w.along * xs[i] + Vec3{0, ys[j], 0}, w.along * (xs[i + 1] - xs[i]),
             {0, ys[j + 1] - ys[j], 0}, i % 2 && j % 2 ? glass : wall);
  }
  quad(m, {x0, height, -z0}, {width, 0, 0}, {0, 0, -depth}, scaled(wall, 0.8f, 0));
  return m;
}

// The same building as a box (its walls and roof; no floor).
Mesh boxBuilding(float width, float depth, int floors, Vec4 wall) {
  Mesh m;
  m.name = "building-box";
  const float height = float(floors) * kFloorHeight;
  // From afar the walls' average: windows are 0.6 of a bay wide and 1.7 m of each 3.2 m storey.
  const float glassShare = 0.6f * 1.7f / kFloorHeight;
  const Vec4 tint{wall.x * (1 - glassShare) + 0.10f * glassShare,
                  wall.y * (1 - glassShare) + 0.13f * glassShare,
                  wall.z * (1 - glassShare) + 0.18f * glassShare, 1};
  const float x0 = -width / 2, z0 = -depth / 2;
  quad(m, {x0, 0, -z0}, {width, 0, 0}, {0, height, 0}, tint);
  quad(m, {-x0, 0, -z0}, {0, 0, -depth}, {0, height, 0}, tint);
  quad(m, {-x0, 0, z0}, {-width, 0, 0}, {0, height, 0}, tint);
  quad(m, {x0, 0, z0}, {0, 0, depth}, {0, height, 0}, tint);
  quad(m, {x0, height, -z0}, {width, 0, 0}, {0, 0, -depth}, scaled(wall, 0.8f, 0));
  return m;
}

// A tree: a trunk and a round crown, at three levels of detail (crown segments × rings).
Mesh tree(int segments, int rings, int trunkSides, Vec4 leaves) {
  Mesh m;
  m.name = "tree";
  const Vec4 bark{0.25f, 0.17f, 0.10f, 1};
  if (trunkSides > 0)
    append(m, formats::detail::makeCylinder(0.25f, 3, trunkSides, false),
           Mat4::translation({0, 1.5f, 0}), bark);
  append(m, formats::detail::makeSphere(2.4f, segments, rings), Mat4::translation({0, 4.6f, 0}),
         leaves);
  return m;
}

}  // namespace

Scene generateCity(const CityParams& p) {
  std::mt19937_64 rng(p.seed ^ 0xC17Au);
  auto uniform = [&](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  Scene s;
  s.background = {0.55f, 0.68f, 0.85f};
  s.light.direction = {-0.45f, -0.8f, -0.35f};
  s.light.ambient = 0.35f;
  s.fog.enabled = true;
  s.fog.color = s.background;
  s.fog.beta = 0.0004f;  // half the colour every 2.5 km
  const int side = std::max(1, int(std::ceil(std::sqrt(double(std::max(p.buildings, 1))))));
  const float extent = float(side) * kBlock;

  // Ground: one quad under the whole city.
  Mesh ground;
  ground.name = "ground";
  quad(ground, {-extent, 0, extent}, {2 * extent, 0, 0}, {0, 0, -2 * extent},
       {0.30f, 0.34f, 0.26f, 1});
  s.meshes.push_back(std::move(ground));
  s.instances.push_back({0, Mat4{}});

  // Buildings: kinds of each size, full detail to 250 m, boxes to 6 km.
  struct Footprint {
    float width, depth;
  };
  std::vector<Footprint> footprints;
  for (int k = 0; k < kBuildingKinds; ++k) {
    const float width = 12 + 2.0f * float(k % 4), depth = 12 + 1.5f * float((k * 3) % 5);
    const int floors = 4 + 3 * k;
    const Vec4 wall{0.55f + 0.05f * float(k % 3), 0.52f, 0.47f + 0.04f * float(k % 4), 1};
    LodGroup g;
    g.name = "building";
    g.fade = 25;
    g.levels.push_back({int(s.meshes.size()), 250});
    s.meshes.push_back(detailedBuilding(width, depth, floors, 4 + k % 3, wall));
    g.levels.push_back({int(s.meshes.size()), 6000});
    s.meshes.push_back(boxBuilding(width, depth, floors, wall));
    s.lodGroups.push_back(std::move(g));
    footprints.push_back({width, depth});
  }
  // Trees: full detail to 100 m, coarse to 400 m, a few facets to 1.5 km.
  for (int k = 0; k < kTreeKinds; ++k) {
    const Vec4 leaves{0.16f + 0.05f * float(k), 0.38f + 0.06f * float(k), 0.14f, 1};
    LodGroup g;
    g.name = "tree";
    g.fade = 15;
    g.levels.push_back({int(s.meshes.size()), 100});
    s.meshes.push_back(tree(20, 11, 10, leaves));
    g.levels.push_back({int(s.meshes.size()), 400});
    s.meshes.push_back(tree(8, 5, 4, leaves));
    g.levels.push_back({int(s.meshes.size()), 1500});
    s.meshes.push_back(tree(4, 2, 0, leaves));
    s.lodGroups.push_back(std::move(g));
  }

  // One building per block, turned by a multiple of 90°.
  std::vector<int> kindOf;
  for (int b = 0; b < p.buildings; ++b) {
    const int bx = b % side, bz = b / side;
    const int kind = int(uniform(0, kBuildingKinds)) % kBuildingKinds;
    const int turn = int(uniform(0, 4)) % 4;
    const Vec3 at{(float(bx) + 0.5f) * kBlock - extent / 2, 0,
                  (float(bz) + 0.5f) * kBlock - extent / 2};
    Instance inst;
    inst.lod = kind;
    inst.mesh = s.lodGroups[size_t(kind)].levels[0].mesh;
    inst.transform =
        Mat4::translation(at) * Mat4::rotation({0, 1, 0}, float(turn) * float(M_PI) / 2);
    s.instances.push_back(inst);
    kindOf.push_back(turn % 2 ? -1 - kind : kind);
  }
  // Trees anywhere in the city but inside a building's footprint.
  for (int t = 0; t < p.trees; ++t) {
    float x = 0, z = 0;
    for (int attempt = 0; attempt < 64; ++attempt) {
      x = float(uniform(-extent / 2, extent / 2));
      z = float(uniform(-extent / 2, extent / 2));
      const int bx = std::clamp(int((x + extent / 2) / kBlock), 0, side - 1);
      const int bz = std::clamp(int((z + extent / 2) / kBlock), 0, side - 1);
      const int b = bz * side + bx;
      if (b >= int(kindOf.size())) break;
      const Footprint f =
          footprints[size_t(kindOf[size_t(b)] < 0 ? -1 - kindOf[size_t(b)] : kindOf[size_t(b)])];
      const float hw = (kindOf[size_t(b)] < 0 ? f.depth : f.width) / 2 + 3;
      const float hd = (kindOf[size_t(b)] < 0 ? f.width : f.depth) / 2 + 3;
      const float cx = (float(bx) + 0.5f) * kBlock - extent / 2,
                  cz = (float(bz) + 0.5f) * kBlock - extent / 2;
      if (std::fabs(x - cx) > hw || std::fabs(z - cz) > hd) break;
    }
    const int kind = kBuildingKinds + int(uniform(0, kTreeKinds)) % kTreeKinds;
    const float scale = float(uniform(0.8, 1.3)), turn = float(uniform(0, 2 * M_PI));
    Instance inst;
    inst.lod = kind;
    inst.mesh = s.lodGroups[size_t(kind)].levels[0].mesh;
    inst.transform = Mat4::translation({x, 0, z}) * Mat4::rotation({0, 1, 0}, turn) *
                     Mat4::scaling({scale, scale, scale});
    s.instances.push_back(inst);
  }
  // Looking across the city from its south-west corner, 150 m up (above the tallest roofs).
  s.cameras.push_back(detail::benchCamera({-0.47f * extent, 150, 0.47f * extent},
                                          {0.2f * extent, 0, -0.2f * extent}, 60, 1, 8000));
  buildInstanceTree(s);
  return s;
}

}  // namespace sv::generators
