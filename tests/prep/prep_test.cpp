// The database preparation system (src/prep) and the prepared database (src/scene/database.cpp):
// a database holds back exactly the scene it was given; a prepared database renders
// bit-identically to its source (with levels of detail off, and wherever level 0 is drawn);
// generated levels shrink and switch at increasing ranges; a damaged file is refused by name.
#include "synthvis/prep.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "formats/flt_writer.h"
#include "formats/primitives.h"
#include "synthvis/formats.h"
#include "synthvis/generators.h"
#include "synthvis/height_field.h"
#include "synthvis/render.h"
#include "synthvis/scene.h"

namespace sv::prep {
namespace {

namespace fs = std::filesystem;

struct TempFile {
  std::string path;
  explicit TempFile(const std::string& name) {
    std::random_device r;
    path = (fs::temp_directory_path() / ("synthvis_prep_" + std::to_string(r()) + "_" + name))
               .string();
  }
  ~TempFile() {
    std::error_code ec;
    fs::remove(path, ec);
  }
};

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// A scene with a dense sphere and torus (levels to generate), a checker ground, a textured box,
// light points, a switch and a degree of freedom (from an OpenFlight file), channels and fog.
scene::Scene richScene() {
  TempFile flt("every.flt");
  writeBytes(flt.path, formats::testing::everyNodeFlt());
  Result<scene::Scene> loaded = formats::loadScene(flt.path);
  EXPECT_TRUE(loaded.ok()) << loaded.error().str();
  scene::Scene s = std::move(loaded.value());
  auto place = [&](scene::Mesh m, Mat4 at, int material) {
    m.material = material;
    s.meshes.push_back(std::move(m));
    s.instances.push_back({int(s.meshes.size() - 1), at, 0, -1});
  };
  scene::Material red;
  red.name = "red";
  red.baseColor = {0.7f, 0.1f, 0.05f, 1};
  s.materials.push_back(red);
  const int redIndex = int(s.materials.size() - 1);
  place(formats::detail::makeSphere(1, 96, 48), Mat4::translation({0, 1, -4}), redIndex);
  place(formats::detail::makeSphere(1, 96, 48), Mat4::translation({3, 1, -60}), redIndex);
  place(formats::detail::makeTorus(1.5f, 0.4f, 96, 32), Mat4::translation({-3, 1, -20}), -1);
  place(formats::detail::makeChecker(60, 200, 12, 40, {0.8f, 0.8f, 0.8f, 1}, {0.3f, 0.3f, 0.3f, 1}),
        Mat4::translation({0, 0, -80}), -1);
  scene::Camera cam;
  cam.position = {2, 3, 8};
  cam.target = {0, 1, -20};
  cam.zfar = 500;
  s.cameras.insert(s.cameras.begin(), cam);
  s.fog.enabled = true;
  s.fog.beta = 0.004f;
  s.channels = scene::arcChannels(2, 90, 160, 90);
  // A wireframe square on the ground, drawn by the line pass.
  const Vec3 square[4] = {{-4, 0.01f, -10}, {4, 0.01f, -10}, {4, 0.01f, -18}, {-4, 0.01f, -18}};
  for (int k = 0; k < 4; ++k) s.lines.push_back({square[k], square[(k + 1) % 4], {1, 0.8f, 0.1f}});
  s.lineSettings.width = 1.5f;
  scene::buildInstanceTree(s);
  return s;
}

// The scene from its first camera (its channels left out), 320 × 180, as its RGB bytes.
std::vector<uint8_t> render(const scene::Scene& s, bool lod) {
  RenderOptions o;
  o.width = 320;
  o.height = 180;
  o.threads = 2;
  o.lod = lod;
  Image img;
  scene::Scene one = s;
  one.channels.clear();
  EXPECT_TRUE(Renderer(o).render(one, img).ok());
  return img.rgb;
}

void expectSameScene(const scene::Scene& a, const scene::Scene& b) {
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    const scene::Mesh &x = a.meshes[i], &y = b.meshes[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.material, y.material);
    EXPECT_EQ(x.indices, y.indices);
    ASSERT_EQ(x.positions.size(), y.positions.size());
    if (!x.positions.empty()) {
      EXPECT_EQ(0, std::memcmp(x.positions.data(), y.positions.data(), x.positions.size() * 12));
    }
    EXPECT_EQ(x.normals.size(), y.normals.size());
    EXPECT_EQ(x.colors.size(), y.colors.size());
    EXPECT_EQ(x.uvs.size(), y.uvs.size());
  }
  ASSERT_EQ(a.instances.size(), b.instances.size());
  for (size_t i = 0; i < a.instances.size(); ++i) {
    EXPECT_EQ(a.instances[i].mesh, b.instances[i].mesh);
    EXPECT_EQ(a.instances[i].transform, b.instances[i].transform);
    EXPECT_EQ(a.instances[i].lod, b.instances[i].lod);
    EXPECT_EQ(a.instances[i].visible, b.instances[i].visible);
    EXPECT_EQ(a.instances[i].articulated, b.instances[i].articulated);
  }
  ASSERT_EQ(a.lodGroups.size(), b.lodGroups.size());
  for (size_t i = 0; i < a.lodGroups.size(); ++i) {
    EXPECT_EQ(a.lodGroups[i].fade, b.lodGroups[i].fade);
    EXPECT_EQ(a.lodGroups[i].center.has_value(), b.lodGroups[i].center.has_value());
    ASSERT_EQ(a.lodGroups[i].levels.size(), b.lodGroups[i].levels.size());
    for (size_t k = 0; k < a.lodGroups[i].levels.size(); ++k) {
      EXPECT_EQ(a.lodGroups[i].levels[k].mesh, b.lodGroups[i].levels[k].mesh);
      EXPECT_EQ(a.lodGroups[i].levels[k].to, b.lodGroups[i].levels[k].to);
    }
  }
  ASSERT_EQ(a.switches.size(), b.switches.size());
  for (size_t i = 0; i < a.switches.size(); ++i) {
    EXPECT_EQ(a.switches[i].children, b.switches[i].children);
    EXPECT_EQ(a.switches[i].masks, b.switches[i].masks);
    EXPECT_EQ(a.switches[i].current, b.switches[i].current);
  }
  ASSERT_EQ(a.dofs.size(), b.dofs.size());
  for (size_t i = 0; i < a.dofs.size(); ++i) {
    EXPECT_EQ(a.dofs[i].place, b.dofs[i].place);
    EXPECT_EQ(a.dofs[i].frame, b.dofs[i].frame);
    EXPECT_EQ(a.dofs[i].parts.size(), b.dofs[i].parts.size());
    EXPECT_EQ(a.dofs[i].current.rotate.z, b.dofs[i].current.rotate.z);
  }
  EXPECT_EQ(a.materials.size(), b.materials.size());
  ASSERT_EQ(a.lightPoints.size(), b.lightPoints.size());
  for (size_t i = 0; i < a.lightPoints.size(); ++i)
    EXPECT_EQ(a.lightPoints[i].appearance, b.lightPoints[i].appearance);
  EXPECT_EQ(a.lightAppearances.size(), b.lightAppearances.size());
  ASSERT_EQ(a.lines.size(), b.lines.size());
  if (!a.lines.empty()) {
    EXPECT_EQ(0, std::memcmp(a.lines.data(), b.lines.data(),
                             a.lines.size() * sizeof(scene::LineSegment)));
  }
  EXPECT_EQ(a.lineSettings.width, b.lineSettings.width);
  EXPECT_EQ(a.cameras.size(), b.cameras.size());
  EXPECT_EQ(a.channels.size(), b.channels.size());
  EXPECT_EQ(a.fog.beta, b.fog.beta);
  ASSERT_EQ(a.instanceTree != nullptr, b.instanceTree != nullptr);
  if (a.instanceTree) {
    EXPECT_EQ(a.instanceTree->order, b.instanceTree->order);
    EXPECT_EQ(a.instanceTree->loose, b.instanceTree->loose);
    EXPECT_EQ(a.instanceTree->nodes.size(), b.instanceTree->nodes.size());
  }
}

TEST(Database, HoldsBackTheSceneItWasGiven) {
  const scene::Scene s = richScene();
  TempFile db("rich.svdb");
  ASSERT_TRUE(formats::saveDatabase(s, db.path).ok());
  Result<scene::Scene> back = formats::loadScene(db.path);
  ASSERT_TRUE(back.ok()) << back.error().str();
  expectSameScene(s, back.value());
  EXPECT_EQ(render(s, true), render(back.value(), true));
  // Written twice, the same bytes: nothing in the file depends on memory contents.
  TempFile again("again.svdb");
  ASSERT_TRUE(formats::saveDatabase(back.value(), again.path).ok());
  EXPECT_EQ(readBytes(db.path), readBytes(again.path));
}

TEST(Prep, RendersBitIdenticallyToItsSource) {
  const scene::Scene source = richScene();
  scene::Scene prepared = source;
  Result<PrepReport> r = prepare(prepared, PrepOptions{});
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_LT(r->verticesOut, r->verticesIn);  // the primitives' seams, the faces' corners merged
  EXPECT_GE(r->groupsMade, 3u);              // the spheres' mesh, the torus, the ground
  TempFile db("prepared.svdb");
  ASSERT_TRUE(formats::saveDatabase(prepared, db.path).ok());
  Result<scene::Scene> loaded = formats::loadScene(db.path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().str();
  // Every instance at full detail: the source's image, bit for bit.
  const std::vector<uint8_t> full = render(source, false);
  EXPECT_EQ(render(loaded.value(), false), full);
  // Without generated levels (optimized vertex order only), also with levels of detail on.
  scene::Scene optimizedOnly = source;
  PrepOptions noLods;
  noLods.generateLods = false;
  ASSERT_TRUE(prepare(optimizedOnly, noLods).ok());
  EXPECT_EQ(render(optimizedOnly, true), render(source, true));
  // With them, the near sphere still draws its level 0 — and most pixels are the same.
  const std::vector<uint8_t> withLods = render(loaded.value(), true);
  size_t same = 0;
  for (size_t i = 0; i < full.size(); ++i) same += withLods[i] == full[i];
  EXPECT_GT(double(same) / double(full.size()), 0.98);
}

TEST(Prep, GeneratedLevelsShrinkAndSwitchFartherOut) {
  scene::Scene s;
  s.meshes.push_back(formats::detail::makeSphere(2, 128, 64));
  s.instances.push_back({0, Mat4::scaling({3, 3, 3}), 0, -1});
  s.instances.push_back({0, Mat4::translation({10, 0, 0}), 0, -1});
  PrepOptions o;
  Result<PrepReport> r = prepare(s, o);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(s.lodGroups.size(), 1u);
  const scene::LodGroup& g = s.lodGroups[0];
  ASSERT_EQ(g.levels.size(), 4u);
  EXPECT_EQ(g.levels[0].mesh, 0);
  // Each level at most 9/10 of the one before (the simplifier stops short of its target where
  // the topology holds it); the first at about a quarter.
  auto triangles = [&](size_t k) { return s.meshes[size_t(g.levels[k].mesh)].triangleCount(); };
  EXPECT_LE(triangles(1), triangles(0) * 3 / 10);
  for (size_t k = 1; k < g.levels.size(); ++k) {
    EXPECT_LE(triangles(k) * 10, triangles(k - 1) * 9);
    EXPECT_GT(g.levels[k].to, g.levels[k - 1].to);
  }
  EXPECT_EQ(g.levels.back().to, 1e30f);  // the coarsest level is drawn at any range
  EXPECT_EQ(s.instances[0].lod, 0);
  EXPECT_EQ(s.instances[1].lod, 0);
  // A finer pixel error switches farther out: ranges scale as 1 / error.
  scene::Scene t;
  t.meshes.push_back(formats::detail::makeSphere(2, 128, 64));
  t.instances.push_back({0, Mat4::scaling({3, 3, 3}), 0, -1});
  t.instances.push_back({0, Mat4::translation({10, 0, 0}), 0, -1});
  o.pixelError = 0.5f;
  ASSERT_TRUE(prepare(t, o).ok());
  EXPECT_NEAR(t.lodGroups[0].levels[0].to, 2 * g.levels[0].to, 1e-3 * g.levels[0].to);
  EXPECT_FALSE(prepare(t, PrepOptions{.maxLevels = 9}).ok());
}

TEST(Database, RefusesDamagedFiles) {
  scene::Scene s;
  s.meshes.push_back(formats::detail::makeBox({1, 1, 1}));
  s.instances.push_back({0, Mat4{}, 0, -1});
  TempFile db("box.svdb");
  ASSERT_TRUE(formats::saveDatabase(s, db.path).ok());
  const std::string good = readBytes(db.path);
  auto error = [&](const std::string& bytes) {
    writeBytes(db.path, bytes);
    Result<scene::Scene> r = formats::loadScene(db.path);
    return r.ok() ? std::string("(loaded)") : r.error().str().substr(db.path.size() + 2);
  };
  EXPECT_EQ(error(good), "(loaded)");
  EXPECT_EQ(error(good.substr(0, good.size() - 1)),
            "database is " + std::to_string(good.size() - 1) + " bytes, its header says " +
                std::to_string(good.size()) + " (truncated or appended to)");
  std::string flipped = good;
  flipped[200] ^= 4;
  EXPECT_EQ(error(flipped), "database is damaged (its checksum does not match)");
  std::string newer = good;
  newer[8] = 4;
  EXPECT_EQ(error(newer),
            "database version 4, this synthvis reads version 3 (run `synthvis prep` again on the "
            "source)");
  EXPECT_EQ(error("glTF" + good), "not a synthvis database (no SVDB header)");
  EXPECT_EQ(error(""), "not a synthvis database (empty file)");
  // A terrain whose draped image does not exist is refused on load, by name.
  Result<scene::Scene> terrain = generators::generateTerrain({.size = 65});
  ASSERT_TRUE(terrain.ok()) << terrain.error().str();
  terrain->terrains[0].name = "hills";
  terrain->terrains[0].image = 7;
  ASSERT_TRUE(formats::saveDatabase(terrain.value(), db.path).ok());
  Result<scene::Scene> bad = formats::loadScene(db.path);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().str().substr(db.path.size() + 2),
            "database: terrain 'hills': a value is not finite or out of range");
}

// Terrain is stored with its table and how it is drawn; the pyramid is built on load. The frame
// is the same, for both filters.
TEST(Database, HoldsTerrainAndDrawsItTheSame) {
  for (bool bicubic : {false, true}) {
    Result<scene::Scene> s =
        generators::generateTerrain({.size = 257, .seed = 3, .bicubic = bicubic});
    ASSERT_TRUE(s.ok()) << s.error().str();
    TempFile db("terrain.svdb");
    ASSERT_TRUE(formats::saveDatabase(s.value(), db.path).ok());
    Result<scene::Scene> back = formats::loadScene(db.path);
    ASSERT_TRUE(back.ok()) << back.error().str();
    ASSERT_EQ(back->terrains.size(), 1u);
    const scene::Terrain &a = s->terrains[0], &b = back->terrains[0];
    EXPECT_EQ(a.heights->q, b.heights->q);
    EXPECT_EQ(a.heights->spacingU, b.heights->spacingU);
    EXPECT_EQ(a.bicubic, b.bicubic);
    EXPECT_EQ(a.image, b.image);
    EXPECT_EQ(render(s.value(), true), render(back.value(), true)) << bicubic;
  }
}

}  // namespace
}  // namespace sv::prep
