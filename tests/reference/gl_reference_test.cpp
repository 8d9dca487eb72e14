// The gl reference (OpenGL on Mesa llvmpipe) draws the same picture as synthvis.
//
// In its own executable because Mesa's driver leaks a few hundred bytes that LeakSanitizer cannot
// attribute (the driver is unloaded by then): leak checking is off for this test only
// (tests/reference/CMakeLists.txt); AddressSanitizer's other checks stay on.
#include <gtest/gtest.h>

#include <filesystem>

#include "reference/gl_renderer.h"
#include "small_settings.h"
#include "support/temp_dir.h"
#include "synthvis/bench.h"
#include "synthvis/formats.h"

namespace sv::reference {
namespace {

using testing::smallSettings;

// The reference draws the same triangles: PSNR ≥ 40 dB against synthvis (issue 3's bar), on a
// lit mesh scene and on the no-AA Gouraud bench scenes.
TEST(GlReference, DrawsWhatSynthvisDraws) {
  if (!glBuilt()) GTEST_SKIP() << "the gl reference is not in this build";
  const BenchSettings s = smallSettings();
  BenchRunner runner(s);
  if (Status st = runner.startReference(); !st)
    GTEST_SKIP() << "the gl reference cannot start here: " << st.error().str();
  BenchCase tris;
  tris.name = "tris";
  tris.generator = generators::Generator::tris;
  tris.tris.count = 2000;
  tris.tris.area = 60;
  BenchCase layers;
  layers.name = "layers";
  layers.generator = generators::Generator::layers;
  layers.layers.layers = 3;
  for (const BenchCase& c : {tris, layers}) {
    auto r = runner.run(c);
    ASSERT_TRUE(r.ok()) << r.error().str();
    ASSERT_EQ(r->runs.size(), 2u);
    EXPECT_EQ(r->runs[1].renderer, "gl");
    EXPECT_GE(r->psnrDb, 40.0) << c.name;
  }
  // Textured with fog (BENCH.md's layers as issue 6 benchmarks them): the same texture pyramid,
  // the same fog by range.
  {
    BenchSettings shaded = s;
    shaded.textured = shaded.fog = true;
    BenchRunner shadedRunner(shaded);
    ASSERT_TRUE(shadedRunner.startReference().ok());
    auto r = shadedRunner.run(layers);
    ASSERT_TRUE(r.ok()) << r.error().str();
    EXPECT_GE(r->psnrDb, 40.0);
  }
  // A lit scene with cameras, culling and the background: the demo scene through a file.
  const std::string demo = sv::tests::processTemp().path("suite_demo.glb");
  ASSERT_TRUE(formats::saveGltf(formats::demoScene(), demo).ok());
  BenchCase file;
  file.name = "demo";
  file.file = demo;
  auto r = runner.run(file);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_GE(r->psnrDb, 40.0);
}

}  // namespace
}  // namespace sv::reference
