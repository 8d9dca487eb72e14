#include "render/shading_tables.h"

namespace sv::render {
namespace {

texture::Filter samplerOf(scene::TextureFilter f) {
  switch (f) {
    case scene::TextureFilter::point:
    case scene::TextureFilter::nearest:
      return texture::Filter::nearest;
    case scene::TextureFilter::threePoint:
      return texture::Filter::threePoint;
    case scene::TextureFilter::bilinear:
      return texture::Filter::bilinear;
    case scene::TextureFilter::trilinearThreePoint:
      return texture::Filter::trilinearThreePoint;
    default:
      return texture::Filter::trilinear;
  }
}

}  // namespace

void buildShading(const scene::Scene& scene, const RenderOptions& o, const Mat4& view,
                  ShadingTables& out) {
  out.materials.clear();
  const bool hasLights = scene.light.enabled || !scene.pointLights.empty();
  for (int m = -1; m < int(scene.materials.size()); ++m) {
    const scene::Material& mat = scene.materialAt(m);
    for (int normals = 0; normals < 2; ++normals) {
      shade::MaterialShading s;
      if (mat.texture >= 0) s.texture = scene.textures[size_t(mat.texture)].texture.get();
      const scene::TextureFilter f =
          mat.textureFilter == scene::TextureFilter::inherit ? o.textureFilter : mat.textureFilter;
      s.filter = samplerOf(f);
      s.anisotropic = f == scene::TextureFilter::anisotropic;
      s.levelZero = f == scene::TextureFilter::point;
      s.phong = mat.phong && hasLights && !mat.unlit && normals;  // as the vertex stage's `lit`
      s.twoSided = mat.doubleSided;
      s.specular = mat.specular;
      s.shininess = mat.shininess;
      s.alpha = mat.alphaMode == scene::AlphaMode::blend  ? shade::AlphaUse::blend
                : mat.alphaMode == scene::AlphaMode::mask ? shade::AlphaUse::mask
                                                          : shade::AlphaUse::opaque;
      s.alphaCutoff = mat.alphaCutoff;
      out.materials.push_back(s);
    }
  }
  shade::Environment& env = out.environment;
  env.lightOn = scene.light.enabled;
  env.toLight = normalize(view.transformDirection(normalize(-scene.light.direction)));
  env.lightColor = scene.light.color;
  env.ambient = scene.light.ambient;
  env.points.clear();
  for (const scene::PointLight& p : scene.pointLights)
    env.points.push_back({view.transformPoint(p.position), p.color});
  env.fog = scene.fog.enabled && scene.fog.beta > 0;
  env.fogColor = scene.fog.color;
  env.fogBeta = scene.fog.beta;
  out.any = env.fog;
  for (const scene::Material& mat : scene.materials) out.any |= mat.needsPixelShading();
  // A level of detail dissolving into the next is cut by its door in pixel shading.
  if (o.lod)
    for (const scene::LodGroup& g : scene.lodGroups) out.any |= g.fade > 0;
}

}  // namespace sv::render
