// The scene's free forms for the frame (SPEC §11–§12): as the free-form pass casts them, or — the
// polygon baseline — tessellated.
#include "render/freeforms.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "freeform/tessellate.h"
#include "render/draw_packets.h"
#include "render/terrains.h"

namespace sv::render {

std::vector<freeform::ShadedForm> makeShadedForms(const scene::Scene& scene, const Mat4& view,
                                                  const Mat4& projection,
                                                  const ShadingTables& shading) {
  std::vector<freeform::ShadedForm> out;
  const bool lights = shading.environment.lightOn || !shading.environment.points.empty();
  for (const scene::FreeFormObject& object : scene.freeForms) {
    const scene::Material& mat = scene.materialAt(object.material);
    const Mat4d toEye = Mat4d::of(view * object.transform);
    const std::optional<Mat4d> eyeInverse = toEye.inverse();
    const freeform::FreeForm form = freeform::fromNode(object.form);
    std::optional<freeform::ProjectedFreeForm> projected =
        freeform::ProjectedFreeForm::make(form, Mat4d::of(projection) * toEye);
    if (!eyeInverse || !projected) continue;  // a singular placement shows nothing
    freeform::ShadedForm s{form, std::move(*projected), toEye, eyeInverse->transposed(), {}, {},
                           {}};
    s.material = *shading.of(object.material, true);
    s.material.phong = lights && !mat.unlit;
    s.material.twoSided = true;
    s.material.alpha = shade::AlphaUse::opaque;
    s.uvScale[0] = mat.uvScale.x;
    s.uvScale[1] = mat.uvScale.y;
    s.color[0] = mat.baseColor.x;
    s.color[1] = mat.baseColor.y;
    s.color[2] = mat.baseColor.z;
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace sv::render

namespace sv {

Result<scene::Scene> tessellatedScene(const scene::Scene& scene, const RenderOptions& o) {
  // The views the frame has: the camera's, or every display channel's (SPEC §9); each object is
  // cut finely enough for the view that sees it largest.
  std::vector<render::FrameCamera> cameras;
  std::vector<int> heights;
  if (scene.channels.empty()) {
    const Result<render::FrameCamera> camera = render::chooseCamera(scene, o);
    if (!camera.ok()) return camera.error();
    cameras.push_back(camera.value());
    heights.push_back(o.height);
  }
  for (const scene::Channel& channel : scene.channels) {
    const Result<render::FrameCamera> camera = render::channelCamera(scene, o, channel);
    if (!camera.ok()) return camera.error();
    cameras.push_back(camera.value());
    heights.push_back(channel.height);
  }
  scene::Scene out = scene;
  out.freeForms.clear();
  constexpr size_t kMaxTriangles = size_t(1) << 22;
  for (size_t i = 0; i < scene.freeForms.size(); ++i) {
    const scene::FreeFormObject& object = scene.freeForms[i];
    const std::string label = object.name.empty() ? fmt::format("freeForms[{}]", i)
                                                  : fmt::format("free form '{}'", object.name);
    const freeform::FreeForm form = freeform::fromNode(object.form);
    bool unbounded = false;
    const std::optional<freeform::Box> box = freeform::surfaceBounds(form, 1e4, 16, unbounded);
    if (unbounded)
      return Error{"", "", fmt::format("{} is unbounded or too large to tessellate", label)};
    if (!box) continue;  // no surface
    // Per view: the nearest eye depth of the box, and a pixel's height per unit eye depth (from
    // the view window, FrameCamera's tangents) — the smallest pixel there, in world units.
    double worldPixel = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < cameras.size(); ++k) {
      const Mat4 toEye = cameras[k].view * object.transform;
      const auto single = [](Vec3d v) { return Vec3{float(v.x), float(v.y), float(v.z)}; };
      const double nearest =
          std::max(double(render::nearestEyeDepth(toEye, single((*box)[0]), single((*box)[1]))),
                   double(cameras[k].camera.znear));
      const double pixelPerDepth =
          (cameras[k].tanTop - cameras[k].tanBottom) / double(heights[k] * o.supersample);
      worldPixel = std::min(worldPixel, nearest * pixelPerDepth);
    }
    // Its smallest half extent as the curvature radius.
    const Vec3d extent = (*box)[1] - (*box)[0];
    const double radius = 0.5 * std::min({extent.x, extent.y, extent.z});
    // Object units per pixel at that depth (the transform's largest scale brings it to the world).
    double scale = 0;
    for (int c = 0; c < 3; ++c)
      scale = std::max(scale, double(length(object.transform.transformDirection(
                                  Vec3{float(c == 0), float(c == 1), float(c == 2)}))));
    const double pixel = worldPixel / std::max(scale, 1e-30);
    // Sagitta c²/(8r) ≤ pixel/4 for chords c ≤ √3·cell (a leaf's diagonal).
    const double cell = std::sqrt(2 * radius * pixel / 3);
    freeform::TriangleSoup soup;
    if (!freeform::tessellate(form, *box, cell, kMaxTriangles, soup))
      return Error{"", "",
                   fmt::format("{} is unbounded or needs over {} triangles to tessellate", label,
                               kMaxTriangles)};
    scene::Mesh mesh;
    mesh.name = object.name + " (tessellated)";
    mesh.material = object.material;
    for (size_t v = 0; v < soup.positions.size(); ++v) {
      const Vec3d& p = soup.positions[v];
      const Vec3d& n = soup.normals[v];
      mesh.positions.push_back({float(p.x), float(p.y), float(p.z)});
      mesh.normals.push_back({float(n.x), float(n.y), float(n.z)});
      mesh.uvs.push_back(
          {float(p.x), float(p.z)});  // the free form's projection (ShadedForm::uvScale)
      mesh.indices.push_back(uint32_t(v));
    }
    out.meshes.push_back(std::move(mesh));
    out.instances.push_back({int(out.meshes.size()) - 1, object.transform});
  }
  out.terrains.clear();
  for (const scene::Terrain& t : scene.terrains)
    if (t.heights) render::appendTerrainGrid(t, o, out);
  return out;
}

}  // namespace sv
