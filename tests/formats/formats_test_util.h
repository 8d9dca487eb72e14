// Helpers shared by the formats' tests: temporary directories, small files, and glTF
// documents assembled in memory (so that each malformed case is built from a valid one by one
// deliberate change).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "support/expect.h"
#include "support/temp_dir.h"
#include "synthvis/formats.h"

namespace sv::formats {
// The tests build and read the database's records throughout.
using namespace sv::scene;  // NOLINT(google-build-using-namespace)
}  // namespace sv::formats

namespace sv::formats::testing {

using sv::tests::TempDir;

inline std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::string sourcePath(const std::string& relative) {
  return std::string(SV_SOURCE_DIR) + "/" + relative;
}
inline std::string dataPath(const std::string& relative) {
  return std::string(SV_TEST_DATA_DIR) + "/" + relative;
}

// Loading the data file `relative` fails with exactly "<its path>: <message>".
inline void expectLoadError(const std::string& relative, const std::string& message) {
  const std::string path = dataPath(relative);
  Result<Scene> r = loadScene(path);
  ASSERT_FALSE(r.ok()) << path;
  EXPECT_EQ(r.error().str(), path + ": " + message);
}

inline std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t chunk = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) chunk |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) chunk |= uint32_t(uint8_t(bytes[i + 2]));
    out += kAlphabet[(chunk >> 18) & 63];
    out += kAlphabet[(chunk >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(chunk >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[chunk & 63] : '=';
  }
  return out;
}

template <class T>
void appendBytes(std::string& buffer, const std::vector<T>& values) {
  buffer.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  while (buffer.size() % 4) buffer.push_back('\0');
}

// A glTF document under construction: a JSON object plus its one binary buffer.
struct GltfBuilder {
  nlohmann::json doc = {{"asset", {{"version", "2.0"}}}};
  std::string buffer;

  // Appends `values` to the buffer with a buffer view and an accessor; returns the accessor.
  template <class T>
  int addAccessor(const std::vector<T>& values, int componentType, const char* type, size_t count) {
    size_t offset = buffer.size();
    appendBytes(buffer, values);
    doc["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * sizeof(T)}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                {"componentType", componentType},
                                {"count", count},
                                {"type", type}});
    return int(doc["accessors"].size() - 1);
  }
  int addPositions(const std::vector<float>& xyz) {
    return addAccessor(xyz, 5126, "VEC3", xyz.size() / 3);
  }
  int addIndices(const std::vector<uint16_t>& indices) {
    return addAccessor(indices, 5123, "SCALAR", indices.size());
  }
  // A mesh with one primitive; returns the mesh index.
  int addMesh(nlohmann::json primitive) {
    doc["meshes"].push_back({{"primitives", nlohmann::json::array({primitive})}});
    return int(doc["meshes"].size() - 1);
  }
  int addNode(nlohmann::json node) {
    doc["nodes"].push_back(node);
    return int(doc["nodes"].size() - 1);
  }

  // .gltf text with the buffer embedded as a data URI.
  std::string gltf() const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", buffer.size()},
                     {"uri", "data:application/octet-stream;base64," + base64(buffer)}}};
    return d.dump();
  }
  // .glb bytes: header, JSON chunk, BIN chunk (spec 4.4).
  std::string glb() const {
    nlohmann::json d = doc;
    d["buffers"] = {{{"byteLength", buffer.size()}}};
    std::string json = d.dump();
    while (json.size() % 4) json.push_back(' ');
    std::string bin = buffer;
    while (bin.size() % 4) bin.push_back('\0');
    auto u32 = [](uint32_t x) { return std::string(reinterpret_cast<const char*>(&x), 4); };
    std::string out = "glTF" + u32(2) + u32(uint32_t(12 + 8 + json.size() + 8 + bin.size()));
    out += u32(uint32_t(json.size())) + u32(0x4E4F534A) + json;
    out += u32(uint32_t(bin.size())) + u32(0x004E4942) + bin;
    return out;
  }
};

// A valid model: one triangle (three vertices, indexed) under one node.
inline GltfBuilder oneTriangle() {
  GltfBuilder b;
  int positions = b.addPositions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  int indices = b.addIndices({0, 1, 2});
  int mesh = b.addMesh({{"attributes", {{"POSITION", positions}}}, {"indices", indices}});
  b.addNode({{"mesh", mesh}});
  return b;
}

using sv::tests::contains;

// Each component of `a` within `eps` of `b`'s.
inline void expectNear(Vec3 a, Vec3 b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

}  // namespace sv::formats::testing
