// The JSON scene format's free-form objects (docs/scene-format.md, "Free forms"): quadrics with
// perturbations and clips, placed in the world.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/quadric.h"
#include "formats/json/json_reader.h"

namespace sv::formats::json {

// A free-form object (SPEC §11; docs/scene-format.md "Free forms"): "freeform" holds the root
// quadric node.
void SceneReader::readFreeFormObject(const Json& v, const std::string& where) {
  expectKeys(v, where, {"name", "freeform", "material", "color", "transform", "priority"});
  FreeFormObject f;
  if (const Json* name = find(v, "name")) f.name = string(*name, member(where, "name"));
  if (const Json* t = find(v, "transform"))
    f.transform = readTransform(*t, member(where, "transform"));
  // Free forms are depth-tested, never masked: a priority is accepted (an object list may give
  // every object one) and has no effect on them.
  if (const Json* x = find(v, "priority"))
    integer(*x, member(where, "priority"), -1000000000, 1000000000);
  f.material = readObjectMaterial(v, where);
  int quadrics = 0;
  f.form = readFreeForm(*find(v, "freeform"), member(where, "freeform"), 1, quadrics, true);
  if (scene_.freeForms.size() >= kMaxFreeFormObjects)
    fail(where,
         fmt::format("the scene would have more than {} free-form objects", kMaxFreeFormObjects));
  scene_.freeForms.push_back(std::move(f));
}

FreeFormNode SceneReader::readFreeForm(const Json& v, const std::string& where, int depth,
                                       int& quadrics, bool root) const {
  if (!v.is_object()) fail(where, fmt::format("expected a quadric object, got {}", typeName(v)));
  if (depth > kMaxFreeFormDepth)
    fail(where, fmt::format("perturbations nested deeper than {}", kMaxFreeFormDepth));
  if (++quadrics > kMaxFreeFormQuadrics)
    fail(where, fmt::format("a free form of more than {} quadrics", kMaxFreeFormQuadrics));
  const Json* kindJson = find(v, "quadric");
  if (!kindJson) fail(where, "missing key 'quadric'");
  const std::string kindWhere = member(where, "quadric");
  const std::string kind = string(*kindJson, kindWhere);
  auto d3 = [](Vec3 a) { return Vec3d{a.x, a.y, a.z}; };
  auto vecOr = [&](const char* key, Vec3 fallback, bool nonZero) {
    const Json* x = find(v, key);
    if (!x) return d3(fallback);
    return d3(nonZero ? nonZeroVec3(*x, member(where, key)) : vec3(*x, member(where, key)));
  };
  auto positiveOr = [&](const char* key, double fallback) {
    const Json* x = find(v, key);
    return x ? double(positive(*x, member(where, key))) : fallback;
  };
  // Step 1: the quadric, by kind.
  FreeFormNode node;
  Quadric q;
  if (kind == "sphere") {
    expectKeys(v, where, {"quadric", "weight", "perturbations", "clip", "center", "radius"});
    q = Quadric::sphere(vecOr("center", {}, false), positiveOr("radius", 1));
  } else if (kind == "ellipsoid") {
    expectKeys(v, where, {"quadric", "weight", "perturbations", "clip", "center", "radii"});
    Vec3d radii{1, 1, 1};
    if (const Json* x = find(v, "radii")) {
      const auto r = sizes<3>(*x, member(where, "radii"));
      radii = {r[0], r[1], r[2]};
    }
    q = Quadric::ellipsoid(vecOr("center", {}, false), radii);
  } else if (kind == "cylinder") {
    expectKeys(v, where, {"quadric", "weight", "perturbations", "clip", "point", "axis", "radius"});
    q = Quadric::cylinder(vecOr("point", {}, false), vecOr("axis", {0, 1, 0}, true),
                          positiveOr("radius", 1));
  } else if (kind == "cone") {
    expectKeys(v, where, {"quadric", "weight", "perturbations", "clip", "apex", "axis", "angle"});
    double angle = 30;
    if (const Json* x = find(v, "angle")) {
      angle = number(*x, member(where, "angle"));
      if (!(angle > 0 && angle < 90))
        fail(member(where, "angle"),
             fmt::format("{} is out of range (0 < angle < 90 degrees)", x->dump()));
    }
    q = Quadric::cone(vecOr("apex", {}, false), vecOr("axis", {0, 1, 0}, true),
                      angle * std::numbers::pi / 180);
  } else if (kind == "paraboloid") {
    expectKeys(v, where, {"quadric", "weight", "perturbations", "clip", "vertex", "axis", "k"});
    q = Quadric::paraboloid(vecOr("vertex", {}, false), vecOr("axis", {0, 1, 0}, true),
                            positiveOr("k", 1));
  } else if (kind == "plane") {
    expectKeys(v, where, {"quadric", "weight", "perturbations", "clip", "normal", "d"});
    const Json* d = find(v, "d");
    q = Quadric::halfSpace(vecOr("normal", {0, 1, 0}, true),
                           d ? double(number(*d, member(where, "d"))) : 0.0);
  } else if (kind == "general") {
    expectKeys(v, where, {"quadric", "weight", "perturbations", "clip", "coefficients"});
    const Json* c = find(v, "coefficients");
    if (!c) fail(where, "missing key 'coefficients' (A … K, 10 numbers)");
    const auto a = numbers<10>(*c, member(where, "coefficients"));
    for (size_t i = 0; i < 10; ++i) q.c[i] = a[i];
  } else {
    fail(kindWhere, fmt::format("unknown quadric '{}' (expected sphere, ellipsoid, cylinder, "
                                "cone, paraboloid, plane or general)",
                                kind));
  }
  node.quadric = q.c;
  // Step 2: its weight as a perturbation, and its own perturbations.
  if (const Json* w = find(v, "weight")) {
    if (root)
      fail(member(where, "weight"), "'weight' belongs to perturbations, not the base quadric");
    node.weight = number(*w, member(where, "weight"));
  }
  if (const Json* clips = find(v, "clip")) {
    const std::string clipWhere = member(where, "clip");
    if (!root) fail(clipWhere, "'clip' belongs to the base quadric of a free form");
    const Json& a = array(*clips, clipWhere);
    for (size_t i = 0; i < a.size(); ++i) {
      const std::string w = element(clipWhere, i);
      if (a[i].is_object() &&
          (find(a[i], "perturbations") || find(a[i], "weight") || find(a[i], "clip")))
        fail(w, "a clip is a plain quadric (no 'weight', 'perturbations' or 'clip')");
      node.clips.push_back(readFreeForm(a[i], w, depth + 1, quadrics, false).quadric);
    }
  }
  if (const Json* list = find(v, "perturbations")) {
    const std::string listWhere = member(where, "perturbations");
    const Json& a = array(*list, listWhere);
    for (size_t i = 0; i < a.size(); ++i)
      node.perturbations.push_back(
          readFreeForm(a[i], element(listWhere, i), depth + 1, quadrics, false));
  }
  return node;
}

}  // namespace sv::formats::json
