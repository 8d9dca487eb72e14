// `synthvis terrain SCENE --height X,Y,Z | --los X,Y,Z,X,Y,Z`: the host's terrain queries
// (synthvis/terrain.h) — the ground's height under a point, or where a line of sight meets it.
#include <fmt/format.h>

#include <memory>
#include <vector>

#include "cli.h"
#include "synthvis/formats.h"
#include "synthvis/terrain.h"

namespace sv::cli {
namespace {

int runTerrainQuery(const std::string& scenePath, const std::vector<double>& at,
                    const std::vector<double>& los, const std::string& filterName) {
  const Result<RenderOptions::TerrainFilter> parsed = parseTerrainFilter(filterName);
  if (!parsed) return fail(parsed.error());
  const RenderOptions::TerrainFilter filter = parsed.value();
  if (at.empty() == los.empty())
    return fail({"", "", "give one query: --height X,Y,Z or --los X,Y,Z,X,Y,Z"});
  auto loaded = formats::loadScene(scenePath);
  if (!loaded) return fail(loaded.error());
  const scene::Scene& scene = loaded.value();
  if (scene.terrains.empty()) return fail({scenePath, "", "the scene has no terrain"});
  if (!at.empty()) {
    const auto h = terrainHeight(scene, at[0], at[1], at[2], filter);
    if (!h) {
      fmt::print("no terrain under ({}, {}, {})\n", at[0], at[1], at[2]);
      return 1;
    }
    fmt::print("terrain {}: ground at {:.4f} m, the point {:.4f} m above it\n", h->terrain,
               h->elevation, h->above);
    return 0;
  }
  const auto hit = lineOfSight(scene, los.data(), los.data() + 3, filter);
  if (!hit) {
    fmt::print("clear: the line of sight does not meet the ground\n");
    return 0;
  }
  fmt::print("blocked by terrain {} at ({:.4f}, {:.4f}, {:.4f}), {:.6f} of the way\n", hit->terrain,
             hit->x, hit->y, hit->z, hit->fraction);
  return 0;
}

}  // namespace

void addTerrainCommand(CLI::App& app, Run& run) {
  struct QueryArgs {
    std::string queryScene, queryFilter = "scene";
    std::vector<double> queryAt, queryLos;
  };
  auto args = std::make_shared<QueryArgs>();
  CLI::App* query = app.add_subcommand(
      "terrain", "ask a scene's terrain: the ground's height at a point, or a line of sight");
  query->add_option("scene", args->queryScene, "scene file with terrain")->required();
  query->add_option("--height", args->queryAt, "X,Y,Z: the ground under this world point")
      ->delimiter(',')
      ->expected(3);
  query
      ->add_option("--los", args->queryLos, "X,Y,Z,X,Y,Z: where the segment first meets the ground")
      ->delimiter(',')
      ->expected(6);
  query->add_option("--terrain-filter", args->queryFilter, "scene, bilinear or bicubic")
      ->capture_default_str();
  query->callback([&run, args] {
    run = [args] {
      return runTerrainQuery(args->queryScene, args->queryAt, args->queryLos, args->queryFilter);
    };
  });
}

}  // namespace sv::cli
