// BENCH.md's generators' options, shared by `bench`, `gen` and `prep` (cli.h).
#include <fmt/format.h>

#include <cstdio>

#include "cli.h"

namespace sv::cli {
namespace {

// lights --stars auto: xplanet's catalogue where Debian installs it, or where scripts/lib.sh
// (sv_data) unpacks it in a checkout (the current directory); none if neither is there.
std::string starCatalog(const std::string& option) {
  if (option == "none") return "";
  if (option != "auto") return option;
  for (const char* path :
       {"/usr/share/xplanet/stars/BSC", "build-data/root/usr/share/xplanet/stars/BSC"})
    if (std::FILE* f = std::fopen(path, "rb")) {
      std::fclose(f);
      return path;
    }
  return "";
}

}  // namespace

void addGeneratorOptions(CLI::App* app, GeneratorArgs& g) {
  app->add_option("--count", g.tris.count, "tris: number of triangles")->capture_default_str();
  app->add_option("--lights", g.lights, "lights: light points, stars included")
      ->capture_default_str();
  app->add_option("--buildings", g.city.buildings, "city: buildings, one per 40 m block")
      ->capture_default_str();
  app->add_option("--trees", g.city.trees, "city: trees")->capture_default_str();
  app->add_option("--voxels", g.volume.size, "volume: samples a side")->capture_default_str();
  app->add_flag("--opaque", g.volume.opaque,
                "volume: iso-surface-like (opaque above the threshold)");
  app->add_flag(
      "--no-shell", [&g](int64_t) { g.volume.shell = false; },
      "volume: cast through the whole box, without the free-form shell");
  app->add_flag("--precomputed-normals", g.volume.precomputedNormals,
                "volume: gradient directions precomputed per sample (SPEC §11's second way)");
  app->add_option("--stars", g.stars,
                  "lights: the star catalogue (xplanet's BSC), auto (found where Debian or "
                  "scripts/lib.sh puts it) or none")
      ->capture_default_str();
  app->add_option("--area", g.tris.area, "tris: mean projected area, pixels")
      ->capture_default_str();
  app->add_option("--depth", g.tris.depth, "tris: depth complexity (0 = whole screen)")
      ->capture_default_str();
  app->add_option("--layers", g.layers, "layers: depth complexity D")->capture_default_str();
  app->add_option("--objects", g.objects, "freeform: number of perturbed quadrics")
      ->capture_default_str();
  app->add_option("--order", g.order, "tris, layers: random, f2b or b2f")->capture_default_str();
  app->add_option("--size", g.size, "terrain: heights a side (the map is 40.96 km square)")
      ->capture_default_str();
  app->add_option("--terrain-filter", g.terrainFilter,
                  "terrain: interpolation below the finest level, bilinear or bicubic")
      ->capture_default_str();
  app->add_option("--seed", g.tris.seed, "generator seed")->capture_default_str();
}

Result<reference::BenchCase> generatorCase(const std::string& kind, const GeneratorArgs& g) {
  auto generator = generators::parseGenerator(kind);
  if (!generator) return generator.error();
  auto order = generators::parseSubmitOrder(g.order);
  if (!order) return order.error();
  reference::BenchCase c;
  c.name = kind;
  c.generator = generator.value();
  c.tris = g.tris;
  c.tris.order = order.value();
  c.layers.layers = g.layers;
  c.layers.order = order.value();
  c.layers.seed = g.tris.seed;
  c.grazing.seed = g.tris.seed;
  c.freeform.count = g.objects;
  c.freeform.seed = g.tris.seed;
  c.terrain.size = g.size;
  c.terrain.seed = g.tris.seed;
  // The terrain generator's own interpolation: bilinear or bicubic ("scene" is not a choice here).
  auto filter = parseTerrainFilter(g.terrainFilter);
  if (!filter || filter.value() == RenderOptions::TerrainFilter::scene)
    return Error{"", "",
                 fmt::format("unknown interpolation '{}' (bilinear or bicubic)", g.terrainFilter)};
  c.terrain.bicubic = filter.value() == RenderOptions::TerrainFilter::bicubic;
  c.lights.count = g.lights;
  c.lights.seed = g.tris.seed;
  c.lights.starCatalog = starCatalog(g.stars);
  c.city = g.city;
  c.city.seed = g.tris.seed;
  c.volume = g.volume;
  c.volume.seed = g.tris.seed;
  return c;
}

}  // namespace sv::cli
