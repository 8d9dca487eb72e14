// The JSON scene format, version 1. Based on: docs/scene-format.md (the reference for every key,
// default and limit used here).
//
// Parsing has two steps. nlohmann::json turns the text into a document (syntax errors carry
// line:column; a parse callback limits nesting depth and rejects duplicate keys, which nlohmann
// would silently resolve to the last one). A SceneReader then walks the document, checking every
// key, type and range before using it, and reports the first problem with its place in the
// document ("objects[2].transform.translate: expected an array of 3 numbers").
//
// Inside this file the walker reports a problem by throwing JsonProblem: it keeps each field
// read to one line. parseJsonSceneIn catches it, and every other exception, and returns an
// Error; nothing is thrown past this file.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

#include "core/quadric.h"
#include "scene/channels.h"
#include "scene/loader_common.h"
#include "scene/primitives.h"
#include "synthvis/generators.h"
#include "terrain/caster.h"
#include "terrain/ground.h"
#include "terrain/ortho_image.h"
#include "texture/texture.h"

namespace sv::scene {
namespace detail {
namespace {

using Json = nlohmann::json;

constexpr int kFormatVersion = 1;
// Deeper than any valid scene needs (an inline mesh is 4 levels down); guards the recursion-free
// but memory-hungry parse of "[[[[…" and keeps error paths short.
constexpr size_t kMaxJsonDepth = 64;
// Every number must be finite and at most this large in magnitude, so that it converts to float
// and stays finite through a few products.
constexpr double kMaxMagnitude = 1e30;

// A problem at a place in the document; see the file comment.
struct JsonProblem {
  std::string where;  // "objects[2].transform.translate", or "" for the top level
  std::string message;
};

[[noreturn]] void fail(const std::string& where, std::string message) {
  throw JsonProblem{where, std::move(message)};
}

std::string member(const std::string& where, std::string_view key) {
  return where.empty() ? std::string(key) : fmt::format("{}.{}", where, key);
}
std::string element(const std::string& where, size_t i) { return fmt::format("{}[{}]", where, i); }

const char* typeName(const Json& v) {
  switch (v.type()) {
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return "an array";
    case Json::value_t::string:
      return "a string";
    case Json::value_t::boolean:
      return "a boolean";
    case Json::value_t::null:
      return "null";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
      return "an integer";
    case Json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

// Levenshtein distance, for "did you mean" hints on misspelt keys.
size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string suggestion(std::string_view key, std::initializer_list<std::string_view> allowed) {
  std::string_view best;
  size_t bestDistance = 3;  // more than two edits is a different word, not a typo
  for (std::string_view candidate : allowed) {
    size_t d = editDistance(key, candidate);
    if (d < bestDistance && d < candidate.size()) {
      best = candidate;
      bestDistance = d;
    }
  }
  return best.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", best);
}

// Step 0: the parse callback. nlohmann calls it for every token event; it tracks the path of the
// current container so that its own errors can say where they are.
class ParseGuard {
 public:
  bool operator()(int /*depth*/, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        if (frames_.size() >= kMaxJsonDepth)
          fail(path(), fmt::format("values are nested more than {} levels deep", kMaxJsonDepth));
        frames_.push_back({event == Json::parse_event_t::array_start, 0, {}, {}});
        break;
      case Json::parse_event_t::key: {
        Frame& frame = frames_.back();
        frame.key = parsed.get<std::string>();
        if (!frame.keys.insert(frame.key).second)
          fail(path(), fmt::format("duplicate key '{}'", frame.key));
        break;
      }
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        frames_.pop_back();
        finishValue();
        break;
      case Json::parse_event_t::value:
        finishValue();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array;
    size_t index;     // arrays: elements completed so far
    std::string key;  // objects: the key being read
    std::set<std::string> keys;
  };

  void finishValue() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }
  // The path of the innermost open container.
  std::string path() const {
    std::string p;
    for (size_t i = 0; i + 1 < frames_.size(); ++i)
      p = frames_[i].array ? element(p, frames_[i].index) : member(p, frames_[i].key);
    return p;
  }

  std::vector<Frame> frames_;
};

// 1-based "line:column" of the 1-based byte offset nlohmann reports (the byte after the last one
// it read).
std::string lineColumn(const std::string& text, size_t byte) {
  size_t offset = std::min(byte > 0 ? byte - 1 : 0, text.size());
  size_t line = 1 + size_t(std::count(text.begin(), text.begin() + ptrdiff_t(offset), '\n'));
  size_t lineStart = text.rfind('\n', offset > 0 ? offset - 1 : 0);
  lineStart = (lineStart == std::string::npos || offset == 0) ? 0 : lineStart + 1;
  return fmt::format("{}:{}", line, offset - lineStart + 1);
}

// "[json.exception.parse_error.101] parse error at line 3, column 4: syntax error …" → the part
// after the position, which we print in our own "file:line:col: message" form.
std::string parseErrorMessage(const std::string& what) {
  size_t column = what.find("column ");
  size_t colon = what.find(": ", column == std::string::npos ? 0 : column);
  if (colon != std::string::npos) return oneLine(what.substr(colon + 2));
  size_t bracket = what.find("] ");
  return oneLine(bracket == std::string::npos ? what : what.substr(bracket + 2));
}

// --- Typed readers. Each checks its value completely and fails with the value's place. ---

const Json* find(const Json& object, std::string_view key) {
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

// Checks that `v` is an object whose keys are all in `allowed` (a misspelt key is an error, not a
// silently ignored setting).
void expectKeys(const Json& v, const std::string& where,
                std::initializer_list<std::string_view> allowed) {
  if (!v.is_object()) fail(where, fmt::format("expected an object, got {}", typeName(v)));
  for (const auto& item : v.items()) {
    const std::string& key = item.key();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      fail(where, fmt::format("unknown key '{}'{}", key, suggestion(key, allowed)));
  }
}

// Empty when `v` is an acceptable number, else what is wrong with it.
std::string numberProblem(const Json& v) {
  if (!v.is_number()) return fmt::format("expected a number, got {}", typeName(v));
  double d = v.get<double>();
  if (!std::isfinite(d) || std::fabs(d) > kMaxMagnitude)
    return fmt::format("{} is out of range (numbers must be finite, magnitude at most 1e30)",
                       v.dump());
  return {};
}

float number(const Json& v, const std::string& where) {
  std::string problem = numberProblem(v);
  if (!problem.empty()) fail(where, problem);
  return static_cast<float>(v.get<double>());
}

float positive(const Json& v, const std::string& where) {
  float x = number(v, where);
  if (!(x > 0)) fail(where, fmt::format("expected a number greater than 0, got {}", v.dump()));
  return x;
}

float inRange(const Json& v, const std::string& where, float lo, float hi) {
  float x = number(v, where);
  if (x < lo || x > hi) fail(where, fmt::format("{} is out of range {}..{}", v.dump(), lo, hi));
  return x;
}

int64_t integer(const Json& v, const std::string& where, int64_t lo, int64_t hi) {
  if (!v.is_number_integer()) fail(where, fmt::format("expected an integer, got {}", typeName(v)));
  // Unsigned values beyond int64 are out of every range we accept.
  bool tooBig = v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(hi);
  int64_t x = tooBig ? hi : v.get<int64_t>();
  if (tooBig || x < lo || x > hi)
    fail(where, fmt::format("{} is out of range {}..{}", v.dump(), lo, hi));
  return x;
}

bool boolean(const Json& v, const std::string& where) {
  if (!v.is_boolean()) fail(where, fmt::format("expected true or false, got {}", typeName(v)));
  return v.get<bool>();
}

std::string string(const Json& v, const std::string& where) {
  if (!v.is_string()) fail(where, fmt::format("expected a string, got {}", typeName(v)));
  return v.get<std::string>();
}

const Json& array(const Json& v, const std::string& where) {
  if (!v.is_array()) fail(where, fmt::format("expected an array, got {}", typeName(v)));
  return v;
}

// An array of exactly `n` numbers in double, for map coordinates (a UTM northing needs more than
// float's 24 bits to keep centimetres), each at most 1e9 in magnitude.
template <size_t N>
std::array<double, N> doubles(const Json& v, const std::string& where) {
  if (!v.is_array() || v.size() != N)
    fail(where, fmt::format("expected an array of {} numbers, got {}", N,
                            v.is_array() ? fmt::format("{} elements", v.size()) : typeName(v)));
  std::array<double, N> out;
  for (size_t i = 0; i < N; ++i) {
    if (!v[i].is_number()) fail(element(where, i), fmt::format("expected a number, got {}", typeName(v[i])));
    out[i] = v[i].get<double>();
    if (!std::isfinite(out[i]) || std::fabs(out[i]) > 1e9)
      fail(element(where, i), fmt::format("{} is out of range (at most 1e9 in magnitude)", v[i].dump()));
  }
  return out;
}

// An array of exactly `n` numbers.
template <size_t N>
std::array<float, N> numbers(const Json& v, const std::string& where) {
  if (!v.is_array() || v.size() != N)
    fail(where, fmt::format("expected an array of {} numbers, got {}", N,
                            v.is_array() ? fmt::format("{} elements", v.size()) : typeName(v)));
  std::array<float, N> out;
  for (size_t i = 0; i < N; ++i) out[i] = number(v[i], element(where, i));
  return out;
}

Vec3 vec3(const Json& v, const std::string& where) {
  auto a = numbers<3>(v, where);
  return {a[0], a[1], a[2]};
}

Vec3 nonZeroVec3(const Json& v, const std::string& where) {
  Vec3 x = vec3(v, where);
  if (!(length(x) > 0)) fail(where, "expected a non-zero vector");
  return x;
}

// [r, g, b] or (when `alpha`) [r, g, b, a], each in 0..1; alpha defaults to 1.
Vec4 color(const Json& v, const std::string& where, bool alpha) {
  bool sizeOk = v.is_array() && (v.size() == 3 || (alpha && v.size() == 4));
  if (!sizeOk)
    fail(where, fmt::format("expected a colour [r, g, b{}] with components 0..1, got {}",
                            alpha ? "(, a)" : "",
                            v.is_array() ? fmt::format("{} elements", v.size()) : typeName(v)));
  float c[4] = {1, 1, 1, 1};
  for (size_t i = 0; i < v.size(); ++i) c[i] = inRange(v[i], element(where, i), 0, 1);
  return {c[0], c[1], c[2], c[3]};
}

// A length given as one number for all axes or as an array of `N` numbers, each > 0.
template <size_t N>
std::array<float, N> sizes(const Json& v, const std::string& where) {
  std::array<float, N> out;
  if (v.is_number()) {
    out.fill(positive(v, where));
  } else {
    if (!v.is_array() || v.size() != N)
      fail(where, fmt::format("expected a number or an array of {} numbers, got {}", N,
                              v.is_array() ? fmt::format("{} elements", v.size()) : typeName(v)));
    for (size_t i = 0; i < N; ++i) out[i] = positive(v[i], element(where, i));
  }
  return out;
}

// A count given as one integer for both axes or as [x, z].
std::array<int, 2> counts(const Json& v, const std::string& where, int lo, int hi) {
  if (v.is_array()) {
    if (v.size() != 2)
      fail(where,
           fmt::format("expected an integer or an array of 2 integers, got {} elements", v.size()));
    return {int(integer(v[0], element(where, 0), lo, hi)),
            int(integer(v[1], element(where, 1), lo, hi))};
  }
  int n = int(integer(v, where, lo, hi));
  return {n, n};
}

Mat4 rotationDegrees(Vec3 axis, float degrees) {
  return Mat4::rotation(axis, static_cast<float>(degrees * std::numbers::pi / 180.0));
}

// "transform": {"matrix": [16]} or any of translate / rotate / scale, composed as T·R·S.
Mat4 readTransform(const Json& v, const std::string& where) {
  expectKeys(v, where, {"matrix", "translate", "rotate", "scale"});
  if (const Json* m = find(v, "matrix")) {
    if (v.size() > 1)
      fail(where, "'matrix' cannot be combined with 'translate', 'rotate' or 'scale'");
    std::string w = member(where, "matrix");
    auto a = numbers<16>(*m, w);
    // Column-major: elements 3, 7, 11, 15 form the last row. A projective last row would make
    // positions depend on w, which no stage after the loader expects.
    if (a[3] != 0 || a[7] != 0 || a[11] != 0 || a[15] != 1)
      fail(w, "the last row (elements 3, 7, 11, 15) must be 0, 0, 0, 1");
    return Mat4::fromColumnMajor(a.data());
  }
  Mat4 t, r, s;
  if (const Json* translate = find(v, "translate"))
    t = Mat4::translation(vec3(*translate, member(where, "translate")));
  if (const Json* rotate = find(v, "rotate")) {
    std::string w = member(where, "rotate");
    if (rotate->is_array()) {
      // Euler angles in degrees about the fixed world axes, X first, then Y, then Z.
      Vec3 e = vec3(*rotate, w);
      r = rotationDegrees({0, 0, 1}, e.z) * rotationDegrees({0, 1, 0}, e.y) *
          rotationDegrees({1, 0, 0}, e.x);
    } else {
      expectKeys(*rotate, w, {"axis", "degrees"});
      const Json* axis = find(*rotate, "axis");
      const Json* degrees = find(*rotate, "degrees");
      if (!axis || !degrees)
        fail(w, "expected {\"axis\": [x, y, z], \"degrees\": number} or [x, y, z] Euler degrees");
      r = rotationDegrees(nonZeroVec3(*axis, member(w, "axis")),
                          number(*degrees, member(w, "degrees")));
    }
  }
  if (const Json* scale = find(v, "scale")) {
    std::string w = member(where, "scale");
    Vec3 k = scale->is_number() ? Vec3{1, 1, 1} * number(*scale, w) : vec3(*scale, w);
    s = Mat4::scaling(k);
  }
  return t * r * s;
}

// Turns a scene document into a Scene.
class SceneReader {
 public:
  SceneReader(const std::string& path, LoadContext& context) : path_(path), context_(context) {}

  Scene read(const Json& root);

 private:
  Camera readCamera(const Json& v, const std::string& where) const;
  std::vector<Channel> readChannels(const Json& v, const std::string& where) const;
  void readLight(const Json& v, const std::string& where);
  void readMaterials(const Json& v, const std::string& where);
  void readTextures(const Json& v, const std::string& where);
  void readFog(const Json& v, const std::string& where);
  void readPointLights(const Json& v, const std::string& where);
  void readColorTable(const Json& v, const std::string& where);
  void readObject(const Json& v, const std::string& where);
  void readObjectGeometry(const Json& v, const std::string& where);
  // "lodGroups" (docs/scene-format.md#levels-of-detail): named groups of levels, each level an
  // object of one mesh.
  void readLodGroups(const Json& v, const std::string& where);
  // An object with "lod": its group's instances, at its placements ("at") or its transform.
  void readLodObject(const Json& v, const std::string& where);
  // The highest terrain's height at world (x, z), for objects placed "onGround".
  double groundHeight(double x, double z, const std::string& where) const;
  // The object's "material" and "color" keys as a material index (or −1).
  int readObjectMaterial(const Json& object, const std::string& where);
  void readPrimitive(const Json& object, const std::string& where);
  void readFreeFormObject(const Json& object, const std::string& where);
  void readTerrain(const Json& v, const std::string& where);
  // "lights" (docs/scene-format.md#light-points): appearances, groups, points, strings, arrays,
  // settings, the star field.
  void readLights(const Json& v, const std::string& where);
  LightAppearance readLightAppearance(const Json& v, const std::string& where) const;
  // A light item's "appearance" and "group" (by name or index), "phase".
  LightPoint readLightCommon(const Json& v, const std::string& where,
                             const std::map<std::string, int>& appearances,
                             const std::map<std::string, int>& groups) const;
  void readLightItems(const Json& v, const std::string& where,
                      const std::map<std::string, int>& appearances,
                      const std::map<std::string, int>& groups);
  void addLight(const LightPoint& p, const std::string& where);
  // "lines" (docs/scene-format.md#lines): settings and polylines.
  void readLines(const Json& v, const std::string& where);
  // "volumes" (docs/scene-format.md#volumes): settings and volume objects.
  void readVolumes(const Json& v, const std::string& where);
  std::shared_ptr<terrain::Ground> readHeights(const Json& v, const std::string& where);
  int textureRef(const Json& v, const std::string& where) const;
  FreeFormNode readFreeForm(const Json& v, const std::string& where, int depth, int& quadrics,
                            bool root) const;
  void readInlineMesh(const Json& v, const std::string& where, Mesh& mesh) const;
  void readMeshFile(const Json& v, const std::string& where, std::optional<int> material,
                    const Mat4& m);
  // Charges `triangles` (instanced) to the scene's budget.
  void addTriangles(uint64_t triangles, const std::string& where);

  const std::string& path_;
  LoadContext& context_;
  Scene scene_;
  uint64_t triangles_ = 0;
  std::map<std::string, int> materialByName_;
  std::map<std::string, int> textureByName_;
  uint64_t texels_ = 0;  // decoded or generated so far (LoadOptions::maxTexels)
  std::vector<Vec3> colorTable_;
  // Materials made for objects' "color" overrides, by (base material, colour), to share them.
  std::map<std::pair<int, std::array<float, 4>>, int> colorMaterials_;
  // Where a referenced file's meshes and level-of-detail groups were placed in this scene (its
  // first mesh, its first group), by (file, material override), so that further references to it
  // add instances only.
  std::map<std::pair<std::string, int>, std::pair<int, int>> placedMeshes_;
  std::map<std::string, int> lodGroupByName_;
};

Scene SceneReader::read(const Json& root) {
  if (!root.is_object())
    fail("", fmt::format("expected a JSON object at the top level, got {}", typeName(root)));
  // The version comes first, so that a newer file gets a version message rather than complaints
  // about keys this reader does not know yet.
  const Json* version = find(root, "synthvis");
  if (!version)
    fail("", fmt::format("missing key 'synthvis' (the format version; this reader understands "
                         "version {})",
                         kFormatVersion));
  if (!version->is_number_integer() || version->get<int64_t>() != kFormatVersion)
    fail("synthvis",
         fmt::format("unsupported format version {} (this reader understands version {})",
                     version->dump(), kFormatVersion));
  expectKeys(root, "",
             {"synthvis", "description", "background", "camera", "cameras", "light", "pointLights",
              "fog", "textures", "colorTable", "materials", "lodGroups", "objects", "terrain",
              "lights", "lines", "volumes", "time", "channels"});

  if (const Json* description = find(root, "description")) string(*description, "description");
  if (const Json* background = find(root, "background")) {
    Vec4 c = color(*background, "background", false);
    scene_.background = {c.x, c.y, c.z};
  }
  const Json* camera = find(root, "camera");
  const Json* cameras = find(root, "cameras");
  if (camera && cameras) fail("", "use either 'camera' or 'cameras', not both");
  if (camera) scene_.cameras.push_back(readCamera(*camera, "camera"));
  if (cameras) {
    array(*cameras, "cameras");
    for (size_t i = 0; i < cameras->size(); ++i)
      scene_.cameras.push_back(readCamera((*cameras)[i], element("cameras", i)));
  }
  if (const Json* x = find(root, "channels")) scene_.channels = readChannels(*x, "channels");
  if (const Json* light = find(root, "light")) readLight(*light, "light");
  if (const Json* x = find(root, "pointLights")) readPointLights(*x, "pointLights");
  if (const Json* x = find(root, "fog")) readFog(*x, "fog");
  if (const Json* x = find(root, "textures")) readTextures(*x, "textures");
  if (const Json* x = find(root, "colorTable")) readColorTable(*x, "colorTable");
  if (const Json* materials = find(root, "materials")) readMaterials(*materials, "materials");
  // Terrain before the objects: an object may stand on the ground ("onGround").
  if (const Json* x = find(root, "terrain")) {
    array(*x, "terrain");
    if (x->size() > 64) fail("terrain", "more than 64 terrains");
    for (size_t i = 0; i < x->size(); ++i) readTerrain((*x)[i], element("terrain", i));
  }
  if (const Json* x = find(root, "lodGroups")) readLodGroups(*x, "lodGroups");
  if (const Json* objects = find(root, "objects")) {
    array(*objects, "objects");
    for (size_t i = 0; i < objects->size(); ++i) readObject((*objects)[i], element("objects", i));
  }
  if (const Json* x = find(root, "lights")) readLights(*x, "lights");
  if (const Json* x = find(root, "lines")) readLines(*x, "lines");
  if (const Json* x = find(root, "volumes")) readVolumes(*x, "volumes");
  if (const Json* x = find(root, "time")) scene_.time = number(*x, "time");
  return std::move(scene_);
}

// "terrain" (docs/scene-format.md, "Terrain"): a height field, its placement, base, filter, image
// or colour ramp, and material.
void SceneReader::readTerrain(const Json& v, const std::string& where) {
  expectKeys(v, where,
             {"name", "heights", "generate", "png", "origin", "base", "interpolation", "material",
              "color", "image", "detail", "ramp", "verticalScale"});
  Terrain t;
  if (const Json* x = find(v, "name")) t.name = string(*x, member(where, "name"));
  std::shared_ptr<terrain::Ground> ground = readHeights(v, where);
  t.ground = ground;
  const terrain::HeightField& f = t.ground->field;
  t.origin[0] = 0.5 * (f.originU + f.eastU());
  t.origin[1] = 0.5 * (f.originV + f.southV());
  if (const Json* x = find(v, "origin")) {
    const auto o = doubles<2>(*x, member(where, "origin"));
    t.origin[0] = o[0], t.origin[1] = o[1];
  }
  if (const Json* x = find(v, "base")) {
    const std::string w = member(where, "base");
    if (x->is_string() && x->get<std::string>() == "plane") {
      t.baseRadius = 0;
    } else if (x->is_string() && x->get<std::string>() == "earth") {
      t.baseRadius = terrain::kEarthRadius;
    } else if (x->is_object()) {
      expectKeys(*x, w, {"sphere"});
      const Json* r = find(*x, "sphere");
      if (!r) fail(w, "missing key 'sphere' (the radius, metres)");
      t.baseRadius = inRange(*r, member(w, "sphere"), 1, 1e9f);
    } else {
      fail(w, R"(expected "plane", "earth" or {"sphere": radius})");
    }
  }
  if (const Json* x = find(v, "interpolation")) {
    const Result<terrain::Interpolation> i =
        terrain::parseInterpolation(string(*x, member(where, "interpolation")));
    if (!i) fail(member(where, "interpolation"), i.error().message);
    t.bicubic = i.value() == terrain::Interpolation::bicubic;
  }
  // The pyramid the scene asks for, built now: part of loading, not of the first frame.
  const auto start = std::chrono::steady_clock::now();
  ground->pyramid(t.bicubic ? terrain::Interpolation::bicubic : terrain::Interpolation::bilinear);
  ground->loadMs +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  t.material = readObjectMaterial(v, where);
  if (const Json* x = find(v, "image")) {
    const std::string w = member(where, "image");
    expectKeys(*x, w, {"file", "texture", "bands", "bounds"});
    const Json* file = find(*x, "file");
    const Json* tex = find(*x, "texture");
    if (!file == !tex) fail(w, "give either 'file' (a GDAL raster) or 'texture' (a scene texture)");
    const Json* bounds = find(*x, "bounds");
    if (bounds) {
      const auto b = doubles<4>(*bounds, member(w, "bounds"));
      if (!(b[2] > b[0] && b[3] > b[1]))
        fail(member(w, "bounds"), "expected [west, south, east, north] with east > west, north > south");
      for (int k = 0; k < 4; ++k) t.imageBounds[k] = b[size_t(k)];
    }
    if (tex) {
      if (!bounds) fail(w, "a texture needs 'bounds' [west, south, east, north] (map metres)");
      t.image = textureRef(*tex, member(w, "texture"));
    } else {
      std::array<int, 3> bands{1, 2, 3};
      if (const Json* b = find(*x, "bands")) {
        const std::string bw = member(w, "bands");
        array(*b, bw);
        if (b->size() != 3 && b->size() != 1) fail(bw, "expected 1 or 3 band numbers");
        for (size_t k = 0; k < 3; ++k)
          bands[k] = int(integer((*b)[b->size() == 1 ? 0 : k], element(bw, k), 1, 65535));
      }
      const std::string ref = string(*file, member(w, "file"));
      if (!context_.options.followReferences)
        fail(member(w, "file"), "referenced files are not read here");
      Result<terrain::OrthoImage> img =
          terrain::loadOrthoImage(resolvePath(directoryOf(path_), ref), bands);
      if (!img) fail(member(w, "file"), img.error().str());
      if (!bounds && !img->georeferenced)
        fail(w, "the image has no georeferencing: give 'bounds' [west, south, east, north]");
      if (!bounds)
        for (int k = 0; k < 4; ++k) t.imageBounds[k] = img->bounds[size_t(k)];
      const uint64_t texels = uint64_t(img->level.width) * uint64_t(img->level.height);
      if (texels > context_.options.maxTexels - std::min(texels_, context_.options.maxTexels))
        fail(w, fmt::format("the scene's textures exceed {} texels", context_.options.maxTexels));
      texels_ += texels;
      TextureMap map;
      map.name = ref;
      map.texture = std::make_shared<texture::Texture>(std::move(img->level), texture::Wrap::clamp,
                                                       texture::Wrap::clamp);
      scene_.textures.push_back(std::move(map));
      t.image = int(scene_.textures.size()) - 1;
    }
  }
  if (const Json* x = find(v, "detail")) {
    const std::string w = member(where, "detail");
    expectKeys(*x, w, {"texture", "size"});
    const Json* tex = find(*x, "texture");
    if (!tex) fail(w, "missing key 'texture'");
    t.detail = textureRef(*tex, member(w, "texture"));
    if (const Json* s = find(*x, "size")) t.detailSize = inRange(*s, member(w, "size"), 1e-3f, 1e6f);
  }
  if (const Json* x = find(v, "ramp")) {
    const std::string w = member(where, "ramp");
    array(*x, w);
    if (x->empty() || x->size() > 64) fail(w, "expected 1 … 64 stops [height, [r, g, b]]");
    for (size_t i = 0; i < x->size(); ++i) {
      const std::string sw = element(w, i);
      const Json& stop = (*x)[i];
      if (!stop.is_array() || stop.size() != 2) fail(sw, "expected [height, [r, g, b]]");
      TerrainColorStop c;
      c.height = number(stop[0], element(sw, 0));
      const Vec4 col = color(stop[1], element(sw, 1), false);
      c.color = {col.x, col.y, col.z};
      if (!t.ramp.empty() && !(c.height > t.ramp.back().height))
        fail(sw, "heights must increase from stop to stop");
      t.ramp.push_back(c);
    }
  }
  scene_.terrains.push_back(std::move(t));
}

// The table: "heights" (a file, or an array of files: a mosaic) or "generate" (a fractal).
std::shared_ptr<terrain::Ground> SceneReader::readHeights(const Json& v,
                                                          const std::string& where) {
  const Json* heights = find(v, "heights");
  const Json* generate = find(v, "generate");
  if (!heights == !generate)
    fail(where, "give either 'heights' (a file or a list of tiles) or 'generate' (a fractal)");
  if (!context_.options.followReferences && heights)
    fail(member(where, "heights"), "referenced files are not read here");
  const auto start = std::chrono::steady_clock::now();
  Result<terrain::HeightField> field = Error{};
  if (generate) {
    const std::string w = member(where, "generate");
    expectKeys(*generate, w, {"size", "spacing", "relief", "seed"});
    int size = 1025;
    double spacing = 10, relief = 800;
    uint32_t seed = 1;
    if (const Json* x = find(*generate, "size"))
      size = int(integer(*x, member(w, "size"), 2, terrain::kMaxSide));
    if (const Json* x = find(*generate, "spacing")) spacing = inRange(*x, member(w, "spacing"), 1e-3f, 1e5f);
    if (const Json* x = find(*generate, "relief")) relief = inRange(*x, member(w, "relief"), 1e-3f, 1e5f);
    if (const Json* x = find(*generate, "seed"))
      seed = uint32_t(integer(*x, member(w, "seed"), 0, 0xffffffffll));
    // Each generated sample is a texel's worth of memory against the scene's budget.
    if (uint64_t(size) * uint64_t(size) > context_.options.maxTexels)
      fail(member(w, "size"), fmt::format("{0} × {0} heights exceed the scene's budget", size));
    field = terrain::generateFractal(size, spacing, relief, seed);
    if (!field) fail(w, field.error().str());
  } else {
    const std::string w = member(where, "heights");
    terrain::PngPlacement png;
    if (const Json* x = find(v, "png")) {
      const std::string pw = member(where, "png");
      expectKeys(*x, pw, {"spacing", "origin", "offset", "scale"});
      if (const Json* s = find(*x, "spacing")) {
        const auto k = s->is_number() ? std::array<float, 2>{number(*s, member(pw, "spacing")),
                                                              number(*s, member(pw, "spacing"))}
                                      : numbers<2>(*s, member(pw, "spacing"));
        if (!(k[0] > 0 && k[1] > 0)) fail(member(pw, "spacing"), "spacing must be positive");
        png.spacingU = k[0], png.spacingV = k[1];
      }
      if (const Json* s = find(*x, "origin")) {
        const auto o = doubles<2>(*s, member(pw, "origin"));
        png.originU = o[0], png.originV = o[1];
      }
      if (const Json* s = find(*x, "offset")) png.offset = number(*s, member(pw, "offset"));
      if (const Json* s = find(*x, "scale")) png.scale = positive(*s, member(pw, "scale"));
    }
    std::vector<std::string> files;
    if (heights->is_array()) {
      if (heights->empty() || heights->size() > 256) fail(w, "expected 1 … 256 tiles");
      for (size_t i = 0; i < heights->size(); ++i)
        files.push_back(string((*heights)[i], element(w, i)));
    } else {
      files.push_back(string(*heights, w));
    }
    std::vector<terrain::HeightField> tiles;
    for (size_t i = 0; i < files.size(); ++i) {
      Result<terrain::HeightField> tile =
          terrain::loadHeights(resolvePath(directoryOf(path_), files[i]), png);
      if (!tile) fail(heights->is_array() ? element(w, i) : w, tile.error().str());
      tiles.push_back(std::move(tile.value()));
    }
    field = tiles.size() == 1 ? Result<terrain::HeightField>(std::move(tiles[0]))
                              : terrain::mosaic(tiles);
    if (!field) fail(w, field.error().str());
  }
  // Vertical exaggeration, for low ground (a coastal plain's 90 m over 10 km shows little relief).
  if (const Json* x = find(v, "verticalScale")) {
    const double k = inRange(*x, member(where, "verticalScale"), 1e-3f, 1e3f);
    field->scale *= k;
    field->offset *= k;
  }
  auto ground = std::make_shared<terrain::Ground>(std::move(field.value()));
  ground->loadMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return ground;
}

// A texture by name or index.
int SceneReader::textureRef(const Json& x, const std::string& w) const {
  if (x.is_string()) {
    auto it = textureByName_.find(x.get<std::string>());
    if (it == textureByName_.end()) fail(w, fmt::format("no texture named '{}'", x.get<std::string>()));
    return it->second;
  }
  if (scene_.textures.empty()) fail(w, "there are no textures to refer to");
  return int(integer(x, w, 0, int64_t(scene_.textures.size()) - 1));
}

Camera SceneReader::readCamera(const Json& v, const std::string& where) const {
  expectKeys(v, where, {"name", "position", "target", "up", "yfov", "near", "far"});
  Camera c;
  if (const Json* x = find(v, "name")) c.name = string(*x, member(where, "name"));
  if (const Json* x = find(v, "position")) c.position = vec3(*x, member(where, "position"));
  if (const Json* x = find(v, "target")) c.target = vec3(*x, member(where, "target"));
  if (const Json* x = find(v, "up")) c.up = nonZeroVec3(*x, member(where, "up"));
  if (const Json* x = find(v, "yfov")) {
    c.yfovDegrees = number(*x, member(where, "yfov"));
    if (!(c.yfovDegrees > 0 && c.yfovDegrees < 180))
      fail(member(where, "yfov"), fmt::format("{} is out of range (0, 180) degrees", x->dump()));
  }
  if (const Json* x = find(v, "near")) c.znear = positive(*x, member(where, "near"));
  if (const Json* x = find(v, "far")) c.zfar = number(*x, member(where, "far"));
  if (!(c.zfar > c.znear))
    fail(where, fmt::format("far ({}) must be greater than near ({})", c.zfar, c.znear));
  Vec3 view = c.target - c.position;
  if (!(length(view) > 0)) fail(where, "position and target must differ");
  if (!(length(cross(view, c.up)) > 0))
    fail(where, "up must not be parallel to the view direction");
  return c;
}

// "channels" (docs/scene-format.md, "Channels"; SPEC §9): a list of channels, or an arc of
// abutting ones (scene::arcChannels).
std::vector<Channel> SceneReader::readChannels(const Json& v, const std::string& where) const {
  if (v.is_object()) {
    expectKeys(v, where, {"arc", "count", "width", "height", "vfov"});
    for (const char* key : {"arc", "count", "width", "height"})
      if (!find(v, key)) fail(where, fmt::format("missing key '{}'", key));
    const int n = int(integer(*find(v, "count"), member(where, "count"), 1, kMaxChannels));
    const float arc = number(*find(v, "arc"), member(where, "arc"));
    if (!(arc > 0 && arc < 180.0f * float(n)))
      fail(
          member(where, "arc"),
          fmt::format("{} is out of range (0, {}) degrees (each channel under 180)", arc, 180 * n));
    const int w = int(integer(*find(v, "width"), member(where, "width"), 1, 8192));
    const int h = int(integer(*find(v, "height"), member(where, "height"), 1, 8192));
    float vfov = 0;
    if (const Json* x = find(v, "vfov")) {
      vfov = number(*x, member(where, "vfov"));
      if (!(vfov > 0 && vfov < 180))
        fail(member(where, "vfov"), fmt::format("{} is out of range (0, 180) degrees", x->dump()));
    }
    return arcChannels(n, arc, w, h, vfov);
  }
  array(v, where);
  if (v.size() > kMaxChannels)
    fail(where, fmt::format("{} channels is more than the {} supported", v.size(), kMaxChannels));
  std::vector<Channel> out;
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string w = element(where, i);
    expectKeys(v[i], w, {"name", "yaw", "pitch", "roll", "offset", "frustum", "width", "height"});
    Channel c;
    if (const Json* x = find(v[i], "name")) {
      c.name = string(*x, member(w, "name"));
      if (!detail::isChannelName(c.name))
        fail(member(w, "name"), "use 1 … 64 letters, digits, '-' or '_' (it names an image file)");
      for (const Channel& other : out)
        if (other.name == c.name)
          fail(member(w, "name"), fmt::format("duplicate channel name '{}'", c.name));
    }
    if (const Json* x = find(v[i], "yaw")) c.yawDegrees = inRange(*x, member(w, "yaw"), -180, 180);
    if (const Json* x = find(v[i], "pitch"))
      c.pitchDegrees = inRange(*x, member(w, "pitch"), -90, 90);
    if (const Json* x = find(v[i], "roll"))
      c.rollDegrees = inRange(*x, member(w, "roll"), -180, 180);
    if (const Json* x = find(v[i], "offset")) c.offset = vec3(*x, member(w, "offset"));
    if (const Json* x = find(v[i], "frustum")) {
      const std::string fw = member(w, "frustum");
      expectKeys(*x, fw, {"left", "right", "down", "up"});
      float a[4];
      const char* keys[4] = {"left", "right", "down", "up"};
      for (int k = 0; k < 4; ++k) {
        const Json* y = find(*x, keys[k]);
        if (!y) fail(fw, fmt::format("missing key '{}'", keys[k]));
        a[k] = number(*y, member(fw, keys[k]));
        if (!(a[k] > -90 && a[k] < 90))
          fail(member(fw, keys[k]), fmt::format("{} is out of range (-90, 90) degrees", y->dump()));
      }
      if (!(a[0] < a[1]))
        fail(fw, fmt::format("left ({}) must be less than right ({})", a[0], a[1]));
      if (!(a[2] < a[3])) fail(fw, fmt::format("down ({}) must be less than up ({})", a[2], a[3]));
      c.frustum = ChannelFrustum{a[0], a[1], a[2], a[3]};
    }
    for (const char* key : {"width", "height"})
      if (!find(v[i], key)) fail(w, fmt::format("missing key '{}'", key));
    c.width = int(integer(*find(v[i], "width"), member(w, "width"), 1, 8192));
    c.height = int(integer(*find(v[i], "height"), member(w, "height"), 1, 8192));
    out.push_back(c);
  }
  return out;
}

// Light colours may exceed 1 (a brighter light); they may not be negative.
Vec3 lightColor(const Json& v, const std::string& where) {
  Vec3 c = vec3(v, where);
  if (c.x < 0 || c.y < 0 || c.z < 0) fail(where, "components must not be negative");
  return c;
}

void SceneReader::readLight(const Json& v, const std::string& where) {
  expectKeys(v, where, {"direction", "color", "ambient", "enabled"});
  Light& light = scene_.light;
  if (const Json* x = find(v, "direction"))
    light.direction = normalize(nonZeroVec3(*x, member(where, "direction")));
  if (const Json* x = find(v, "color")) light.color = lightColor(*x, member(where, "color"));
  if (const Json* x = find(v, "ambient"))
    light.ambient = inRange(*x, member(where, "ambient"), 0, 1);
  if (const Json* x = find(v, "enabled")) light.enabled = boolean(*x, member(where, "enabled"));
}

void SceneReader::readPointLights(const Json& v, const std::string& where) {
  array(v, where);
  constexpr size_t kMaxPointLights = 64;  // each costs every Phong pixel a term
  if (v.size() > kMaxPointLights)
    fail(where,
         fmt::format("{} point lights is more than the {} supported", v.size(), kMaxPointLights));
  for (size_t i = 0; i < v.size(); ++i) {
    std::string w = element(where, i);
    expectKeys(v[i], w, {"position", "color"});
    PointLight light;
    if (const Json* x = find(v[i], "position"))
      light.position = vec3(*x, member(w, "position"));
    else
      fail(w, "missing key 'position'");
    if (const Json* x = find(v[i], "color")) light.color = lightColor(*x, member(w, "color"));
    scene_.pointLights.push_back(light);
  }
}

void SceneReader::readFog(const Json& v, const std::string& where) {
  expectKeys(v, where, {"color", "beta", "enabled"});
  Fog& fog = scene_.fog;
  fog.enabled = true;
  if (const Json* x = find(v, "color")) {
    Vec4 c = color(*x, member(where, "color"), false);
    fog.color = {c.x, c.y, c.z};
  }
  if (const Json* x = find(v, "beta")) fog.beta = inRange(*x, member(where, "beta"), 0, 1e6f);
  if (const Json* x = find(v, "enabled")) fog.enabled = boolean(*x, member(where, "enabled"));
}

// At most this many light appearances and groups in a scene (and synthvis/light_points.h's
// kMaxLightPoints lights).
constexpr size_t kMaxLightAppearances = 65536, kMaxLightGroups = 4096;

// "lines" (docs/scene-format.md, "Lines"): {"width", "depthBias", "polylines": [{"points",
// "color", "closed"}]}, in world coordinates.
void SceneReader::readLines(const Json& v, const std::string& where) {
  expectKeys(v, where, {"width", "depthBias", "polylines"});
  LineSettings& l = scene_.lineSettings;
  if (const Json* x = find(v, "width")) l.width = inRange(*x, member(where, "width"), 1.0f / 64, 64);
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

void SceneReader::readVolumes(const Json& v, const std::string& where) {
  expectKeys(v, where, {"step", "termination", "skipEmpty", "precomputedNormals", "objects"});
  VolumeSettings& settings = scene_.volumeSettings;
  if (const Json* x = find(v, "step")) settings.step = inRange(*x, member(where, "step"), 0.05f, 8);
  if (const Json* x = find(v, "termination"))
    settings.termination = inRange(*x, member(where, "termination"), 0, 0.5f);
  if (const Json* x = find(v, "skipEmpty")) settings.skipEmpty = boolean(*x, member(where, "skipEmpty"));
  if (const Json* x = find(v, "precomputedNormals"))
    settings.precomputedNormals = boolean(*x, member(where, "precomputedNormals"));
  const Json* objects = find(v, "objects");
  if (!objects) return;
  const std::string w = member(where, "objects");
  array(*objects, w);
  if (objects->size() > 64) fail(w, fmt::format("{} volumes (at most 64)", objects->size()));
  for (size_t i = 0; i < objects->size(); ++i) {
    const Json& o = (*objects)[i];
    const std::string wo = element(w, i);
    expectKeys(o, wo, {"name", "file", "generate", "transform", "transfer", "opacityUnit", "shaded",
                       "shell"});
    VolumeObject vo;
    if (const Json* x = find(o, "name")) vo.name = string(*x, member(wo, "name"));
    const Json* file = find(o, "file");
    const Json* generate = find(o, "generate");
    if (bool(file) == bool(generate)) fail(wo, "needs one of 'file' and 'generate'");
    if (file) {
      const std::string ref = string(*file, member(wo, "file"));
      if (!context_.options.followReferences)
        fail(member(wo, "file"), fmt::format("'{}' is not opened here", ref));
      Result<VolumeGrid> grid = loadVolume(resolvePath(directoryOf(path_), ref));
      if (!grid) fail(member(wo, "file"), grid.error().str());
      vo.grid = std::make_shared<VolumeGrid>(std::move(grid.value()));
      if (vo.name.empty()) vo.name = ref;
    } else {
      const std::string wg = member(wo, "generate");
      expectKeys(*generate, wg, {"kind", "size", "bits", "seed", "cover"});
      const Json* kind = find(*generate, "kind");
      if (!kind) fail(wg, "missing key 'kind'");
      const std::string k = string(*kind, member(wg, "kind"));
      const Json* size = find(*generate, "size");
      if (k == "marschner-lobb") {
        const int n = size ? int(integer(*size, member(wg, "size"), 2, 512)) : 41;
        int bits = 8;
        if (const Json* b = find(*generate, "bits")) {
          bits = int(integer(*b, member(wg, "bits"), 8, 16));
          if (bits != 8 && bits != 16) fail(member(wg, "bits"), "must be 8 or 16");
        }
        vo.grid = std::make_shared<VolumeGrid>(marschnerLobbGrid(n, bits));
      } else if (k == "cloud") {
        const int n = size ? int(integer(*size, member(wg, "size"), 8, 512)) : 128;
        const uint64_t seed = find(*generate, "seed")
                                  ? uint64_t(integer(*find(*generate, "seed"), member(wg, "seed"), 0, int64_t(1) << 53))
                                  : 1;
        const float cover = find(*generate, "cover")
                                ? inRange(*find(*generate, "cover"), member(wg, "cover"), 0, 0.95f)
                                : 0.55f;
        vo.grid = std::make_shared<VolumeGrid>(cloudGrid(n, seed, cover));
      } else {
        fail(member(wg, "kind"), fmt::format("unknown volume generator '{}' (marschner-lobb or cloud)", k));
      }
      if (vo.name.empty()) vo.name = k;
    }
    if (const Json* x = find(o, "transform")) vo.transform = readTransform(*x, member(wo, "transform"));
    const Json* transfer = find(o, "transfer");
    if (!transfer) fail(wo, "missing key 'transfer'");
    const std::string wt = member(wo, "transfer");
    array(*transfer, wt);
    if (transfer->empty() || transfer->size() > 256)
      fail(wt, fmt::format("{} points (1 … 256)", transfer->size()));
    for (size_t k = 0; k < transfer->size(); ++k) {
      const Json& t = (*transfer)[k];
      const std::string wk = element(wt, k);
      expectKeys(t, wk, {"value", "color", "opacity"});
      TransferPoint point;
      const Json* value = find(t, "value");
      if (!value) fail(wk, "missing key 'value'");
      point.value = number(*value, member(wk, "value"));
      if (k > 0 && !(point.value > vo.transfer.back().value))
        fail(member(wk, "value"), "values must increase from point to point");
      if (const Json* x = find(t, "color")) {
        const Vec4 c = color(*x, member(wk, "color"), false);
        point.color = {c.x, c.y, c.z};
      }
      if (const Json* x = find(t, "opacity")) point.opacity = inRange(*x, member(wk, "opacity"), 0, 1);
      vo.transfer.push_back(point);
    }
    if (const Json* x = find(o, "opacityUnit"))
      vo.opacityUnit = inRange(*x, member(wo, "opacityUnit"), 0, 1e30f);
    if (const Json* x = find(o, "shaded")) vo.shaded = boolean(*x, member(wo, "shaded"));
    if (const Json* x = find(o, "shell")) {
      // A free form's quadric with its clips, in the volume's own space; no perturbations.
      int quadrics = 0;
      const FreeFormNode shell = readFreeForm(*x, member(wo, "shell"), 0, quadrics, true);
      if (!shell.perturbations.empty())
        fail(member(wo, "shell"), "a shell is a quadric with clips, not perturbed");
      if (shell.clips.size() > 15) fail(member(wo, "shell"), "at most 15 clips");
      vo.shell.push_back(shell.quadric);
      vo.shell.insert(vo.shell.end(), shell.clips.begin(), shell.clips.end());
    }
    scene_.volumes.push_back(std::move(vo));
  }
}

// "lights" (docs/scene-format.md, "Light points").
void SceneReader::readLights(const Json& v, const std::string& where) {
  expectKeys(v, where, {"settings", "appearances", "groups", "points", "strings", "arrays", "stars"});
  if (const Json* x = find(v, "settings")) {
    const std::string w = member(where, "settings");
    expectKeys(*x, w, {"exposure", "minSize", "maxSize", "punchThrough", "depthBias"});
    LightSettings& l = scene_.lightSettings;
    if (const Json* y = find(*x, "exposure")) l.exposure = inRange(*y, member(w, "exposure"), 0, 1e12f);
    if (const Json* y = find(*x, "minSize")) l.minSize = inRange(*y, member(w, "minSize"), 0.5f, 64);
    if (const Json* y = find(*x, "maxSize")) l.maxSize = inRange(*y, member(w, "maxSize"), 0.5f, 64);
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
      (find(v, "points") || find(v, "strings") || find(v, "arrays")))
  {
    LightAppearance a;
    a.name = "default";
    scene_.lightAppearances.push_back(a);
  }
  readLightItems(v, where, appearances, groups);
  if (const Json* x = find(v, "stars")) {
    const std::string w = member(where, "stars");
    expectKeys(*x, w, {"catalog", "latitude", "siderealTime", "brightness", "limit"});
    StarField& f = scene_.stars;
    if (const Json* y = find(*x, "latitude")) f.latitude = inRange(*y, member(w, "latitude"), -90, 90);
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
  expectKeys(v, w, {"name", "color", "intensity", "direction", "lobe", "falloff", "back", "split",
                    "blink", "rotation"});
  LightAppearance a;
  if (const Json* x = find(v, "name")) a.name = string(*x, member(w, "name"));
  if (const Json* x = find(v, "color")) a.color = lightColor(*x, member(w, "color"));
  if (const Json* x = find(v, "intensity")) a.intensity = inRange(*x, member(w, "intensity"), 0, 1e9f);
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
    if (const Json* y = find(*x, "period")) a.blink.period = inRange(*y, member(wb, "period"), 0, 1e6f);
    if (const Json* y = find(*x, "phase")) a.blink.phase = inRange(*y, member(wb, "phase"), -1e6f, 1e6f);
    if (const Json* y = find(*x, "on")) a.blink.onFraction = inRange(*y, member(wb, "on"), 0, 1);
  }
  if (const Json* x = find(v, "rotation")) {
    a.rotationPeriod = positive(*x, member(w, "rotation"));
    if (!a.directional) fail(w, "'rotation' needs a 'direction' (the beacon's lobe)");
  }
  return a;
}

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
      expectKeys(item, wi, {"start", "end", "count", "spacing", "sequence", "appearance", "group",
                            "phase"});
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
          fail(member(wi, "spacing"), fmt::format("{} m over {} m is more than {} lights", sp,
                                                  len, kMaxLightPoints));
        n = int64_t(lights);
        step = len > 0 ? d * (sp / len) : Vec3{};
      }
      const bool sequence = find(item, "sequence") && boolean(*find(item, "sequence"),
                                                              member(wi, "sequence"));
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
      if (!origin || !u || !vv || !counts_) fail(wi, "an array needs 'origin', 'u', 'v' and 'counts'");
      const Vec3 o = vec3(*origin, member(wi, "origin")), du = vec3(*u, member(wi, "u")),
                 dv = vec3(*vv, member(wi, "v"));
      const std::array<int, 2> n = counts(*counts_, member(wi, "counts"), 1, 1 << 16);
      if (uint64_t(n[0]) * uint64_t(n[1]) > kMaxLightPoints)
        fail(member(wi, "counts"), fmt::format("{} × {} is more than {} lights", n[0], n[1],
                                               kMaxLightPoints));
      for (int j = 0; j < n[1]; ++j)
        for (int k = 0; k < n[0]; ++k) {
          LightPoint p = common;
          p.position = o + du * float(k) + dv * float(j);
          addLight(p, wi);
        }
    }
  }
}

void SceneReader::readColorTable(const Json& v, const std::string& where) {
  array(v, where);
  if (v.size() > 256)
    fail(where, fmt::format("{} entries is more than 256 (an 8-bit code)", v.size()));
  for (size_t i = 0; i < v.size(); ++i) {
    Vec4 c = color(v[i], element(where, i), false);
    colorTable_.push_back({c.x, c.y, c.z});
  }
}

texture::Wrap wrapMode(const Json& v, const std::string& where) {
  const std::string name = string(v, where);
  if (name == "repeat") return texture::Wrap::repeat;
  if (name == "clamp") return texture::Wrap::clamp;
  if (name == "mirror") return texture::Wrap::mirror;
  fail(where, fmt::format("unknown wrap mode '{}' (repeat, clamp or mirror)", name));
}

void SceneReader::readTextures(const Json& v, const std::string& where) {
  array(v, where);
  for (size_t i = 0; i < v.size(); ++i) {
    std::string w = element(where, i);
    expectKeys(v[i], w, {"name", "file", "generate", "size", "colors", "seed", "wrap"});
    TextureMap map;
    if (const Json* x = find(v[i], "name")) map.name = string(*x, member(w, "name"));
    const Json* file = find(v[i], "file");
    const Json* generate = find(v[i], "generate");
    if (!file == !generate) fail(w, "give either 'file' (a PNG) or 'generate' (a pattern)");
    texture::Wrap wrap[2] = {texture::Wrap::repeat, texture::Wrap::repeat};
    if (const Json* x = find(v[i], "wrap")) {
      std::string ww = member(w, "wrap");
      if (x->is_array()) {
        if (x->size() != 2) fail(ww, "expected a wrap mode or an array of 2 ([u, v])");
        for (size_t a = 0; a < 2; ++a) wrap[a] = wrapMode((*x)[a], element(ww, a));
      } else {
        wrap[0] = wrap[1] = wrapMode(*x, ww);
      }
    }
    texture::Level level;
    // The texel budget (LoadOptions::maxTexels), before anything is decoded or generated.
    auto charge = [&](uint64_t texels) {
      texels_ += texels;
      if (texels_ > context_.options.maxTexels)
        fail(w, fmt::format("the scene's textures exceed {} texels", context_.options.maxTexels));
    };
    if (file) {
      for (const char* key : {"size", "colors", "seed"})
        if (find(v[i], key)) fail(member(w, key), "only for generated textures");
      const std::string ref = string(*file, member(w, "file"));
      if (!context_.options.followReferences)
        fail(member(w, "file"),
             fmt::format("cannot open '{}' (references to other files are disabled)", ref));
      Result<texture::Level> read = texture::readTextureImage(resolvePath(directoryOf(path_), ref));
      if (!read) fail(member(w, "file"), read.error().str());
      level = std::move(read.value());
      charge(uint64_t(level.width) * uint64_t(level.height));
      if (map.name.empty()) map.name = ref;
    } else {
      const std::string gw = member(w, "generate");
      const std::string pattern = string(*generate, gw);
      texture::Pattern p;
      if (pattern == "noise")
        p = texture::Pattern::noise;
      else if (pattern == "squares")
        p = texture::Pattern::squares;
      else if (pattern == "checker")
        p = texture::Pattern::checker;
      else
        fail(gw, fmt::format("unknown pattern '{}' (noise, squares or checker)", pattern));
      int size = 256;
      if (const Json* x = find(v[i], "size"))
        size = int(integer(*x, member(w, "size"), 1, texture::kMaxGeneratedSide));
      charge(uint64_t(size) * uint64_t(size));
      texture::Color4 c[2] = {{0, 0, 0, 1}, {1, 1, 1, 1}};
      if (const Json* x = find(v[i], "colors")) {
        std::string cw = member(w, "colors");
        if (!x->is_array() || x->size() != 2) fail(cw, "expected an array of 2 colours");
        for (size_t k = 0; k < 2; ++k) {
          Vec4 col = color((*x)[k], element(cw, k), false);
          c[k] = {col.x, col.y, col.z, 1};
        }
      }
      uint32_t seed = 1;
      if (const Json* x = find(v[i], "seed"))
        seed = uint32_t(integer(*x, member(w, "seed"), 0, 0xFFFFFFFF));
      level = texture::generateTexture(p, size, c[0], c[1], seed);
      if (map.name.empty()) map.name = pattern;
    }
    map.texture = std::make_shared<texture::Texture>(std::move(level), wrap[0], wrap[1]);
    if (find(v[i], "name"))
      if (!textureByName_.emplace(map.name, int(i)).second)
        fail(member(w, "name"), fmt::format("duplicate texture name '{}'", map.name));
    scene_.textures.push_back(std::move(map));
  }
}

void SceneReader::readMaterials(const Json& v, const std::string& where) {
  array(v, where);
  for (size_t i = 0; i < v.size(); ++i) {
    std::string w = element(where, i);
    expectKeys(v[i], w,
               {"name", "color", "colorCode", "doubleSided", "unlit", "texture", "textureFilter",
                "textureScale", "phong", "specular", "shininess", "opacity", "alphaCutoff"});
    Material m;
    if (const Json* x = find(v[i], "name")) {
      m.name = string(*x, member(w, "name"));
      if (!m.name.empty() && !materialByName_.emplace(m.name, int(i)).second)
        fail(member(w, "name"), fmt::format("duplicate material name '{}'", m.name));
    }
    if (const Json* x = find(v[i], "color")) m.baseColor = color(*x, member(w, "color"), true);
    if (const Json* x = find(v[i], "colorCode")) {
      // SPEC §8 (seed 002): an 8-bit code selects an R:G:B ratio from the table; intensity (the
      // light) multiplies it as it multiplies any base colour.
      std::string cw = member(w, "colorCode");
      if (find(v[i], "color")) fail(cw, "give either 'color' or 'colorCode', not both");
      if (colorTable_.empty()) fail(cw, "the scene has no 'colorTable'");
      const Vec3 c = colorTable_[size_t(integer(*x, cw, 0, int64_t(colorTable_.size()) - 1))];
      m.baseColor = {c.x, c.y, c.z, 1};
    }
    if (const Json* x = find(v[i], "doubleSided"))
      m.doubleSided = boolean(*x, member(w, "doubleSided"));
    if (const Json* x = find(v[i], "unlit")) m.unlit = boolean(*x, member(w, "unlit"));
    if (const Json* x = find(v[i], "texture")) {
      std::string tw = member(w, "texture");
      if (x->is_string()) {
        auto it = textureByName_.find(x->get<std::string>());
        if (it == textureByName_.end())
          fail(tw, fmt::format("no texture named '{}'", x->get<std::string>()));
        m.texture = it->second;
      } else {
        if (scene_.textures.empty()) fail(tw, "there are no textures to refer to");
        m.texture = int(integer(*x, tw, 0, int64_t(scene_.textures.size()) - 1));
      }
    }
    if (const Json* x = find(v[i], "textureFilter")) {
      Result<TextureFilter> f = parseTextureFilter(string(*x, member(w, "textureFilter")));
      if (!f) fail(member(w, "textureFilter"), f.error().message);
      m.textureFilter = f.value();
    }
    if (const Json* x = find(v[i], "textureScale")) {
      const std::string sw = member(w, "textureScale");
      const auto k = x->is_number() ? std::array<float, 2>{number(*x, sw), number(*x, sw)}
                                    : numbers<2>(*x, sw);
      m.uvScale = {k[0], k[1]};
    }
    if (const Json* x = find(v[i], "phong")) m.phong = boolean(*x, member(w, "phong"));
    if (const Json* x = find(v[i], "specular"))
      m.specular = inRange(*x, member(w, "specular"), 0, 1e6f);
    if (const Json* x = find(v[i], "shininess"))
      m.shininess = inRange(*x, member(w, "shininess"), 0, 1e6f);
    if (const Json* x = find(v[i], "opacity")) {
      m.baseColor.w = inRange(*x, member(w, "opacity"), 0, 1);
      m.alphaMode = AlphaMode::blend;
    }
    if (const Json* x = find(v[i], "alphaCutoff")) {
      if (find(v[i], "opacity"))
        fail(member(w, "alphaCutoff"), "give either 'opacity' or 'alphaCutoff'");
      m.alphaCutoff = inRange(*x, member(w, "alphaCutoff"), 0, 1);
      m.alphaMode = AlphaMode::mask;
    }
    scene_.materials.push_back(std::move(m));
  }
}

int SceneReader::readObjectMaterial(const Json& object, const std::string& where) {
  int material = -1;
  if (const Json* x = find(object, "material")) {
    std::string w = member(where, "material");
    if (x->is_string()) {
      std::string name = x->get<std::string>();
      auto it = materialByName_.find(name);
      if (it == materialByName_.end()) {
        std::string hint;
        for (const auto& [known, index] : materialByName_)
          if (editDistance(name, known) <= 2) hint = fmt::format(" (did you mean '{}'?)", known);
        fail(w, fmt::format("no material named '{}'{}", name, hint));
      }
      material = it->second;
    } else if (x->is_number_integer()) {
      int64_t count = int64_t(scene_.materials.size());
      if (count == 0) fail(w, "there are no materials to refer to");
      material = int(integer(*x, w, 0, count - 1));
    } else {
      fail(w, fmt::format("expected a material name or index, got {}", typeName(*x)));
    }
  }
  if (const Json* x = find(object, "color")) {
    Vec4 c = color(*x, member(where, "color"), true);
    auto key = std::make_pair(material, std::array<float, 4>{c.x, c.y, c.z, c.w});
    auto it = colorMaterials_.find(key);
    if (it != colorMaterials_.end()) return it->second;
    // A copy of the named material (or of the default one) with the colour replaced.
    Material m = material >= 0 ? scene_.materials[size_t(material)] : Material{};
    m.name = m.name.empty() ? std::string("color") : m.name + "+color";
    m.baseColor = c;
    scene_.materials.push_back(std::move(m));
    material = int(scene_.materials.size() - 1);
    colorMaterials_.emplace(key, material);
  }
  return material;
}

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
      if (!(range > from)) fail(member(ew, "to"), fmt::format("must exceed {} (ranges increase)", from));
      if (g.fade > 0 && !(range - g.fade >= from))
        fail(member(w, "fade"), fmt::format("{} is longer than level {}'s span [{}, {})", g.fade,
                                            i, from, range));
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

double SceneReader::groundHeight(double x, double z, const std::string& where) const {
  double best = std::nan("");
  for (const Terrain& t : scene_.terrains) {
    const terrain::Interpolation interp =
        t.bicubic ? terrain::Interpolation::bicubic : terrain::Interpolation::bilinear;
    const terrain::Caster c(t.ground->field, t.ground->pyramid(interp), interp,
                            terrain::Placement{t.origin[0], t.origin[1], t.baseRadius});
    const terrain::Caster::MapPoint m = c.toMap({x, 0, z});
    const double h = c.surface(m.gx, m.gy);
    if (!std::isnan(h) && !(h <= best)) best = h;
  }
  if (std::isnan(best))
    fail(where, fmt::format("no terrain under ({}, {}) to stand on", x, z));
  return best;
}

void SceneReader::readLodObject(const Json& v, const std::string& where) {
  expectKeys(v, where, {"name", "lod", "transform", "priority", "at", "onGround"});
  const Json& ref = *find(v, "lod");
  const auto group = lodGroupByName_.find(string(ref, member(where, "lod")));
  if (group == lodGroupByName_.end())
    fail(member(where, "lod"), fmt::format("no level-of-detail group '{}' in 'lodGroups'",
                                           ref.get<std::string>()));
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
    placed = placedMeshes_.emplace(std::make_pair(key, overrideKey), std::pair{meshBase, lodBase})
                 .first;
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
  appendArticulationsAndLights(scene_, file, m, instanceBase);
  for (Camera camera : file.cameras) {
    camera.position = m.transformPoint(camera.position);
    camera.target = m.transformPoint(camera.target);
    camera.up = normalize(m.transformDirection(camera.up));
    scene_.cameras.push_back(std::move(camera));
  }
}

// Keeps `key` on the open-scenes stack for the lifetime of the guard.
class OpenSceneGuard {
 public:
  OpenSceneGuard(LoadContext& context, std::string key) : context_(context) {
    context_.openScenes.push_back(std::move(key));
  }
  ~OpenSceneGuard() { context_.openScenes.pop_back(); }
  OpenSceneGuard(const OpenSceneGuard&) = delete;
  OpenSceneGuard& operator=(const OpenSceneGuard&) = delete;

 private:
  LoadContext& context_;
};

}  // namespace

Result<Scene> parseJsonSceneIn(const std::string& text, const std::string& path,
                               LoadContext& context) {
  OpenSceneGuard open(context, canonicalKey(path));
  try {
    // Step 1: text → document. Comments are allowed: scene files are written by hand.
    Json root;
    ParseGuard guard;
    try {
      root = Json::parse(
          text,
          [&guard](int depth, Json::parse_event_t event, Json& parsed) {
            return guard(depth, event, parsed);
          },
          /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const Json::parse_error& e) {
      return Error{path, lineColumn(text, e.byte), parseErrorMessage(e.what())};
    } catch (const Json::out_of_range& e) {
      // "number overflow parsing '1e999'": nlohmann gives no position, so find the literal.
      std::string what = e.what();
      size_t open1 = what.find('\''), close1 = what.rfind('\'');
      if (open1 != std::string::npos && close1 > open1) {
        std::string literal = what.substr(open1 + 1, close1 - open1 - 1);
        size_t at = text.find(literal);
        return Error{path, at == std::string::npos ? "" : lineColumn(text, at + 1),
                     fmt::format("number {} is out of range (numbers must be finite)", literal)};
      }
      return Error{path, "", parseErrorMessage(what)};
    }

    // Step 2: document → Scene.
    Scene scene = SceneReader(path, context).read(root);
    Status valid = validate(scene, path);
    if (!valid) return valid.error();
    return scene;
  } catch (const JsonProblem& p) {
    return Error{path, "", p.where.empty() ? p.message : p.where + ": " + p.message};
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  } catch (const std::exception& e) {
    // Every value is type-checked before use, so this is a bug; still an error, not a crash.
    return Error{path, "", oneLine(e.what())};
  }
}

}  // namespace detail

Result<Scene> parseJsonScene(const std::string& text, const std::string& path) {
  return parseJsonScene(text, path, LoadOptions{});
}

Result<Scene> parseJsonScene(const std::string& text, const std::string& path,
                             const LoadOptions& options) {
  try {
    detail::LoadContext context{options, {}, {}};
    return detail::parseJsonSceneIn(text, path, context);
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  }
}

Result<Scene> loadJsonScene(const std::string& path) {
  try {
    Result<std::string> text = detail::readFile(path);
    if (!text) return text.error();
    detail::LoadContext context{LoadOptions{}, {}, {}};
    return detail::parseJsonSceneIn(text.value(), path, context);
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  }
}

}  // namespace sv::scene
