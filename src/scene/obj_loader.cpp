// Wavefront OBJ loader on top of tinyobjloader, with .mtl materials.
// Based on: the Wavefront OBJ and MTL format descriptions (Wavefront Technologies, "Advanced
// Visualizer" manual, appendices B1 and B2), as implemented by tinyobjloader 2.0.
//
// OBJ indexes positions, normals and texture coordinates separately; a Mesh has one index per
// vertex. So each distinct (v, vn, vt) triple becomes one vertex, found again through a hash map,
// and faces are grouped into one Mesh per (shape, material). tinyobjloader does not check indices
// against the attribute arrays; every index is checked here before it is used.
#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <new>
#include <sstream>
#include <unordered_map>

#include "scene/loader_common.h"
#include "texture/texture.h"

namespace sv::scene {
namespace detail {
namespace {

// tinyobjloader triangulates an n-gon by ear clipping, which costs O(n²) or worse; it also stores
// face sizes in a byte. Faces beyond this are refused before parsing.
constexpr size_t kMaxFaceVertices = 255;

// Step 0: one pass over the text for what tinyobjloader would choke on. Returns the line and the
// problem, or an empty problem.
std::pair<size_t, std::string> objTextProblem(const std::string& text) {
  size_t line = 1;
  for (size_t start = 0; start < text.size(); ++line) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    size_t i = start;
    while (i < end && (text[i] == ' ' || text[i] == '\t')) ++i;
    if (i + 1 < end && text[i] == 'f' && (text[i + 1] == ' ' || text[i + 1] == '\t')) {
      size_t vertices = 0;
      bool inToken = false;
      for (size_t k = i + 1; k < end; ++k) {
        bool blank = text[k] == ' ' || text[k] == '\t' || text[k] == '\r';
        if (!blank && !inToken) ++vertices;
        inToken = !blank;
      }
      if (vertices > kMaxFaceVertices)
        return {line, fmt::format("a face with {} vertices (the limit is {})", vertices,
                                  kMaxFaceVertices)};
    }
    start = end + 1;
  }
  return {0, {}};
}

// Reads the .mtl libraries an OBJ names, relative to the OBJ's directory and through readFile's
// checks; with references disabled it reads nothing. A missing library is only a warning for
// tinyobjloader: faces then get the default material.
class MtlReader : public tinyobj::MaterialReader {
 public:
  MtlReader(std::string baseDir, bool followReferences)
      : baseDir_(std::move(baseDir)), followReferences_(followReferences) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* materialMap, std::string* warn,
                  std::string* err) override {
    if (!followReferences_) return false;
    Result<std::string> text = readFile(resolvePath(baseDir_, name));
    if (!text) {
      if (warn) *warn += text.error().str() + "\n";
      return false;
    }
    // tinyobjloader reads .mtl text only from a stream.
    std::istringstream in(text.value());
    tinyobj::LoadMtl(materialMap, materials, &in, warn, err);
    return true;
  }

 private:
  std::string baseDir_;
  bool followReferences_;
};

// A (position, normal, texcoord) index triple; −1 for "none".
struct Corner {
  int v, vn, vt;
  bool operator==(const Corner&) const = default;
};

struct CornerHash {
  size_t operator()(const Corner& c) const {
    // Multiplicative mixing of the three indices (Knuth's golden-ratio constant).
    uint64_t h = uint64_t(uint32_t(c.v)) * 0x9E3779B97F4A7C15ull;
    h ^= (uint64_t(uint32_t(c.vn)) + 0x7F4A7C15ull) * 0xC2B2AE3D27D4EB4Full;
    h ^= (uint64_t(uint32_t(c.vt)) + 0x165667B1ull) * 0x165667B19E3779F9ull;
    return size_t(h ^ (h >> 29));
  }
};

// "Failed parse `f' line(e.g. zero value for face index. line 12.)" → "12", so that the error
// can carry the line in the usual place.
std::string lineOf(const std::string& message) {
  size_t at = message.rfind("line ");
  if (at == std::string::npos) return {};
  size_t end = at + 5;
  while (end < message.size() && message[end] >= '0' && message[end] <= '9') ++end;
  return end > at + 5 ? message.substr(at + 5, end - at - 5) : std::string();
}

struct ObjProblem {
  std::string message;
};

[[noreturn]] void fail(std::string message) { throw ObjProblem{std::move(message)}; }

Scene convertObj(const tinyobj::attrib_t& attrib, const std::vector<tinyobj::shape_t>& shapes,
                 const std::vector<tinyobj::material_t>& materials, const LoadOptions& options,
                 const std::string& baseDir) {
  Scene scene;
  std::map<std::string, int> textureByFile;
  uint64_t texels = 0;  // LoadOptions::maxTexels
  for (const tinyobj::material_t& mtl : materials) {
    const float channels[] = {mtl.diffuse[0], mtl.diffuse[1], mtl.diffuse[2], mtl.dissolve};
    for (float c : channels)
      if (!std::isfinite(c)) fail(fmt::format("material '{}': colour is not finite", mtl.name));
    auto unit = [](float x) { return std::clamp(x, 0.0f, 1.0f); };
    Material m{
        .name = mtl.name,
        .baseColor = {unit(channels[0]), unit(channels[1]), unit(channels[2]), unit(channels[3])},
        .doubleSided = false,
        // Illumination model 0 is "colour on, ambient off": a constant colour.
        .unlit = mtl.illum == 0};
    if (mtl.dissolve < 1) m.alphaMode = AlphaMode::blend;
    // map_Kd: the diffuse colour map, a PNG relative to the OBJ's directory.
    if (!mtl.diffuse_texname.empty()) {
      auto it = textureByFile.find(mtl.diffuse_texname);
      if (it == textureByFile.end()) {
        if (!options.followReferences)
          fail(
              fmt::format("material '{}': cannot open '{}' (references to other files are "
                          "disabled)",
                          mtl.name, mtl.diffuse_texname));
        Result<texture::Level> level =
            texture::readTextureImage(resolvePath(baseDir, mtl.diffuse_texname));
        if (!level) fail(fmt::format("material '{}': {}", mtl.name, level.error().str()));
        texels += uint64_t(level->width) * uint64_t(level->height);
        if (texels > options.maxTexels)
          fail(fmt::format("material '{}': the textures exceed {} texels", mtl.name,
                           options.maxTexels));
        scene.textures.push_back(
            {mtl.diffuse_texname,
             std::make_shared<texture::Texture>(std::move(level.value()), texture::Wrap::repeat,
                                                texture::Wrap::repeat)});
        it = textureByFile.emplace(mtl.diffuse_texname, int(scene.textures.size()) - 1).first;
      }
      m.texture = it->second;
    }
    scene.materials.push_back(std::move(m));
  }

  const size_t nv = attrib.vertices.size() / 3;
  const size_t nn = attrib.normals.size() / 3;
  const size_t nt = attrib.texcoords.size() / 2;
  // Vertex colours exist only if every "v" line had them (tinyobjloader stops collecting at the
  // first one without).
  const bool hasColors = nv > 0 && attrib.colors.size() == attrib.vertices.size();
  uint64_t triangles = 0;

  for (const tinyobj::shape_t& shape : shapes) {
    const tinyobj::mesh_t& m = shape.mesh;
    if (m.num_face_vertices.size() != m.material_ids.size())
      fail(fmt::format("shape '{}': inconsistent face data", shape.name));

    // Step 1: check every corner; find which faces go to which material, and whether every corner
    // of a material group has a normal (and texcoord): a Mesh attribute is all or nothing.
    struct Group {
      std::vector<size_t> faces;  // offsets of triangles into m.indices
      bool allNormals = true, allUvs = true;
    };
    std::map<int, Group> groups;
    size_t offset = 0;
    for (size_t f = 0; f < m.num_face_vertices.size(); ++f) {
      const size_t fv = m.num_face_vertices[f];
      if (offset + fv > m.indices.size())
        fail(fmt::format("shape '{}': inconsistent face data", shape.name));
      if (fv == 3) {
        int material = m.material_ids[f];
        if (material < 0 || size_t(material) >= materials.size()) material = -1;
        Group& g = groups[material];
        for (size_t k = 0; k < 3; ++k) {
          const tinyobj::index_t& c = m.indices[offset + k];
          if (c.vertex_index < 0 || size_t(c.vertex_index) >= nv)
            fail(fmt::format("shape '{}': face {} uses vertex {}, but there are {} vertices",
                             shape.name, f + 1, c.vertex_index + 1, nv));
          if (c.normal_index >= 0 ? size_t(c.normal_index) >= nn : c.normal_index != -1)
            fail(fmt::format("shape '{}': face {} uses normal {}, but there are {} normals",
                             shape.name, f + 1, c.normal_index + 1, nn));
          if (c.texcoord_index >= 0 ? size_t(c.texcoord_index) >= nt : c.texcoord_index != -1)
            fail(fmt::format("shape '{}': face {} uses texture coordinate {}, but there are {}",
                             shape.name, f + 1, c.texcoord_index + 1, nt));
          g.allNormals &= c.normal_index >= 0;
          g.allUvs &= c.texcoord_index >= 0;
        }
        g.faces.push_back(offset);
      }
      offset += fv;  // anything but a triangle is what triangulation could not handle: skipped
    }

    // Step 2: one Mesh per group, each distinct corner one vertex.
    for (const auto& [material, g] : groups) {
      triangles += g.faces.size();
      if (triangles > options.maxTriangles)
        fail(fmt::format("the scene would have more than {} triangles", options.maxTriangles));
      Mesh mesh;
      mesh.name = groups.size() == 1 || material < 0
                      ? shape.name
                      : fmt::format("{}:{}", shape.name, materials[size_t(material)].name);
      mesh.material = material;
      std::unordered_map<Corner, uint32_t, CornerHash> vertexOf;
      vertexOf.reserve(g.faces.size() * 3);
      mesh.indices.reserve(g.faces.size() * 3);
      for (size_t faceOffset : g.faces)
        for (size_t k = 0; k < 3; ++k) {
          const tinyobj::index_t& c = m.indices[faceOffset + k];
          Corner corner{c.vertex_index, g.allNormals ? c.normal_index : -1,
                        g.allUvs ? c.texcoord_index : -1};
          auto [it, added] = vertexOf.try_emplace(corner, uint32_t(mesh.positions.size()));
          if (added) {
            const size_t v = size_t(corner.v);
            mesh.positions.push_back(
                {attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]});
            if (hasColors)
              mesh.colors.push_back({std::clamp(attrib.colors[3 * v], 0.0f, 1.0f),
                                     std::clamp(attrib.colors[3 * v + 1], 0.0f, 1.0f),
                                     std::clamp(attrib.colors[3 * v + 2], 0.0f, 1.0f), 1});
            if (corner.vn >= 0) {
              const size_t n = size_t(corner.vn);
              mesh.normals.push_back(
                  {attrib.normals[3 * n], attrib.normals[3 * n + 1], attrib.normals[3 * n + 2]});
            }
            if (corner.vt >= 0) {
              const size_t t = size_t(corner.vt);
              // OBJ's v runs up from the image's bottom row; synthvis's (glTF's) runs down.
              mesh.uvs.push_back({attrib.texcoords[2 * t], 1 - attrib.texcoords[2 * t + 1]});
            }
          }
          mesh.indices.push_back(it->second);
        }
      scene.meshes.push_back(std::move(mesh));
      scene.instances.push_back({int(scene.meshes.size() - 1), Mat4{}});
    }
  }
  return scene;
}

}  // namespace
}  // namespace detail

Result<Scene> parseObj(const std::string& text, const std::string& path,
                       const LoadOptions& options) {
  using namespace detail;
  try {
    auto [line, problem] = objTextProblem(text);
    if (!problem.empty()) return Error{path, fmt::format("{}", line), problem};

    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    MtlReader mtl(directoryOf(path), options.followReferences);
    std::istringstream in(text);
    bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &mtl,
                               /*triangulate=*/true, /*default_vcols_fallback=*/false);
    if (!ok) {
      std::string message = oneLine(err);
      return Error{path, lineOf(message),
                   fmt::format("invalid OBJ: {}", message.empty() ? "parse failed" : message)};
    }
    Scene scene = convertObj(attrib, shapes, materials, options, directoryOf(path));
    Status valid = validate(scene, path);
    if (!valid) return valid.error();
    return scene;
  } catch (const ObjProblem& p) {
    return Error{path, "", p.message};
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  } catch (const std::exception& e) {
    return Error{path, "", fmt::format("invalid OBJ: {}", oneLine(e.what()))};
  }
}

Result<Scene> loadObj(const std::string& path) {
  try {
    Result<std::string> text = detail::readFile(path);
    if (!text) return text.error();
    return parseObj(text.value(), path, LoadOptions{});
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  }
}

}  // namespace sv::scene
