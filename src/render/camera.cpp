#include "render/camera.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "terrain/ground.h"

namespace sv::render {
namespace {

// A camera for scenes that have none: looks at the centre of the scene's bounds (its instances'
// and terrains') from the front and a little above, far enough to see all of it.
scene::Camera defaultCamera(const scene::Scene& s) {
  Vec3 lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
          std::numeric_limits<float>::max()};
  Vec3 hi = -lo;
  bool any = false;
  for (const auto& inst : s.instances)
    for (const Vec3& p : s.meshes[inst.mesh].positions) {
      const Vec3 w = inst.transform.transformPoint(p);
      if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) continue;
      lo = {std::min(lo.x, w.x), std::min(lo.y, w.y), std::min(lo.z, w.z)};
      hi = {std::max(hi.x, w.x), std::max(hi.y, w.y), std::max(hi.z, w.z)};
      any = true;
    }
  // Terrain: its footprint between its lowest and highest heights (on the plane; a sphere's
  // ground drops below it, which a default view need not mind).
  for (const scene::Terrain& t : s.terrains) {
    if (!t.ground) continue;
    const terrain::HeightField& f = t.ground->field;
    const float x0 = float(f.originU - t.origin[0]), x1 = float(f.eastU() - t.origin[0]);
    const float z0 = float(t.origin[1] - f.originV), z1 = float(t.origin[1] - f.southV());
    const float y0 = float(f.offset), y1 = float(f.offset + 65535 * f.scale);
    lo = {std::min(lo.x, x0), std::min(lo.y, y0), std::min(lo.z, z0)};
    hi = {std::max(hi.x, x1), std::max(hi.y, y1), std::max(hi.z, z1)};
    any = true;
  }
  scene::Camera cam;
  if (!any) return cam;
  const Vec3 centre = (lo + hi) * 0.5f;
  const float radius = std::max(0.5f * length(hi - lo), 1e-3f);
  const float distance =
      radius / std::sin(0.5f * cam.yfovDegrees * std::numbers::pi_v<float> / 180.0f);
  cam.target = centre;
  cam.position = centre + normalize(Vec3{0, 0.35f, 1}) * distance;
  cam.znear = std::max(distance - radius, distance * 1e-3f) * 0.5f;
  cam.zfar = (distance + radius) * 2;
  return cam;
}

}  // namespace

Result<FrameCamera> chooseCamera(const scene::Scene& scene, const RenderOptions& o) {
  FrameCamera f;
  if (!scene.cameras.empty()) {
    if (o.camera >= int(scene.cameras.size()))
      return Error{"", "",
                   fmt::format("camera {} does not exist (the scene has {})", o.camera,
                               scene.cameras.size())};
    f.camera = scene.cameras[size_t(o.camera)];
  } else {
    f.camera = defaultCamera(scene);
  }
  const scene::Camera& cam = f.camera;
  const float aspect = float(o.width) / float(o.height);
  f.view = Mat4::lookAt(cam.position, cam.target, cam.up);
  f.projection = Mat4::perspective(cam.yfovDegrees * std::numbers::pi_v<float> / 180.0f, aspect,
                                   cam.znear, cam.zfar);
  return f;
}

}  // namespace sv::render

namespace sv {

Result<Mat4> viewProjection(const scene::Scene& scene, const RenderOptions& o) {
  const Result<render::FrameCamera> c = render::chooseCamera(scene, o);
  if (!c.ok()) return c.error();
  return c.value().projection * c.value().view;
}

Result<Mat4> viewMatrix(const scene::Scene& scene, const RenderOptions& o) {
  const Result<render::FrameCamera> c = render::chooseCamera(scene, o);
  if (!c.ok()) return c.error();
  return c.value().view;
}

}  // namespace sv
