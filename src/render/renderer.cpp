// The one place that wires a frame together (STYLE.md habit 1): scene → vertex stage → setup and
// binning → tiles → resolve.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <thread>

#include "freeform/tessellate.h"
#include "freeform/tile_pass.h"
#include "geometry/vertex_stage.h"
#include "output/resolve.h"
#include "render/frame_renderer.h"
#include "synthvis/render.h"

namespace sv {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

int resolveThreads(int requested) {
  if (requested > 0) return requested;
  return std::clamp(int(std::thread::hardware_concurrency()), 1, kMaxThreads);
}

// A camera for scenes that have none: looks at the centre of the scene's bounds from the front
// and a little above, far enough to see all of it.
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
  scene::Camera cam;
  if (!any) return cam;
  const Vec3 centre = (lo + hi) * 0.5f;
  const float radius = std::max(0.5f * length(hi - lo), 1e-3f);
  const float distance = radius / std::sin(0.5f * cam.yfovDegrees * 3.14159265f / 180.0f);
  cam.target = centre;
  cam.position = centre + normalize(Vec3{0, 0.35f, 1}) * distance;
  cam.znear = std::max(distance - radius, distance * 1e-3f) * 0.5f;
  cam.zfar = (distance + radius) * 2;
  return cam;
}

}  // namespace

namespace {

struct CameraMatrices {
  Mat4 view, projection;
};

Result<CameraMatrices> cameraMatrices(const scene::Scene& scene, const RenderOptions& o) {
  scene::Camera cam;
  if (!scene.cameras.empty()) {
    if (o.camera >= int(scene.cameras.size()))
      return Error{"", "",
                   fmt::format("camera {} does not exist (the scene has {})", o.camera,
                               scene.cameras.size())};
    cam = scene.cameras[size_t(o.camera)];
  } else {
    cam = defaultCamera(scene);
  }
  const float aspect = float(o.width) / float(o.height);
  return CameraMatrices{
      Mat4::lookAt(cam.position, cam.target, cam.up),
      Mat4::perspective(cam.yfovDegrees * 3.14159265358979f / 180.0f, aspect, cam.znear, cam.zfar)};
}

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

// The shading stage's view of the scene: materials (two variants each — with and without normals
// to light per pixel), and lights and fog in eye space.
struct ShadingTables {
  std::vector<shade::MaterialShading> materials;  // [2·(material + 1) + hasNormals]
  shade::Environment environment;
  bool any = false;  // some draw needs pixel shading (or fog)

  const shade::MaterialShading* of(int material, bool hasNormals) const {
    return &materials[size_t(2 * (material + 1) + (hasNormals ? 1 : 0))];
  }
};

void buildShading(const scene::Scene& scene, const RenderOptions& o, const Mat4& view,
                  ShadingTables& out) {
  out.materials.clear();
  const scene::Material defaultMaterial;
  const bool hasLights = scene.light.enabled || !scene.pointLights.empty();
  for (int m = -1; m < int(scene.materials.size()); ++m) {
    const scene::Material& mat = m >= 0 ? scene.materials[size_t(m)] : defaultMaterial;
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
}

// The smallest view depth of the corners of the box [lo, hi] placed by `toEye`.
float nearestEyeDepth(const Mat4& toEye, Vec3 lo, Vec3 hi) {
  float near = std::numeric_limits<float>::infinity();
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
    near = std::min(near, -toEye.transformPoint(corner).z);
  }
  return near;
}

// The order instances are drawn in (indices into scene.instances). Opaque ones: in submission
// order for the Z-buffer; for masking (SPEC §4) by priority, then nearest first — by the smallest
// view depth of their bounding box's corners, which orders objects separated in depth correctly
// (docs/hidden-surfaces.md). Translucent ones, always: farthest first by the view depth of their
// box's centre, so that nearer ones blend over farther ones. Stable: ties keep submission order.
// `boxes`: every mesh's bounds (Mesh::bounds), or empty when neither sort applies.
std::vector<uint32_t> drawOrder(const scene::Scene& scene, const Mat4& view, RenderOptions::Hsr hsr,
                                const std::vector<std::array<Vec3, 2>>& boxes) {
  std::vector<uint32_t> order(scene.instances.size());
  std::iota(order.begin(), order.end(), 0u);
  if (boxes.empty()) return order;
  const bool sortOpaque = hsr != RenderOptions::Hsr::zbuffer;
  // Per instance the view depths of its mesh's box's corners.
  std::vector<float> nearest(order.size()), centre(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const scene::Instance& inst = scene.instances[i];
    const auto& [lo, hi] = boxes[size_t(inst.mesh)];
    const Mat4 toEye = view * inst.transform;
    nearest[i] = nearestEyeDepth(toEye, lo, hi);
    centre[i] = -toEye.transformPoint((lo + hi) * 0.5f).z;
  }
  auto translucent = [&](uint32_t i) {
    const int m = scene.meshes[size_t(scene.instances[i].mesh)].material;
    return m >= 0 && scene.materials[size_t(m)].alphaMode == scene::AlphaMode::blend;
  };
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const bool ta = translucent(a), tb = translucent(b);
    if (ta != tb) return tb;  // opaque first (the passes pick them out again)
    if (ta) return centre[a] > centre[b];
    if (!sortOpaque) return false;
    if (scene.instances[a].priority != scene.instances[b].priority)
      return scene.instances[a].priority < scene.instances[b].priority;
    return nearest[a] < nearest[b];
  });
  return order;
}

freeform::Mat4d toDouble(const Mat4& m) {  // column-major float → row-major double
  freeform::Mat4d d;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) d.m[r][c] = m.m[c][r];
  return d;
}

freeform::FreeForm toFreeForm(const scene::FreeFormNode& n) {
  freeform::FreeForm f;
  f.base.c = n.quadric;
  f.weight = n.weight;
  for (const scene::FreeFormNode& p : n.perturbations) f.perturbations.push_back(toFreeForm(p));
  for (const auto& c : n.clips) f.clips.push_back(freeform::Quadric{c});
  return f;
}

// The frame's free forms for the tile pass: each carried into the cube by projection · view ·
// model (SPEC §12), lit per pixel with its material's colour and specular term (Phong whenever the
// scene has lights and the material is lit: the normal is exact at every pixel), both sides lit.
// A texture is projected along the object's y axis (tile_pass.h). Free forms are always opaque.
std::vector<freeform::ShadedForm> shadedForms(const scene::Scene& scene, const Mat4& view,
                                              const Mat4& projection,
                                              const ShadingTables& shading) {
  std::vector<freeform::ShadedForm> out;
  const scene::Material defaultMaterial;
  const bool lights = shading.environment.lightOn || !shading.environment.points.empty();
  for (const scene::FreeFormObject& object : scene.freeForms) {
    const scene::Material& mat =
        object.material >= 0 ? scene.materials[size_t(object.material)] : defaultMaterial;
    const freeform::Mat4d toEye = toDouble(view * object.transform);
    const std::optional<freeform::Mat4d> eyeInverse = toEye.inverse();
    const freeform::FreeForm form = toFreeForm(object.form);
    std::optional<freeform::ProjectedFreeForm> projected =
        freeform::ProjectedFreeForm::make(form, toDouble(projection) * toEye);
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

}  // namespace

Result<Mat4> viewProjection(const scene::Scene& scene, const RenderOptions& o) {
  const Result<CameraMatrices> m = cameraMatrices(scene, o);
  if (!m.ok()) return m.error();
  return m.value().projection * m.value().view;
}

Result<Mat4> viewMatrix(const scene::Scene& scene, const RenderOptions& o) {
  const Result<CameraMatrices> m = cameraMatrices(scene, o);
  if (!m.ok()) return m.error();
  return m.value().view;
}

Status validate(const RenderOptions& o) {
  if (o.width < 1 || o.width > kMaxRasterSize || o.height < 1 || o.height > kMaxRasterSize)
    return Error{"", "",
                 fmt::format("image size {}x{} is out of range (1…{} each)", o.width, o.height,
                             kMaxRasterSize)};
  if (o.threads < 0 || o.threads > kMaxThreads)
    return Error{"", "",
                 fmt::format("thread count {} is out of range (0…{})", o.threads, kMaxThreads)};
  if (o.camera < 0) return Error{"", "", "camera index must not be negative"};
  if (o.supersample != 1 && o.supersample != 2 && o.supersample != 4 && o.supersample != 8 &&
      o.supersample != 16)
    return Error{
        "", "", fmt::format("supersampling {} is not supported (1, 2, 4, 8 or 16)", o.supersample)};
  if (o.supersample > 1 &&
      (o.width * o.supersample > kMaxRasterSize || o.height * o.supersample > kMaxRasterSize))
    return Error{"", "",
                 fmt::format("supersampling {}x{} by {} exceeds the {}-pixel raster", o.width,
                             o.height, o.supersample, kMaxRasterSize)};
  const bool debug = o.debugView != RenderOptions::DebugView::none;
  if (o.supersample > 1 && debug)
    return Error{"", "", "a debug view shows one value per pixel; it cannot be supersampled"};
  if (o.samples != 1 && o.samples != 4 && o.samples != 8 && o.samples != 16 && o.samples != 64)
    return Error{
        "", "",
        fmt::format("{} samples per pixel is not supported (1, 4, 8, 16 or 64)", o.samples)};
  if (o.samples > 1 && o.supersample > 1)
    return Error{"", "", "anti-aliasing and supersampling are alternatives; choose one"};
  if (o.samples > 1 && debug)
    return Error{"", "", "a debug view shows one value per pixel; it cannot be anti-aliased"};
  if (o.filter != RenderOptions::Filter::box && debug)
    return Error{"", "", "a debug view cannot be filtered"};
  if (o.debugView == RenderOptions::DebugView::occupancy && o.hsr == RenderOptions::Hsr::zbuffer)
    return Error{"", "", "the occupancy view shows masking: use --hsr priority or hybrid"};
  if (o.marchSteps < 1 || o.marchSteps > 1000000)
    return Error{"", "", fmt::format("{} march steps is out of range (1…1000000)", o.marchSteps)};
  if (o.gamma != 0 && !(o.gamma >= 0.5 && o.gamma <= 5))
    return Error{"", "", fmt::format("gamma {} is out of range (0.5…5, or 0 for sRGB)", o.gamma)};
  return {};
}

std::string FrameStats::summary() const {
  return fmt::format(
             "triangles in {} / culled {} (facing {}, outside {}, degenerate {}, invalid {}{}) / "
             "drawn {} "
             "| windows 64:{} 32:{} 16:{} 8:{} 4:{} px-tests:{} full:{} occluded:{} (triangles {}, "
             "objects {}{}) | fragments {} (hidden {}{}) | {:.2f} ms (vertex {:.2f}, setup {:.2f}, "
             "tiles "
             "{:.2f} incl. resolve)",
             trianglesIn, culled(), culledFacing, culledOutside, culledDegenerate, culledInvalid,
             culledOccluded ? fmt::format(", occluded {}", culledOccluded) : std::string(), drawn,
             windows[0], windows[1], windows[2], windows[3], windows[4], windows[5], fullWindows,
             occludedWindows, occludedTriangles, occludedObjects,
             hybridWoken ? fmt::format(", hybrid woke in {} tiles", hybridWoken) : std::string(),
             fragments, hiddenFragments,
             shadedByList + shadedByScan ? fmt::format("; shading passes by list {}, by scan {}",
                                                       shadedByList, shadedByScan)
                                         : std::string(),
             totalMs, vertexMs, setupMs, rasterMs) +
         (freeForms ? fmt::format(" | free forms {}: cells {} (masked {}), bounds {}, rays {}, "
                                  "hits {}",
                                  freeForms, freeFormCells, freeFormMaskedCells, freeFormBounds,
                                  freeFormRays, freeFormHits)
                    : std::string());
}

Result<scene::Scene> tessellatedScene(const scene::Scene& scene, const RenderOptions& o) {
  const Result<CameraMatrices> camera = cameraMatrices(scene, o);
  if (!camera.ok()) return camera.error();
  scene::Camera cam =
      scene.cameras.empty() ? defaultCamera(scene) : scene.cameras[size_t(o.camera)];
  const double pixelPerDepth =
      2 * std::tan(cam.yfovDegrees * 3.14159265358979 / 360) / double(o.height * o.supersample);
  scene::Scene out = scene;
  out.freeForms.clear();
  constexpr size_t kMaxTriangles = size_t(1) << 22;
  for (size_t i = 0; i < scene.freeForms.size(); ++i) {
    const scene::FreeFormObject& object = scene.freeForms[i];
    const std::string label = object.name.empty() ? fmt::format("freeForms[{}]", i)
                                                  : fmt::format("free form '{}'", object.name);
    const freeform::FreeForm form = toFreeForm(object.form);
    bool unbounded = false;
    const std::optional<freeform::Box> box = freeform::surfaceBounds(form, 1e4, 16, unbounded);
    if (unbounded)
      return Error{"", "", fmt::format("{} is unbounded or too large to tessellate", label)};
    if (!box) continue;  // no surface
    // The nearest eye depth of the box, and its smallest half extent as the curvature radius.
    const Mat4 toEye = camera.value().view * object.transform;
    const auto single = [](freeform::Vec3d v) { return Vec3{float(v.x), float(v.y), float(v.z)}; };
    const double nearest = std::max(
        double(nearestEyeDepth(toEye, single((*box)[0]), single((*box)[1]))), double(cam.znear));
    const freeform::Vec3d extent = (*box)[1] - (*box)[0];
    const double radius = 0.5 * std::min({extent.x, extent.y, extent.z});
    // Object units per pixel at that depth (the transform's largest scale brings it to the world).
    double scale = 0;
    for (int c = 0; c < 3; ++c)
      scale = std::max(scale, double(length(object.transform.transformDirection(
                                  Vec3{float(c == 0), float(c == 1), float(c == 2)}))));
    const double pixel = nearest * pixelPerDepth / std::max(scale, 1e-30);
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
      const freeform::Vec3d& p = soup.positions[v];
      const freeform::Vec3d& n = soup.normals[v];
      mesh.positions.push_back({float(p.x), float(p.y), float(p.z)});
      mesh.normals.push_back({float(n.x), float(n.y), float(n.z)});
      mesh.uvs.push_back({float(p.x), float(p.z)});  // the free form's projection (tile_pass.h)
      mesh.indices.push_back(uint32_t(v));
    }
    out.meshes.push_back(std::move(mesh));
    out.instances.push_back({int(out.meshes.size()) - 1, object.transform});
  }
  return out;
}

Result<RenderOptions::Hsr> parseHsr(const std::string& text) {
  if (text == "zbuffer") return RenderOptions::Hsr::zbuffer;
  if (text == "priority") return RenderOptions::Hsr::priority;
  if (text == "hybrid") return RenderOptions::Hsr::hybrid;
  return Error{
      "", "",
      fmt::format("unknown hidden-surface method '{}' (zbuffer, priority or hybrid)", text)};
}

const char* hsrName(RenderOptions::Hsr hsr) {
  switch (hsr) {
    case RenderOptions::Hsr::priority:
      return "priority";
    case RenderOptions::Hsr::hybrid:
      return "hybrid";
    default:
      return "zbuffer";
  }
}

struct Renderer::Impl {
  explicit Impl(const RenderOptions& o)
      : options(o),
        frame(resolveThreads(o.threads)),
        gamma(o.gamma == 0 ? output::GammaTable::srgb() : output::GammaTable::power(o.gamma)) {}
  RenderOptions options;
  render::FrameRenderer frame;
  output::GammaTable gamma;
  ShadingTables shading;
  render::DrawPackets packets;
  output::LinearImage linear;  // the box-resolved frame, for the tent filter
  freeform::FreeFormFrame freeForms;
  std::vector<freeform::FreeFormFrame::Scratch> freeFormScratch;  // per worker
  // Per worker, a cache line each: workers count into theirs while casting, and two workers'
  // counters in one line would make each write wait for the other core (false sharing).
  struct alignas(64) WorkerCastStats {
    freeform::CastStats counts;
  };
  std::vector<WorkerCastStats> freeFormStats;
};

Renderer::Renderer(const RenderOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;
const RenderOptions& Renderer::options() const { return impl_->options; }

Status Renderer::render(const scene::Scene& scene, Image& image, FrameStats* statsOut) {
  if (Status s = validate(impl_->options); !s) return s;
  // Every vertex and index the frame draws is checked as the vertex stage reads it (below), not in
  // a pass of its own; the full check runs only to name an offender. (A mesh no instance draws is
  // left to the loaders' validation.)
  if (Status s = scene::validate(scene, "", false); !s) return s;
  auto invalidVertexData = [&]() -> Status {
    if (Status s = scene::validate(scene, ""); !s) return s;
    return Error{"", "", "invalid vertex data"};  // (validate finds what the stage found)
  };
  const RenderOptions& o = impl_->options;
  FrameStats stats;
  const auto start = Clock::now();

  // Stage 2–3: camera, then every instance's vertices to clip space.
  const Result<CameraMatrices> camera = cameraMatrices(scene, o);
  if (!camera.ok()) return camera.error();
  geometry::VertexContext vertexContext{camera.value().view,
                                        camera.value().projection * camera.value().view,
                                        &scene.light, &scene.pointLights};
  ShadingTables& shading = impl_->shading;
  buildShading(scene, o, camera.value().view, shading);
  const bool pixelShading = shading.any && o.debugView == RenderOptions::DebugView::none;
  using DebugView = RenderOptions::DebugView;

  auto t0 = Clock::now();
  render::DrawPackets& p = impl_->packets;
  // Vertices, attributes and indices are resized below and every one is written by the vertex
  // stage: not cleared first, so that a frame of the same size does not zero megabytes for nothing.
  p.calls.clear();
  const scene::Material defaultMaterial;
  auto materialOf = [&](const scene::Mesh& mesh) -> const scene::Material& {
    return mesh.material >= 0 ? scene.materials[mesh.material] : defaultMaterial;
  };
  // Lay out every instance's vertices and triangles, then transform the vertices and copy the
  // indices (offset to the frame's vertex numbering, and range-checked) in parallel chunks, each
  // writing its own range.
  struct VertexJob {
    const scene::Instance* instance;
    bool indices;  // else vertices
    size_t begin, end, out;
    uint32_t base;  // the instance's first vertex in the frame (indices)
  };
  constexpr size_t kVertexChunk = 1 << 14, kIndexChunk = 1 << 16;
  std::vector<VertexJob> jobs;
  size_t vertexCount = 0, indexCount = 0;
  unsigned stored = 0;  // the attributes some material reads (shade::AttributeLayout)
  // Every mesh's bounds, for the draw order and the objects' screen bounds, when they are needed.
  const bool masking = o.hsr != RenderOptions::Hsr::zbuffer && o.debugView != DebugView::overdraw;
  bool anyTranslucent = false;
  for (const scene::Material& m : scene.materials)
    anyTranslucent |= m.alphaMode == scene::AlphaMode::blend;
  std::vector<std::array<Vec3, 2>> boxes;
  if (o.hsr != RenderOptions::Hsr::zbuffer || anyTranslucent)
    for (const scene::Mesh& m : scene.meshes) {
      boxes.push_back(m.bounds());
      // An infinite position (not yet checked: the vertex stage checks them) would give the draw
      // order NaN depths to sort by.
      for (const Vec3& corner : boxes.back())
        if (!isFinite(corner)) return invalidVertexData();
    }
  const geometry::Viewport boundViewport{o.width * o.supersample, o.height * o.supersample};
  // Opaque materials first, then translucent ones (SPEC §4: blended over what is behind them).
  const std::vector<uint32_t> order = drawOrder(scene, camera.value().view, o.hsr, boxes);
  for (const bool translucentPass : {false, true})
    for (const uint32_t instance : order) {
      const scene::Instance& inst = scene.instances[instance];
      const scene::Mesh& mesh = scene.meshes[inst.mesh];
      const scene::Material& mat = materialOf(mesh);
      if ((mat.alphaMode == scene::AlphaMode::blend) != translucentPass) continue;
      // Indices are 32-bit; a frame of more vertices or triangles than that cannot be expressed.
      if (vertexCount + mesh.positions.size() > (size_t(1) << 31) ||
          indexCount + mesh.indices.size() > (size_t(1) << 31))
        return Error{"", "", "scene too large for one frame (over 2^31 vertices or indices)"};
      const auto base = static_cast<uint32_t>(vertexCount);
      for (size_t b = 0; b < mesh.positions.size(); b += kVertexChunk)
        jobs.push_back({&inst, false, b, std::min(mesh.positions.size(), b + kVertexChunk),
                        vertexCount + b, base});
      for (size_t b = 0; b < mesh.indices.size(); b += kIndexChunk)
        jobs.push_back(
            {&inst, true, b, std::min(mesh.indices.size(), b + kIndexChunk), indexCount + b, base});
      render::DrawCall call;
      call.firstTriangle = static_cast<uint32_t>(indexCount / 3);
      call.triangleCount = static_cast<uint32_t>(mesh.triangleCount());
      call.cull =
          o.cullBackFaces && !mat.doubleSided ? geometry::CullMode::back : geometry::CullMode::none;
      if (pixelShading && (mat.needsPixelShading() || shading.environment.fog))
        call.material = shading.of(mesh.material, !mesh.normals.empty());
      if (call.material) stored |= shade::attributesUsed(*call.material, shading.environment);
      if (masking)
        call.bounded = geometry::boundObject(
            vertexContext.viewProj * inst.transform, boxes[size_t(inst.mesh)][0],
            boxes[size_t(inst.mesh)][1], boundViewport, call.bound);
      p.calls.push_back(call);
      vertexCount += mesh.positions.size();
      indexCount += mesh.indices.size();
    }
  p.vertices.resize(vertexCount);
  p.indices.resize(indexCount);
  // Only the attributes some material reads (shade::AttributeLayout).
  p.attributeLayout = shade::AttributeLayout::of(pixelShading ? stored : 0);
  const size_t stride = size_t(p.attributeLayout.stride);
  p.attributes.resize(vertexCount * stride);
  std::vector<uint8_t> finite(jobs.size());  // positions finite, indices in range
  impl_->frame.pool().parallelFor(jobs.size(), [&](size_t j, int) {
    const VertexJob& job = jobs[j];
    const scene::Mesh& mesh = scene.meshes[job.instance->mesh];
    if (job.indices) {
      uint32_t maxIndex = 0;
      uint32_t* out = p.indices.data() + job.out;
      for (size_t i = job.begin; i < job.end; ++i) {
        maxIndex = std::max(maxIndex, mesh.indices[i]);
        out[i - job.begin] = job.base + mesh.indices[i];
      }
      finite[j] = maxIndex < mesh.positions.size();
      return;
    }
    finite[j] = geometry::transformVertices(
        mesh, materialOf(mesh), job.instance->transform, vertexContext, job.begin, job.end,
        p.vertices.data() + job.out, stride ? p.attributes.data() + job.out * stride : nullptr,
        &p.attributeLayout);
  });
  if (std::find(finite.begin(), finite.end(), 0) != finite.end()) return invalidVertexData();
  stats.vertexMs = msSince(t0);

  // Stage 3–4: setup, binning, tiles (on the k-times larger raster when supersampling).
  const int k = o.supersample;
  render::FrameSettings fs;
  fs.width = o.width * k;
  fs.height = o.height * k;
  fs.clearColor[0] = scene.background.x;
  fs.clearColor[1] = scene.background.y;
  fs.clearColor[2] = scene.background.z;
  fs.shade = o.debugView == DebugView::overdraw ? raster::ShadeMode::overdraw
             : o.debugView == DebugView::levels ? raster::ShadeMode::levels
             : pixelShading                     ? raster::ShadeMode::material
                                                : raster::ShadeMode::gouraud;
  fs.environment = &shading.environment;
  fs.samples = o.samples;
  fs.debugOccupancy = o.debugView == DebugView::occupancy;
  fs.masking = o.debugView == DebugView::overdraw      ? raster::Masking::none
               : o.hsr == RenderOptions::Hsr::priority ? raster::Masking::priority
               : o.hsr == RenderOptions::Hsr::hybrid   ? raster::Masking::hybrid
                                                       : raster::Masking::none;
  if (o.samples > 1) {
    // A frame of several batches keeps a whole-frame sample buffer (samples × 10 bytes a pixel:
    // 330 MB at 1080p with 16 samples). Batches as large as the records that buffer would hold
    // (144 bytes a triangle) cost no more memory and avoid it for all but huge scenes; beyond
    // that the buffer is allowed up to 4 GiB.
    const size_t tiles = size_t((fs.width + raster::kTileSize - 1) >> raster::kTileLog2) *
                         size_t((fs.height + raster::kTileSize - 1) >> raster::kTileLog2);
    const size_t bufferBytes = tiles * raster::kTilePixels * size_t(o.samples) *
                               (sizeof(float) + raster::kColorChannels * sizeof(uint16_t));
    const size_t batch = std::clamp<size_t>(bufferBytes / sizeof(geometry::TriangleSetup),
                                            fs.batchTriangles, render::kMaxBatchTriangles);
    fs.batchTriangles = uint32_t(batch);
    if (p.indices.size() / 3 > batch && bufferBytes > (size_t(4) << 30))
      return Error{"", "",
                   fmt::format("{} triangles in a {}x{} frame with {} samples per pixel need a "
                               "{:.1f} GB sample buffer (over the 4 GB limit); use fewer samples",
                               p.indices.size() / 3, o.width, o.height, o.samples,
                               double(bufferBytes) / 1e9)};
  }
  // Stage 5, display: each tile is resolved into the image as soon as it is finished (k divides
  // the 64-pixel tile, so a pixel's k×k samples always lie in one tile) — or, for the tent filter,
  // which reads across tile borders, into a linear frame that is filtered once all tiles are in.
  const int tilesX = (fs.width + raster::kTileSize - 1) >> raster::kTileLog2;
  const bool tent = o.filter == RenderOptions::Filter::tent3;
  output::LinearImage& linear = impl_->linear;
  if (tent) linear.resize(o.width, o.height);
  // Both sample resolves need only each pixel's sum (the debug views read the planes).
  fs.colorSums = o.debugView == DebugView::none && k == 1;
  if (o.debugView != DebugView::none)
    fs.finishTile = [&](int tile, const float*, const uint16_t* color, const int32_t*) {
      output::resolveDebugTile(color, tile % tilesX, tile / tilesX,
                               o.debugView == DebugView::overdraw ? output::DebugPalette::count
                                                                  : output::DebugPalette::level,
                               image);
    };
  else if (tent)
    fs.finishTile = [&](int tile, const float*, const uint16_t* color, const int32_t* sums) {
      output::resolveTileLinear(color, sums, tile % tilesX, tile / tilesX, k, o.samples, linear);
    };
  else if (o.samples > 1)
    fs.finishTile = [&](int tile, const float*, const uint16_t* color, const int32_t* sums) {
      output::resolveSampleTile(color, sums, tile % tilesX, tile / tilesX, o.samples, impl_->gamma,
                                image);
    };
  else
    fs.finishTile = [&](int tile, const float*, const uint16_t* color, const int32_t*) {
      output::resolveTile(color, tile % tilesX, tile / tilesX, k, impl_->gamma, image);
    };
  // The free forms, cast into each tile between its opaque and translucent polygons (not in the
  // debug views, which show the polygon pipeline).
  if (!scene.freeForms.empty() && o.debugView == DebugView::none) {
    const raster::CoverageTables* cov =
        o.samples > 1 ? raster::CoverageTables::forCount(o.samples) : nullptr;
    impl_->freeForms.prepare(
        shadedForms(scene, camera.value().view, camera.value().projection, shading), fs.width,
        fs.height, o.samples, cov ? cov->offsetX : nullptr, cov ? cov->offsetY : nullptr,
        &shading.environment,
        freeform::CastSettings{.masking = true, .adaptiveSamples = !o.freeFormEverySample},
        o.freeFormMethod == RenderOptions::FreeFormMethod::march ? o.marchSteps : 0,
        &impl_->frame.pool());
    const int threads = impl_->frame.pool().threadCount();
    impl_->freeFormScratch.resize(size_t(threads));
    impl_->freeFormStats.assign(size_t(threads), Impl::WorkerCastStats{});
    const int tilesAcross = tilesX;
    fs.afterOpaque = [&, tilesAcross](int tile, int worker, float* depth, uint16_t* color) {
      impl_->freeForms.drawTile(tile % tilesAcross, tile / tilesAcross, depth, color,
                                impl_->freeFormScratch[size_t(worker)],
                                impl_->freeFormStats[size_t(worker)].counts);
    };
  }
  output::prepareImage(o.width, o.height, image);
  impl_->frame.render(p, fs, stats);
  if (fs.afterOpaque) {
    freeform::CastStats cast;
    for (const Impl::WorkerCastStats& s : impl_->freeFormStats) cast.add(s.counts);
    stats.freeForms += impl_->freeForms.size();
    stats.freeFormCells += cast.cells;
    stats.freeFormMaskedCells += cast.maskedCells;
    stats.freeFormBounds += cast.depthTests;
    stats.freeFormRays += cast.pixels;
    stats.freeFormHits += cast.hits;
  }
  if (tent) {
    t0 = Clock::now();
    constexpr int kBand = 16;  // rows per task
    impl_->frame.pool().parallelFor(size_t((o.height + kBand - 1) / kBand), [&](size_t band, int) {
      const int y0 = int(band) * kBand;
      output::tentFilterRows(linear, impl_->gamma, y0, std::min(o.height, y0 + kBand), image);
    });
    stats.rasterMs += msSince(t0);
  }
  stats.totalMs = msSince(start);
  if (statsOut) *statsOut = stats;
  return {};
}

}  // namespace sv
