// The scene database's own operations: counting, checking the invariants the loaders promise,
// and merging one scene into another.
#include "synthvis/scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "scene/append.h"
#include "scene/channels.h"

namespace sv::scene {

std::array<Vec3, 2> Mesh::bounds() const {
  if (positions.empty()) return {Vec3{0, 0, 0}, Vec3{0, 0, 0}};
  Vec3 lo = positions[0], hi = positions[0];
  for (const Vec3& p : positions) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  return {lo, hi};
}

const Material& Scene::materialAt(int index) const {
  static const Material defaultMaterial;
  return index >= 0 ? materials[size_t(index)] : defaultMaterial;
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const Instance& instance : instances)
    if (instance.mesh >= 0 && size_t(instance.mesh) < meshes.size())
      n += meshes[size_t(instance.mesh)].triangleCount();
  return n;
}

namespace {

bool isFinite(Vec4 v) { return isFinite(Vec3{v.x, v.y, v.z}) && std::isfinite(v.w); }

// "meshes[3] 'wheel'" — the name helps when a file has hundreds of meshes.
std::string meshLabel(const Mesh& mesh, size_t i) {
  return mesh.name.empty() ? fmt::format("meshes[{}]", i)
                           : fmt::format("meshes[{}] '{}'", i, mesh.name);
}

}  // namespace

namespace {
constexpr std::pair<const char*, TextureFilter> kTextureFilterNames[] = {
    {"point", TextureFilter::point},
    {"nearest", TextureFilter::nearest},
    {"tri3", TextureFilter::threePoint},
    {"bilinear", TextureFilter::bilinear},
    {"trilinear3", TextureFilter::trilinearThreePoint},
    {"trilinear", TextureFilter::trilinear},
    {"aniso", TextureFilter::anisotropic}};
}  // namespace

Result<TextureFilter> parseTextureFilter(const std::string& name) {
  for (const auto& [n, f] : kTextureFilterNames)
    if (name == n) return f;
  return Error{"", "",
               fmt::format("unknown texture filter '{}' (point, nearest, tri3, bilinear, "
                           "trilinear3, trilinear or aniso)",
                           name)};
}

const char* textureFilterName(TextureFilter filter) {
  for (const auto& [n, f] : kTextureFilterNames)
    if (filter == f) return n;
  return "inherit";
}

namespace {

bool inRange(float v, float lo, float hi) { return v >= lo && v <= hi; }

// A free form's own invariants (FreeFormNode): its size, finite coefficients and weights, clips
// at its root alone. `label` names it in the message.
Status validateForm(const FreeFormNode& form, const std::string& label) {
  auto fail = [](std::string message) { return Status(Error{"", "", std::move(message)}); };
  if (form.quadricCount() > kMaxFreeFormQuadrics)
    return fail(fmt::format("{}: {} quadrics (at most {})", label, form.quadricCount(),
                            kMaxFreeFormQuadrics));
  std::vector<const FreeFormNode*> stack{&form};
  while (!stack.empty()) {
    const FreeFormNode* n = stack.back();
    stack.pop_back();
    bool finite = true;
    for (double c : n->quadric) finite &= std::fabs(c) <= 1e30;
    for (const auto& clip : n->clips)
      for (double c : clip) finite &= std::fabs(c) <= 1e30;
    if (!finite)
      return fail(fmt::format("{}: a quadric coefficient is not finite (or over 1e30)", label));
    if (n != &form && !n->clips.empty())
      return fail(fmt::format("{}: clips belong to the root of a free form", label));
    if (!(std::fabs(n->weight) <= 1e30))
      return fail(fmt::format("{}: a weight is not finite", label));
    for (const FreeFormNode& p : n->perturbations) stack.push_back(&p);
  }
  return {};
}

// The volumes' invariants (synthvis/volumes.h): a grid of the size it says, within the limits,
// finite positive spacing and scale; a finite affine invertible transform; a transfer function of
// 1 … 256 points, values increasing, colours finite and non-negative, opacities in [0, 1].
Status validateVolumes(const Scene& scene) {
  auto fail = [](size_t i, const std::string& name, std::string message) {
    return Status(Error{"", "", fmt::format("volumes[{}] ('{}'): {}", i, name, message)});
  };
  for (size_t i = 0; i < scene.volumes.size(); ++i) {
    const VolumeObject& v = scene.volumes[i];
    if (!v.grid) return fail(i, v.name, "no grid");
    const VolumeGrid& g = *v.grid;
    if (g.nx < 2 || g.ny < 2 || g.nz < 2 || g.nx > kMaxVolumeSide || g.ny > kMaxVolumeSide ||
        g.nz > kMaxVolumeSide || size_t(g.nx) * size_t(g.ny) * size_t(g.nz) > kMaxVolumeSamples)
      return fail(i, v.name,
                  fmt::format("{} × {} × {} samples (2 … {} a side, at most {} in all)", g.nx, g.ny,
                              g.nz, kMaxVolumeSide, kMaxVolumeSamples));
    if (g.codes.size() != size_t(g.nx) * size_t(g.ny) * size_t(g.nz))
      return fail(i, v.name, fmt::format("{} codes for {} samples", g.codes.size(),
                                         size_t(g.nx) * size_t(g.ny) * size_t(g.nz)));
    if (!(g.scale > 0) || !std::isfinite(g.scale) || !std::isfinite(g.offset) ||
        !std::isfinite(g.offset + 65535 * g.scale) || !(g.spacing.x > 0) || !(g.spacing.y > 0) ||
        !(g.spacing.z > 0) || !isFinite(g.spacing))
      return fail(i, v.name, "its value scale and spacing must be finite and positive");
    bool finite = true;
    for (const auto& row : v.transform.m)
      for (float x : row) finite &= std::isfinite(x);
    const Mat4& m = v.transform;
    const double det = linearDeterminant(m);
    if (!finite || m.m[0][3] != 0 || m.m[1][3] != 0 || m.m[2][3] != 0 || m.m[3][3] != 1 ||
        !(std::fabs(det) > 1e-30) || !std::isfinite(det))
      return fail(i, v.name, "its transform must be finite, affine and invertible");
    if (v.transfer.empty() || v.transfer.size() > 256)
      return fail(i, v.name, fmt::format("{} transfer points (1 … 256)", v.transfer.size()));
    for (size_t k = 0; k < v.transfer.size(); ++k) {
      const TransferPoint& p = v.transfer[k];
      if (!std::isfinite(p.value) || (k > 0 && !(p.value > v.transfer[k - 1].value)) ||
          !inRange(p.color.x, 0, 1e6f) || !inRange(p.color.y, 0, 1e6f) ||
          !inRange(p.color.z, 0, 1e6f) || !inRange(p.opacity, 0, 1))
        return fail(i, v.name,
                    fmt::format("transfer point {}: values must increase, colours be finite and "
                                "non-negative, opacities in [0, 1]",
                                k));
    }
    if (!inRange(v.opacityUnit, 0, 1e30f)) return fail(i, v.name, "opacityUnit must be ≥ 0");
    if (v.shell.size() > 16) return fail(i, v.name, fmt::format("{} shell quadrics (at most 16)", v.shell.size()));
    for (const auto& q : v.shell)
      for (double c : q)
        if (!std::isfinite(c) || std::fabs(c) > 1e30) return fail(i, v.name, "a shell coefficient is not finite");
    if (v.freeFormShell)
      if (Status st = validateForm(*v.freeFormShell, fmt::format("volume '{}': shell", v.name));
          !st)
        return st;
  }
  const VolumeSettings& s = scene.volumeSettings;
  if (!inRange(s.step, 0.05f, 8) || !inRange(s.termination, 0, 0.5f))
    return Status(Error{"", "", "volumeSettings: step must be 0.05 … 8 voxels, termination 0 … 0.5"});
  return {};
}

// The light points' invariants (synthvis/light_points.h): every number finite and in its range,
// every index in range. The per-light checks are branch-free reductions (they run every frame).
Status validateLights(const Scene& scene) {
  auto fail = [](std::string message) { return Status(Error{"", "", std::move(message)}); };
  for (size_t i = 0; i < scene.lightAppearances.size(); ++i) {
    const LightAppearance& a = scene.lightAppearances[i];
    const bool ok = isFinite(a.color) && isFinite(a.backColor) && isFinite(a.lowColor) &&
                    isFinite(a.direction) && length(a.direction) > 0 &&
                    inRange(a.intensity, 0, 1e9f) && inRange(a.horizontalLobe, 1e-3f, 179.9f) &&
                    inRange(a.verticalLobe, 1e-3f, 179.9f) && inRange(a.falloff, 0, 64) &&
                    inRange(a.splitAngle, -90, 90) && inRange(a.splitWidth, 0, 90) &&
                    inRange(a.blink.period, 0, 1e6f) && inRange(a.blink.phase, -1e6f, 1e6f) &&
                    inRange(a.blink.onFraction, 0, 1) && inRange(a.rotationPeriod, 0, 1e6f) &&
                    a.color.x >= 0 && a.color.y >= 0 && a.color.z >= 0;
    if (!ok) return fail(fmt::format("lightAppearances[{}] ('{}'): a value is not finite or out "
                                     "of range", i, a.name));
  }
  bool ok = true;
  const auto appearances = uint32_t(scene.lightAppearances.size());
  const auto groups = int32_t(scene.lightGroups.size());
  for (const LightPoint& p : scene.lightPoints)
    ok &= isFinite(p.position) & (p.appearance < appearances) & (p.group >= -1) &
          (p.group < groups) & std::isfinite(p.phase);
  if (!ok)
    for (size_t i = 0; i < scene.lightPoints.size(); ++i) {
      const LightPoint& p = scene.lightPoints[i];
      if (!isFinite(p.position) || !std::isfinite(p.phase))
        return fail(fmt::format("lightPoints[{}]: not finite", i));
      if (p.appearance >= appearances)
        return fail(fmt::format("lightPoints[{}]: appearance {} does not exist ({} appearances)",
                                i, p.appearance, appearances));
      if (p.group < -1 || p.group >= groups)
        return fail(fmt::format("lightPoints[{}]: group {} does not exist ({} groups)", i,
                                p.group, groups));
    }
  for (size_t i = 0; i < scene.lightGroups.size(); ++i)
    if (!inRange(scene.lightGroups[i].dim, 0, 1))
      return fail(fmt::format("lightGroups[{}] ('{}'): dim {} is not in [0, 1]", i,
                              scene.lightGroups[i].name, scene.lightGroups[i].dim));
  const LightSettings& l = scene.lightSettings;
  if (!inRange(l.exposure, 0, 1e12f) || !inRange(l.minSize, 0.5f, 64) ||
      !inRange(l.maxSize, l.minSize, 64) || !inRange(l.punchThrough, 0, 1) ||
      !inRange(l.depthBias, 0, 1e6f))
    return fail("lightSettings: a value is not finite or out of range (sizes 0.5 … 64 pixels, "
                "min ≤ max; punchThrough 0 … 1)");
  for (size_t i = 0; i < scene.lines.size(); ++i) {
    const LineSegment& seg = scene.lines[i];
    if (!isFinite(seg.a) || !isFinite(seg.b) || !inRange(seg.color.x, 0, 1e6f) ||
        !inRange(seg.color.y, 0, 1e6f) || !inRange(seg.color.z, 0, 1e6f))
      return fail(fmt::format("lines[{}]: not finite, or a negative colour", i));
  }
  if (!inRange(scene.lineSettings.width, 1.0f / 64, 64) ||
      !inRange(scene.lineSettings.depthBias, 0, 0.5f))
    return fail("lineSettings: width must be 1/64 … 64 pixels and depthBias 0 … 0.5");
  if (Status st = validateVolumes(scene); !st) return st;
  const StarField& f = scene.stars;
  if (!inRange(f.latitude, -90, 90) || !std::isfinite(f.siderealTime) ||
      !inRange(f.brightness, 0, 1e6f) || !std::isfinite(f.limit))
    return fail("stars: latitude, siderealTime, brightness or limit not finite or out of range");
  ok = true;
  for (const Star& star : f.stars)
    ok &= isFinite(star.direction) & isFinite(star.color) & std::isfinite(star.magnitude);
  if (!ok) return fail("stars: a star's direction, colour or magnitude is not finite");
  if (!std::isfinite(scene.time)) return fail("time is not finite");
  return {};
}

// The meshes' invariants (scene.h, Mesh); `vertexData`: also every position finite and every
// index in range.
Status validateMeshes(const Scene& scene, bool vertexData) {
  auto fail = [](std::string message) { return Status(Error{"", "", std::move(message)}); };
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& mesh = scene.meshes[i];
    const size_t n = mesh.positions.size();
    if (mesh.indices.size() % 3 != 0)
      return fail(fmt::format("{}: {} indices is not a multiple of 3", meshLabel(mesh, i),
                              mesh.indices.size()));
    auto sizeOk = [n](size_t size) { return size == 0 || size == n; };
    if (!sizeOk(mesh.normals.size()) || !sizeOk(mesh.colors.size()) || !sizeOk(mesh.uvs.size()))
      return fail(fmt::format(
          "{}: attribute arrays must be empty or match the {} positions (normals {}, colors {}, "
          "uvs {})",
          meshLabel(mesh, i), n, mesh.normals.size(), mesh.colors.size(), mesh.uvs.size()));
    if (mesh.material < -1 ||
        (mesh.material >= 0 && size_t(mesh.material) >= scene.materials.size()))
      return fail(fmt::format("{}: material {} does not exist ({} materials)", meshLabel(mesh, i),
                              mesh.material, scene.materials.size()));
    if (!vertexData) continue;
    // Two branch-free reductions (they vectorize) in the common case, the offender searched for
    // only when one fails: early-exit loops cost the renderer, which ran them every frame on one
    // thread while the others waited (docs/performance.md, "Vertex stage").
    uint32_t maxIndex = 0;
    for (uint32_t index : mesh.indices) maxIndex = std::max(maxIndex, index);
    if (!mesh.indices.empty() && maxIndex >= n) {
      size_t k = 0;
      while (mesh.indices[k] < n) ++k;
      return fail(fmt::format("{}: indices[{}] = {} is out of range ({} vertices)",
                              meshLabel(mesh, i), k, mesh.indices[k], n));
    }
    bool finite = true;
    for (const Vec3& p : mesh.positions) finite &= isFinite(p);
    if (!finite) {
      for (size_t k = 0; k < n; ++k)
        if (!isFinite(mesh.positions[k]))
          return fail(fmt::format("{}: positions[{}] is not finite", meshLabel(mesh, i), k));
    }
  }
  return {};
}

// The instances' invariants (scene.h, Instance, LodGroup, InstanceTree).
Status validateInstances(const Scene& scene) {
  auto fail = [](std::string message) { return Status(Error{"", "", std::move(message)}); };
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    if (instance.mesh < 0 || size_t(instance.mesh) >= scene.meshes.size())
      return fail(fmt::format("instances[{}]: mesh {} does not exist ({} meshes)", i, instance.mesh,
                              scene.meshes.size()));
    if (!isFinite(instance.transform))
      return fail(fmt::format("instances[{}]: transform is not finite", i));
    if (instance.lod < -1 || (instance.lod >= 0 && size_t(instance.lod) >= scene.lodGroups.size()))
      return fail(fmt::format("instances[{}]: level-of-detail group {} does not exist ({} groups)",
                              i, instance.lod, scene.lodGroups.size()));
    if (instance.lod >= 0 && scene.lodGroups[size_t(instance.lod)].levels[0].mesh != instance.mesh)
      return fail(fmt::format(
          "instances[{}]: mesh {} is not level 0 of its level-of-detail group (mesh {})", i,
          instance.mesh, scene.lodGroups[size_t(instance.lod)].levels[0].mesh));
  }
  if (scene.instanceTree && scene.instanceTree->instanceCount > scene.instances.size())
    return fail(fmt::format("the instance tree covers {} instances, the scene has {}",
                            scene.instanceTree->instanceCount, scene.instances.size()));
  for (size_t i = 0; i < scene.lodGroups.size(); ++i) {
    const LodGroup& g = scene.lodGroups[i];
    const std::string label =
        g.name.empty() ? fmt::format("lodGroups[{}]", i) : fmt::format("LOD group '{}'", g.name);
    if (g.levels.empty() || g.levels.size() > kMaxLodLevels)
      return fail(fmt::format("{}: {} levels (1 to {})", label, g.levels.size(), kMaxLodLevels));
    if (!(g.fade >= 0 && g.fade <= 1e30f))
      return fail(fmt::format("{}: fade {} is negative or not finite", label, g.fade));
    float from = 0;
    for (size_t k = 0; k < g.levels.size(); ++k) {
      const LodLevel& l = g.levels[k];
      if (l.mesh < 0 || size_t(l.mesh) >= scene.meshes.size())
        return fail(fmt::format("{}: level {}: mesh {} does not exist ({} meshes)", label, k,
                                l.mesh, scene.meshes.size()));
      if (!(l.to > from && l.to <= 1e30f))
        return fail(fmt::format("{}: level {}: 'to' {} must exceed {} (ranges increase)", label, k,
                                l.to, from));
      if (g.fade > 0 && !(l.to - g.fade >= from))
        return fail(fmt::format("{}: level {}: the fade of {} is longer than its span [{}, {})",
                                label, k, g.fade, from, l.to));
      from = l.to;
    }
  }
  return {};
}

// The articulations' invariants (scene.h, Switch, Dof).
Status validateArticulations(const Scene& scene) {
  auto fail = [](std::string message) { return Status(Error{"", "", std::move(message)}); };
  for (size_t i = 0; i < scene.switches.size(); ++i) {
    const Switch& sw = scene.switches[i];
    for (const std::vector<uint32_t>& child : sw.children)
      for (uint32_t k : child)
        if (k >= scene.instances.size())
          return fail(fmt::format("switches[{}]: instance {} does not exist", i, k));
    for (const std::vector<bool>& mask : sw.masks)
      if (mask.size() != sw.children.size())
        return fail(fmt::format("switches[{}]: a mask of {} flags for {} children", i,
                                mask.size(), sw.children.size()));
    if (!sw.masks.empty() && sw.current >= sw.masks.size())
      return fail(fmt::format("switches[{}]: current mask {} of {}", i, sw.current,
                              sw.masks.size()));
  }
  for (size_t i = 0; i < scene.dofs.size(); ++i) {
    const Dof& d = scene.dofs[i];
    if (d.parent < -1 || d.parent >= int(i))
      return fail(fmt::format("dofs[{}]: parent {} is not an earlier degree of freedom", i,
                              d.parent));
    if (!isFinite(d.place) || !isFinite(d.frame))
      return fail(fmt::format("dofs[{}]: a transform is not finite", i));
    for (const auto& [k, part] : d.parts)
      if (k >= scene.instances.size() || !scene.instances[k].articulated || !isFinite(part))
        return fail(fmt::format("dofs[{}]: part instance {} does not exist, is not marked "
                                "articulated, or has a transform that is not finite",
                                i, k));
  }
  return {};
}

// The free forms' invariants (scene.h, FreeFormObject, FreeFormNode).
Status validateFreeForms(const Scene& scene) {
  auto fail = [](std::string message) { return Status(Error{"", "", std::move(message)}); };
  for (size_t i = 0; i < scene.freeForms.size(); ++i) {
    const FreeFormObject& f = scene.freeForms[i];
    const std::string label =
        f.name.empty() ? fmt::format("freeForms[{}]", i) : fmt::format("free form '{}'", f.name);
    if (f.material < -1 || (f.material >= 0 && size_t(f.material) >= scene.materials.size()))
      return fail(fmt::format("{}: material {} does not exist ({} materials)", label, f.material,
                              scene.materials.size()));
    if (!isFinite(f.transform)) return fail(fmt::format("{}: transform is not finite", label));
    const auto& m = f.transform.m;
    if (m[0][3] != 0 || m[1][3] != 0 || m[2][3] != 0 || m[3][3] != 1)
      return fail(fmt::format("{}: transform is not affine (last row must be 0, 0, 0, 1)", label));
    if (!(std::fabs(linearDeterminant(f.transform)) > 1e-20))
      return fail(fmt::format("{}: transform is singular", label));
    if (Status st = validateForm(f.form, label); !st) return st;
  }
  return {};
}

// The materials', textures', fog's, lights' (validateLights) and cameras' invariants: finite,
// and every index in range.
Status validateLooks(const Scene& scene) {
  auto fail = [](std::string message) { return Status(Error{"", "", std::move(message)}); };
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    if (m.texture < -1 || (m.texture >= 0 && size_t(m.texture) >= scene.textures.size()))
      return fail(fmt::format("materials[{}]: texture {} does not exist ({} textures)", i,
                              m.texture, scene.textures.size()));
    if (!isFinite(m.baseColor) || !std::isfinite(m.uvScale.x) || !std::isfinite(m.uvScale.y) ||
        !(m.specular >= 0 && m.specular <= 1e6f) || !(m.shininess >= 0 && m.shininess <= 1e6f) ||
        !std::isfinite(m.alphaCutoff))
      return fail(
          fmt::format("materials[{}]: colour, specular, shininess or alphaCutoff is not "
                      "finite or out of range",
                      i));
  }
  for (size_t i = 0; i < scene.textures.size(); ++i)
    if (!scene.textures[i].texture)
      return fail(fmt::format("textures[{}] ('{}') holds no image", i, scene.textures[i].name));
  if (!isFinite(scene.fog.color) || !(scene.fog.beta >= 0 && std::isfinite(scene.fog.beta)))
    return fail("fog: colour or beta is not finite, or beta is negative");
  for (size_t i = 0; i < scene.pointLights.size(); ++i)
    if (!isFinite(scene.pointLights[i].position) || !isFinite(scene.pointLights[i].color))
      return fail(fmt::format("pointLights[{}]: not finite", i));
  if (Status st = validateLights(scene); !st) return st;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const Camera& c = scene.cameras[i];
    if (!isFinite(c.position) || !isFinite(c.target) || !isFinite(c.up) ||
        !std::isfinite(c.yfovDegrees) || !std::isfinite(c.znear) || !std::isfinite(c.zfar))
      return fail(fmt::format("cameras[{}]: not finite", i));
  }
  return {};
}

}  // namespace

Status validate(const Scene& scene, const std::string& file, bool vertexData) {
  // Each part's first problem, named by `file`.
  for (const Status& s :
       {validateMeshes(scene, vertexData), validateInstances(scene), validateArticulations(scene),
        validateFreeForms(scene), validateLooks(scene)})
    if (!s) return Status(Error{file, "", s.error().message});
  if (std::string problem = detail::channelsProblem(scene.channels); !problem.empty())
    return Status(Error{file, "", std::move(problem)});
  return {};
}

namespace detail {

void appendArticulationsAndLights(Scene& scene, const Scene& other, const Mat4& transform,
                                  uint32_t instanceBase) {
  // Articulations keep their instances; top-level degrees of freedom move into the new place.
  for (Switch s : other.switches) {
    for (std::vector<uint32_t>& child : s.children)
      for (uint32_t& i : child) i += instanceBase;
    scene.switches.push_back(std::move(s));
  }
  const int dofBase = static_cast<int>(scene.dofs.size());
  for (Dof d : other.dofs) {
    if (d.parent >= 0) d.parent += dofBase;
    else d.place = transform * d.place;
    for (auto& part : d.parts) part.first += instanceBase;
    scene.dofs.push_back(std::move(d));
  }
  // Light points, their appearances turned and their groups kept.
  const uint32_t appearanceBase = static_cast<uint32_t>(scene.lightAppearances.size());
  const int32_t groupBase = static_cast<int32_t>(scene.lightGroups.size());
  for (LightAppearance a : other.lightAppearances) {
    if (a.directional) a.direction = normalize(transform.transformDirection(a.direction));
    scene.lightAppearances.push_back(std::move(a));
  }
  scene.lightGroups.insert(scene.lightGroups.end(), other.lightGroups.begin(),
                           other.lightGroups.end());
  for (LightPoint p : other.lightPoints) {
    p.position = transform.transformPoint(p.position);
    p.appearance += appearanceBase;
    if (p.group >= 0) p.group += groupBase;
    scene.lightPoints.push_back(p);
  }
  for (LineSegment l : other.lines) {
    l.a = transform.transformPoint(l.a);
    l.b = transform.transformPoint(l.b);
    scene.lines.push_back(l);
  }
  for (VolumeObject v : other.volumes) {
    v.transform = transform * v.transform;
    scene.volumes.push_back(std::move(v));
  }
}

}  // namespace detail

void appendScene(Scene& scene, Scene other, const Mat4& transform) {
  const int materialBase = static_cast<int>(scene.materials.size());
  const int meshBase = static_cast<int>(scene.meshes.size());
  const int textureBase = static_cast<int>(scene.textures.size());
  const uint32_t instanceBase = static_cast<uint32_t>(scene.instances.size());
  for (TextureMap& map : other.textures) scene.textures.push_back(std::move(map));
  for (Material& material : other.materials) {
    if (material.texture >= 0) material.texture += textureBase;
    scene.materials.push_back(std::move(material));
  }
  for (Mesh& mesh : other.meshes) {
    if (mesh.material >= 0) mesh.material += materialBase;
    scene.meshes.push_back(std::move(mesh));
  }
  const int lodBase = static_cast<int>(scene.lodGroups.size());
  for (LodGroup& group : other.lodGroups) {
    for (LodLevel& level : group.levels) level.mesh += meshBase;
    scene.lodGroups.push_back(std::move(group));
  }
  for (Instance instance : other.instances) {
    instance.mesh += meshBase;
    instance.transform = transform * instance.transform;
    if (instance.lod >= 0) instance.lod += lodBase;
    scene.instances.push_back(instance);
  }
  detail::appendArticulationsAndLights(scene, other, transform, instanceBase);
  for (std::string& w : other.warnings) scene.warnings.push_back(std::move(w));
  for (FreeFormObject& f : other.freeForms) {
    if (f.material >= 0) f.material += materialBase;
    f.transform = transform * f.transform;
    scene.freeForms.push_back(std::move(f));
  }
  // Cameras travel with their geometry; the lights, fog and background belong to the outer scene
  // (docs/scene-format.md, "Referenced files").
  for (Camera camera : other.cameras) {
    camera.position = transform.transformPoint(camera.position);
    camera.target = transform.transformPoint(camera.target);
    camera.up = normalize(transform.transformDirection(camera.up));
    scene.cameras.push_back(std::move(camera));
  }
}

}  // namespace sv::scene
