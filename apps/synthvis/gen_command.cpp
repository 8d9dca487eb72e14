// `synthvis gen KIND -o scene.glb`: a BENCH.md scene written as glTF, for other renderers.
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "synthvis/formats.h"

namespace sv::cli {
namespace {

struct GenArgs {
  std::string kind;
  std::string output;
  GeneratorArgs generator;
  int width = 1920, height = 1080;
  std::string shade = "gouraud";
};

int runGen(const GenArgs& a) {
  if (a.width < 1 || a.width > kMaxRasterSize || a.height < 1 || a.height > kMaxRasterSize)
    return fail({"", "", "width and height must be 1…8192"});
  if (a.shade != "gouraud" && a.shade != "textured")
    return fail({"", "", fmt::format("unknown shading '{}' (gouraud or textured)", a.shade)});
  auto c = generatorCase(a.kind, a.generator);
  if (!c) return fail(c.error());
  c.value().tris.textured = c.value().layers.textured = a.shade == "textured";
  RenderOptions o;
  o.width = a.width;
  o.height = a.height;
  auto made = reference::makeScene(c.value(), o);
  if (!made) return fail(made.error());
  if (Status s = formats::saveGltf(made.value().scene, a.output); !s) return fail(s.error());
  if (made.value().meanArea > 0)
    fmt::print("{}: {} {} triangles, mean area {:.1f} px at {}x{}, depth complexity {:.2f}\n",
               a.output, a.kind, made.value().scene.triangleCount(), made.value().meanArea, a.width,
               a.height, made.value().depthComplexity);
  else
    fmt::print("{}: {} {} triangles, {} textures\n", a.output, a.kind,
               made.value().scene.triangleCount(), made.value().scene.textures.size());
  return 0;
}

}  // namespace

void addGenCommand(CLI::App& app, Run& run) {
  auto args = std::make_shared<GenArgs>();
  GenArgs& g = *args;
  CLI::App* gen = app.add_subcommand("gen", "write a BENCH.md scene as glTF (.glb or .gltf)");
  gen->add_option("kind", g.kind, "generator: tris, layers or grazing")->required();
  gen->add_option("-o,--output", g.output, "output file (.glb or .gltf)")->required();
  addGeneratorOptions(gen, g.generator);
  gen->add_option("--width", g.width, "the raster the areas refer to")->capture_default_str();
  gen->add_option("--height", g.height, "the raster the areas refer to")->capture_default_str();
  gen->add_option("--shade", g.shade,
                  "tris, layers: gouraud, or textured (BENCH.md's 1024x1024 texture, as a PNG)")
      ->capture_default_str();
  gen->callback([&run, args] { run = [args] { return runGen(*args); }; });
}

}  // namespace sv::cli
