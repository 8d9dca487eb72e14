// The bench harness (src/reference): suites, PSNR, JSON rows, HTML, and the gl reference drawing
// the same picture as synthvis.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <filesystem>

#include "small_settings.h"
#include "support/temp_dir.h"
#include "synthvis/bench.h"

namespace sv::reference {
namespace {

// Without the gl reference: these tests are about the harness.
BenchSettings smallSettings() {
  BenchSettings s = testing::smallSettings();
  s.reference = false;
  return s;
}

TEST(Psnr, KnownValues) {
  Image a{4, 4, std::vector<uint8_t>(48, 100)}, b = a;
  EXPECT_TRUE(std::isinf(psnr(a, b)));
  b.rgb[0] = 110;  // MSE = 100 / 48
  EXPECT_NEAR(psnr(a, b), 10 * std::log10(255.0 * 255.0 * 48 / 100), 1e-9);
  Image c{2, 2, std::vector<uint8_t>(12, 0)};
  EXPECT_EQ(psnr(a, c), 0);  // sizes differ
}

TEST(Suites, QuickAndFullNameBenchMdScenes) {
  auto quick = suiteCases("quick");
  ASSERT_TRUE(quick.ok());
  ASSERT_FALSE(quick->empty());
  EXPECT_EQ(quick->front().name, "tris-10k-a10");
  auto full = suiteCases("full");
  ASSERT_TRUE(full.ok());
  EXPECT_GT(full->size(), quick->size());
  bool hasLayers16 = false, hasFreeForm = false;
  for (const auto& c : full.value()) {
    hasLayers16 |= c.name == "layers-d16-b2f";
    hasFreeForm |= c.generator == generators::Generator::freeform;
  }
  EXPECT_TRUE(hasLayers16);
  EXPECT_TRUE(hasFreeForm);
  EXPECT_FALSE(suiteCases("huge").ok());
}

TEST(BenchRunner, JsonRowsCarryBenchMdFields) {
  const BenchSettings s = smallSettings();
  BenchRunner runner(s);
  BenchCase c;
  c.name = "tris-small";
  c.generator = generators::Generator::tris;
  c.tris.count = 300;
  c.tris.area = 40;
  auto r = runner.run(c);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->runs.size(), 1u);
  EXPECT_EQ(r->runs[0].frameMs.size(), 2u);
  EXPECT_NEAR(r->meanArea, 40, 2);
  const nlohmann::json rows = jsonRows(r.value(), s);
  ASSERT_EQ(rows.size(), 1u);
  for (const char* key :
       {"scene", "renderer", "width", "height", "threads", "frames", "median_ms", "min_ms",
        "max_ms", "triangles", "count", "area", "realized_mean_area", "simd"})
    EXPECT_TRUE(rows[0].contains(key)) << key;
  EXPECT_EQ(rows[0]["renderer"], "synthvis");
  EXPECT_EQ(rows[0]["simd"], simdTarget());
  EXPECT_EQ(rows[0]["triangles"], 300);
}

// The target named is the one the kernels dispatch to: the scalar one when only it is allowed.
TEST(Bench, NamesTheSimdTargetTheKernelsRunOn) {
  const int64_t before = hwy::SupportedTargets();  // test_main may have narrowed it already
  hwy::SetSupportedTargetsForTest(HWY_BASELINE_SCALAR);
  EXPECT_EQ(simdTarget(), hwy::TargetName(HWY_BASELINE_SCALAR));
  hwy::SetSupportedTargetsForTest(before);
  EXPECT_NE(simdTarget(), "none");
}

TEST(Html, WritesPageImagesAndPlots) {
  const BenchSettings s = smallSettings();
  BenchRunner runner(s);
  BenchCase c;
  c.name = "tris-html";
  c.generator = generators::Generator::tris;
  c.tris.count = 100;
  auto r = runner.run(c);
  ASSERT_TRUE(r.ok());
  const auto dir = sv::tests::processTemp().dir() / "suite_html";
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(writeHtml(dir.string(), {r.value()}, s, "").ok());
  for (const char* f : {"index.html", "ratio.svg", "time-triangles.svg", "time-area.svg",
                        "time-depth.svg", "tris-html-synthvis.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
}

}  // namespace
// Free-form scenes against their two baselines, frame by frame: the fixed-step marcher and the
// same forms tessellated (issue 7).
TEST(BenchRunner, FreeFormsRunAgainstTheMarcherAndTheirTessellation) {
  for (const bool sphereTrace : {true, false}) {
    BenchSettings s = smallSettings();
    s.sphereTrace = sphereTrace;
    s.tessellated = !sphereTrace;
    s.options.marchSteps = 64;
    BenchRunner runner(s);
    BenchCase c;
    c.name = "freeform-one";
    c.generator = generators::Generator::freeformOne;
    auto r = runner.run(c);
    ASSERT_TRUE(r.ok()) << r.error().str();
    ASSERT_EQ(r->runs.size(), 2u);
    EXPECT_EQ(r->runs[1].renderer, sphereTrace ? "sphere-trace" : "tessellated");
    EXPECT_GT(r->psnrDb, 20) << "both drew the same object";
    if (!sphereTrace) {
      EXPECT_GT(r->params.value("tessellated_triangles", 0), 1000);
    }
  }
}

}  // namespace sv::reference
