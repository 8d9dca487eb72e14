// Based on: SPEC §11–§12 (height fields, ray cast per tile by the terrain stage); the scene's
// terrains turned into that stage's plain inputs.
#include "render/terrains.h"

#include <algorithm>
#include <cmath>

#include "terrain/ground.h"

namespace sv::render {

terrain::Interpolation interpolationFor(const scene::Terrain& t,
                                        RenderOptions::TerrainFilter filter) {
  return filter == RenderOptions::TerrainFilter::bicubic ||
                 (filter == RenderOptions::TerrainFilter::scene && t.bicubic)
             ? terrain::Interpolation::bicubic
             : terrain::Interpolation::bilinear;
}

terrain::Caster casterOf(const scene::Terrain& t, terrain::Interpolation interp) {
  return terrain::Caster(*t.heights, terrain::pyramidOf(*t.heights, interp), interp,
                         terrain::Placement{t.origin[0], t.origin[1], t.baseRadius});
}

std::vector<terrain::TerrainDraw> terrainDraws(const scene::Scene& scene, const EyeRays& rays,
                                               const ShadingTables& shading,
                                               const RenderOptions& options) {
  std::vector<terrain::TerrainDraw> draws;
  const bool lights = shading.environment.lightOn || !shading.environment.points.empty();
  for (const scene::Terrain& t : scene.terrains) {
    if (!t.heights) continue;
    terrain::TerrainDraw d;
    const terrain::HeightField& f = *t.heights;
    d.field = &f;
    d.interp = interpolationFor(t, options.terrainFilter);
    d.placement = terrain::Placement{t.origin[0], t.origin[1], t.baseRadius};
    const scene::Material& mat = scene.materialAt(t.material);
    d.material = *shading.of(t.material, true);
    d.material.phong = lights && !mat.unlit;
    d.material.twoSided = true;  // the prism's walls face every way
    d.material.alpha = shade::AlphaUse::opaque;
    d.material.anisotropic = false;  // footprints are per pixel here (TexCoords), not per call
    d.material.texture = t.image >= 0 ? scene.textures[size_t(t.image)].texture.get() : nullptr;
    d.color[0] = mat.baseColor.x, d.color[1] = mat.baseColor.y, d.color[2] = mat.baseColor.z;
    d.detail = t.detail >= 0 ? scene.textures[size_t(t.detail)].texture.get() : nullptr;
    d.detailSize = t.detailSize;
    std::copy_n(t.imageBounds, 4, d.imageBounds);
    d.ramp = t.ramp.empty() ? terrain::defaultRamp(f.offset, f.offset + 65535 * f.scale) : t.ramp;
    // A pixel's width per unit eye depth, in grid steps (at the view's centre: the level of
    // detail needs no more), or 0 for the exact surface everywhere.
    d.pixel = options.terrainLod
                  ? std::ldexp(2 * rays.halfSpanY() / (options.height * options.supersample) /
                                   std::min(f.spacingU, f.spacingV),
                               std::clamp(options.terrainLodBias, 0, 8))
                  : 0.0;
    draws.push_back(std::move(d));
  }
  return draws;
}

void appendTerrainGrid(const scene::Terrain& t, const RenderOptions& o, scene::Scene& out) {
  const terrain::HeightField& f = *t.heights;
  const terrain::Caster c = casterOf(t, interpolationFor(t, o.terrainFilter));
  const std::vector<scene::TerrainColorStop> ramp =
      t.ramp.empty() ? terrain::defaultRamp(f.offset, f.offset + 65535 * f.scale) : t.ramp;
  scene::Material m = out.materialAt(t.material);
  m.name = (t.name.empty() ? std::string("terrain") : t.name) + " (grid)";
  m.texture = t.image;
  m.doubleSided = true;
  m.uvScale = {1, 1};
  if (!m.unlit) m.phong = true;
  out.materials.push_back(m);
  scene::Mesh mesh;
  mesh.name = m.name;
  mesh.material = int(out.materials.size()) - 1;
  const size_t n = size_t(f.width) * size_t(f.height);
  mesh.positions.reserve(n);
  mesh.normals.reserve(n);
  for (int j = 0; j < f.height; ++j)
    for (int i = 0; i < f.width; ++i) {
      const double h = f.at(i, j);
      const Vec3d p = c.toWorld(i, j, h);
      const Vec3d nn = c.normal(i, j);
      mesh.positions.push_back({float(p.x), float(p.y), float(p.z)});
      mesh.normals.push_back({float(nn.x), float(nn.y), float(nn.z)});
      if (t.image >= 0) {
        const double* b = t.imageBounds;
        mesh.uvs.push_back(
            {float((c.mapU(i) - b[0]) / (b[2] - b[0])), float((b[3] - c.mapV(j)) / (b[3] - b[1]))});
      } else {
        const Vec3 col = terrain::rampAt(ramp, h);
        mesh.colors.push_back({col.x, col.y, col.z, 1});
      }
    }
  mesh.indices.reserve(size_t(f.width - 1) * size_t(f.height - 1) * 6);
  for (int j = 0; j + 1 < f.height; ++j)
    for (int i = 0; i + 1 < f.width; ++i) {
      const uint32_t a = uint32_t(j * f.width + i), b = a + 1, d = a + uint32_t(f.width), e = d + 1;
      for (uint32_t k : {a, d, b, b, d, e}) mesh.indices.push_back(k);
    }
  out.meshes.push_back(std::move(mesh));
  out.instances.push_back({int(out.meshes.size()) - 1, Mat4{}});
}

}  // namespace sv::render
