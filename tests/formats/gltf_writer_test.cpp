// saveGltf writes what loadGltf reads back: generated benchmark scenes survive the round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "formats/formats_test_util.h"
#include "support/temp_dir.h"
#include "synthvis/generators.h"
#include "texture/texture.h"

namespace sv::formats {
namespace {

using generators::generateGrazing;
using generators::generateTris;
using generators::TrisParams;

std::string tempPath(const std::string& name) { return sv::tests::processTemp().path(name); }

void expectSameScene(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    EXPECT_EQ(a.meshes[i].positions, b.meshes[i].positions);
    EXPECT_EQ(a.meshes[i].colors, b.meshes[i].colors);
    EXPECT_EQ(a.meshes[i].normals, b.meshes[i].normals);
    EXPECT_EQ(a.meshes[i].indices, b.meshes[i].indices);
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  EXPECT_EQ(a.materials[0].unlit, b.materials[0].unlit);
  EXPECT_EQ(a.materials[0].doubleSided, b.materials[0].doubleSided);
  ASSERT_EQ(b.cameras.size(), 1u);
  EXPECT_NEAR(b.cameras[0].yfovDegrees, a.cameras[0].yfovDegrees, 1e-4);
  const Vec3 dir = normalize(b.cameras[0].target - b.cameras[0].position);
  EXPECT_NEAR(dir.z, -1, 1e-6);
  EXPECT_NEAR(b.cameras[0].up.y, 1, 1e-6);
  EXPECT_EQ(a.triangleCount(), b.triangleCount());
}

TEST(GltfWriter, GeneratedTrisRoundTripThroughGlbAndGltf) {
  TrisParams p;
  p.count = 500;
  const Scene s = generateTris(p);
  for (const char* name : {"tris.glb", "tris.gltf"}) {
    const std::string path = tempPath(name);
    ASSERT_TRUE(saveGltf(s, path).ok()) << name;
    auto back = loadGltf(path);
    ASSERT_TRUE(back.ok()) << back.error().str();
    expectSameScene(s, back.value());
  }
}

TEST(GltfWriter, LitMeshesKeepTheirNormals) {
  Scene s = demoScene();
  const std::string path = tempPath("demo.glb");
  ASSERT_TRUE(saveGltf(s, path).ok());
  auto back = loadGltf(path);
  ASSERT_TRUE(back.ok()) << back.error().str();
  EXPECT_EQ(back->triangleCount(), s.triangleCount());
  EXPECT_EQ(back->meshes[0].normals, s.meshes[0].normals);
}

// Textures go out as 8-bit sRGB PNGs with their wrap modes and come back within 8-bit rounding;
// the material's uvScale is multiplied into the UVs; alpha modes survive.
TEST(GltfWriter, TexturesWrapModesAndUvScaleRoundTrip) {
  Scene s = generateGrazing({});
  ASSERT_EQ(s.textures.size(), 2u);
  // A third, clamped and mirrored texture with alpha, on a cut-out material.
  texture::Level level;
  level.width = 3;
  level.height = 2;
  for (int i = 0; i < 6; ++i) {
    const uint16_t a = uint16_t(i * 13000);
    level.texels.push_back({uint16_t(a / 2), uint16_t(a / 3), a, a});
  }
  s.textures.push_back({"odd", std::make_shared<texture::Texture>(
                                   std::move(level), texture::Wrap::clamp, texture::Wrap::mirror)});
  Material cutOut = s.materials[1];
  cutOut.texture = 2;
  cutOut.alphaMode = AlphaMode::mask;
  cutOut.alphaCutoff = 0.3f;
  cutOut.uvScale = {2, 3};
  s.materials.push_back(cutOut);
  s.meshes[1].material = 2;
  for (const char* name : {"grazing.glb", "grazing.gltf"}) {
    const std::string path = tempPath(name);
    ASSERT_TRUE(saveGltf(s, path).ok()) << name;
    auto back = loadGltf(path);
    ASSERT_TRUE(back.ok()) << back.error().str();
    ASSERT_EQ(back->textures.size(), 3u) << name;
    for (size_t t = 0; t < 3; ++t) {
      const texture::Texture &a = *s.textures[t].texture, &b = *back->textures[t].texture;
      EXPECT_EQ(a.wrapX(), b.wrapX()) << t;
      EXPECT_EQ(a.wrapY(), b.wrapY()) << t;
      const texture::LevelView la = a.level(0), lb = b.level(0);
      ASSERT_EQ(la.width, lb.width);
      ASSERT_EQ(la.height, lb.height);
      double worst = 0;
      for (int y = 0; y < la.height; ++y)
        for (int x = 0; x < la.width; ++x) {
          // Premultiplied linear; 8-bit sRGB steps are at most 1/78 of linear (near white).
          const texture::Color4 ca = la.at(x, y), cb = lb.at(x, y);
          worst = std::max({worst, double(std::fabs(ca.r - cb.r)), double(std::fabs(ca.b - cb.b)),
                            double(std::fabs(ca.a - cb.a))});
        }
      EXPECT_LT(worst, 0.015) << t;
    }
    ASSERT_EQ(back->materials.size(), s.materials.size());
    EXPECT_EQ(back->materials[0].texture, 0);
    EXPECT_EQ(back->materials[1].texture, 1);
    EXPECT_EQ(back->materials[2].texture, 2);
    EXPECT_EQ(back->materials[2].alphaMode, AlphaMode::mask);
    EXPECT_FLOAT_EQ(back->materials[2].alphaCutoff, 0.3f);
    // The ground's uvScale of 80 is in its UVs now.
    for (size_t m = 0; m < s.meshes.size(); ++m) {
      const Vec2 scale = s.materials[size_t(s.meshes[m].material)].uvScale;
      ASSERT_EQ(back->meshes[m].uvs.size(), s.meshes[m].uvs.size());
      for (size_t i = 0; i < s.meshes[m].uvs.size(); ++i) {
        EXPECT_FLOAT_EQ(back->meshes[m].uvs[i].x, s.meshes[m].uvs[i].x * scale.x);
        EXPECT_FLOAT_EQ(back->meshes[m].uvs[i].y, s.meshes[m].uvs[i].y * scale.y);
      }
    }
  }
}

// Lines go out as one LINES primitive in world coordinates and come back as the same segments.
TEST(GltfWriter, LinesRoundTrip) {
  Scene s = generateTris({});
  s.lines = {{{0, 0, 0}, {1, 2, 3}, {1, 0, 0}}, {{-1, 0, 5}, {0, 4, 5}, {0.5f, 0.25f, 1}}};
  const std::string path = tempPath("lines.glb");
  ASSERT_TRUE(saveGltf(s, path).ok());
  Result<Scene> r = loadGltf(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->lines.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(r->lines[i].a, s.lines[i].a);
    EXPECT_EQ(r->lines[i].b, s.lines[i].b);
    EXPECT_EQ(r->lines[i].color, s.lines[i].color);
  }
  EXPECT_EQ(r->triangleCount(), s.triangleCount());
}

// tinygltf's own file writer reported success for a .glb it could not open or finish.
TEST(GltfWriter, AFileThatCannotBeWrittenIsAnError) {
  for (const char* name : {"full.glb", "full.gltf"}) {
    const std::string path = sv::tests::fullDiskPath(name);
    if (path.empty()) GTEST_SKIP() << "no /dev/full here";
    const Status st = saveGltf(generateTris({}), path);
    ASSERT_FALSE(st.ok()) << name;
    EXPECT_EQ(st.error().str(), path + ": cannot write: No space left on device");
  }
  const Status st = saveGltf(generateTris({}), tempPath("no-such-folder/x.glb"));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().str().find("No such file or directory"), std::string::npos);
}

TEST(GltfWriter, RefusesOtherExtensions) {
  const Status st = saveGltf(generateTris({}), tempPath("x.obj"));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().str().find(".glb or .gltf"), std::string::npos);
}

}  // namespace
}  // namespace sv::formats
