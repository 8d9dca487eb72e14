// Terrain in the frame (issue 29): the pass against the host's queries, mosaics against the
// merged map, and thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "formats/heights.h"
#include "raster/framebuffer.h"
#include "render/camera.h"
#include "render/shading_tables.h"
#include "render/terrains.h"
#include "synthvis/generators.h"
#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/terrain.h"
#include "terrain/ground.h"

namespace sv {
namespace {

scene::Scene smallTerrain(int size, bool bicubic) {
  generators::TerrainParams p;
  p.size = size;
  p.bicubic = bicubic;
  return generators::generateTerrain(p).value();
}

RenderOptions smallOptions(int threads) {
  RenderOptions o;
  o.width = 192;
  o.height = 128;
  o.threads = threads;
  return o;
}

TEST(TerrainRender, TheHeightQueryAgreesWithTheRenderedDepth) {
  for (bool bicubic : {false, true}) {
    const scene::Scene s = smallTerrain(257, bicubic);
    const RenderOptions o = smallOptions(1);
    const render::FrameCamera camera = render::chooseCamera(s, o).value();
    render::ShadingTables shading;
    render::buildShading(s, o, camera.view, shading);
    terrain::TerrainPass pass;
    const EyeRays rays = render::eyeRays(camera);
    pass.setTerrains(render::terrainDraws(s, rays, shading, o), rays, shading.environment);
    pass.prepare(raster::PassFrame{o.width, o.height, 1, nullptr, nullptr});
    // One tile's buffers, cleared to the far plane.
    std::vector<float> depth(raster::kTileSize * raster::kTileSize, 1.0f);
    std::vector<uint16_t> color(raster::kTileSize * raster::kTileSize * 3, 0);
    const int tx = 1, ty = 1;  // the middle of the lower half: ground
    pass.drawTile({tx, ty, depth.data(), color.data(), 0});
    int checked = 0;
    for (int ly = 0; ly < raster::kTileSize; ly += 9)
      for (int lx = 0; lx < raster::kTileSize; lx += 9) {
        const float z = depth[raster::FrameBuffer::depthOffset(lx, ly)];
        if (!(z < 1.0f)) continue;
        // The pixel centre's ray, in the world, to the depth the pass wrote.
        const double ndc = 2.0 * z - 1, p22 = camera.projection.m[2][2],
                     p23 = camera.projection.m[3][2];
        const double range = p23 / (ndc + p22);
        const Mat4& v = camera.view;
        const double px = tx * 64 + lx + 0.5, py = ty * 64 + ly + 0.5;
        const double tanY = std::tan(camera.camera.yfovDegrees * M_PI / 360);
        const double ex = (2 * px / o.width - 1) * tanY * o.width / o.height * range;
        const double ey = (1 - 2 * py / o.height) * tanY * range, ez = -range;
        // Eye to world: the view's rotation transposed, about the eye.
        const scene::Camera& c = camera.camera;
        double w[3];
        for (int k = 0; k < 3; ++k)
          w[k] = (&c.position.x)[k] + v.m[k][0] * ex + v.m[k][1] * ey + v.m[k][2] * ez;
        const std::optional<TerrainHeight> h = terrainHeight(
            s, w[0], w[1], w[2],
            bicubic ? RenderOptions::TerrainFilter::bicubic : RenderOptions::TerrainFilter::bilinear);
        ASSERT_TRUE(h.has_value());
        // The depth buffer's float keeps ~7 digits of window depth: at a few km that is
        // centimetres to decimetres of range, less of height along a ray looking down.
        EXPECT_NEAR(h->above, 0.0, 0.5) << "pixel " << px << ", " << py << " at range " << range;
        ++checked;
      }
    EXPECT_GT(checked, 30);
  }
}

TEST(TerrainRender, TheLineOfSightMeetsTheGroundWhereTheQuerySaysItIs) {
  const scene::Scene s = smallTerrain(257, true);
  const scene::Camera& c = s.cameras[0];
  const double from[3] = {c.position.x, c.position.y, c.position.z};
  const double to[3] = {0, 0, -20000};
  const std::optional<TerrainHit> hit = lineOfSight(s, from, to);
  ASSERT_TRUE(hit.has_value());
  const std::optional<TerrainHeight> h = terrainHeight(s, hit->x, hit->y, hit->z);
  ASSERT_TRUE(h.has_value());
  EXPECT_NEAR(h->above, 0.0, 1e-3);
  const double up[3] = {0, 1e5, 0};
  EXPECT_FALSE(lineOfSight(s, from, up).has_value());
}

TEST(TerrainRender, SameImageForAnyThreadCount) {
  // Bilinear: the packets' walk on the table itself; bicubic: on the mean levels beyond the near
  // field, the per-ray cast near it.
  for (const bool bicubic : {false, true}) {
    const scene::Scene s = smallTerrain(129, bicubic);
    Image one;
    RenderOptions o = smallOptions(1);
    o.samples = 4;
    ASSERT_TRUE(Renderer(o).render(s, one));
    for (const int threads : {2, 5}) {
      Image other;
      o.threads = threads;
      ASSERT_TRUE(Renderer(o).render(s, other));
      EXPECT_EQ(one.rgb, other.rgb) << threads << " threads, bicubic " << bicubic;
    }
  }
}

TEST(TerrainRender, AMosaicOfFourTilesRendersAsTheMergedMap) {
  scene::Scene merged = smallTerrain(129, false);
  const scene::HeightField& f = *merged.terrains[0].heights;
  // Four tiles sharing their edge row and column, as SRTM tiles do.
  std::vector<scene::HeightField> tiles;
  for (int ty = 0; ty < 2; ++ty)
    for (int tx = 0; tx < 2; ++tx) {
      scene::HeightField t;
      t.width = t.height = 65;
      t.spacingU = f.spacingU, t.spacingV = f.spacingV;
      t.originU = f.originU + tx * 64 * f.spacingU;
      t.originV = f.originV - ty * 64 * f.spacingV;
      t.offset = f.offset, t.scale = f.scale;
      t.source = "tile " + std::to_string(ty * 2 + tx);
      for (int j = 0; j < 65; ++j)
        for (int i = 0; i < 65; ++i) t.q.push_back(f.code(tx * 64 + i, ty * 64 + j));
      tiles.push_back(std::move(t));
    }
  Result<scene::HeightField> m = formats::mosaic(tiles);
  ASSERT_TRUE(m.ok()) << m.error().str();
  scene::Scene fromTiles = merged;
  fromTiles.terrains[0].heights = std::make_shared<scene::HeightField>(std::move(m.value()));
  Image a, b;
  const RenderOptions o = smallOptions(2);
  ASSERT_TRUE(Renderer(o).render(merged, a));
  ASSERT_TRUE(Renderer(o).render(fromTiles, b));
  EXPECT_EQ(a.rgb, b.rgb);
}

}  // namespace
}  // namespace sv
