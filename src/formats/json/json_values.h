// The JSON scene format's typed value readers, shared by its sections (json_*.cpp): each checks a
// value completely — type, range, finiteness — and reports the first problem with the value's
// place in the document ("objects[2].transform.translate: expected an array of 3 numbers").
//
// Inside the reader a problem is thrown as JsonProblem, which keeps each field read to one line;
// parseJsonSceneIn (json_scene.cpp) catches it, and every other exception, and returns an Error:
// nothing is thrown past the reader.
#pragma once

#include <fmt/format.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "formats/reader.h"
#include "synthvis/math.h"

namespace sv::formats::json {

// The readers' plumbing (reader.h) and the database's records, unqualified.
using namespace sv::formats::detail;  // NOLINT(google-build-using-namespace)

using Json = nlohmann::json;

// Every number must be finite and at most this large in magnitude, so that it converts to float
// and stays finite through a few products.
inline constexpr double kMaxMagnitude = 1e30;

// A problem at a place in the document; see the file comment.
struct JsonProblem {
  std::string where;  // "objects[2].transform.translate", or "" for the top level
  std::string message;
};
[[noreturn]] void fail(const std::string& where, std::string message);

// Places: "where.key", "where[i]".
std::string member(const std::string& where, std::string_view key);
std::string element(const std::string& where, size_t i);
// "an object", "an array", "a string", … for messages.
const char* typeName(const Json& v);

// Levenshtein distance, and " (did you mean 'x'?)" for the nearest of `allowed` within two edits
// (or ""): hints on misspelt keys and names.
size_t editDistance(std::string_view a, std::string_view b);
std::string suggestion(std::string_view key, std::initializer_list<std::string_view> allowed);

// The member `key` of an object, or null.
const Json* find(const Json& object, std::string_view key);
// Checks that `v` is an object whose keys are all in `allowed` (a misspelt key is an error, with
// a "did you mean" hint, not a silently ignored setting).
void expectKeys(const Json& v, const std::string& where,
                std::initializer_list<std::string_view> allowed);

// Empty when `v` is an acceptable number, else what is wrong with it.
std::string numberProblem(const Json& v);
float number(const Json& v, const std::string& where);
float positive(const Json& v, const std::string& where);  // > 0
float inRange(const Json& v, const std::string& where, float lo, float hi);
int64_t integer(const Json& v, const std::string& where, int64_t lo, int64_t hi);
bool boolean(const Json& v, const std::string& where);
std::string string(const Json& v, const std::string& where);
const Json& array(const Json& v, const std::string& where);

// An array of exactly `N` numbers in double, for map coordinates (a UTM northing needs more than
// float's 24 bits to keep centimetres), each at most 1e9 in magnitude.
template <size_t N>
std::array<double, N> doubles(const Json& v, const std::string& where) {
  if (!v.is_array() || v.size() != N)
    fail(where, fmt::format("expected an array of {} numbers, got {}", N,
                            v.is_array() ? fmt::format("{} elements", v.size()) : typeName(v)));
  std::array<double, N> out;
  for (size_t i = 0; i < N; ++i) {
    if (!v[i].is_number())
      fail(element(where, i), fmt::format("expected a number, got {}", typeName(v[i])));
    out[i] = v[i].get<double>();
    if (!std::isfinite(out[i]) || std::fabs(out[i]) > 1e9)
      fail(element(where, i),
           fmt::format("{} is out of range (at most 1e9 in magnitude)", v[i].dump()));
  }
  return out;
}

// An array of exactly `N` numbers.
template <size_t N>
std::array<float, N> numbers(const Json& v, const std::string& where) {
  if (!v.is_array() || v.size() != N)
    fail(where, fmt::format("expected an array of {} numbers, got {}", N,
                            v.is_array() ? fmt::format("{} elements", v.size()) : typeName(v)));
  std::array<float, N> out;
  for (size_t i = 0; i < N; ++i) out[i] = number(v[i], element(where, i));
  return out;
}

Vec3 vec3(const Json& v, const std::string& where);
Vec3 nonZeroVec3(const Json& v, const std::string& where);
// [r, g, b] or (when `alpha`) [r, g, b, a], each in 0..1; alpha defaults to 1.
Vec4 color(const Json& v, const std::string& where, bool alpha);

// A light's colour: may exceed 1 (a brighter light), may not be negative.
Vec3 lightColor(const Json& v, const std::string& where);

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
std::array<int, 2> counts(const Json& v, const std::string& where, int lo, int hi);

// "transform": {"matrix": [16]} or any of translate / rotate / scale, composed as T·R·S.
Mat4 readTransform(const Json& v, const std::string& where);

}  // namespace sv::formats::json
