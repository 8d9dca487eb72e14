// saveGltf writes what loadGltf reads back: generated benchmark scenes survive the round trip.
#include <filesystem>

#include <gtest/gtest.h>

#include "synthvis/generators.h"
#include "synthvis/scene.h"

namespace sv::scene {
namespace {

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("sv_gltf_writer_" + name)).string();
}

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

TEST(GltfWriter, RefusesOtherExtensions) {
  const Status st = saveGltf(generateTris({}), tempPath("x.obj"));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().str().find(".glb or .gltf"), std::string::npos);
}

}  // namespace
}  // namespace sv::scene
