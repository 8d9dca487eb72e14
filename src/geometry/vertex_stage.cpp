// Based on: SPEC §8 (seed 002: Gouraud intensity, seed 003: the diffuse term n·l).
#include "geometry/vertex_stage.h"

#include <algorithm>

namespace sv::geometry {

void transformVertices(const scene::Mesh& mesh, const scene::Material& material, const Mat4& model,
                       const Mat4& viewProj, const scene::Light& light, size_t begin, size_t end,
                       ClipVertex* out) {
  const Mat4 mvp = viewProj * model;
  const Mat4 normalToWorld = model.normalMatrix();
  const bool lit = light.enabled && !material.unlit && !mesh.normals.empty();
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
    if (lit) {
      const Vec3 n = normalize(normalToWorld.transformDirection(mesh.normals[i]));
      const float diffuse = std::max(0.0f, dot(n, toLight));
      intensity = Vec3{light.ambient, light.ambient, light.ambient} +
                  light.color * ((1 - light.ambient) * diffuse);
    }
    *out++ = {c.x, c.y, c.z, c.w, std::clamp(color.x * intensity.x, 0.0f, 1.0f),
              std::clamp(color.y * intensity.y, 0.0f, 1.0f),
              std::clamp(color.z * intensity.z, 0.0f, 1.0f), std::clamp(color.w, 0.0f, 1.0f)};
  }
}

}  // namespace sv::geometry
