// The traversal stage (SPEC §1; render/traversal.h): levels of detail switch at the stated
// ranges and dissolve across the switch pixel by pixel; culling (the instance tree, instance by
// instance) never changes a pixel of the full draw at the chosen levels; instances draw as copies
// of their mesh would; the same bits for any thread count.
#include "traversal/traversal.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <set>

#include "formats/primitives.h"
#include "synthvis/generators.h"
#include "synthvis/render.h"

namespace sv {
namespace {

constexpr uint8_t kRed[3] = {255, 0, 0}, kGreen[3] = {0, 255, 0}, kBlue[3] = {0, 0, 255};

// A 100 m square facing +z at the origin, in three unlit colours as three levels of detail (to
// 10, 20 and 30 m, with `fade` metres of dissolve below each), and the camera on the +z axis at
// `distance`, looking at it (60° vertical field of view: ranges are distances).
scene::Scene lodScene(float distance, float fade) {
  scene::Scene s;
  for (Vec4 c : {Vec4{1, 0, 0, 1}, Vec4{0, 1, 0, 1}, Vec4{0, 0, 1, 1}}) {
    scene::Material m;
    m.baseColor = c;
    m.unlit = true;
    m.doubleSided = true;
    s.materials.push_back(m);
    scene::Mesh square = formats::detail::makePlane(100, 100, 1, 1);
    for (Vec3& p : square.positions) p = {p.x, -p.z, 0};
    square.normals.clear();
    square.material = int(s.meshes.size());
    s.meshes.push_back(square);
  }
  scene::LodGroup g;
  g.fade = fade;
  g.levels = {{0, 10}, {1, 20}, {2, 30}};
  s.lodGroups.push_back(g);
  scene::Instance inst;
  inst.mesh = 0;
  inst.lod = 0;
  s.instances.push_back(inst);
  scene::Camera cam;
  cam.position = {0, 0, distance};
  cam.target = {0, 0, 0};
  cam.znear = 0.1f;
  cam.zfar = 100;
  s.cameras.push_back(cam);
  s.background = {0, 0, 0};
  return s;
}

// How many pixels of `img` are exactly `rgb`.
size_t count(const Image& img, const uint8_t* rgb) {
  size_t n = 0;
  for (size_t i = 0; i < img.rgb.size(); i += 3)
    n += img.rgb[i] == rgb[0] && img.rgb[i + 1] == rgb[1] && img.rgb[i + 2] == rgb[2];
  return n;
}

Image render(const scene::Scene& s, RenderOptions o, FrameStats* stats = nullptr) {
  Image img;
  EXPECT_TRUE(Renderer(o).render(s, img, stats).ok());
  return img;
}

RenderOptions small() {
  RenderOptions o;
  o.width = 64;
  o.height = 48;
  o.threads = 2;
  return o;
}

TEST(Traversal, DoorPatternsSplitEveryBlockByTheBayerOrder) {
  for (int k = 0; k <= 16; ++k) {
    EXPECT_EQ(std::popcount(traversal::doorPattern(k)), k);
    if (k < 16) {
      EXPECT_EQ(traversal::doorPattern(k) & ~traversal::doorPattern(k + 1), 0) << k;
    }
  }
  EXPECT_EQ(traversal::doorPattern(16), 0xFFFF);
}

TEST(Traversal, LevelsSwitchAtTheStatedRanges) {
  const RenderOptions o = small();
  const size_t all = size_t(o.width) * o.height;
  struct Case {
    float distance;
    const uint8_t* color;  // nullptr: nothing drawn
    int level;
  };
  for (const Case c : {Case{9.9f, kRed, 0}, Case{10.1f, kGreen, 1}, Case{19.9f, kGreen, 1},
                       Case{20.1f, kBlue, 2}, Case{29.9f, kBlue, 2}, Case{30.1f, nullptr, -1}}) {
    FrameStats stats;
    const Image img = render(lodScene(c.distance, 0), o, &stats);
    if (c.color) {
      EXPECT_EQ(count(img, c.color), all) << c.distance;
      EXPECT_EQ(stats.lodDrawn[c.level], 1u) << c.distance;
    } else {
      EXPECT_EQ(stats.lodBeyond, 1u);
      EXPECT_EQ(stats.drawn, 0u);
    }
  }
  // The scale multiplies the range; a zoomed view (30°) divides it by tan 30° / tan 15°.
  RenderOptions scaled = o;
  scaled.lodScale = 2;
  EXPECT_EQ(count(render(lodScene(6, 0), scaled), kGreen), all);
  scene::Scene zoomed = lodScene(15, 0);
  zoomed.cameras[0].yfovDegrees = 30;
  EXPECT_EQ(count(render(zoomed, o), kRed), all);  // range 15·0.464 = 6.96
  // Without levels of detail: level 0 at every range.
  RenderOptions full = o;
  full.lod = false;
  EXPECT_EQ(count(render(lodScene(35, 0), full), kRed), all);
}

// Across the fade band below a switch, k of every 16 pixels (a screen-aligned 4×4 block) belong to
// the next level — or to nothing after the last — and every pixel is drawn by exactly one level,
// with and without anti-aliasing and masking.
TEST(Traversal, LevelsDissolvePixelByPixelAcrossTheFade) {
  for (int samples : {1, 16})
    for (auto hsr : {RenderOptions::Hsr::zbuffer, RenderOptions::Hsr::hybrid}) {
      RenderOptions o = small();
      o.samples = samples;
      o.hsr = hsr;
      const size_t all = size_t(o.width) * o.height;
      for (int k : {1, 5, 12}) {
        // Range 6 + 4·k/16 in the band [6, 10): k/16 of the way.
        FrameStats stats;
        const Image img = render(lodScene(6 + 4.0f * float(k) / 16, 4), o, &stats);
        EXPECT_EQ(count(img, kGreen), all * size_t(k) / 16) << k << " " << samples;
        EXPECT_EQ(count(img, kRed), all * size_t(16 - k) / 16) << k << " " << samples;
        EXPECT_EQ(stats.lodDissolving, 1u);
        EXPECT_EQ(stats.lodDrawn[0] + stats.lodDrawn[1], 2u);
        // After the last level: into the background.
        const Image last = render(lodScene(26 + 4.0f * float(k) / 16, 4), o);
        EXPECT_EQ(count(last, kBlue), all * size_t(16 - k) / 16) << k;
        EXPECT_EQ(count(last, kBlue) + count(last, std::array<uint8_t, 3>{0, 0, 0}.data()), all);
      }
    }
}

// The city (BENCH.md) at a small size: culling through the tree and instance by instance changes
// no pixel of the full draw at the levels chosen, the levels are in use, and the image has the
// same bits with 1, 2 and 3 threads.
TEST(Traversal, CullingChangesNoPixelOfTheDrawAtTheChosenLevels) {
  generators::CityParams p;
  p.buildings = 64;
  p.trees = 600;
  scene::Scene city = generators::generateCity(p);
  // Low over the town, so that every level and the culling are in play.
  city.cameras[0].position = {-120, 12, 120};
  city.cameras[0].target = {40, 0, -30};
  ASSERT_TRUE(city.instanceTree);
  RenderOptions o;
  o.width = 320;
  o.height = 180;
  o.threads = 2;
  for (int samples : {1, 4}) {
    o.samples = samples;
    o.cullInstances = true;
    FrameStats culled, full;
    const Image withCulling = render(city, o, &culled);
    o.cullInstances = false;
    const Image without = render(city, o, &full);
    EXPECT_EQ(withCulling.rgb, without.rgb) << samples;
    EXPECT_GT(culled.culledInstances, 0u);
    EXPECT_EQ(full.culledInstances, 0u);
    EXPECT_GT(culled.lodDrawn[0], 0u);
    EXPECT_GT(culled.lodDrawn[1], 0u);
    EXPECT_GT(culled.lodDissolving, 0u);
    EXPECT_EQ(culled.drawn, full.drawn);
    o.cullInstances = true;
    for (int threads : {1, 3}) {
      o.threads = threads;
      EXPECT_EQ(render(city, o).rgb, withCulling.rgb) << threads << " threads";
    }
    o.threads = 2;
  }
}

// One mesh placed many times draws exactly as many copies of it would.
TEST(Traversal, InstancesDrawAsCopiesOfTheirMesh) {
  scene::Scene shared;
  scene::Mesh sphere = formats::detail::makeSphere(0.4f, 12, 8);
  shared.meshes.push_back(sphere);
  shared.cameras.push_back({});
  shared.cameras[0].position = {0, 2, 6};
  scene::Scene copies = shared;
  copies.meshes.clear();
  for (int i = 0; i < 30; ++i) {
    const Mat4 at = Mat4::translation({float(i % 6) - 2.5f, 0, -float(i / 6)});
    shared.instances.push_back({0, at});
    copies.meshes.push_back(sphere);
    copies.instances.push_back({i, at});
  }
  const RenderOptions o = small();
  EXPECT_EQ(render(shared, o).rgb, render(copies, o).rgb);
}

// The tree holds every instance once, leaves of at most 8, and each node's box holds its
// children's and its instances' world boxes.
TEST(Traversal, TheInstanceTreeBoundsEveryInstanceOnce) {
  generators::CityParams p;
  p.buildings = 50;
  p.trees = 777;
  const scene::Scene city = generators::generateCity(p);
  const scene::InstanceTree& t = *city.instanceTree;
  ASSERT_EQ(t.instanceCount, city.instances.size());
  EXPECT_EQ(std::set<uint32_t>(t.order.begin(), t.order.end()).size(), city.instances.size());
  const std::vector<std::array<Vec3, 2>> meshBounds = scene::meshBounds(city);
  auto inside = [](Vec3 q, const scene::InstanceTree::Node& n) {
    const float e = 1e-3f;
    return q.x >= n.lo.x - e && q.y >= n.lo.y - e && q.z >= n.lo.z - e && q.x <= n.hi.x + e &&
           q.y <= n.hi.y + e && q.z <= n.hi.z + e;
  };
  size_t leaves = 0;
  for (const scene::InstanceTree::Node& n : t.nodes) {
    if (n.count == 0) {
      for (uint32_t c : {n.first, n.first + 1}) {
        EXPECT_TRUE(inside(t.nodes[c].lo, n) && inside(t.nodes[c].hi, n));
      }
      continue;
    }
    ++leaves;
    EXPECT_LE(n.count, 8u);
    for (uint32_t i = n.first; i < n.first + n.count; ++i) {
      const scene::Instance& inst = city.instances[t.order[i]];
      const auto [lo, hi] = scene::instanceBounds(city, inst, meshBounds);
      for (int c = 0; c < 8; ++c)
        EXPECT_TRUE(inside(inst.transform.transformPoint(
                               {c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z}),
                           n));
    }
  }
  EXPECT_GE(leaves, city.instances.size() / 8);
}

// Hierarchical levels of detail (InstanceTree::Cell): a 6 × 6 grid of instances 1.2 m apart whose
// level 1 (at any range) is a 12-triangle box and level 0 (to `near` m) a sphere, lit, seen from
// `distance` m. Its tree merges the boxes by cells of 5 m: four cells, of 16, 8, 8 and 4.
scene::Scene gridScene(float distance, float near = 10) {
  scene::Scene s;
  scene::Material m;
  m.baseColor = {0.8f, 0.6f, 0.3f, 1};
  s.materials.push_back(m);
  scene::Mesh sphere = formats::detail::makeSphere(0.4f, 12, 8);
  sphere.material = 0;
  s.meshes.push_back(sphere);
  scene::Mesh box = formats::detail::makeBox({0.7f, 0.9f, 0.5f});
  box.material = 0;
  s.meshes.push_back(box);
  scene::LodGroup g;
  g.levels = {{0, near}, {1, 1e30f}};
  s.lodGroups.push_back(g);
  for (int i = 0; i < 36; ++i) {
    scene::Instance inst;
    inst.mesh = 0;
    inst.lod = 0;
    inst.transform =
        Mat4::translation({0.3f + 1.2f * float(i % 6), 0, -0.3f - 1.2f * float(i / 6)}) *
        Mat4::rotation({0, 1, 0}, 0.3f * float(i)) *
        Mat4::scaling({1 + 0.05f * float(i % 5), 1, 1});
    s.instances.push_back(inst);
  }
  scene::Camera cam;
  cam.position = {3.3f - 0.3f * distance, 0.5f * distance, 0.8f * distance};
  cam.target = {3.3f, 0, -3.3f};
  cam.znear = 0.1f;
  cam.zfar = 2000;
  s.cameras.push_back(cam);
  scene::buildInstanceTree(s);
  return s;
}

// Drawn merged, the instances' far levels are the cells' meshes: the same image as one instance
// of each cell's mesh (its vertices placed at load time), bit for bit, for any thread count.
TEST(MergedCells, DrawAsTheirMeshesPlacedInTheWorld) {
  const scene::Scene grid = gridScene(12);
  const scene::InstanceTree& tree = *grid.instanceTree;
  ASSERT_EQ(tree.cells.size(), 4u);
  EXPECT_EQ(tree.members.size(), 36u);
  scene::Scene placed = grid;
  placed.instances.clear();
  placed.lodGroups.clear();
  placed.meshes.clear();
  for (const scene::InstanceTree::Cell& cell : tree.cells) {
    placed.instances.push_back({int(placed.meshes.size()), Mat4{}});
    placed.meshes.push_back(cell.mesh);
  }
  scene::buildInstanceTree(placed);
  EXPECT_TRUE(placed.instanceTree->cells.empty());  // no levels of detail: nothing to merge
  RenderOptions o = small();
  FrameStats merged, plain;
  const Image image = render(grid, o, &merged);
  EXPECT_EQ(image.rgb, render(placed, o, &plain).rgb);
  EXPECT_EQ(merged.mergedCells, tree.cells.size());
  EXPECT_EQ(merged.mergedInstances, 36u);
  EXPECT_EQ(merged.lodDrawn[1], 36u);
  EXPECT_EQ(merged.drawn, plain.drawn);
  EXPECT_GT(merged.drawn, 100u);
  for (int threads : {1, 3}) {
    o.threads = threads;
    EXPECT_EQ(render(grid, o).rgb, image.rgb) << threads << " threads";
  }
}

// Against each member drawn on its own, only the rounding of the vertices' placement differs: the
// same levels, nearly every pixel the same.
TEST(MergedCells, DifferFromTheirMembersOnlyInRounding) {
  const scene::Scene grid = gridScene(12);
  RenderOptions o = small();
  o.width = 320;
  o.height = 240;
  FrameStats merged, members;
  const Image a = render(grid, o, &merged);
  o.mergeCells = false;
  const Image b = render(grid, o, &members);
  EXPECT_EQ(members.mergedCells, 0u);
  EXPECT_EQ(merged.lodDrawn[1], members.lodDrawn[1]);
  size_t differ = 0, covered = 0;
  const uint8_t background[3] = {uint8_t(a.rgb[0]), uint8_t(a.rgb[1]), uint8_t(a.rgb[2])};
  for (size_t i = 0; i < a.rgb.size(); i += 3) {
    differ += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2];
    covered +=
        b.rgb[i] != background[0] || b.rgb[i + 1] != background[1] || b.rgb[i + 2] != background[2];
  }
  EXPECT_GT(covered, 3000u);
  EXPECT_LT(differ, covered / 100) << differ << " of " << covered << " covered pixels differ";
  // Under masking, objects are drawn nearest first, which a cell is not: never merged.
  o.mergeCells = true;
  o.hsr = RenderOptions::Hsr::priority;
  FrameStats masked;
  render(grid, o, &masked);
  EXPECT_EQ(masked.mergedCells, 0u);
}

// A cell is drawn only where every member draws its level alone: not while one is still at level
// 0 nearer the eye, nor while one is switched off.
TEST(MergedCells, OnlyWhereEveryMemberDrawsTheLevelAlone) {
  RenderOptions o = small();
  // The near switch at 12.5 m: the grid's nearer members are at level 0, its farther at level 1.
  const scene::Scene straddling = gridScene(12, 12.5f);
  FrameStats merged, members;
  const Image a = render(straddling, o, &merged);
  o.mergeCells = false;
  EXPECT_EQ(render(straddling, o, &members).rgb.size(), a.rgb.size());
  EXPECT_GT(members.lodDrawn[0], 0u);
  EXPECT_GT(members.lodDrawn[1], 0u);
  EXPECT_EQ(merged.lodDrawn[0], members.lodDrawn[0]);
  EXPECT_EQ(merged.lodDrawn[1], members.lodDrawn[1]);
  EXPECT_LT(merged.mergedInstances, members.lodDrawn[1]);
  o.mergeCells = true;
  scene::Scene switched = gridScene(12);
  const scene::InstanceTree::Cell& first = switched.instanceTree->cells[0];
  switched.instances[switched.instanceTree->members[first.firstMember]].visible = false;
  FrameStats off;
  render(switched, o, &off);
  EXPECT_EQ(off.mergedCells, switched.instanceTree->cells.size() - 1);
  EXPECT_EQ(off.mergedInstances, 36u - first.memberCount);
  EXPECT_EQ(off.lodDrawn[1], 35u);
}

// Beyond their last level, the members of a cell are counted as the visit counts them, without
// being visited; a cell nearer than that is left to its members.
TEST(MergedCells, CountMembersBeyondTheLastLevelWithoutVisitingThem) {
  scene::Scene grid = gridScene(60);
  grid.lodGroups[0].levels[1].to = 40;
  scene::buildInstanceTree(grid);
  ASSERT_EQ(grid.instanceTree->cells.size(), 5u);  // the four cells, and one beyond 40 m
  const scene::InstanceTree::Cell& beyond = grid.instanceTree->cells.back();
  EXPECT_TRUE(beyond.beyond);
  EXPECT_EQ(beyond.memberCount, 36u);
  EXPECT_TRUE(beyond.mesh.positions.empty());
  RenderOptions o = small();
  for (float distance : {60.0f, 30.0f}) {  // all beyond 40 m, then none
    grid.cameras[0].position = {3.3f - 0.3f * distance, 0.5f * distance, 0.8f * distance};
    FrameStats merged, members;
    const Image a = render(grid, o, &merged);
    o.mergeCells = false;
    EXPECT_EQ(render(grid, o, &members).rgb.size(), a.rgb.size());
    o.mergeCells = true;
    EXPECT_EQ(merged.lodBeyond, distance > 40 ? 36u : 0u);
    EXPECT_EQ(merged.lodBeyond, members.lodBeyond);
    EXPECT_EQ(merged.culledInstances, members.culledInstances);
    EXPECT_EQ(merged.trianglesIn, members.trianglesIn);
    EXPECT_EQ(merged.culledOutside, members.culledOutside);
    EXPECT_EQ(merged.mergedCells, distance > 40 ? 0u : 4u);
  }
}

// What is merged: levels beyond the first of at most kMergeTriangles triangles, not translucent,
// in cells of two or more; every member once a level, in instance order within its cell.
TEST(MergedCells, MergeOnlySmallOpaqueFarLevels) {
  scene::Scene grid = gridScene(12);
  EXPECT_EQ(grid.instanceTree->cells[0].level, 1);
  for (const scene::InstanceTree::Cell& cell : grid.instanceTree->cells) {
    EXPECT_GE(cell.memberCount, 2u);
    EXPECT_EQ(cell.mesh.triangleCount(), 12u * cell.memberCount);
    for (uint32_t k = 1; k < cell.memberCount; ++k)
      EXPECT_LT(grid.instanceTree->members[cell.firstMember + k - 1],
                grid.instanceTree->members[cell.firstMember + k]);
  }
  grid.meshes[1] = formats::detail::makeSphere(0.4f, 6, 4);  // 36 triangles: a draw of its own
  ASSERT_GT(grid.meshes[1].triangleCount(), scene::kMergeTriangles);
  scene::buildInstanceTree(grid);
  EXPECT_TRUE(grid.instanceTree->cells.empty());
  grid.meshes[1] = formats::detail::makeBox({0.7f, 0.9f, 0.5f});
  grid.meshes[1].material = 0;
  grid.materials[0].alphaMode = scene::AlphaMode::blend;  // sorted far to near: not merged
  scene::buildInstanceTree(grid);
  EXPECT_TRUE(grid.instanceTree->cells.empty());
  grid.materials[0].alphaMode = scene::AlphaMode::opaque;
  grid.instances.resize(1);  // alone: nothing saved
  scene::buildInstanceTree(grid);
  EXPECT_TRUE(grid.instanceTree->cells.empty());
}

}  // namespace
}  // namespace sv

namespace sv {
namespace {

// A scene without cameras is seen from an oblique three-quarter direction: a flat model lying in
// any axis plane covers pixels (issue 32: one in the x = 0 plane was seen edge-on, as nothing).
TEST(DefaultCamera, SeesAFlatModelInEveryAxisPlane) {
  for (int axis = 0; axis < 3; ++axis) {
    scene::Scene s;
    scene::Mesh square = formats::detail::makePlane(2, 2, 1, 1);  // in y = 0
    for (Vec3& p : square.positions)
      p = axis == 0 ? Vec3{0, p.x, p.z} : axis == 1 ? p : Vec3{p.x, p.z, 0};
    square.normals.clear();
    scene::Material m;
    m.doubleSided = true;
    m.unlit = true;
    s.materials.push_back(m);
    square.material = 0;
    s.meshes.push_back(square);
    s.instances.push_back({0, Mat4{}});
    s.background = {0, 0, 0};
    RenderOptions o = small();
    const Image img = render(s, o);
    const size_t white = count(img, std::array<uint8_t, 3>{255, 255, 255}.data());
    EXPECT_GT(white, size_t(o.width) * o.height / 20) << "axis " << axis;
  }
}

}  // namespace
}  // namespace sv
