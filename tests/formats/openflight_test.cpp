// The OpenFlight reader (src/scene/openflight_loader.cpp): files built record by record with
// FltWriter check each record's meaning; files written by OpenSceneGraph's exporter (osgconv) from
// models of other formats, and OSG's own reading of our files, check that we read the same
// geometry as an independent implementation (triangle count, bounds and vertices).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "formats/flt_writer.h"
#include "formats/formats_test_util.h"
#include "formats/osg_peer.h"
#include "synthvis/scene.h"

namespace sv::formats {
namespace {

using testing::allTriangles;
using testing::contains;
using testing::corners;
using testing::distinct;
using testing::FltWriter;
using testing::TempDir;
using V = FltWriter::V;
using Face = FltWriter::Face;

TEST(OpenFlight, ReadsEveryNodeKind) {
  TempDir dir;
  const std::string path = dir.write("every.flt", testing::everyNodeFlt());
  Result<Scene> r = loadScene(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  // 2 + 1 + 1 + 1 + 1 + 1 + 1 + 12 triangles, every level counted.
  EXPECT_EQ(allTriangles(s), 20u);
  ASSERT_TRUE(validate(s, path).ok()) << validate(s, path).error().str();

  // The quad: moved +10 in x, y-up: OpenFlight (11, 1, 0) is synthvis (11, 0, −1).
  const auto pts = distinct(corners(s));
  EXPECT_TRUE(pts.count({11000, 1000, 0})) << "the group's matrix";
  // Its colour: red face × cyan material → the material's diffuse in baseColor, the face's red in
  // the vertex colours; lit, one-sided.
  const Mesh* quad = nullptr;
  for (const Mesh& m : s.meshes)
    if (m.name == "o" && m.material >= 0 && s.materials[size_t(m.material)].name == "cyan")
      quad = &m;
  ASSERT_NE(quad, nullptr);
  EXPECT_EQ(quad->triangleCount(), 2u);
  EXPECT_FLOAT_EQ(quad->colors[0].x, 1);
  EXPECT_FLOAT_EQ(quad->colors[0].y, 0);
  const Material& cyan = s.materials[size_t(quad->material)];
  EXPECT_FLOAT_EQ(cyan.baseColor.x, 0.5f);
  EXPECT_FALSE(cyan.doubleSided);
  EXPECT_FALSE(cyan.unlit);
  // The triangle: palette grey at full intensity, two-sided, unlit (light mode 0).
  bool grey = false;
  for (const Mesh& m : s.meshes)
    if (m.name == "o" && m.triangleCount() == 1) {
      grey = true;
      EXPECT_NEAR(m.colors[0].x, 128 / 255.0, 1e-6);
      EXPECT_TRUE(s.materials[size_t(m.material)].doubleSided);
      EXPECT_TRUE(s.materials[size_t(m.material)].unlit);
    }
  EXPECT_TRUE(grey);

  // Levels of detail: "hi" draws in [0, 100), "lo" in [100, 1000) after an empty level, with its
  // transition as the fade, both ranged to the LOD centre.
  std::vector<const LodGroup*> groups;
  for (const LodGroup& g : s.lodGroups) groups.push_back(&g);
  ASSERT_EQ(groups.size(), 2u);
  const LodGroup& hiGroup = *groups[0];
  const LodGroup& loGroup = *groups[1];
  EXPECT_EQ(hiGroup.name, "hi");
  ASSERT_EQ(hiGroup.levels.size(), 1u);
  EXPECT_FLOAT_EQ(hiGroup.levels[0].to, 100);
  ASSERT_EQ(loGroup.levels.size(), 2u);
  EXPECT_TRUE(s.meshes[size_t(loGroup.levels[0].mesh)].positions.empty());
  EXPECT_FLOAT_EQ(loGroup.levels[0].to, 100);
  EXPECT_FLOAT_EQ(loGroup.levels[1].to, 1000);
  EXPECT_FLOAT_EQ(loGroup.fade, 10);
  ASSERT_TRUE(loGroup.center.has_value());
  EXPECT_FLOAT_EQ(loGroup.center->x, 0.5f);  // in the instance's own space (the group's)

  // The switch: mask 0 draws child "a" only; mask 1 child "b".
  ASSERT_EQ(s.switches.size(), 1u);
  const Switch& sw = s.switches[0];
  EXPECT_EQ(sw.name, "sw");
  ASSERT_EQ(sw.children.size(), 2u);
  ASSERT_EQ(sw.children[0].size(), 1u);
  EXPECT_TRUE(s.instances[sw.children[0][0]].visible);
  EXPECT_FALSE(s.instances[sw.children[1][0]].visible);
  Scene t = s;
  t.switches[0].current = 1;
  applyArticulations(t);
  EXPECT_FALSE(t.instances[sw.children[0][0]].visible);
  EXPECT_TRUE(t.instances[sw.children[1][0]].visible);

  // The DOF: yaw 90° about the frame at (5, 0, 0) turns its triangle's (6, 0, .25) to (5, 1, .25)
  // before pitch; its part is articulated, and moves when the host changes the yaw.
  ASSERT_EQ(s.dofs.size(), 1u);
  const Dof& dof = s.dofs[0];
  EXPECT_FLOAT_EQ(dof.current.rotate.z, 90);
  EXPECT_FLOAT_EQ(dof.max.rotate.x, 45);
  EXPECT_FLOAT_EQ(dof.max.translate.x, 1e30f);  // not limited
  ASSERT_EQ(dof.parts.size(), 1u);
  const uint32_t part = dof.parts[0].first;
  EXPECT_TRUE(s.instances[part].articulated);
  t = s;
  t.dofs[0].current.rotate = {0, 0, 0};
  applyArticulations(t);
  const Vec3 still = t.instances[part].transform.transformPoint({6, 0, 0.25f});
  EXPECT_NEAR(still.x, 16, 1e-5);  // the group's +10 and nothing else
  t.dofs[0].current.rotate = {0, 0, 90};
  applyArticulations(t);
  const Vec3 turned = t.instances[part].transform.transformPoint({6, 0, 0.25f});
  EXPECT_NEAR(turned.x, 15, 1e-5);  // (6, 0) about (5, 0) by 90°: (5, 1) in OpenFlight's x, y
  EXPECT_NEAR(turned.z, -1, 1e-5);  // OpenFlight y 1 is synthvis z −1
  t.dofs[0].current.rotate = {0, 0, 500};  // clamped to the limit, 180°
  applyArticulations(t);
  EXPECT_NEAR(t.instances[part].transform.transformPoint({6, 0, 0.25f}).x, 14, 1e-5);
  // The instance tree leaves the articulated part out.
  ASSERT_TRUE(s.instanceTree);
  EXPECT_EQ(s.instanceTree->loose, std::vector<uint32_t>{part});

  // The light point record: three yellow omnidirectional lights.
  ASSERT_EQ(s.lightPoints.size(), 3u);
  const LightAppearance& look = s.lightAppearances[s.lightPoints[0].appearance];
  EXPECT_FLOAT_EQ(look.color.x, 1);
  EXPECT_FLOAT_EQ(look.color.z, 0);
  EXPECT_FALSE(look.directional);
  EXPECT_NEAR(s.lightPoints[2].position.x, 12, 1e-5);
  EXPECT_NEAR(s.lightPoints[2].position.y, 3, 1e-5);
}

// A scene file placing an OpenFlight model twice gets its switches, degrees of freedom and light
// points twice, each placement's own.
TEST(OpenFlight, PlacedByASceneFileKeepsItsArticulationsAndLights) {
  TempDir dir;
  dir.write("every.flt", testing::everyNodeFlt());
  const std::string sceneFile = dir.write("two.json", R"({"synthvis": 1, "objects": [
    {"mesh": "every.flt"}, {"mesh": "every.flt", "transform": {"translate": [0, 0, -50]}}]})");
  Result<Scene> r = loadScene(sceneFile);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->switches.size(), 2u);
  ASSERT_EQ(r->dofs.size(), 2u);
  ASSERT_EQ(r->lightPoints.size(), 6u);
  EXPECT_NEAR(r->lightPoints[3].position.z - r->lightPoints[0].position.z, -50, 1e-4);
  // Each switch holds its own placement's instances; the second DOF moves the second copy.
  EXPECT_NE(r->switches[0].children[0], r->switches[1].children[0]);
  const uint32_t part = r->dofs[1].parts[0].first;
  EXPECT_TRUE(r->instances[part].articulated);
  Scene t = r.value();
  t.dofs[1].current.rotate = {0, 0, 0};
  applyArticulations(t);
  EXPECT_NEAR(t.instances[part].transform.transformPoint({6, 0, 0.25f}).z, -50, 1e-4);
  ASSERT_TRUE(validate(t, sceneFile).ok());
}

// Textures: an SGI image (OpenFlight's own format) is read; one that cannot be read is named in a
// warning and its faces drawn without it. Texture coordinates run up the image in OpenFlight.
TEST(OpenFlight, ReadsSgiTexturesAndNamesMissingOnes) {
  TempDir dir;
  std::string rgb(512, '\0');
  const unsigned char head[] = {0x01, 0xDA, 0, 1, 0, 3, 0, 2, 0, 2, 0, 3};  // verbatim 2×2 RGB
  std::copy(std::begin(head), std::end(head), rgb.begin());
  rgb += std::string(12, char(200));
  dir.write("wall.rgb", rgb);
  FltWriter w;
  w.header();
  w.texture(0, "wall.rgb");
  w.texture(1, "missing.rgb");
  w.vertexPalette();
  std::vector<int32_t> v;
  for (double x : {0.0, 1.0, 0.0}) {
    V corner = V::at(x, x == 0 && v.size() == 2 ? 1 : 0, 0);
    corner.uv = std::array<float, 2>{float(x), 0.25f};
    v.push_back(w.vertex(corner));
  }
  w.push();
  w.object("o");
  w.push();
  Face textured;
  textured.texture = 0;
  w.polygon(textured, v);
  Face missing;
  missing.texture = 1;
  w.polygon(missing, v);
  w.pop();
  w.pop();
  const std::string path = dir.write("tex.flt", w.bytes);
  Result<Scene> r = loadScene(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->textures.size(), 1u);
  ASSERT_EQ(r->warnings.size(), 1u);
  EXPECT_TRUE(contains(r->warnings[0], "texture 'missing.rgb'"));
  EXPECT_TRUE(contains(r->warnings[0], "drawn without it"));
  size_t withTexture = 0;
  for (const Mesh& m : r->meshes)
    if (m.material >= 0 && r->materials[size_t(m.material)].texture == 0) {
      ++withTexture;
      ASSERT_EQ(m.uvs.size(), m.positions.size());
      EXPECT_FLOAT_EQ(m.uvs[0].y, 0.75f);  // t 0.25 up the image is v 0.75 down it
    }
  EXPECT_EQ(withTexture, 1u);
  EXPECT_EQ(r->triangleCount(), 2u);
}

// Units (feet here) become metres; a long local vertex pool arrives in continuation records.
TEST(OpenFlight, UnitsAndContinuationRecords) {
  FltWriter w;
  w.header(1640, 4);  // 16.4, feet
  w.vertexPalette();
  w.push();
  w.mesh({});
  w.push();
  std::vector<std::array<double, 3>> pool;
  std::vector<uint32_t> strip;
  for (uint32_t k = 0; k < 4000; ++k) {  // 96 000 bytes: two continuations
    pool.push_back({double(k / 2), double(k % 2), 0});
    strip.push_back(k);
  }
  w.localPool(pool);
  w.meshPrimitive(1, strip);
  w.pop();
  w.pop();
  Result<Scene> r = parseOpenFlight(w.bytes, "long.flt");
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->triangleCount(), 3998u);
  const auto [lo, hi] = r->meshes[0].bounds();
  const Vec3 far = r->instances[0].transform.transformPoint(hi);
  EXPECT_NEAR(far.x, 1999 * 0.3048, 1e-3);
}

// Instance definitions are drawn where referenced, one mesh shared; external references load the
// file once and place it; a reference back to the file is refused.
TEST(OpenFlight, InstancesAndExternalReferences) {
  TempDir dir;
  FltWriter part;
  part.header();
  part.vertexPalette();
  std::vector<int32_t> t;
  for (double x : {0.0, 1.0, 0.0})
    t.push_back(part.vertex(V::at(x, x == 0 && t.size() == 2 ? 1 : 0, 0)));
  part.push();
  part.instanceDefinition(7);
  part.push();
  part.object("def");
  part.push();
  part.polygon({}, t);
  part.pop();
  part.pop();
  part.group("one");
  part.push();
  part.instanceReference(7);
  part.pop();
  part.group("two");
  part.matrix(FltWriter::translation(0, 0, 5));
  part.push();
  part.instanceReference(7);
  part.pop();
  part.pop();
  dir.write("part.flt", part.bytes);
  Result<Scene> p = loadScene(dir.path("part.flt"));
  ASSERT_TRUE(p.ok()) << p.error().str();
  ASSERT_EQ(p->instances.size(), 2u);
  EXPECT_EQ(p->instances[0].mesh, p->instances[1].mesh);  // no copy of the vertices
  EXPECT_NEAR(p->instances[1].transform.transformPoint({0, 0, 0}).y, 5, 1e-6);  // z up is y

  FltWriter top;
  top.header(1610, 1);  // kilometres: the reference in metres is scaled down to match
  top.vertexPalette();
  top.push();
  top.group("ref");
  top.matrix(FltWriter::translation(1, 0, 0));  // 1 km east
  top.push();
  top.externalReference("part.flt");
  top.externalReference("part.flt<one>");  // a node name: warned, the whole file placed
  top.pop();
  top.pop();
  dir.write("top.flt", top.bytes);
  Result<Scene> s = loadScene(dir.path("top.flt"));
  ASSERT_TRUE(s.ok()) << s.error().str();
  EXPECT_EQ(s->instances.size(), 4u);
  EXPECT_NEAR(s->instances[1].transform.transformPoint({0, 0, 0}).x, 1000, 1e-3);
  EXPECT_NEAR(s->instances[1].transform.transformPoint({0, 0, 0}).y, 5, 1e-3);
  ASSERT_EQ(s->warnings.size(), 1u);
  EXPECT_TRUE(contains(s->warnings[0], "only whole files are referenced"));

  FltWriter loop;
  loop.header();
  loop.vertexPalette();
  loop.push();
  loop.externalReference("loop.flt");
  loop.pop();
  const std::string loopPath = dir.write("loop.flt", loop.bytes);
  Result<Scene> l = loadScene(loopPath);
  ASSERT_FALSE(l.ok());
  EXPECT_EQ(l.error().str(), loopPath + ": external reference 'loop.flt' refers back to itself");
}

// Faces drawn as lights (draw types 8–10) become light points; wireframe faces (2 closed, 3 open)
// lines along their edges; hidden faces are not drawn.
TEST(OpenFlight, LightFacesWireframesAndHiddenFaces) {
  FltWriter w;
  w.header();
  w.vertexPalette();
  std::vector<int32_t> v;
  for (double x : {0.0, 1.0, 0.5})
    v.push_back(w.vertex(V::at(x, x == 0.5 ? 1 : 0, 0, std::array<float, 3>{0, -1, 0})));
  w.push();
  w.object("o");
  w.push();
  w.polygon(Face().draw(10).rgb(0xFF00FF00u), v);  // two-way green lights
  w.polygon(Face().draw(3).rgb(0xFFFF0000u), v);
  w.polygon(Face().draw(2), v);
  w.polygon(Face().hide(), v);
  w.polygon({}, v);
  w.pop();
  w.pop();
  Result<Scene> r = parseOpenFlight(w.bytes, "lights.flt");
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->triangleCount(), 1u);
  ASSERT_EQ(r->lightPoints.size(), 3u);
  const LightAppearance& a = r->lightAppearances[r->lightPoints[0].appearance];
  EXPECT_TRUE(a.directional);
  EXPECT_TRUE(a.backLobe);
  EXPECT_FLOAT_EQ(a.color.y, 1);
  EXPECT_NEAR(a.direction.z, 1, 1e-6);  // OpenFlight −y (south) is synthvis +z
  EXPECT_TRUE(r->warnings.empty());
  // The open wireframe's 2 edges in its colour, then the closed one's 3.
  ASSERT_EQ(r->lines.size(), 5u);
  EXPECT_FLOAT_EQ(r->lines[0].color.z, 1);  // packed ABGR: 0xFFFF0000 is blue
  EXPECT_FLOAT_EQ(r->lines[0].color.x, 0);
  EXPECT_NEAR(r->lines[1].b.y, 0, 1e-6);  // (0.5, 1, 0) in OpenFlight: z-up → y-up is (x, z, −y)
  EXPECT_NEAR(r->lines[1].b.z, -1, 1e-6);
  EXPECT_NEAR(r->lines[4].a.x, 0.5, 1e-6);  // the closing edge, back to the first vertex
  EXPECT_NEAR(r->lines[4].b.x, 0, 1e-6);
}

// Indexed light points (130) take their look from the appearance palette (128) and their blinking
// from the animation palette (129): a strobe, a rotating beacon, a flashing sequence; one whose
// appearance is not in the palette, and Morse code (drawn steady), are named in warnings.
TEST(OpenFlight, IndexedLightPointsUseTheirPalettes) {
  FltWriter w;
  w.header();
  w.colorPalette({0xFF000000u, 0xFF0000FFu});                    // entry 1: red (ABGR)
  w.lightPointAppearance(3, 2.0f, 2, 1u << 7 | 127, 1.0f);       // two-way, red back at half
  w.lightPointAppearance(4, 0.5f, 0);                            // omnidirectional
  w.lightPointAnimation(7, 2, 1.0f, 0.25f, 0.1f);                // strobe: 0.1 s of every 1 s
  w.lightPointAnimation(8, 1, 4.0f, 0, 0);                       // rotating every 4 s
  w.lightPointAnimation(9, 0, 0, 0, 0, {{0, 0.2f}, {1, 0.6f}});  // on 0.2 s, off 0.6 s
  w.lightPointAnimation(10, 3, 1.0f, 0, 0.5f);                   // Morse code: drawn steady
  w.vertexPalette();
  const int32_t v = w.vertex(V::at(1, 2, 3, std::array<float, 3>{0, -1, 0}));
  w.push();
  int k = 0;
  for (auto [look, animation] : {std::pair{3, 7}, std::pair{4, 8}, std::pair{4, 9},
                                 std::pair{4, -1}, std::pair{5, -1}, std::pair{4, 10}}) {
    w.indexedLightPoint("lp" + std::to_string(k++), look, animation);
    w.push();
    w.vertexList({v});
    w.pop();
  }
  w.pop();
  Result<Scene> r = parseOpenFlight(w.bytes, "indexed.flt");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->lightPoints.size(), 5u);
  auto look = [&](size_t i) -> const LightAppearance& {
    return r->lightAppearances[r->lightPoints[i].appearance];
  };
  EXPECT_FLOAT_EQ(look(0).intensity, 400);  // 2 × the full 200 cd
  EXPECT_TRUE(look(0).directional);
  EXPECT_TRUE(look(0).backLobe);
  EXPECT_NEAR(look(0).backColor.x, 0.5, 1e-6);  // red at half the front's intensity
  EXPECT_NEAR(look(0).backColor.y, 0, 1e-6);
  EXPECT_FLOAT_EQ(look(0).blink.period, 1);
  EXPECT_FLOAT_EQ(look(0).blink.onFraction, 0.1f);
  EXPECT_FLOAT_EQ(look(0).blink.phase, 0.25f);
  EXPECT_FALSE(look(1).directional);
  EXPECT_FLOAT_EQ(look(1).intensity, 100);
  EXPECT_FLOAT_EQ(look(1).rotationPeriod, 4);
  EXPECT_FLOAT_EQ(look(2).blink.period, 0.8f);
  EXPECT_FLOAT_EQ(look(2).blink.onFraction, 0.25f);
  EXPECT_FLOAT_EQ(look(3).blink.period, 0);
  EXPECT_NEAR(r->lightPoints[3].position.z, -2, 1e-6);  // OpenFlight y north is −z
  EXPECT_FLOAT_EQ(look(4).blink.period, 0);
  ASSERT_EQ(r->warnings.size(), 2u);
  EXPECT_EQ(r->warnings[0],
            "indexed.flt: 1 indexed light point (its appearance not in the palette) record not "
            "drawn");
  EXPECT_EQ(r->warnings[1],
            "indexed.flt: 1 light point record animated by Morse code drawn steady");
}

// A switch without masks draws all its children, whatever its current-mask field holds (a fuzzed
// file with 62 there loaded as a scene that failed validation).
TEST(OpenFlight, ASwitchWithoutMasksDrawsEveryChild) {
  FltWriter w;
  w.header();
  w.vertexPalette();
  std::vector<int32_t> tri;
  for (double x : {0.0, 1.0, 0.5})
    tri.push_back(w.vertex(FltWriter::V::at(x, x == 0.5 ? 1 : 0, 0)));
  w.push();
  w.switchNode("sw", 62, {});
  w.push();
  for (const char* name : {"a", "b"}) {
    w.object(name);
    w.push();
    w.polygon({}, tri);
    w.pop();
  }
  w.pop();
  w.pop();
  Result<Scene> r = parseOpenFlight(w.bytes, "switch.flt");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->switches.size(), 1u);
  EXPECT_EQ(r->switches[0].current, 0u);
  EXPECT_TRUE(validate(r.value(), "switch.flt").ok())
      << validate(r.value(), "switch.flt").error().str();
  for (const std::vector<uint32_t>& child : r->switches[0].children)
    for (uint32_t k : child) EXPECT_TRUE(r->instances[k].visible);
}

// Malformed files: one line naming the file and the problem.
TEST(OpenFlight, RefusesMalformedFiles) {
  auto error = [](const std::string& bytes) {
    Result<Scene> r = parseOpenFlight(bytes, "bad.flt");
    return r.ok() ? std::string("(loaded)") : r.error().str();
  };
  EXPECT_EQ(error("glTF"),
            "bad.flt: record at byte 0 (opcode 26476) runs past the end of the file");
  EXPECT_EQ(error(std::string("\0\2\0\4", 4)),
            "bad.flt: not an OpenFlight file (it does not begin with a header record)");
  FltWriter old;
  old.header(1420);
  EXPECT_EQ(error(old.bytes),
            "bad.flt: OpenFlight revision 14.2 is not supported (15.0 to 16.x are; format code "
            "1420)");
  FltWriter pop;
  pop.header();
  pop.pop();
  EXPECT_EQ(error(pop.bytes), "bad.flt: pop record at byte 324 without a push");
  FltWriter missing;
  missing.header();
  missing.vertexPalette();
  missing.push();
  missing.polygon({}, {8, 48, 88});
  missing.pop();
  EXPECT_TRUE(contains(error(missing.bytes), "no vertex at palette offset 8"));
  FltWriter prim;
  prim.header();
  prim.push();
  prim.mesh({});
  prim.push();
  prim.localPool({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  prim.meshPrimitive(9, {0, 1, 2});
  prim.meshPrimitive(1, {0, 1, 3});
  prim.pop();
  prim.pop();
  EXPECT_TRUE(contains(error(prim.bytes), "unknown type 9"));
  FltWriter whole;
  whole.header();
  EXPECT_TRUE(contains(error(whole.bytes.substr(0, 100)), "runs past the end of the file"));
  FltWriter deep;
  deep.header();
  for (int k = 0; k < 200; ++k) deep.group("g"), deep.push();
  EXPECT_TRUE(contains(error(deep.bytes), "nesting deeper than 128 levels"));
  // A switch of 2^25 masks of no words and no children: its record holds none of their bits, so
  // its size did not bound them, and each placed an empty mask (a fuzzed file of 972 bytes asked
  // for 2.7 GB). Every mask counts against the loader's bound on mask flags.
  FltWriter masks;
  masks.header();
  masks.push();
  masks.switchNode("sw", 0, {}, 1 << 25, 0);
  masks.pop();
  EXPECT_EQ(error(masks.bytes), "bad.flt: switches hold more than 16777216 mask flags");
  // A degree of freedom placed beyond float's range (finite in the file's doubles), directly or
  // through a matrix above it: refused rather than loaded as a scene its validation fails.
  for (bool byMatrix : {false, true}) {
    FltWriter far;
    far.header();
    far.push();
    if (byMatrix)  // two translations by 3e38 each: finite floats, their sum is not
      for (int k = 0; k < 2; ++k) {
        far.group("g");
        far.matrix(FltWriter::translation(3e38f, 0, 0));
        far.push();
      }
    const double at = byMatrix ? 0 : 1e300;
    far.dof("d", {at, 0, 0}, {at + 1, 0, 0}, {at, 1, 0}, {});
    far.push();
    far.object("o");
    far.pop();
    if (byMatrix) far.pop(), far.pop();
    far.pop();
    EXPECT_TRUE(contains(error(far.bytes), "its frame lies beyond float's range"))
        << error(far.bytes);
  }
}

// --- OpenSceneGraph as the peer (its osgconv tool, Debian's openscenegraph) -------------------

// Our reading of `flt` against OSG's (osgconv flt → obj): the same triangle count, bounds and
// distinct vertices.
void expectSameAsOsg(const std::string& flt, const TempDir& dir, const std::string& name) {
  const testing::PeerComparison c = testing::compareWithOsg(flt, dir.path(name + "-osg.obj"));
  ASSERT_TRUE(c.error.empty()) << name << ": " << c.error;
  EXPECT_EQ(c.ours, c.theirs) << name << ": triangles";
  EXPECT_LE(c.boundsDifference, 1e-3) << name << ": bounds";
  EXPECT_EQ(c.verticesOnlyOurs + c.verticesOnlyTheirs, 0u) << name << ": vertices";
}

class OpenFlightPeer : public ::testing::Test {
 protected:
  void SetUp() override {
    if (testing::haveOsgconv()) return;
    const char* allow = std::getenv("SV_ALLOW_MISSING_DATA");
    if (allow && std::string(allow) == "1") GTEST_SKIP() << "osgconv is missing";
    FAIL() << "osgconv (Debian's openscenegraph) is missing: run scripts/test, which installs it, "
              "or set SV_ALLOW_MISSING_DATA=1 to skip";
  }
};

// OSG reads the file we build record by record as we do (every level, every switch child, the
// DOF at its current values; light points are not geometry).
TEST_F(OpenFlightPeer, OsgReadsOurFilesAsWeDo) {
  TempDir dir;
  expectSameAsOsg(dir.write("every.flt", testing::everyNodeFlt()), dir, "every");
}

// Files written by OSG's OpenFlight exporter from other formats read back as OSG reads them.
TEST_F(OpenFlightPeer, WeReadOsgExportsAsOsgDoes) {
  TempDir dir;
  // The house of scenes/ (OBJ with materials) and a concave, textured, many-sided OBJ.
  const std::string house = dir.path("house.flt");
  ASSERT_TRUE(testing::osgconv(testing::sourcePath("scenes/house.obj"), house));
  expectSameAsOsg(house, dir, "house");
  std::ostringstream obj;
  obj << "mtllib m.mtl\nusemtl t\n";
  for (int k = 0; k < 12; ++k) {
    const double a = k * M_PI / 6, r = k % 2 ? 1.0 : 2.0;
    obj << "v " << r * std::cos(a) << " " << r * std::sin(a) << " 0.5\n";
    obj << "vt " << 0.5 + 0.25 * r * std::cos(a) << " " << 0.5 + 0.25 * r * std::sin(a) << "\n";
  }
  obj << "f";
  for (int k = 1; k <= 12; ++k) obj << " " << k << "/" << k;
  obj << "\nv 0 0 3\nv 1 0 3\nv 0 1 3\nvt 0 0\nf 13/13 14/13 15/13\n";
  dir.write("star.obj", obj.str());
  dir.write("m.mtl", "newmtl t\nKd 0.2 0.8 0.3\n");
  const std::string star = dir.path("star.flt");
  ASSERT_TRUE(testing::osgconv(dir.path("star.obj"), star));
  expectSameAsOsg(star, dir, "star");
}

}  // namespace
}  // namespace sv::formats
