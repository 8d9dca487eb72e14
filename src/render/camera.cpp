#include "render/camera.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/check.h"
#include "synthvis/height_field.h"

namespace sv::render {
namespace {

// A camera for scenes that have none: looks at the centre of the scene's bounds (its instances'
// and terrains') from an oblique three-quarter direction — front, right and above, so that a flat
// model lying in any axis plane is not seen edge-on — far enough to see all of it.
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
    if (!t.heights) continue;
    const scene::HeightField& f = *t.heights;
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
  cam.position = centre + normalize(Vec3{0.6f, 0.45f, 1}) * distance;
  cam.znear = std::max(distance - radius, distance * 1e-3f) * 0.5f;
  cam.zfar = (distance + radius) * 2;
  return cam;
}

float radians(float degrees) { return degrees * std::numbers::pi_v<float> / 180.0f; }

// The inverse of a rotation followed by a translation: the rotation transposed, and the
// translation brought back through it.
Mat4 rigidInverse(const Mat4& m) {
  Mat4 r;
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) r.m[c][row] = m.m[row][c];
  const Vec3 t{m.m[3][0], m.m[3][1], m.m[3][2]};
  r.m[3] = {-r.m[0][0] * t.x - r.m[1][0] * t.y - r.m[2][0] * t.z,
            -r.m[0][1] * t.x - r.m[1][1] * t.y - r.m[2][1] * t.z,
            -r.m[0][2] * t.x - r.m[1][2] * t.y - r.m[2][2] * t.z, 1};
  return r;
}

// The camera's own window: yfov high, width / height wide, symmetric about the view axis. The
// tangents are computed as the terrain pass and free-form tessellation always did (in double from
// the degrees), so that their images stay bit for bit what they were.
void setSymmetricWindow(FrameCamera& f, int width, int height) {
  const scene::Camera& cam = f.camera;
  const float aspect = float(width) / float(height);
  f.projection = Mat4::perspective(cam.yfovDegrees * std::numbers::pi_v<float> / 180.0f, aspect,
                                   cam.znear, cam.zfar);
  f.tanTop = std::tan(cam.yfovDegrees * std::numbers::pi / 360);
  f.tanBottom = -f.tanTop;
  f.tanRight = f.tanTop * double(width) / double(height);
  f.tanLeft = -f.tanRight;
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
  f.view = Mat4::lookAt(f.camera.position, f.camera.target, f.camera.up);
  setSymmetricWindow(f, o.width, o.height);
  return f;
}

Result<FrameCamera> channelCamera(const scene::Scene& scene, const RenderOptions& o,
                                  const scene::Channel& channel) {
  Result<FrameCamera> base = chooseCamera(scene, o);
  if (!base.ok()) return base.error();
  FrameCamera f = std::move(base).value();
  // Channel → camera eye space: the offset, then heading, pitch and bank about the channel's own
  // axes. Yaw right is a turn about −y (a right-handed turn about +y swings −z to −x, the left);
  // pitch up a turn about +x; roll right (up leaning to +x) a turn about −z. The view is that
  // placement's inverse before the camera's. Skipped when it is the identity, so that a centred
  // channel keeps the camera's view bit for bit.
  const scene::Channel& c = channel;
  if (c.yawDegrees != 0 || c.pitchDegrees != 0 || c.rollDegrees != 0 ||
      !(c.offset == Vec3{0, 0, 0})) {
    const Mat4 toCamera = Mat4::translation(c.offset) *
                          Mat4::rotation({0, 1, 0}, -radians(c.yawDegrees)) *
                          Mat4::rotation({1, 0, 0}, radians(c.pitchDegrees)) *
                          Mat4::rotation({0, 0, -1}, radians(c.rollDegrees));
    f.view = rigidInverse(toCamera) * f.view;
  }
  if (!c.frustum) {
    setSymmetricWindow(f, c.width, c.height);
    return f;
  }
  // The channel's own window: tangents of its half-angles, and glFrustum's matrix on the near
  // plane (SPEC §9: abutting channels share an edge direction, so they meet without gap or
  // overlap).
  const double toRadians = std::numbers::pi / 180;
  f.tanLeft = std::tan(c.frustum->leftDegrees * toRadians);
  f.tanRight = std::tan(c.frustum->rightDegrees * toRadians);
  f.tanBottom = std::tan(c.frustum->downDegrees * toRadians);
  f.tanTop = std::tan(c.frustum->upDegrees * toRadians);
  const double n = f.camera.znear;
  f.projection = Mat4::frustum(float(n * f.tanLeft), float(n * f.tanRight), float(n * f.tanBottom),
                               float(n * f.tanTop), f.camera.znear, f.camera.zfar);
  return f;
}

EyeRays eyeRays(const FrameCamera& camera) {
  const double znear = camera.camera.znear, zfar = camera.camera.zfar;
  if (camera.projective) {
    // A sub-frustum's projection is invertible by construction (its homography is fitted on four
    // rays with no three coplanar, display/subfrustum.h).
    std::optional<EyeRays> rays =
        EyeRays::ofProjection(camera.view, camera.projection, znear, zfar);
    SV_CHECK(rays.has_value());
    return *rays;
  }
  return EyeRays::of(camera.view, camera.projection, camera.tanLeft, camera.tanRight,
                     camera.tanBottom, camera.tanTop, znear, zfar);
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
