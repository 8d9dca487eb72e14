// The JSON scene format's "objects" and "lodGroups" sections (docs/scene-format.md, "Objects",
// "Levels of detail"): primitives, inline meshes, referenced files, placed and instanced.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "formats/json/json_reader.h"
#include "formats/primitives.h"

namespace sv::formats::json {

void SceneReader::addTriangles(uint64_t triangles, const std::string& where) {
  if (triangles > context_.options.maxTriangles - triangles_)
    fail(where,
         fmt::format("the scene would have more than {} triangles", context_.options.maxTriangles));
  triangles_ += triangles;
}

void SceneReader::readObject(const Json& v, const std::string& where) {
  if (!v.is_object()) fail(where, fmt::format("expected an object, got {}", typeName(v)));
  const size_t firstInstance = scene_.instances.size();
  readObjectGeometry(v, where);
  // The object's priority (SPEC §4 masking: smaller first, nearer), for every instance it made.
  if (const Json* x = find(v, "priority")) {
    const int priority = int(integer(*x, member(where, "priority"), -1000000000, 1000000000));
    for (size_t i = firstInstance; i < scene_.instances.size(); ++i)
      scene_.instances[i].priority = priority;
  }
}

void SceneReader::readLodGroups(const Json& v, const std::string& where) {
  if (!v.is_object())
    fail(where, fmt::format("expected an object of named groups, got {}", typeName(v)));
  if (v.size() > 65536) fail(where, "more than 65536 groups");
  for (const auto& [name, group] : v.items()) {
    const std::string w = member(where, name);
    if (!group.is_object()) fail(w, fmt::format("expected an object, got {}", typeName(group)));
    expectKeys(group, w, {"levels", "fade"});
    LodGroup g;
    g.name = name;
    if (const Json* x = find(group, "fade")) g.fade = inRange(*x, member(w, "fade"), 0, 1e30f);
    const Json* levels = find(group, "levels");
    if (!levels) fail(w, "missing key 'levels'");
    const std::string lw = member(w, "levels");
    array(*levels, lw);
    if (levels->empty() || levels->size() > kMaxLodLevels)
      fail(lw, fmt::format("{} levels (1 to {})", levels->size(), kMaxLodLevels));
    float from = 0;
    for (size_t i = 0; i < levels->size(); ++i) {
      const std::string ew = element(lw, i);
      const Json& level = (*levels)[i];
      if (!level.is_object()) fail(ew, fmt::format("expected an object, got {}", typeName(level)));
      const Json* to = find(level, "to");
      if (!to) fail(ew, "missing key 'to' (the range this level gives way at, metres)");
      const float range = inRange(*to, member(ew, "to"), 1e-6f, 1e30f);
      if (!(range > from))
        fail(member(ew, "to"), fmt::format("must exceed {} (ranges increase)", from));
      if (g.fade > 0 && !(range - g.fade >= from))
        fail(member(w, "fade"),
             fmt::format("{} is longer than level {}'s span [{}, {})", g.fade, i, from, range));
      from = range;
      if (find(level, "freeform")) fail(ew, "a level of detail is a mesh, not a free form");
      if (find(level, "priority")) fail(ew, "a priority belongs to the object, not to a level");
      // The level is an object of one mesh, read as objects are and then taken out of the scene's
      // instances: its mesh, with the level's own placement built in.
      Json object = level;
      object.erase("to");
      const size_t before = scene_.instances.size();
      readObjectGeometry(object, ew);
      if (scene_.instances.size() != before + 1)
        fail(ew, fmt::format("a level of detail is one mesh; this one makes {}",
                             scene_.instances.size() - before));
      const Instance made = scene_.instances.back();
      scene_.instances.pop_back();
      int mesh = made.mesh;
      if (made.transform.m != Mat4{}.m) {
        Mesh placed = scene_.meshes[size_t(mesh)];
        const Mat4 normals = made.transform.normalMatrix();
        for (Vec3& p : placed.positions) p = made.transform.transformPoint(p);
        for (Vec3& n : placed.normals) n = normalize(normals.transformDirection(n));
        mesh = int(scene_.meshes.size());
        scene_.meshes.push_back(std::move(placed));
      }
      g.levels.push_back({mesh, range});
    }
    lodGroupByName_[name] = int(scene_.lodGroups.size());
    scene_.lodGroups.push_back(std::move(g));
  }
}

void SceneReader::readLodObject(const Json& v, const std::string& where) {
  expectKeys(v, where, {"name", "lod", "transform", "priority", "at", "onGround"});
  const Json& ref = *find(v, "lod");
  const auto group = lodGroupByName_.find(string(ref, member(where, "lod")));
  if (group == lodGroupByName_.end())
    fail(member(where, "lod"),
         fmt::format("no level-of-detail group '{}' in 'lodGroups'", ref.get<std::string>()));
  const LodGroup& g = scene_.lodGroups[size_t(group->second)];
  Mat4 m;
  if (const Json* t = find(v, "transform")) m = readTransform(*t, member(where, "transform"));
  bool onGround = false;
  if (const Json* x = find(v, "onGround")) onGround = boolean(*x, member(where, "onGround"));
  auto place = [&](const Mat4& at) {
    addTriangles(scene_.meshes[size_t(g.levels[0].mesh)].triangleCount(), where);
    Instance inst;
    inst.mesh = g.levels[0].mesh;
    inst.lod = group->second;
    inst.transform = at * m;
    scene_.instances.push_back(inst);
  };
  const Json* at = find(v, "at");
  if (!at) {
    if (onGround) {
      const Vec3 p = m.transformPoint({0, 0, 0});
      return place(Mat4::translation({0, float(groundHeight(p.x, p.z, where)), 0}));
    }
    return place(Mat4{});
  }
  // Placements: [x, y, z] with an optional heading (degrees, about +y) and scale.
  const std::string aw = member(where, "at");
  array(*at, aw);
  for (size_t i = 0; i < at->size(); ++i) {
    const std::string ew = element(aw, i);
    const Json& p = (*at)[i];
    if (!p.is_array() || p.size() < 3 || p.size() > 5)
      fail(ew, "expected [x, y, z], [x, y, z, heading] or [x, y, z, heading, scale]");
    float c[5] = {0, 0, 0, 0, 1};
    for (size_t k = 0; k < p.size(); ++k) c[k] = number(p[k], element(ew, k));
    if (!(c[4] > 0)) fail(element(ew, 4), "scale must be positive");
    if (onGround) c[1] += float(groundHeight(c[0], c[2], ew));
    place(Mat4::translation({c[0], c[1], c[2]}) *
          Mat4::rotation({0, 1, 0}, c[3] * float(std::numbers::pi) / 180) *
          Mat4::scaling({c[4], c[4], c[4]}));
  }
}

void SceneReader::readObjectGeometry(const Json& v, const std::string& where) {
  if (find(v, "lod")) {
    if (find(v, "mesh") || find(v, "primitive") || find(v, "freeform"))
      fail(where, "an object has one of 'mesh', 'primitive', 'freeform' or 'lod', not several");
    return readLodObject(v, where);
  }
  const Json* mesh = find(v, "mesh");
  const Json* primitive = find(v, "primitive");
  const Json* freeform = find(v, "freeform");
  if (int(mesh != nullptr) + int(primitive != nullptr) + int(freeform != nullptr) > 1)
    fail(where, "an object has one of 'mesh', 'primitive' or 'freeform', not several");
  if (!mesh && !primitive && !freeform)
    fail(where, "missing key 'mesh', 'primitive' or 'freeform'");
  if (freeform) return readFreeFormObject(v, where);

  if (primitive) {
    // The allowed keys depend on the kind, so readPrimitive checks them.
    readPrimitive(v, where);
    return;
  }
  expectKeys(v, where, {"name", "mesh", "material", "color", "transform", "priority"});
  Mat4 m;
  if (const Json* t = find(v, "transform")) m = readTransform(*t, member(where, "transform"));
  bool overridesMaterial = find(v, "material") || find(v, "color");
  int material = readObjectMaterial(v, where);
  std::string w = member(where, "mesh");
  if (mesh->is_string()) {
    readMeshFile(*mesh, w, overridesMaterial ? std::optional<int>(material) : std::nullopt, m);
    return;
  }
  if (!mesh->is_object())
    fail(w, fmt::format("expected a file path or an inline mesh object, got {}", typeName(*mesh)));
  Mesh inlineMesh;
  if (const Json* name = find(v, "name")) inlineMesh.name = string(*name, member(where, "name"));
  readInlineMesh(*mesh, w, inlineMesh);
  addTriangles(inlineMesh.triangleCount(), where);
  inlineMesh.material = material;
  scene_.meshes.push_back(std::move(inlineMesh));
  scene_.instances.push_back({int(scene_.meshes.size() - 1), m});
}

void SceneReader::readPrimitive(const Json& v, const std::string& where) {
  const std::string kindWhere = member(where, "primitive");
  const std::string kind = string(*find(v, "primitive"), kindWhere);
  PrimitiveParams p;
  // Step 1: the kind decides which keys are allowed.
  if (kind == "box") {
    p.kind = PrimitiveKind::kBox;
    expectKeys(v, where,
               {"name", "primitive", "material", "color", "transform", "priority", "size"});
  } else if (kind == "sphere") {
    p.kind = PrimitiveKind::kSphere;
    expectKeys(v, where,
               {"name", "primitive", "material", "color", "transform", "priority", "radius",
                "segments", "rings"});
  } else if (kind == "plane") {
    p.kind = PrimitiveKind::kPlane;
    expectKeys(v, where,
               {"name", "primitive", "material", "color", "transform", "priority", "size",
                "subdivisions"});
  } else if (kind == "checker") {
    p.kind = PrimitiveKind::kChecker;
    p.size = {8, 1, 8};
    p.divisionsX = p.divisionsZ = 8;
    expectKeys(v, where,
               {"name", "primitive", "material", "color", "transform", "priority", "size",
                "squares", "colors"});
  } else if (kind == "cylinder") {
    p.kind = PrimitiveKind::kCylinder;
    expectKeys(v, where,
               {"name", "primitive", "material", "color", "transform", "priority", "radius",
                "height", "segments", "caps"});
  } else if (kind == "cone") {
    p.kind = PrimitiveKind::kCone;
    expectKeys(v, where,
               {"name", "primitive", "material", "color", "transform", "priority", "radius",
                "height", "segments", "caps"});
  } else if (kind == "torus") {
    p.kind = PrimitiveKind::kTorus;
    p.radius = 0.375f;
    p.segments = 48;
    p.sides = 24;
    expectKeys(v, where,
               {"name", "primitive", "material", "color", "transform", "priority", "radius", "tube",
                "segments", "sides"});
  } else {
    fail(kindWhere, fmt::format("unknown primitive '{}' (expected box, sphere, plane, checker, "
                                "cylinder, cone or torus)",
                                kind));
  }

  // Step 2: the parameters, each with its default already in p.
  if (const Json* x = find(v, "size")) {
    std::string w = member(where, "size");
    if (p.kind == PrimitiveKind::kBox) {
      auto s = sizes<3>(*x, w);
      p.size = {s[0], s[1], s[2]};
    } else {
      auto s = sizes<2>(*x, w);
      p.size = {s[0], 1, s[1]};
    }
  }
  if (const Json* x = find(v, "radius")) p.radius = positive(*x, member(where, "radius"));
  if (const Json* x = find(v, "height")) p.height = positive(*x, member(where, "height"));
  if (const Json* x = find(v, "tube")) p.tube = positive(*x, member(where, "tube"));
  if (const Json* x = find(v, "segments"))
    p.segments = int(integer(*x, member(where, "segments"), kMinSegments, kMaxSegments));
  p.rings = std::max(kMinRings, p.segments / 2);
  if (const Json* x = find(v, "rings"))
    p.rings = int(integer(*x, member(where, "rings"), kMinRings, kMaxSegments));
  if (const Json* x = find(v, "sides"))
    p.sides = int(integer(*x, member(where, "sides"), kMinSegments, kMaxSegments));
  for (const char* key : {"subdivisions", "squares"})
    if (const Json* x = find(v, key)) {
      auto n = counts(*x, member(where, key), kMinDivisions, kMaxSegments);
      p.divisionsX = n[0];
      p.divisionsZ = n[1];
    }
  if (const Json* x = find(v, "caps")) p.caps = boolean(*x, member(where, "caps"));
  if (const Json* x = find(v, "colors")) {
    std::string w = member(where, "colors");
    if (!x->is_array() || x->size() != 2)
      fail(w, fmt::format("expected an array of 2 colours, got {}",
                          x->is_array() ? fmt::format("{} elements", x->size()) : typeName(*x)));
    for (size_t i = 0; i < 2; ++i) p.colors[i] = color((*x)[i], element(w, i), true);
  }

  Mat4 m;
  if (const Json* t = find(v, "transform")) m = readTransform(*t, member(where, "transform"));
  int material = readObjectMaterial(v, where);

  // Step 3: charge the budget before building, so an absurd primitive costs nothing.
  addTriangles(primitiveTriangleCount(p), where);
  Mesh mesh = makePrimitive(p);
  mesh.name = kind;
  if (const Json* name = find(v, "name")) mesh.name = string(*name, member(where, "name"));
  mesh.material = material;
  scene_.meshes.push_back(std::move(mesh));
  scene_.instances.push_back({int(scene_.meshes.size() - 1), m});
}

void SceneReader::readInlineMesh(const Json& v, const std::string& where, Mesh& mesh) const {
  expectKeys(v, where, {"positions", "indices", "normals", "colors", "uvs"});
  const Json* positions = find(v, "positions");
  if (!positions) fail(where, "missing key 'positions'");

  // Reads a flat array of numbers in groups of `k`, naming the element at fault only on failure
  // (formatting a path per element would dominate the cost of large meshes).
  auto flat = [&](const Json& a, const std::string& w, size_t k, size_t expectedGroups,
                  auto&& store) {
    array(a, w);
    if (a.size() % k != 0 || (expectedGroups != SIZE_MAX && a.size() / k != expectedGroups))
      fail(w, expectedGroups == SIZE_MAX
                  ? fmt::format("expected a multiple of {} numbers, got {}", k, a.size())
                  : fmt::format("expected {} numbers ({} per vertex), got {}", expectedGroups * k,
                                k, a.size()));
    float group[4];
    for (size_t i = 0; i < a.size(); ++i) {
      std::string problem = numberProblem(a[i]);
      if (!problem.empty()) fail(element(w, i), problem);
      group[i % k] = static_cast<float>(a[i].get<double>());
      if (i % k == k - 1 && !store(group)) fail(element(w, i - k + 1), "value out of range 0..1");
    }
  };

  std::string w = member(where, "positions");
  flat(*positions, w, 3, SIZE_MAX, [&](const float* g) {
    mesh.positions.push_back({g[0], g[1], g[2]});
    return true;
  });
  const size_t n = mesh.positions.size();
  if (const Json* x = find(v, "normals"))
    flat(*x, member(where, "normals"), 3, n, [&](const float* g) {
      mesh.normals.push_back({g[0], g[1], g[2]});
      return true;
    });
  if (const Json* x = find(v, "uvs"))
    flat(*x, member(where, "uvs"), 2, n, [&](const float* g) {
      mesh.uvs.push_back({g[0], g[1]});
      return true;
    });
  if (const Json* x = find(v, "colors")) {
    // RGB or RGBA per vertex, told apart by the array's length.
    std::string cw = member(where, "colors");
    size_t k = (x->is_array() && n > 0 && x->size() == 4 * n) ? 4 : 3;
    flat(*x, cw, k, n, [&](const float* g) {
      Vec4 c{g[0], g[1], g[2], k == 4 ? g[3] : 1.0f};
      for (float component : {c.x, c.y, c.z, c.w})
        if (component < 0 || component > 1) return false;
      mesh.colors.push_back(c);
      return true;
    });
  }
  if (const Json* x = find(v, "indices")) {
    std::string iw = member(where, "indices");
    array(*x, iw);
    if (x->size() % 3 != 0)
      fail(iw, fmt::format("expected a multiple of 3 indices, got {}", x->size()));
    mesh.indices.reserve(x->size());
    for (size_t i = 0; i < x->size(); ++i) {
      const Json& index = (*x)[i];
      if (!index.is_number_integer() || index.get<int64_t>() < 0 || index.get<uint64_t>() >= n)
        fail(element(iw, i),
             fmt::format("expected a vertex index 0..{}, got {}", n == 0 ? 0 : n - 1,
                         index.is_number() ? index.dump() : typeName(index)));
      mesh.indices.push_back(static_cast<uint32_t>(index.get<uint64_t>()));
    }
  } else {
    // No indices: consecutive vertex triples are the triangles.
    if (n % 3 != 0)
      fail(w, fmt::format("without 'indices' the vertex count must be a multiple of 3, got {}", n));
    mesh.indices.resize(n);
    for (size_t i = 0; i < n; ++i) mesh.indices[i] = static_cast<uint32_t>(i);
  }
}

void SceneReader::readMeshFile(const Json& v, const std::string& where, std::optional<int> material,
                               const Mat4& m) {
  const std::string ref = string(v, where);
  if (ref.empty()) fail(where, "expected a file path, got an empty string");
  // Untrusted text (fuzzing) must not make the loader touch the file system at all.
  if (!context_.options.followReferences)
    fail(where, fmt::format("cannot open '{}' (references to other files are disabled)", ref));
  const std::string resolved = resolvePath(directoryOf(path_), ref);
  std::error_code ec;
  if (!std::filesystem::exists(resolved, ec))
    fail(where, fmt::format("cannot open '{}': no such file", ref));

  // Step 1: nesting and cycles. The current file is the last entry of openScenes.
  const std::string key = canonicalKey(resolved);
  auto open = std::find(context_.openScenes.begin(), context_.openScenes.end(), key);
  if (open != context_.openScenes.end()) {
    std::string cycle;
    for (auto it = open; it != context_.openScenes.end(); ++it)
      cycle += std::filesystem::path(*it).filename().string() + " → ";
    fail(where, fmt::format("'{}' refers back to a scene that is being loaded ({}{})", ref, cycle,
                            std::filesystem::path(key).filename().string()));
  }
  if (context_.openScenes.size() > size_t(std::max(context_.options.maxNesting, 0)))
    fail(where, fmt::format("cannot load '{}': scene files are nested more than {} deep", ref,
                            context_.options.maxNesting));

  // Step 2: load it, once per top-level load.
  auto loaded = context_.loaded.find(key);
  if (loaded == context_.loaded.end()) {
    Result<Scene> file = loadFile(resolved, context_);
    if (!file) fail(where, fmt::format("cannot load '{}': {}", ref, file.error().str()));
    loaded = context_.loaded.emplace(key, std::move(file.value())).first;
  }
  const Scene& file = loaded->second;
  addTriangles(file.triangleCount(), where);
  // What the file left out is said once, however often it is placed.
  if (placedMeshes_.find({key, material ? *material : -2}) == placedMeshes_.end())
    scene_.warnings.insert(scene_.warnings.end(), file.warnings.begin(), file.warnings.end());

  // Step 3: place its meshes in this scene once per material override; every further reference
  // only adds instances.
  const int overrideKey = material ? *material : -2;
  auto placed = placedMeshes_.find({key, overrideKey});
  if (placed == placedMeshes_.end()) {
    const int meshBase = int(scene_.meshes.size());
    const int materialBase = int(scene_.materials.size());
    const int textureBase = int(scene_.textures.size());
    if (!material) {
      scene_.textures.insert(scene_.textures.end(), file.textures.begin(), file.textures.end());
      for (Material fm : file.materials) {
        if (fm.texture >= 0) fm.texture += textureBase;
        scene_.materials.push_back(std::move(fm));
      }
    }
    for (Mesh mesh : file.meshes) {
      mesh.material = material ? *material : mesh.material >= 0 ? mesh.material + materialBase : -1;
      scene_.meshes.push_back(std::move(mesh));
    }
    // Its levels of detail, their meshes renumbered.
    const int lodBase = int(scene_.lodGroups.size());
    for (LodGroup group : file.lodGroups) {
      for (LodLevel& level : group.levels) level.mesh += meshBase;
      scene_.lodGroups.push_back(std::move(group));
    }
    placed =
        placedMeshes_.emplace(std::make_pair(key, overrideKey), std::pair{meshBase, lodBase}).first;
  }
  const auto [meshBase, lodBase] = placed->second;
  const uint32_t instanceBase = uint32_t(scene_.instances.size());
  for (Instance instance : file.instances) {
    instance.mesh += meshBase;
    instance.transform = m * instance.transform;
    instance.priority = 0;
    if (instance.lod >= 0) instance.lod += lodBase;
    scene_.instances.push_back(instance);
  }
  // Its switches, degrees of freedom and light points come along with every placement.
  if (scene_.lightPoints.size() + file.lightPoints.size() > kMaxLightPoints)
    fail(where, fmt::format("placing '{}' makes more than {} light points", ref, kMaxLightPoints));
  if (scene_.lines.size() + file.lines.size() > kMaxLines)
    fail(where, fmt::format("placing '{}' makes more than {} lines", ref, kMaxLines));
  scene::detail::appendArticulationsAndLights(scene_, file, m, instanceBase);
  for (Camera camera : file.cameras) {
    camera.position = m.transformPoint(camera.position);
    camera.target = m.transformPoint(camera.target);
    camera.up = normalize(m.transformDirection(camera.up));
    scene_.cameras.push_back(std::move(camera));
  }
}

}  // namespace sv::formats::json
