// Based on: SPEC §1 (seed 004's database preparation system); meshoptimizer's vertex fetch,
// vertex cache, overdraw and simplification algorithms (Kapoulkine, meshoptimizer 0.18).
#include "synthvis/prep.h"

#include <fmt/format.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

namespace sv::prep {
namespace {

constexpr unsigned kCacheSize = 16;

double acmr(const std::vector<uint32_t>& indices, size_t vertices) {
  if (indices.empty()) return 0;
  return meshopt_analyzeVertexCache(indices.data(), indices.size(), vertices, kCacheSize, 0, 0).acmr;
}

// Applies `remap` (old vertex → new, ~0u for unused) with `count` new vertices to every attribute.
void remapVertices(scene::Mesh& m, const std::vector<unsigned>& remap, size_t count) {
  auto apply = [&](auto& v) {
    if (v.empty()) return;
    using T = typename std::decay_t<decltype(v)>::value_type;
    std::vector<T> out(count);
    meshopt_remapVertexBuffer(out.data(), v.data(), v.size(), sizeof(T), remap.data());
    v = std::move(out);
  };
  apply(m.positions), apply(m.normals), apply(m.colors), apply(m.uvs);
  meshopt_remapIndexBuffer(m.indices.data(), m.indices.data(), m.indices.size(), remap.data());
}

// Step 1 for one mesh: equal vertices merged (all attributes equal, bit for bit), then numbered
// in the order the triangles first use them. The triangles keep their order and corners.
void optimizeMesh(scene::Mesh& m) {
  if (m.indices.empty() || m.positions.empty()) return;
  std::vector<meshopt_Stream> streams{{m.positions.data(), sizeof(Vec3), sizeof(Vec3)}};
  if (!m.normals.empty()) streams.push_back({m.normals.data(), sizeof(Vec3), sizeof(Vec3)});
  if (!m.colors.empty()) streams.push_back({m.colors.data(), sizeof(Vec4), sizeof(Vec4)});
  if (!m.uvs.empty()) streams.push_back({m.uvs.data(), sizeof(Vec2), sizeof(Vec2)});
  std::vector<unsigned> remap(m.positions.size());
  const size_t unique =
      meshopt_generateVertexRemapMulti(remap.data(), m.indices.data(), m.indices.size(),
                                       m.positions.size(), streams.data(), streams.size());
  remapVertices(m, remap, unique);
  const size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), m.indices.data(),
                                                       m.indices.size(), m.positions.size());
  remapVertices(m, remap, used);
}

// Step 2 for one mesh: its simplified levels (each a mesh of its own, vertices compacted) with the
// absolute geometric error of each, coarsest last. Stops when a level would not shrink by a tenth.
struct Level {
  scene::Mesh mesh;
  float error = 0;  // in the mesh's units
};
std::vector<Level> simplify(const scene::Mesh& source, const PrepOptions& o) {
  std::vector<Level> out;
  const float scale = meshopt_simplifyScale(&source.positions[0].x, source.positions.size(),
                                            sizeof(Vec3));
  std::vector<uint32_t> indices = source.indices;
  for (int level = 1; level < o.maxLevels; ++level) {
    const size_t target = size_t(double(indices.size() / 3) * o.reduction) * 3;
    if (target < 3 * 4) break;
    std::vector<uint32_t> next(indices.size());
    float error = 0;
    // A target error of 1 (the whole extent) lets the triangle count decide.
    next.resize(meshopt_simplify(next.data(), indices.data(), indices.size(),
                                 &source.positions[0].x, source.positions.size(), sizeof(Vec3),
                                 target, 1.0f, 0, &error));
    if (next.empty() || next.size() * 10 > indices.size() * 9) break;
    Level l;
    l.mesh = source;
    l.mesh.name = fmt::format("{} (level {})", source.name, level);
    l.mesh.indices = next;
    std::vector<unsigned> remap(source.positions.size());
    const size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), next.data(), next.size(),
                                                         source.positions.size());
    remapVertices(l.mesh, remap, used);
    l.error = error * scale;
    out.push_back(std::move(l));
    indices = std::move(next);
  }
  return out;
}

// The largest scale an instance's transform applies (the longest column of its 3×3 part).
float maxScale(const Mat4& m) {
  float s = 0;
  for (int c = 0; c < 3; ++c)
    s = std::max(s, std::sqrt(m.m[c][0] * m.m[c][0] + m.m[c][1] * m.m[c][1] + m.m[c][2] * m.m[c][2]));
  return s;
}

}  // namespace

std::string PrepReport::summary() const {
  return fmt::format(
      "{} meshes ({} triangles, {} → {} vertices, ACMR {:.3f} → {:.3f}), {} instances; {} "
      "level-of-detail groups made, {} levels, {} triangles in them",
      meshes, trianglesIn, verticesIn, verticesOut, acmrIn, acmrOut, instances, groupsMade,
      levelsMade, levelTriangles);
}

Result<PrepReport> prepare(scene::Scene& scene, const PrepOptions& o,
                           const std::function<void(size_t, size_t)>& progress) {
  if (o.maxLevels < 2 || o.maxLevels > int(scene::kMaxLodLevels))
    return Error{"", "", fmt::format("--lod-levels {}: must be 2 to {}", o.maxLevels,
                                     scene::kMaxLodLevels)};
  if (!(o.reduction > 0 && o.reduction < 1))
    return Error{"", "", fmt::format("--reduction {}: must lie in (0, 1)", o.reduction)};
  if (!(o.pixelError > 0 && o.pixelError < 1e6f) || o.screenHeight < 1)
    return Error{"", "", "--pixel-error must be positive, and the screen height at least 1"};
  if (Status s = validate(scene, "prep"); !s) return s.error();
  PrepReport r;
  r.meshes = scene.meshes.size();
  r.instances = scene.instances.size();
  const size_t total = scene.meshes.size();
  double missesIn = 0, missesOut = 0, triangles = 0;
  for (size_t i = 0; i < total; ++i) {
    scene::Mesh& m = scene.meshes[i];
    const double t = double(m.triangleCount());
    r.trianglesIn += m.triangleCount();
    r.verticesIn += m.positions.size();
    missesIn += acmr(m.indices, m.positions.size()) * t;
    if (o.optimize) optimizeMesh(m);
    r.verticesOut += m.positions.size();
    missesOut += acmr(m.indices, m.positions.size()) * t;
    triangles += t;
    if (progress && (i % 256 == 255 || i + 1 == total)) progress(i + 1, total);
  }
  if (triangles > 0) r.acmrIn = missesIn / triangles, r.acmrOut = missesOut / triangles;

  if (o.generateLods) {
    // The meshes instances draw without levels of detail, with the largest scale they get.
    std::map<int, float> candidates;
    for (const scene::Instance& inst : scene.instances)
      if (inst.lod < 0 && scene.meshes[size_t(inst.mesh)].triangleCount() >= o.minTriangles) {
        float& s = candidates[inst.mesh];
        s = std::max(s, maxScale(inst.transform));
      }
    // Range d of a level whose error e (world units) shows as p pixels: e / (d · tan 30°) ·
    // (H / 2) = p (scene.h: ranges are taken at a 60° vertical field of view).
    const double perError = 0.5 * o.screenHeight / (std::tan(std::numbers::pi / 6) * o.pixelError);
    std::map<int, int> groupOf;
    for (const auto& [mesh, scale] : candidates) {
      std::vector<Level> levels = simplify(scene.meshes[size_t(mesh)], o);
      if (levels.empty()) continue;
      scene::LodGroup g;
      g.name = scene.meshes[size_t(mesh)].name;
      g.levels.push_back({mesh, 0});
      for (Level& l : levels) {
        // Level k − 1 gives way where level k's error shows as p pixels; ranges strictly increase.
        const float from = g.levels.size() > 1 ? g.levels[g.levels.size() - 2].to : 0;
        g.levels.back().to = std::max(float(double(l.error) * scale * perError),
                                      std::max(from * 1.01f, 1e-3f));
        r.levelTriangles += l.mesh.triangleCount();
        scene.meshes.push_back(std::move(l.mesh));
        g.levels.push_back({int(scene.meshes.size() - 1), 1e30f});
        ++r.levelsMade;
      }
      // A dissolve across the last tenth of the shortest level.
      float from = 0, span = 1e30f;
      for (const scene::LodLevel& l : g.levels) span = std::min(span, l.to - from), from = l.to;
      g.fade = 0.1f * span;
      scene.lodGroups.push_back(std::move(g));
      groupOf[mesh] = int(scene.lodGroups.size() - 1);
      ++r.groupsMade;
    }
    for (scene::Instance& inst : scene.instances)
      if (inst.lod < 0)
        if (auto it = groupOf.find(inst.mesh); it != groupOf.end()) inst.lod = it->second;
  }
  scene::buildInstanceTree(scene);
  if (Status s = validate(scene, "prep"); !s) return s.error();
  return r;
}

}  // namespace sv::prep
