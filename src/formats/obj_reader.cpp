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
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <new>
#include <sstream>
#include <unordered_map>

#include "formats/reader.h"
#include "texture/texture.h"

namespace sv::formats {
namespace detail {
namespace {

// tinyobjloader stores face sizes in a byte: faces of more than 255 vertices are taken out of the
// text before it parses (left as blank lines, so line numbers hold) and triangulated here, up to
// this many vertices (ear clipping within a budget of 8·n² point tests: under a second).
constexpr size_t kMaxTinyobjFace = 255;
constexpr size_t kMaxFaceVertices = 8192;

// A face of more than kMaxTinyobjFace vertices, as the text gave it.
struct BigFace {
  size_t line = 0;
  std::vector<std::string> corners;  // "v", "v/vt", "v//vn" or "v/vt/vn" tokens
  std::string material;              // the `usemtl` in force
  std::string object;                // the `o` (or `g`) in force, the shape it belongs to
  size_t positions = 0, texcoords = 0, normals = 0;  // defined before it (relative indices)
};

// Step 0: one pass over the text: faces too large for tinyobjloader are moved into `big` and
// blanked; one beyond kMaxFaceVertices is an error. Returns the line and the problem, or an
// empty problem.
std::pair<size_t, std::string> takeBigFaces(std::string& text, std::vector<BigFace>& big) {
  size_t line = 1, v = 0, vt = 0, vn = 0;
  std::string material, object;
  for (size_t start = 0; start < text.size(); ++line) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    size_t i = start;
    while (i < end && (text[i] == ' ' || text[i] == '\t')) ++i;
    auto keyword = [&](const char* k) {
      const size_t n = std::strlen(k);
      return i + n < end && text.compare(i, n, k) == 0 &&
             (text[i + n] == ' ' || text[i + n] == '\t');
    };
    auto rest = [&](size_t from) {
      std::string r = text.substr(from, end - from);
      while (!r.empty() && (r.back() == '\r' || r.back() == ' ' || r.back() == '\t')) r.pop_back();
      const size_t first = r.find_first_not_of(" \t");
      return first == std::string::npos ? std::string() : r.substr(first);
    };
    if (keyword("v"))
      ++v;
    else if (keyword("vt"))
      ++vt;
    else if (keyword("vn"))
      ++vn;
    else if (keyword("usemtl"))
      material = rest(i + 6);
    else if (keyword("o") || keyword("g"))
      object = rest(i + 1);
    else if (keyword("f")) {
      std::vector<std::string> corners;
      std::istringstream tokens(text.substr(i + 1, end - i - 1));
      for (std::string t; tokens >> t;) corners.push_back(t);
      if (corners.size() > kMaxFaceVertices)
        return {line, fmt::format("a face with {} vertices (the limit is {})", corners.size(),
                                  kMaxFaceVertices)};
      if (corners.size() > kMaxTinyobjFace) {
        big.push_back({line, std::move(corners), material, object, v, vt, vn});
        std::fill(text.begin() + std::ptrdiff_t(start), text.begin() + std::ptrdiff_t(end), ' ');
      }
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

// The big faces (takeBigFaces), triangulated, as faces of the shapes they belong to (a shape of
// their object's name, added when the text left it none).
void addBigFaces(const std::vector<BigFace>& big, const tinyobj::attrib_t& attrib,
                 const std::vector<tinyobj::material_t>& materials,
                 std::vector<tinyobj::shape_t>& shapes) {
  const size_t nv = attrib.vertices.size() / 3;
  for (const BigFace& f : big) {
    std::vector<tinyobj::index_t> corners;
    std::vector<Vec3> outline;
    for (const std::string& token : f.corners) {
      // v[/vt[/vn]], 1-based or negative (relative to the elements defined before the face).
      int parts[3] = {0, 0, 0};
      bool given[3] = {false, false, false};
      size_t from = 0;
      for (int field = 0; field < 3; ++field) {
        const size_t slash = token.find('/', from);
        const std::string part =
            token.substr(from, slash == std::string::npos ? std::string::npos : slash - from);
        if (!part.empty()) {
          char* endp = nullptr;
          const long value = std::strtol(part.c_str(), &endp, 10);
          if (*endp != 0 || value == 0 || value > (1l << 30) || value < -(1l << 30))
            fail(fmt::format("line {}: invalid face corner '{}'", f.line, token));
          parts[field] = int(value);
          given[field] = true;
        }
        if (slash == std::string::npos) break;
        from = slash + 1;
      }
      if (!given[0]) fail(fmt::format("line {}: invalid face corner '{}'", f.line, token));
      auto index = [](int value, size_t defined) {
        return value > 0 ? value - 1 : int(defined) + value;
      };
      tinyobj::index_t c;
      c.vertex_index = index(parts[0], f.positions);
      c.texcoord_index = given[1] ? index(parts[1], f.texcoords) : -1;
      c.normal_index = given[2] ? index(parts[2], f.normals) : -1;
      if (c.vertex_index < 0 || size_t(c.vertex_index) >= nv)
        fail(fmt::format("line {}: face uses vertex {}, but there are {} vertices", f.line,
                         parts[0], nv));
      corners.push_back(c);
      const size_t v = size_t(c.vertex_index);
      outline.push_back(
          {attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]});
    }
    int material = -1;
    for (size_t m = 0; m < materials.size(); ++m)
      if (materials[m].name == f.material) material = int(m);
    tinyobj::shape_t* shape = nullptr;
    for (tinyobj::shape_t& s : shapes)
      if (s.name == f.object) shape = &s;
    if (!shape) {
      shapes.emplace_back();
      shapes.back().name = f.object;
      shape = &shapes.back();
    }
    const std::vector<uint32_t> triangles = triangulatePolygon(outline);
    for (size_t t = 0; t < triangles.size(); t += 3) {
      for (int k = 0; k < 3; ++k) shape->mesh.indices.push_back(corners[triangles[t + size_t(k)]]);
      shape->mesh.num_face_vertices.push_back(3);
      shape->mesh.material_ids.push_back(material);
      shape->mesh.smoothing_group_ids.push_back(0);
    }
  }
}

// OBJ says nothing of sidedness, and a model's faces are often wound either way: its materials,
// and the default one it gets where it names none, are two-sided (a single-sided default drew
// nothing of a model that faced away from the camera).
Material defaultObjMaterial() {
  Material m;
  m.name = "OBJ default";
  m.doubleSided = true;
  return m;
}

// The .mtl materials (colour, dissolve, illum 0, map_Kd), appended to `scene` in order.
void convertMaterials(const std::vector<tinyobj::material_t>& materials, const LoadOptions& options,
                      const std::string& baseDir, Scene& scene) {
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
        .doubleSided = true,  // defaultObjMaterial says why
        // Illumination model 0 is "colour on, ambient off": a constant colour.
        .unlit = mtl.illum == 0};
    if (mtl.dissolve < 1) m.alphaMode = AlphaMode::blend;
    // map_Kd: the diffuse colour map (PNG, JPEG or SGI), relative to the OBJ's directory; a path
    // written with Windows separators is read with '/' (core::resolvePath).
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
}

// The vertex data an OBJ's faces and lines index.
struct Vertices {
  const tinyobj::attrib_t& attrib;
  size_t nv, nn, nt;
  bool hasColors;  // every "v" line had one (tinyobjloader stops collecting at the first without)
  Vec3 position(size_t v) const {
    return {attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]};
  }
  Vec3 color(size_t v) const {
    return {std::clamp(attrib.colors[3 * v], 0.0f, 1.0f),
            std::clamp(attrib.colors[3 * v + 1], 0.0f, 1.0f),
            std::clamp(attrib.colors[3 * v + 2], 0.0f, 1.0f)};
  }
};

// A shape's triangles, one Mesh per material (the OBJ default where it names none), each distinct
// corner one vertex, placed once; `triangles` counts against LoadOptions::maxTriangles.
void convertFaces(const tinyobj::shape_t& shape, const Vertices& vs,
                  const std::vector<tinyobj::material_t>& materials, const LoadOptions& options,
                  uint64_t& triangles, int& defaultMaterial, Scene& scene) {
  const tinyobj::attrib_t& attrib = vs.attrib;
  const size_t nv = vs.nv, nn = vs.nn, nt = vs.nt;
  const bool hasColors = vs.hasColors;
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
    if (material < 0 && defaultMaterial < 0) {
      scene.materials.push_back(defaultObjMaterial());
      defaultMaterial = int(scene.materials.size()) - 1;
    }
    mesh.material = material >= 0 ? material : defaultMaterial;
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

// A shape's `l` elements: polylines, each consecutive pair a line segment in the vertices' colour
// (white without vertex colours; tinyobjloader keeps no material for lines).
void convertLines(const tinyobj::shape_t& shape, const Vertices& vs, Scene& scene) {
  const size_t nv = vs.nv;
  const tinyobj::lines_t& l = shape.lines;
  size_t at = 0;
  for (size_t k = 0; k < l.num_line_vertices.size(); ++k) {
    const size_t n = size_t(std::max(l.num_line_vertices[k], 0));
    if (at + n > l.indices.size())
      fail(fmt::format("shape '{}': inconsistent line data", shape.name));
    if (n >= 2 && scene.lines.size() + n - 1 > kMaxLines)
      fail(fmt::format("more than {} line segments", kMaxLines));
    for (size_t j = 0; j < n; ++j) {
      const int v = l.indices[at + j].vertex_index;
      if (v < 0 || size_t(v) >= nv)
        fail(fmt::format("shape '{}': line {} uses vertex {}, but there are {} vertices",
                         shape.name, k + 1, v + 1, nv));
    }
    auto position = [&](size_t j) { return vs.position(size_t(l.indices[at + j].vertex_index)); };
    auto color = [&](size_t j) {
      return vs.hasColors ? vs.color(size_t(l.indices[at + j].vertex_index)) : Vec3{1, 1, 1};
    };
    for (size_t j = 0; j + 1 < n; ++j)
      scene.lines.push_back({position(j), position(j + 1), (color(j) + color(j + 1)) * 0.5f});
    at += n;
  }
}

Scene convertObj(const tinyobj::attrib_t& attrib, const std::vector<tinyobj::shape_t>& shapes,
                 const std::vector<tinyobj::material_t>& materials, const LoadOptions& options,
                 const std::string& baseDir) {
  Scene scene;
  convertMaterials(materials, options, baseDir, scene);
  const Vertices vs{attrib, attrib.vertices.size() / 3, attrib.normals.size() / 3,
                    attrib.texcoords.size() / 2,
                    attrib.vertices.size() >= 3 && attrib.colors.size() == attrib.vertices.size()};
  uint64_t triangles = 0;
  size_t points = 0;
  int defaultMaterial = -1;  // made when a face needs it
  for (const tinyobj::shape_t& shape : shapes) {
    convertFaces(shape, vs, materials, options, triangles, defaultMaterial, scene);
    convertLines(shape, vs, scene);
    points += shape.points.indices.size();
  }
  // `p` elements: named, not drawn.
  if (points)
    scene.warnings.push_back(
        fmt::format("{} points (`p`) are not drawn (only faces and lines are)", points));
  return scene;
}

}  // namespace

// The polygon `outline` (indices into `p`), possibly concave, as triangles by ear clipping in the
// plane of its Newell normal, counter-clockwise about that normal as the outline is. An outline
// that leaves no ear (self-intersecting, or degenerate) is closed by a fan of what remains.
std::vector<uint32_t> triangulatePolygon(const std::vector<Vec3>& p) {
  const size_t n = p.size();
  std::vector<uint32_t> out;
  if (n < 3) return out;
  double nx = 0, ny = 0, nz = 0;  // Newell's normal
  for (size_t i = 0; i < n; ++i) {
    const Vec3 a = p[i], b = p[(i + 1) % n];
    nx += double(a.y - b.y) * double(a.z + b.z);
    ny += double(a.z - b.z) * double(a.x + b.x);
    nz += double(a.x - b.x) * double(a.y + b.y);
  }
  // Project onto the plane across the normal's largest component, keeping the winding.
  const double ax = std::fabs(nx), ay = std::fabs(ny), az = std::fabs(nz);
  const int drop = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
  const double sign = (drop == 0 ? nx : drop == 1 ? ny : nz) >= 0 ? 1 : -1;
  std::vector<std::array<double, 2>> q(n);
  for (size_t i = 0; i < n; ++i) {
    const double c[3] = {p[i].x, p[i].y, p[i].z};
    q[i] = {c[(drop + 1) % 3], c[(drop + 2) % 3]};
  }
  auto cross = [&](size_t a, size_t b, size_t c) {
    return sign *
           ((q[b][0] - q[a][0]) * (q[c][1] - q[a][1]) - (q[b][1] - q[a][1]) * (q[c][0] - q[a][0]));
  };
  std::vector<size_t> prev(n), next(n);
  for (size_t i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
  auto inside = [&](size_t a, size_t b, size_t c, size_t x) {
    return cross(a, b, x) >= 0 && cross(b, c, x) >= 0 && cross(c, a, x) >= 0;
  };
  size_t remaining = n, at = 0, misses = 0;
  // Each ear search tests up to `remaining` points; past the budget (a hostile outline) the rest
  // is closed as a fan, so the work stays O(n²).
  uint64_t budget = 8 * uint64_t(n) * uint64_t(n);
  while (remaining > 3) {
    const size_t a = prev[at], c = next[at];
    bool ear = cross(a, at, c) > 0;
    // No other remaining vertex (reflex ones are the only candidates) inside the triangle.
    for (size_t x = next[c]; ear && x != a && budget; x = next[x], --budget)
      if (cross(prev[x], x, next[x]) <= 0 && inside(a, at, c, x)) ear = false;
    if (ear || misses > remaining || !budget) {
      out.insert(out.end(), {uint32_t(a), uint32_t(at), uint32_t(c)});
      next[a] = c, prev[c] = a;
      --remaining;
      at = c;
      misses = 0;
    } else {
      at = next[at];
      ++misses;
    }
  }
  out.insert(out.end(), {uint32_t(prev[at]), uint32_t(at), uint32_t(next[at])});
  return out;
}

}  // namespace detail

Result<Scene> parseObj(const std::string& text, const std::string& path,
                       const LoadOptions& options) {
  using namespace detail;
  try {
    std::string body = text;
    std::vector<BigFace> big;
    auto [line, problem] = takeBigFaces(body, big);
    if (!problem.empty()) return Error{path, fmt::format("{}", line), problem};

    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    MtlReader mtl(directoryOf(path), options.followReferences);
    std::istringstream in(body);
    bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &mtl,
                               /*triangulate=*/true, /*default_vcols_fallback=*/false);
    if (!ok) {
      std::string message = oneLine(err);
      return Error{path, lineOf(message),
                   fmt::format("invalid OBJ: {}", message.empty() ? "parse failed" : message)};
    }
    addBigFaces(big, attrib, materials, shapes);
    Scene scene = convertObj(attrib, shapes, materials, options, directoryOf(path));
    for (std::string& w : scene.warnings) w = fmt::format("{}: {}", path, w);
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

}  // namespace sv::formats
