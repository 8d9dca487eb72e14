// Every kind of image the project makes, held bit for bit: each scene in scenes/, the built-in demo
// and every bench generator, at 1 and 16 samples, with the options that take other paths through
// the frame (masking, filters, supersampling, debug views, the free-form methods) — rendered on
// every compiled SIMD target and compared with the hashes recorded in
// tests/golden/image_hashes.txt.
//
// A refactor must leave every image the same; when a change means to alter images, look at them
// (`synthvis render`), then record the new hashes:
//   SV_UPDATE_IMAGE_HASHES=1 build/tests/render/image_hashes_test
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "synthvis/bench.h"
#include "synthvis/formats.h"
#include "synthvis/ground_truth.h"
#include "synthvis/render.h"

namespace sv {
namespace {

// The raster of every case: 4 × 3 tiles, the last row and column partial.
constexpr int kWidth = 224, kHeight = 136;

struct HashCase {
  std::string name;
  reference::BenchCase scene;  // a generator's, or a file (relative to the source tree)
  RenderOptions options;
  bool textured = false, fog = false;  // for the generators, as `bench --shade textured --fog`
};

RenderOptions baseOptions(int samples) {
  RenderOptions o;
  o.width = kWidth;
  o.height = kHeight;
  o.threads = 2;
  o.samples = samples;
  return o;
}

reference::BenchCase fileCase(const std::string& file) {
  reference::BenchCase c;
  c.name = file;
  c.file = file.empty() ? "" : std::string(SV_SOURCE_DIR) + "/" + file;
  return c;
}

reference::BenchCase generatorCase(const std::string& generator) {
  reference::BenchCase c;
  c.name = generator;
  c.generator = generators::parseGenerator(generator).value();
  c.tris.count = 3000;
  c.tris.area = 12;
  c.freeform.count = 12;
  return c;
}

// The cases, each at 1 and 16 samples unless it cannot be anti-aliased.
std::vector<HashCase> hashCases() {
  std::vector<HashCase> cases;
  auto both = [&](const std::string& name, const reference::BenchCase& scene, auto tweak,
                  bool textured = false, bool fog = false) {
    for (int samples : {1, 16}) {
      HashCase h{name + "@" + std::to_string(samples), scene, baseOptions(samples), textured, fog};
      tweak(h.options);
      cases.push_back(h);
    }
  };
  auto single = [&](const std::string& name, const reference::BenchCase& scene, auto tweak) {
    HashCase h{name, scene, baseOptions(1), false, false};
    tweak(h.options);
    cases.push_back(h);
  };
  auto none = [](RenderOptions&) {};
  for (const char* file :
       {"", "scenes/demo.json", "scenes/aa-edges.json", "scenes/mixed.json", "scenes/grazing.json",
        "scenes/grazing-plane.json", "scenes/freeform-mixed.json", "scenes/freeform-sculpture.json",
        "scenes/crate.gltf", "scenes/pyramid.gltf", "scenes/house.obj",
        "scenes/terrain-olinda.json", "scenes/airport.json", "scenes/powerlines.json",
        "scenes/volume-ml.json", "scenes/mri-head.json", "scenes/volume-panes.json",
        "scenes/cloud-shell.json"})
    both(*file ? file : "demo", fileCase(file), none);
  both("tris", generatorCase("tris"), none);
  both("tris-textured", generatorCase("tris"), none, true);
  both("tris-textured-fog", generatorCase("tris"), none, true, true);
  reference::BenchCase large = generatorCase("tris");
  large.tris.count = 60;
  large.tris.area = 3000;
  both("tris-large-textured", large, none, true);
  both("layers-textured", generatorCase("layers"), none, true);
  both("grazing", generatorCase("grazing"), none);
  both("grazing-fog", generatorCase("grazing"), none, true, true);
  both("freeform", generatorCase("freeform"), none);
  both("freeform-one", generatorCase("freeform-one"), none);
  reference::BenchCase terrain = generatorCase("terrain");
  terrain.terrain.size = 257;
  both("terrain", terrain, none);
  both("terrain-exact", terrain, [](RenderOptions& o) { o.terrainLod = false; });
  terrain.terrain.bicubic = true;
  both("terrain-bicubic", terrain, none);
  reference::BenchCase lights = generatorCase("lights");
  lights.lights.count = 5000;
  both("lights", lights, none);
  // Other paths through the frame.
  both("demo-priority", fileCase(""),
       [](RenderOptions& o) { o.hsr = RenderOptions::Hsr::priority; });
  both("demo-hybrid", fileCase(""), [](RenderOptions& o) { o.hsr = RenderOptions::Hsr::hybrid; });
  reference::BenchCase f2b = generatorCase("layers");
  f2b.layers.order = generators::SubmitOrder::frontToBack;
  both("layers-f2b-priority", f2b, [](RenderOptions& o) { o.hsr = RenderOptions::Hsr::priority; });
  both(
      "layers-textured-hybrid", generatorCase("layers"),
      [](RenderOptions& o) { o.hsr = RenderOptions::Hsr::hybrid; }, true);
  both("mixed-tent3", fileCase("scenes/mixed.json"),
       [](RenderOptions& o) { o.filter = RenderOptions::Filter::tent3; });
  both("freeform-mixed-tent3", fileCase("scenes/freeform-mixed.json"),
       [](RenderOptions& o) { o.filter = RenderOptions::Filter::tent3; });
  both("grazing-aniso", fileCase("scenes/grazing.json"),
       [](RenderOptions& o) { o.textureFilter = scene::TextureFilter::anisotropic; });
  both("demo-gamma2.2", fileCase(""), [](RenderOptions& o) { o.gamma = 2.2; });
  single("demo-supersample2", fileCase(""), [](RenderOptions& o) { o.supersample = 2; });
  single("mixed-supersample4-tent3", fileCase("scenes/mixed.json"), [](RenderOptions& o) {
    o.supersample = 4;
    o.filter = RenderOptions::Filter::tent3;
  });
  single("demo-overdraw", fileCase(""),
         [](RenderOptions& o) { o.debugView = RenderOptions::DebugView::overdraw; });
  single("grazing-levels", fileCase("scenes/grazing.json"),
         [](RenderOptions& o) { o.debugView = RenderOptions::DebugView::levels; });
  single("grazing-occupancy", fileCase("scenes/grazing.json"), [](RenderOptions& o) {
    o.hsr = RenderOptions::Hsr::hybrid;
    o.debugView = RenderOptions::DebugView::occupancy;
  });
  single("freeform-sculpture-march", fileCase("scenes/freeform-sculpture.json"),
         [](RenderOptions& o) {
           o.freeFormMethod = RenderOptions::FreeFormMethod::march;
           o.marchSteps = 64;
         });
  HashCase every{"freeform-sculpture-every-sample@16", fileCase("scenes/freeform-sculpture.json"),
                 baseOptions(16), false, false};
  every.options.freeFormEverySample = true;
  cases.push_back(every);
  single("demo-no-cull", fileCase(""), [](RenderOptions& o) { o.cullBackFaces = false; });
  return cases;
}

// FNV-1a over the image's size and bytes.
uint64_t imageHash(const Image& image) {
  uint64_t h = 0xcbf29ce484222325ull;
  auto add = [&](uint8_t byte) { h = (h ^ byte) * 0x100000001b3ull; };
  for (int v : {image.width, image.height})
    for (int i = 0; i < 4; ++i) add(uint8_t(uint32_t(v) >> (8 * i)));
  for (uint8_t byte : image.rgb) add(byte);
  return h;
}

std::string hashText(uint64_t h) {
  std::ostringstream s;
  s << std::hex << h;
  return s.str();
}

const char* kHashFile = SV_SOURCE_DIR "/tests/golden/image_hashes.txt";

std::map<std::string, std::string> recordedHashes() {
  std::map<std::string, std::string> out;
  std::ifstream in(kHashFile);
  std::string name, hash;
  while (in >> name >> hash) out[name] = hash;
  return out;
}

TEST(ImageHashes, EveryImageOnEveryTargetIsTheRecordedOne) {
  const std::vector<HashCase> cases = hashCases();
  // The scenes, made once.
  std::vector<scene::Scene> scenes;
  for (const HashCase& c : cases) {
    reference::BenchCase shaded = c.scene;
    shaded.tris.textured = shaded.layers.textured = c.textured;
    shaded.tris.fog = shaded.layers.fog = shaded.grazing.fog = c.fog;
    if (shaded.generator == generators::Generator::none && shaded.file.empty()) {
      scenes.push_back(formats::demoScene());
      continue;
    }
    auto made = reference::makeScene(shaded, c.options);
    ASSERT_TRUE(made.ok()) << c.name << ": " << made.error().str();
    scenes.push_back(std::move(made).value().scene);
  }
  const bool update = std::getenv("SV_UPDATE_IMAGE_HASHES") != nullptr;
  const std::map<std::string, std::string> recorded = recordedHashes();
  if (!update) {
    ASSERT_FALSE(recorded.empty()) << "no hashes recorded in " << kHashFile;
  }
  std::map<std::string, std::string> first;  // the first target's, to record
  int targets = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    ++targets;
    for (size_t i = 0; i < cases.size(); ++i) {
      const HashCase& c = cases[i];
      Renderer renderer(c.options);
      Image image;
      const Status s = renderer.render(scenes[i], image);
      ASSERT_TRUE(s.ok()) << c.name << ": " << s.error().str();
      const std::string h = hashText(imageHash(image));
      if (targets == 1) first[c.name] = h;
      if (update) {
        EXPECT_EQ(h, first[c.name])
            << c.name << " on " << hwy::TargetName(target) << " differs from the first target";
        continue;
      }
      const auto it = recorded.find(c.name);
      ASSERT_NE(it, recorded.end()) << c.name << ": no hash recorded in " << kHashFile;
      EXPECT_EQ(h, it->second) << c.name << " on " << hwy::TargetName(target)
                               << " is not the recorded image";
    }
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(targets, 1);
  // The ground truth (`synthvis truth`) and its edge mask: scalar code, once.
  for (const char* file :
       {"", "scenes/mixed.json", "scenes/aa-edges.json", "scenes/freeform-mixed.json"}) {
    auto loaded = *file ? formats::loadScene(std::string(SV_SOURCE_DIR) + "/" + file)
                        : Result<scene::Scene>(formats::demoScene());
    ASSERT_TRUE(loaded.ok()) << file;
    reference::GroundTruthOptions g{baseOptions(1), 4};
    Image edges;
    auto truth = reference::renderGroundTruth(loaded.value(), g, &edges);
    ASSERT_TRUE(truth.ok()) << file << ": " << truth.error().str();
    const std::string name = std::string("truth:") + (*file ? file : "demo");
    for (const auto& [suffix, image] :
         {std::pair{"", &truth.value()}, std::pair{"-edges", &edges}}) {
      const std::string h = hashText(imageHash(*image)), key = name + suffix;
      first[key] = h;
      if (update) continue;
      const auto it = recorded.find(key);
      ASSERT_NE(it, recorded.end()) << key << ": no hash recorded in " << kHashFile;
      EXPECT_EQ(h, it->second) << key << " is not the recorded image";
    }
  }
  if (update) {
    std::ofstream out(kHashFile);
    for (const auto& [name, hash] : first) out << name << " " << hash << "\n";
    ASSERT_TRUE(out.good()) << "cannot write " << kHashFile;
  } else {
    EXPECT_EQ(recorded.size(), first.size()) << kHashFile << " records cases no longer rendered";
  }
}

}  // namespace
}  // namespace sv
