// The JSON scene format's "lights" section (docs/scene-format.md, "Light points"): appearances,
// groups, points, strings and arrays of lights, their settings, and the star field.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "formats/json/json_reader.h"

namespace sv::formats::json {

namespace {

// At most this many light appearances and groups in a scene (and synthvis/light_points.h's
// kMaxLightPoints lights).
constexpr size_t kMaxLightAppearances = 65536, kMaxLightGroups = 4096;

// An index by name (a string) or number (an integer) into a table of `count` entries.
int tableRef(const Json& v, const std::string& where, const std::map<std::string, int>& byName,
             size_t count, const char* what) {
  if (v.is_string()) {
    auto it = byName.find(v.get<std::string>());
    if (it == byName.end()) fail(where, fmt::format("no {} named {}", what, v.dump()));
    return it->second;
  }
  if (count == 0) fail(where, fmt::format("there are no {}s", what));
  return int(integer(v, where, 0, int64_t(count) - 1));
}

}  // namespace

// "lights" (docs/scene-format.md, "Light points").
void SceneReader::readLights(const Json& v, const std::string& where) {
  expectKeys(v, where,
             {"settings", "appearances", "groups", "points", "strings", "arrays", "stars"});
  if (const Json* x = find(v, "settings")) {
    const std::string w = member(where, "settings");
    expectKeys(*x, w, {"exposure", "minSize", "maxSize", "punchThrough", "depthBias"});
    LightSettings& l = scene_.lightSettings;
    if (const Json* y = find(*x, "exposure"))
      l.exposure = inRange(*y, member(w, "exposure"), 0, 1e12f);
    if (const Json* y = find(*x, "minSize"))
      l.minSize = inRange(*y, member(w, "minSize"), 0.5f, 64);
    if (const Json* y = find(*x, "maxSize"))
      l.maxSize = inRange(*y, member(w, "maxSize"), 0.5f, 64);
    if (!(l.maxSize >= l.minSize))
      fail(w, fmt::format("maxSize ({}) is less than minSize ({})", l.maxSize, l.minSize));
    if (const Json* y = find(*x, "punchThrough"))
      l.punchThrough = inRange(*y, member(w, "punchThrough"), 0, 1);
    if (const Json* y = find(*x, "depthBias"))
      l.depthBias = inRange(*y, member(w, "depthBias"), 0, 1e6f);
  }
  std::map<std::string, int> appearances, groups;
  if (const Json* x = find(v, "appearances")) {
    const std::string w = member(where, "appearances");
    array(*x, w);
    if (x->size() > kMaxLightAppearances)
      fail(w, fmt::format("more than {} appearances", kMaxLightAppearances));
    for (size_t i = 0; i < x->size(); ++i) {
      LightAppearance a = readLightAppearance((*x)[i], element(w, i));
      if (!a.name.empty() && !appearances.emplace(a.name, int(i)).second)
        fail(element(w, i), fmt::format("a second appearance named '{}'", a.name));
      scene_.lightAppearances.push_back(std::move(a));
    }
  }
  if (const Json* x = find(v, "groups")) {
    const std::string w = member(where, "groups");
    array(*x, w);
    if (x->size() > kMaxLightGroups) fail(w, fmt::format("more than {} groups", kMaxLightGroups));
    for (size_t i = 0; i < x->size(); ++i) {
      const std::string wi = element(w, i);
      expectKeys((*x)[i], wi, {"name", "on", "dim"});
      LightGroup g;
      if (const Json* y = find((*x)[i], "name")) g.name = string(*y, member(wi, "name"));
      if (const Json* y = find((*x)[i], "on")) g.on = boolean(*y, member(wi, "on"));
      if (const Json* y = find((*x)[i], "dim")) g.dim = inRange(*y, member(wi, "dim"), 0, 1);
      if (!g.name.empty() && !groups.emplace(g.name, int(i)).second)
        fail(wi, fmt::format("a second group named '{}'", g.name));
      scene_.lightGroups.push_back(std::move(g));
    }
  }
  // Lights without appearances of their own are white, omnidirectional, 200 cd.
  if (scene_.lightAppearances.empty() &&
      (find(v, "points") || find(v, "strings") || find(v, "arrays"))) {
    LightAppearance a;
    a.name = "default";
    scene_.lightAppearances.push_back(a);
  }
  readLightItems(v, where, appearances, groups);
  if (const Json* x = find(v, "stars")) {
    const std::string w = member(where, "stars");
    expectKeys(*x, w, {"catalog", "latitude", "siderealTime", "brightness", "limit"});
    StarField& f = scene_.stars;
    if (const Json* y = find(*x, "latitude"))
      f.latitude = inRange(*y, member(w, "latitude"), -90, 90);
    if (const Json* y = find(*x, "siderealTime"))
      f.siderealTime = inRange(*y, member(w, "siderealTime"), 0, 24);
    if (const Json* y = find(*x, "brightness"))
      f.brightness = inRange(*y, member(w, "brightness"), 0, 1e6f);
    if (const Json* y = find(*x, "limit")) f.limit = inRange(*y, member(w, "limit"), -30, 30);
    const Json* catalog = find(*x, "catalog");
    if (!catalog) fail(w, "missing key 'catalog' (a star catalogue file, docs/lights.md#stars)");
    const std::string ref = string(*catalog, member(w, "catalog"));
    if (context_.options.followReferences) {
      Result<std::vector<Star>> stars = loadStarCatalog(resolvePath(directoryOf(path_), ref));
      if (!stars.ok()) fail(member(w, "catalog"), stars.error().str());
      f.stars = std::move(stars.value());
    }
  }
}

LightAppearance SceneReader::readLightAppearance(const Json& v, const std::string& w) const {
  expectKeys(v, w,
             {"name", "color", "intensity", "direction", "lobe", "falloff", "back", "split",
              "blink", "rotation"});
  LightAppearance a;
  if (const Json* x = find(v, "name")) a.name = string(*x, member(w, "name"));
  if (const Json* x = find(v, "color")) a.color = lightColor(*x, member(w, "color"));
  if (const Json* x = find(v, "intensity"))
    a.intensity = inRange(*x, member(w, "intensity"), 0, 1e9f);
  if (const Json* x = find(v, "direction")) {
    a.directional = true;
    a.direction = normalize(nonZeroVec3(*x, member(w, "direction")));
  }
  if (const Json* x = find(v, "lobe")) {
    const auto lobe = numbers<2>(*x, member(w, "lobe"));
    for (int i = 0; i < 2; ++i)
      if (!(lobe[size_t(i)] > 0 && lobe[size_t(i)] < 180))
        fail(element(member(w, "lobe"), size_t(i)),
             fmt::format("{} is not a lobe width in (0, 180) degrees", lobe[size_t(i)]));
    a.horizontalLobe = lobe[0];
    a.verticalLobe = lobe[1];
  }
  if (const Json* x = find(v, "falloff")) a.falloff = inRange(*x, member(w, "falloff"), 0, 64);
  if (const Json* x = find(v, "back")) {
    a.backLobe = true;
    a.backColor = lightColor(*x, member(w, "back"));
  }
  if ((find(v, "lobe") || find(v, "back") || find(v, "falloff")) && !a.directional)
    fail(w, "'lobe', 'falloff' and 'back' need a 'direction'");
  if (const Json* x = find(v, "split")) {
    const std::string ws = member(w, "split");
    expectKeys(*x, ws, {"angle", "width", "below"});
    a.split = true;
    if (const Json* y = find(*x, "angle")) a.splitAngle = inRange(*y, member(ws, "angle"), -90, 90);
    if (const Json* y = find(*x, "width")) a.splitWidth = inRange(*y, member(ws, "width"), 0, 90);
    if (const Json* y = find(*x, "below")) a.lowColor = lightColor(*y, member(ws, "below"));
  }
  if (const Json* x = find(v, "blink")) {
    const std::string wb = member(w, "blink");
    expectKeys(*x, wb, {"period", "phase", "on"});
    if (const Json* y = find(*x, "period"))
      a.blink.period = inRange(*y, member(wb, "period"), 0, 1e6f);
    if (const Json* y = find(*x, "phase"))
      a.blink.phase = inRange(*y, member(wb, "phase"), -1e6f, 1e6f);
    if (const Json* y = find(*x, "on")) a.blink.onFraction = inRange(*y, member(wb, "on"), 0, 1);
  }
  if (const Json* x = find(v, "rotation")) {
    a.rotationPeriod = positive(*x, member(w, "rotation"));
    if (!a.directional) fail(w, "'rotation' needs a 'direction' (the beacon's lobe)");
  }
  return a;
}

LightPoint SceneReader::readLightCommon(const Json& v, const std::string& w,
                                        const std::map<std::string, int>& appearances,
                                        const std::map<std::string, int>& groups) const {
  LightPoint p;
  if (const Json* x = find(v, "appearance"))
    p.appearance = uint32_t(tableRef(*x, member(w, "appearance"), appearances,
                                     scene_.lightAppearances.size(), "appearance"));
  if (const Json* x = find(v, "group"))
    p.group = tableRef(*x, member(w, "group"), groups, scene_.lightGroups.size(), "group");
  if (const Json* x = find(v, "phase")) p.phase = inRange(*x, member(w, "phase"), -1e6f, 1e6f);
  return p;
}

void SceneReader::addLight(const LightPoint& p, const std::string& where) {
  if (scene_.lightPoints.size() >= kMaxLightPoints)
    fail(where, fmt::format("the scene would have more than {} light points", kMaxLightPoints));
  scene_.lightPoints.push_back(p);
}

// "points", "strings" (start, end, count or spacing, sequence) and "arrays" (origin, u, v, counts).
void SceneReader::readLightItems(const Json& v, const std::string& where,
                                 const std::map<std::string, int>& appearances,
                                 const std::map<std::string, int>& groups) {
  if (const Json* x = find(v, "points")) {
    const std::string w = member(where, "points");
    array(*x, w);
    for (size_t i = 0; i < x->size(); ++i) {
      const std::string wi = element(w, i);
      expectKeys((*x)[i], wi, {"position", "appearance", "group", "phase"});
      LightPoint p = readLightCommon((*x)[i], wi, appearances, groups);
      const Json* pos = find((*x)[i], "position");
      if (!pos) fail(wi, "missing key 'position'");
      p.position = vec3(*pos, member(wi, "position"));
      addLight(p, wi);
    }
  }
  if (const Json* x = find(v, "strings")) {
    const std::string w = member(where, "strings");
    array(*x, w);
    for (size_t i = 0; i < x->size(); ++i) {
      const std::string wi = element(w, i);
      const Json& item = (*x)[i];
      expectKeys(item, wi,
                 {"start", "end", "count", "spacing", "sequence", "appearance", "group", "phase"});
      const LightPoint common = readLightCommon(item, wi, appearances, groups);
      const Json* start = find(item, "start");
      const Json* end = find(item, "end");
      if (!start || !end) fail(wi, "a string needs 'start' and 'end'");
      const Vec3 a = vec3(*start, member(wi, "start")), b = vec3(*end, member(wi, "end"));
      const Json* count = find(item, "count");
      const Json* spacing = find(item, "spacing");
      if (!count == !spacing) fail(wi, "a string needs one of 'count' and 'spacing'");
      const Vec3 d = b - a;
      const float len = length(d);
      int64_t n;
      Vec3 step;
      if (count) {
        n = integer(*count, member(wi, "count"), 1, int64_t(kMaxLightPoints));
        step = n > 1 ? d * (1.0f / float(n - 1)) : Vec3{};
      } else {
        const float sp = positive(*spacing, member(wi, "spacing"));
        const double lights = std::floor(double(len) / double(sp) + 1e-6) + 1;
        if (lights > double(kMaxLightPoints))
          fail(member(wi, "spacing"),
               fmt::format("{} m over {} m is more than {} lights", sp, len, kMaxLightPoints));
        n = int64_t(lights);
        step = len > 0 ? d * (sp / len) : Vec3{};
      }
      const bool sequence =
          find(item, "sequence") && boolean(*find(item, "sequence"), member(wi, "sequence"));
      for (int64_t k = 0; k < n; ++k) {
        LightPoint p = common;
        p.position = a + step * float(k);
        if (sequence) p.phase = common.phase - float(k) / float(n);
        addLight(p, wi);
      }
    }
  }
  if (const Json* x = find(v, "arrays")) {
    const std::string w = member(where, "arrays");
    array(*x, w);
    for (size_t i = 0; i < x->size(); ++i) {
      const std::string wi = element(w, i);
      const Json& item = (*x)[i];
      expectKeys(item, wi, {"origin", "u", "v", "counts", "appearance", "group", "phase"});
      const LightPoint common = readLightCommon(item, wi, appearances, groups);
      const Json* origin = find(item, "origin");
      const Json* u = find(item, "u");
      const Json* vv = find(item, "v");
      const Json* counts_ = find(item, "counts");
      if (!origin || !u || !vv || !counts_)
        fail(wi, "an array needs 'origin', 'u', 'v' and 'counts'");
      const Vec3 o = vec3(*origin, member(wi, "origin")), du = vec3(*u, member(wi, "u")),
                 dv = vec3(*vv, member(wi, "v"));
      const std::array<int, 2> n = counts(*counts_, member(wi, "counts"), 1, 1 << 16);
      if (uint64_t(n[0]) * uint64_t(n[1]) > kMaxLightPoints)
        fail(member(wi, "counts"),
             fmt::format("{} × {} is more than {} lights", n[0], n[1], kMaxLightPoints));
      for (int j = 0; j < n[1]; ++j)
        for (int k = 0; k < n[0]; ++k) {
          LightPoint p = common;
          p.position = o + du * float(k) + dv * float(j);
          addLight(p, wi);
        }
    }
  }
}

}  // namespace sv::formats::json
