// The JSON scene format, version 1. Based on: docs/scene-format.md (the reference for every key,
// default and limit used here).
//
// Parsing has two steps. nlohmann::json turns the text into a document (syntax errors carry
// line:column; a parse callback limits nesting depth and rejects duplicate keys, which nlohmann
// would silently resolve to the last one). A SceneReader then walks the document, checking every
// key, type and range before using it, and reports the first problem with its place in the
// document ("objects[2].transform.translate: expected an array of 3 numbers").
//
// The walker's sections are files of their own (json_reader.h); this one holds the top level, the
// cameras, channels, light and fog, and the parse itself. A problem is thrown as JsonProblem
// (json_values.h); parseJsonSceneIn catches it, and every other exception, and returns an Error:
// nothing is thrown past the reader.
#include <fmt/format.h>

#include <algorithm>
#include <new>
#include <set>
#include <string_view>

#include "formats/json/json_reader.h"
#include "scene/channels.h"

namespace sv::formats {
namespace json {
namespace {

constexpr int kFormatVersion = 1;
// Deeper than any valid scene needs (an inline mesh is 4 levels down); guards the recursion-free
// but memory-hungry parse of "[[[[…" and keeps error paths short.
constexpr size_t kMaxJsonDepth = 64;

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
  expectKeys(root, "", {"synthvis",  "description", "background", "camera",   "cameras",
                        "light",     "pointLights", "fog",        "textures", "colorTable",
                        "materials", "lodGroups",   "objects",    "terrain",  "lights",
                        "lines",     "volumes",     "time",       "channels", "geodetic"});

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
  if (const Json* x = find(root, "geodetic")) readGeodetic(*x, "geodetic");
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
      if (!scene::detail::isChannelName(c.name))
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

}  // namespace json

namespace detail {

using json::Json;
using json::JsonProblem;
using json::lineColumn;
using json::OpenSceneGuard;
using json::parseErrorMessage;
using json::ParseGuard;

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
    Scene scene = json::SceneReader(path, context).read(root);
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

}  // namespace sv::formats
