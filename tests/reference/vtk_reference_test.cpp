// The vtk reference (VTK's CPU volume ray caster, bench/vtk_volume.py) draws the volume synthvis
// draws: the same codes, transfer function, opacity unit, light and camera.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "reference/vtk_volume.h"
#include "small_settings.h"
#include "synthvis/bench.h"
#include "synthvis/generators.h"

namespace sv::reference {
namespace {

using testing::smallSettings;

BenchCase volumeCase() {
  BenchCase c;
  c.name = "volume";
  c.generator = generators::Generator::volume;
  c.volume.size = 48;
  return c;
}

// The same picture within what the two lighting and sampling schemes differ by: VTK quantizes its
// gradients' directions and samples from the eye, synthvis from each volume's box; measured 19–21 dB
// on the bench volume; an image of another volume or view is below 12 dB.
TEST(VtkReference, DrawsWhatSynthvisDraws) {
  BenchSettings s = smallSettings();
  s.reference = false;
  s.vtk = true;
  BenchRunner runner(s);
  auto r = runner.run(volumeCase());
  if (!r.ok() && r.error().message.find("python3-vtk9 is not installed") != std::string::npos)
    GTEST_SKIP() << r.error().str();
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->runs.size(), 2u);
  EXPECT_EQ(r->runs[1].renderer, "vtk");
  EXPECT_NE(r->runs[1].description.find("vtkFixedPointVolumeRayCastMapper"), std::string::npos);
  EXPECT_EQ(r->runs[1].frameMs.size(), size_t(s.frames));
  EXPECT_GT(r->runs[1].medianMs, 0);
  ASSERT_EQ(r->runs[1].image.width, s.options.width);
  EXPECT_GE(r->psnrDb, 16.0);
  // The opaque classification too (an iso-surface).
  BenchCase opaque = volumeCase();
  opaque.volume.opaque = true;
  auto o = runner.run(opaque);
  ASSERT_TRUE(o.ok()) << o.error().str();
  EXPECT_GE(o->psnrDb, 16.0);
  // Not the same picture: the view turned away from the volume's side lit differently.
  EXPECT_LT(psnr(r->runs[0].image, o->runs[1].image), r->psnrDb);
}

TEST(VtkReference, RefusesWhatItDoesNotDraw) {
  BenchSettings s = smallSettings();
  s.reference = false;
  s.vtk = true;
  s.synthvis = false;
  BenchRunner runner(s);
  // A scene without volumes.
  BenchCase tris;
  tris.name = "tris";
  tris.generator = generators::Generator::tris;
  tris.tris.count = 100;
  auto r = runner.run(tris);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("volume scenes only"), std::string::npos) << r.error().str();
  // A volume beside polygons.
  scene::Scene mixed = generators::generateVolume(generators::VolumeParams{});
  scene::Scene boxes = generators::generateTris(generators::TrisParams{});
  mixed.meshes = boxes.meshes, mixed.instances = boxes.instances, mixed.materials = boxes.materials;
  auto v = VtkVolumeRenderer::create(mixed, s.options);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("volumes alone: the scene also has"), std::string::npos)
      << v.error().str();
  // No script.
  setenv("SV_VTK_SCRIPT", "/nonexistent/vtk_volume.py", 1);
  auto missing =
      VtkVolumeRenderer::create(generators::generateVolume(generators::VolumeParams{}), s.options);
  unsetenv("SV_VTK_SCRIPT");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("script is missing"), std::string::npos);
  EXPECT_EQ(missing.error().file, "/nonexistent/vtk_volume.py");
}

}  // namespace
}  // namespace sv::reference
