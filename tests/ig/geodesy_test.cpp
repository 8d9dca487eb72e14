// One Earth model (synthvis/geodesy.h): a geographic height table placed by a scene's geodetic
// frame and an entity the IG places at the same latitude, longitude and height land on the same
// world point — to a centimetre, 100 km from the origin — on a flat base and on the curved one;
// and the IG's height query there answers the table's height.
#include "synthvis/geodesy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "ig/world.h"
#include "render/terrains.h"
#include "support/gdal_raster.h"
#include "support/temp_dir.h"
#include "synthvis/ig.h"

namespace sv::ig {
namespace {

// A 1° × 1.3° geographic raster (EPSG:4326) north-east of (45° N, 7° E), 0.01° a sample, its
// heights altitudes, a smooth function of the sample; the scene placing it by a geodetic frame at
// (45° N, 7° E, 120 m); the IG's configuration naming the scene (and no origin of its own: the
// database's frame is used).
struct Database {
  tests::TempDir dir;
  static constexpr int kW = 131, kH = 101;
  static constexpr double kStep = 0.01, kLat0 = 46, kLon0 = 7;  // sample (0, 0): the north-west
  IgConfig config;

  explicit Database(bool curved) {
    std::vector<double> heights(size_t(kW) * kH);
    for (int j = 0; j < kH; ++j)
      for (int i = 0; i < kW; ++i)
        heights[size_t(j) * kW + size_t(i)] = 200 + 150 * std::sin(i * 0.07) * std::cos(j * 0.05);
    const double gt[6] = {kLon0 - 0.5 * kStep, kStep, 0, kLat0 + 0.5 * kStep, 0, -kStep};
    tests::writeRaster("GTiff", dir.path("dem.tif"), kW, kH, GDT_Float64, heights, gt, 4326);
    config.scene = dir.write(
        "scene.json",
        std::string(R"({"synthvis": 1, "geodetic": {"origin": {"lat": 45, "lon": 7, "alt": 120},)") +
            R"( "curved": )" + (curved ? "true" : "false") +
            R"(}, "terrain": [{"heights": "dem.tif"}]})");
    config.port = 0;
    config.hostPort = 0;
  }
};

TEST(OneEarthModel, TheTerrainAndTheIgAgreeToACentimetreAt100Km) {
  for (const bool curved : {false, true}) {
    SCOPED_TRACE(curved ? "curved" : "flat");
    const Database db(curved);
    Result<IgWorld> loaded = IgWorld::load(db.config);
    ASSERT_TRUE(loaded.ok()) << loaded.error().str();
    IgWorld& w = loaded.value();
    const scene::Terrain& t = w.database().terrains.at(0);
    const terrain::Caster caster = render::casterOf(t, terrain::Interpolation::bilinear);
    // Samples across the table (inside its edges, where a height query meets it), the farthest
    // 102 km east and 110 km north of the origin.
    for (const auto& [i, j] : {std::pair{1, 1}, {65, 50}, {129, 1}, {1, 99}, {129, 99}}) {
      const double lat = Database::kLat0 - j * Database::kStep;
      const double lon = Database::kLon0 + i * Database::kStep;
      const double h = t.heights->at(i, j);  // above the base: the world's y = 0 at 120 m
      const double altitude = h + 120;       // the table's own value (to its quantization)
      EXPECT_NEAR(altitude, 200 + 150 * std::sin(i * 0.07) * std::cos(j * 0.05), 0.01);
      const Vec3d terrain = caster.toWorld(i, j, h);
      const Vec3d entity = w.earth().toWorld({lat, lon, altitude});
      EXPECT_LT(length(terrain - entity), 0.01) << i << ", " << j;
      if (i == 129 && j == 1) {
        EXPECT_GT(entity.x, 1.0e5);
        EXPECT_LT(entity.z, -1.0e5);
      }
      // The host's height query at the entity's place: the table's own height there.
      cigi::HatHotRequest hot;
      hot.id = uint16_t(i + j);
      hot.type = cigi::HatHotType::hot;
      hot.latOrX = lat, hot.lonOrY = lon, hot.altOrZ = altitude + 50;
      cigi::Datagram d;
      d.packets = {cigi::IgControl{}, hot};
      std::vector<cigi::Packet> replies;
      w.apply(d, replies);
      ASSERT_EQ(replies.size(), 1u);
      const auto& r = std::get<cigi::HatHotResponse>(replies[0]);
      ASSERT_TRUE(r.valid);
      EXPECT_NEAR(r.height, altitude, 0.01) << i << ", " << j;
    }
  }
}

// A configuration whose origin is not the database's geodetic frame's is refused, naming both.
TEST(OneEarthModel, AConfigurationOriginOtherThanTheDatabasesIsRefused) {
  Database db(false);
  db.config.origin = {45, 7.5, 0};
  db.config.hasOrigin = true;
  const Result<IgWorld> w = IgWorld::load(db.config);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().str(), db.config.scene +
                                 ": the database's geodetic origin (45, 7, 120) is not the "
                                 "configuration's origin (45, 7.5, 0)");
}

}  // namespace
}  // namespace sv::ig
