// Based on: SPEC §8 (seed 002: Gouraud intensity, seed 003: the diffuse term n·l).
#include "geometry/vertex_stage.h"

#include <algorithm>
#include <cmath>

namespace sv::geometry {

bool transformVertices(const scene::Mesh& mesh, const scene::Material& material, const Mat4& model,
                       const VertexContext& context, size_t begin, size_t end, ClipVertex* out,
                       float* attributes, const shade::AttributeLayout* layout) {
  bool finite = true;
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
    finite &= isFinite(p);
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
    if (attributes && layout->stored) {
      float* a = attributes;
      attributes += layout->stride;
      auto put = [&](int k, float value) {
        if (layout->stored >> k & 1) a[layout->slot[k]] = value;
      };
      if (layout->stored & (1u << shade::kU | 1u << shade::kV)) {
        const Vec2 uv = mesh.uvs.empty() ? Vec2{0, 0} : mesh.uvs[i];
        put(shade::kU, uv.x * material.uvScale.x);
        put(shade::kV, uv.y * material.uvScale.y);
      }
      if (layout->stored &
          (1u << shade::kNormalX | 1u << shade::kNormalY | 1u << shade::kNormalZ)) {
        // Phong's normal; a mesh without normals (or an unlit material) gets none and is not lit.
        const Vec3 n = lit && material.phong
                           ? normalize(normalToEye.transformDirection(mesh.normals[i]))
                           : Vec3{0, 0, 0};
        put(shade::kNormalX, n.x);
        put(shade::kNormalY, n.y);
        put(shade::kNormalZ, n.z);
      }
      if (layout->stored & (1u << shade::kEyeX | 1u << shade::kEyeY | 1u << shade::kEyeZ)) {
        const Vec3 e = modelView.transformPoint(p);
        put(shade::kEyeX, e.x);
        put(shade::kEyeY, e.y);
        put(shade::kEyeZ, e.z);
      }
      put(shade::kAlpha, alpha);
    }
  }
  return finite;
}

bool boundObject(const Mat4& mvp, Vec3 lo, Vec3 hi, const Viewport& viewport, ObjectBound& out) {
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL, z0 = HUGE_VAL;
  for (int c = 0; c < 8; ++c) {
    const double p[3] = {c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
    double clip[4];
    for (int r = 0; r < 4; ++r)
      clip[r] = double(mvp.m[0][r]) * p[0] + double(mvp.m[1][r]) * p[1] +
                double(mvp.m[2][r]) * p[2] + double(mvp.m[3][r]);
    // In front of the near plane (z ≥ −w, w > 0) the box's image is the hull of its corners'.
    if (!(clip[3] > 0) || !(clip[2] >= -clip[3]) || !std::isfinite(clip[0]) ||
        !std::isfinite(clip[1]))
      return false;
    const double invW = 1.0 / clip[3];
    // As setup.cpp maps clip space to pixels and window depth.
    const double px = (clip[0] + clip[3]) * (0.5 * viewport.width) * invW;
    const double py = (clip[3] - clip[1]) * (0.5 * viewport.height) * invW;
    x0 = std::min(x0, px), x1 = std::max(x1, px);
    y0 = std::min(y0, py), y1 = std::max(y1, py);
    z0 = std::min(z0, 0.5 * (clip[2] + clip[3]) * invW);
  }
  // Pixel p's square is [p, p + 1): two pixels of slack cover the float vertex transform's
  // rounding and the sample aperture of anti-aliasing.
  auto pixel = [](double v, int size) {
    return int(std::clamp(std::floor(v), -4.0, double(size) + 4));
  };
  out.minX = std::max(pixel(x0, viewport.width) - 2, 0);
  out.minY = std::max(pixel(y0, viewport.height) - 2, 0);
  out.maxX = std::min(pixel(x1, viewport.width) + 2, viewport.width - 1);
  out.maxY = std::min(pixel(y1, viewport.height) + 2, viewport.height - 1);
  // Depth planes are evaluated in float per sample; 2^-10 covers their rounding by a wide margin
  // for any triangle whose depth gradient is below ~10^4 per pixel (docs/hidden-surfaces.md).
  out.zmin = float(z0 - 0x1p-10);
  return true;
}

}  // namespace sv::geometry
