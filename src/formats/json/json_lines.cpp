// The JSON scene format's "lines" section (docs/scene-format.md, "Lines").
#include <algorithm>

#include "formats/json/json_reader.h"

namespace sv::formats::json {

// "lines" (docs/scene-format.md, "Lines"): {"width", "depthBias", "polylines": [{"points",
// "color", "closed"}]}, in world coordinates.
void SceneReader::readLines(const Json& v, const std::string& where) {
  expectKeys(v, where, {"width", "depthBias", "polylines"});
  LineSettings& l = scene_.lineSettings;
  if (const Json* x = find(v, "width"))
    l.width = inRange(*x, member(where, "width"), 1.0f / 64, 64);
  if (const Json* x = find(v, "depthBias"))
    l.depthBias = inRange(*x, member(where, "depthBias"), 0, 0.5f);
  const Json* polylines = find(v, "polylines");
  if (!polylines) return;
  const std::string w = member(where, "polylines");
  array(*polylines, w);
  for (size_t i = 0; i < polylines->size(); ++i) {
    const Json& p = (*polylines)[i];
    const std::string wp = element(w, i);
    expectKeys(p, wp, {"points", "color", "closed"});
    const Json* points = find(p, "points");
    if (!points) fail(wp, "missing key 'points'");
    const std::string wpts = member(wp, "points");
    array(*points, wpts);
    if (points->size() < 2) fail(wpts, "a polyline needs at least 2 points");
    Vec3 c{1, 1, 1};
    if (const Json* x = find(p, "color")) {
      const Vec4 c4 = color(*x, member(wp, "color"), false);
      c = {c4.x, c4.y, c4.z};
    }
    const Json* closedKey = find(p, "closed");
    const bool closed = closedKey && boolean(*closedKey, member(wp, "closed"));
    const size_t n = points->size();
    const size_t segments = closed && n > 2 ? n : n - 1;
    if (scene_.lines.size() + segments > kMaxLines)
      fail(wp, fmt::format("more than {} line segments", kMaxLines));
    std::vector<Vec3> q(n);
    for (size_t k = 0; k < n; ++k) q[k] = vec3((*points)[k], element(wpts, k));
    for (size_t k = 0; k < segments; ++k) scene_.lines.push_back({q[k], q[(k + 1) % n], c});
  }
}

}  // namespace sv::formats::json
