// Based on: SPEC §8 (seed 002: Gouraud intensity, seed 003: the diffuse term n·l).
#include "geometry/vertex_stage.h"

#include <algorithm>

namespace sv::geometry {

void transformVertices(const scene::Mesh& mesh, const scene::Material& material, const Mat4& model,
                       const VertexContext& context, size_t begin, size_t end, ClipVertex* out,
                       shade::VertexAttributes* attributes) {
  const Mat4 mvp = context.viewProj * model;
  const Mat4 modelView = context.view * model;
  const Mat4 normalToWorld = model.normalMatrix();
  const Mat4 normalToEye = modelView.normalMatrix();
  const scene::Light& light = *context.light;
  const bool hasLights = light.enabled || (context.pointLights && !context.pointLights->empty());
  const bool lit = hasLights && !material.unlit && !mesh.normals.empty();
  const bool vertexLit = lit && !material.phong;
  const Vec3 toLight = normalize(-light.direction);
  const Vec4 base = material.baseColor;
  for (size_t i = begin; i < end; ++i) {
    const Vec3 p = mesh.positions[i];
    const Vec4 c = mvp * Vec4{p.x, p.y, p.z, 1};
    Vec4 color = base;
    if (!mesh.colors.empty()) {
      const Vec4 vc = mesh.colors[i];
      color = {color.x * vc.x, color.y * vc.y, color.z * vc.z, color.w * vc.w};
    }
    Vec3 intensity{1, 1, 1};
    if (vertexLit) {
      const Vec3 n = normalize(normalToWorld.transformDirection(mesh.normals[i]));
      Vec3 diffuse{0, 0, 0};
      if (light.enabled) diffuse = light.color * std::max(0.0f, dot(n, toLight));
      if (context.pointLights)
        for (const scene::PointLight& pl : *context.pointLights) {
          const Vec3 l = normalize(pl.position - model.transformPoint(p));
          diffuse = diffuse + pl.color * std::max(0.0f, dot(n, l));
        }
      intensity = Vec3{light.ambient, light.ambient, light.ambient} + diffuse * (1 - light.ambient);
    }
    const float alpha = std::clamp(color.w, 0.0f, 1.0f);
    *out++ = {c.x, c.y, c.z, c.w, std::clamp(color.x * intensity.x, 0.0f, 1.0f),
              std::clamp(color.y * intensity.y, 0.0f, 1.0f),
              std::clamp(color.z * intensity.z, 0.0f, 1.0f), alpha};
    if (attributes) {
      shade::VertexAttributes& a = *attributes++;
      const Vec2 uv = mesh.uvs.empty() ? Vec2{0, 0} : mesh.uvs[i];
      // Phong's normal; a mesh without normals (or an unlit material) gets none and is not lit.
      const Vec3 n = lit && material.phong
                         ? normalize(normalToEye.transformDirection(mesh.normals[i]))
                         : Vec3{0, 0, 0};
      const Vec3 e = modelView.transformPoint(p);
      a.value[shade::kU] = uv.x * material.uvScale.x;
      a.value[shade::kV] = uv.y * material.uvScale.y;
      a.value[shade::kNormalX] = n.x;
      a.value[shade::kNormalY] = n.y;
      a.value[shade::kNormalZ] = n.z;
      a.value[shade::kEyeX] = e.x;
      a.value[shade::kEyeY] = e.y;
      a.value[shade::kEyeZ] = e.z;
      a.value[shade::kAlpha] = alpha;
    }
  }
}

}  // namespace sv::geometry
