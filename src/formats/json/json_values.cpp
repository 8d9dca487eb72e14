// The JSON scene format's typed value readers (json_values.h).
#include "formats/json/json_values.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace sv::formats::json {

void fail(const std::string& where, std::string message) {
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

Vec3 lightColor(const Json& v, const std::string& where) {
  Vec3 c = vec3(v, where);
  if (c.x < 0 || c.y < 0 || c.z < 0) fail(where, "components must not be negative");
  return c;
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

namespace {

Mat4 rotationDegrees(Vec3 axis, float degrees) {
  return Mat4::rotation(axis, static_cast<float>(degrees * std::numbers::pi / 180.0));
}

}  // namespace

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

}  // namespace sv::formats::json
