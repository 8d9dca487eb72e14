// The built-in demo scene must always load: the renderer and the CLI fall back on it.
#include <gtest/gtest.h>

#include "formats/formats_test_util.h"
#include "synthvis/scene.h"

namespace sv::formats {
namespace {

TEST(DemoScene, LoadsValidatesAndHasEnoughToLookAt) {
  Result<Scene> parsed = parseJsonScene(demoSceneJson(), "demo.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error().str();
  Scene s = demoScene();
  EXPECT_TRUE(validate(s, "demo").ok());
  EXPECT_GT(s.triangleCount(), 1000u);
  EXPECT_LE(s.triangleCount(), 60000u);
  ASSERT_FALSE(s.cameras.empty());
  EXPECT_EQ(s.cameras[0].yfovDegrees, 50);
  EXPECT_TRUE(s.light.enabled);
  for (const Mesh& m : s.meshes) EXPECT_EQ(m.normals.size(), m.positions.size()) << m.name;
}

TEST(DemoScene, EmbeddedTextIsTheFileInTheSourceTree) {
  EXPECT_EQ(std::string(demoSceneJson()),
            testing::readText(testing::sourcePath("scenes/demo.json")));
}

}  // namespace
}  // namespace sv::formats
