// glTF 2.0 loader (.gltf and .glb) on top of tinygltf.
// Based on: Khronos, glTF 2.0 Specification, sections 3.5 (nodes and hierarchy), 3.6 (binary
// data: buffers, buffer views, accessors), 3.7 (meshes), 3.9 (materials), 3.10 (cameras), 4.4 (GLB
// file format), 3.8 (textures, images, samplers); the KHR_materials_unlit extension.
//
// tinygltf parses the JSON and decodes buffers; it does not check that accessors stay inside
// their buffer views, that indices stay inside their vertex arrays, or that nodes form trees, and
// version 2.7.0 bounds the GLB BIN chunk without its 8-byte header. So this file checks the GLB
// container itself before handing it over, and afterwards checks every index and byte range
// before reading a single element.
#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string_view>
#include <tuple>
#include <utility>

#include "formats/draco_mesh.h"
#include "formats/reader.h"
#include "texture/jpeg.h"
#include "texture/texture.h"

namespace sv::formats {
namespace detail {
namespace {

// tinygltf turns "extras" and "extensions" into its own value tree recursively; bounding the
// nesting depth of the JSON first keeps hostile input from exhausting the stack.
constexpr int kMaxGltfJsonDepth = 64;

// Extensions whose presence in extensionsRequired we can honour.
constexpr const char* kSupportedRequiredExtensions[] = {"KHR_materials_unlit",
                                                        "KHR_mesh_quantization",
                                                        "KHR_texture_transform",
                                                        "EXT_mesh_gpu_instancing",
                                                        "MSFT_lod",
                                                        "KHR_draco_mesh_compression"};

// A problem in the model, reported from deep inside the conversion; caught in convertModel and
// returned as an Error. It never leaves this file.
struct GltfProblem {
  std::string message;
};

[[noreturn]] void fail(std::string message) { throw GltfProblem{std::move(message)}; }

uint32_t readU32(const std::string& bytes, size_t offset) {
  unsigned char b[4];
  std::memcpy(b, bytes.data() + offset, 4);
  return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
}

// GLB layout (spec 4.4): 12-byte header (magic, version, length), then chunks of
// (length, type, payload); the first chunk is JSON, an optional second one BIN. Returns an empty
// string when the container is sound, else the problem.
std::string glbProblem(const std::string& bytes) {
  constexpr uint32_t kJson = 0x4E4F534A, kBin = 0x004E4942;
  if (bytes.size() < 20) return "truncated GLB header";
  if (readU32(bytes, 4) != 2) return fmt::format("unsupported GLB version {}", readU32(bytes, 4));
  uint64_t length = readU32(bytes, 8);
  if (length > bytes.size())
    return fmt::format("truncated GLB: header says {} bytes, the file has {}", length,
                       bytes.size());
  uint64_t jsonLength = readU32(bytes, 12);
  if (readU32(bytes, 16) != kJson) return "the first GLB chunk is not JSON";
  uint64_t jsonEnd = 20 + jsonLength;
  if (jsonLength == 0 || jsonEnd > length)
    return "the GLB JSON chunk runs past the end of the file";
  if (jsonEnd == length) return {};
  if (jsonEnd + 8 > length) return "truncated GLB chunk header";
  uint64_t binLength = readU32(bytes, size_t(jsonEnd));
  if (readU32(bytes, size_t(jsonEnd) + 4) != kBin) return "the second GLB chunk is not BIN";
  if (jsonEnd + 8 + binLength > length) return "the GLB BIN chunk runs past the end of the file";
  if (binLength < 4 || binLength % 4 != 0) return "the GLB BIN chunk length is not a multiple of 4";
  return {};
}

// Deepest nesting of [ and { in JSON text, ignoring brackets inside strings.
bool nestingWithin(const char* text, size_t size, int limit) {
  int depth = 0;
  bool inString = false;
  for (size_t i = 0; i < size; ++i) {
    char c = text[i];
    if (inString) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return false;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return true;
}

// KHR_draco_mesh_compression lets a primitive's accessors go without a bufferView (the Draco
// bufferView holds the data), but tinygltf 2.7.0 refuses an indices accessor without one
// ("accessor[0] invalid bufferView": Khronos' own 2CylinderEngine sample). The indices of a Draco
// primitive are the decoded mesh's (convertDracoPrimitive), so such a primitive's "indices" is
// dropped from the JSON before tinygltf sees it. Returns the rewritten file (text, or a GLB with
// its JSON chunk replaced), or nothing when no primitive needs it.
std::optional<std::string> withoutDracoIndices(const std::string& bytes, bool binary,
                                               const char* json, size_t jsonSize) {
  if (std::string_view(json, jsonSize).find("KHR_draco_mesh_compression") == std::string::npos)
    return std::nullopt;
  nlohmann::json doc = nlohmann::json::parse(json, json + jsonSize, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("meshes") ||
      !doc["meshes"].is_array() || !doc.contains("accessors") || !doc["accessors"].is_array())
    return std::nullopt;  // tinygltf reports what is wrong with it
  const nlohmann::json& accessors = doc["accessors"];
  bool changed = false;
  for (nlohmann::json& mesh : doc["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array())
      continue;
    for (nlohmann::json& p : mesh["primitives"]) {
      if (!p.is_object() || !p.contains("indices") || !p["indices"].is_number_unsigned() ||
          !p.contains("extensions") || !p["extensions"].is_object() ||
          !p["extensions"].contains("KHR_draco_mesh_compression"))
        continue;
      const size_t a = p["indices"].get<size_t>();
      if (a < accessors.size() && accessors[a].is_object() && !accessors[a].contains("bufferView"))
        p.erase("indices"), changed = true;
    }
  }
  if (!changed) return std::nullopt;
  std::string text = doc.dump();
  if (!binary) return text;
  // GLB (spec 4.4): the header, the JSON chunk padded with spaces to 4 bytes, the rest as it was.
  while (text.size() % 4) text += ' ';
  const size_t rest = 20 + jsonSize;
  std::string out(20, '\0');
  const auto put = [&](size_t at, uint32_t v) { std::memcpy(out.data() + at, &v, 4); };
  std::memcpy(out.data(), "glTF", 4);
  put(4, 2);
  put(8, uint32_t(20 + text.size() + (bytes.size() - rest)));
  put(12, uint32_t(text.size()));
  put(16, 0x4E4F534A);  // JSON
  return out + text + bytes.substr(rest);
}

// --- File access for tinygltf: external buffers only, through readFile's checks. ---

// Images are read only as textures, through decodeImage below (PNG, JPEG). A missing image is only a
// warning for tinygltf; a material that uses it then fails with a message naming it.

bool fsFileExists(const std::string& path, void* followReferences) {
  if (!*static_cast<bool*>(followReferences)) return false;
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

// The default expands "~" and environment variables: not something a data file may ask for.
std::string fsExpandFilePath(const std::string& path, void*) { return path; }

bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* followReferences) {
  if (!*static_cast<bool*>(followReferences)) {
    if (err) *err += fmt::format("cannot open '{}'\n", path);
    return false;
  }
  Result<std::string> bytes = readFile(path);
  if (!bytes) {
    if (err) *err += bytes.error().str() + "\n";
    return false;
  }
  out->assign(bytes.value().begin(), bytes.value().end());
  return true;
}

bool fsWriteWholeFile(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
  return false;
}

// The decoded images, by glTF image index, filled by decodeImage as tinygltf meets them.
struct DecodedImages {
  std::map<int, texture::Level> levels;
  uint64_t texels = 0, maxTexels = 0;  // LoadOptions::maxTexels
};

// tinygltf's image callback: PNG or JPEG (texture.h's decoders and limits), into DecodedImages.
bool decodeImage(tinygltf::Image* image, const int index, std::string* err, std::string*, int, int,
                 const unsigned char* bytes, int size, void* user) {
  const std::string name =
      fmt::format("images[{}]{}", index, image->name.empty() ? "" : " ('" + image->name + "')");
  const bool png = size >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0;
  if (!png && !texture::looksLikeJpeg(bytes, size_t(std::max(size, 0)))) {
    if (err)
      *err += fmt::format("{}: only PNG and JPEG textures are supported{}\n", name,
                          image->mimeType.empty() ? "" : " (this is " + image->mimeType + ")");
    return false;
  }
  Result<texture::Level> level = texture::decodeTextureImage(bytes, size_t(size), name);
  if (!level) {
    if (err) *err += level.error().str() + "\n";
    return false;
  }
  DecodedImages& images = *static_cast<DecodedImages*>(user);
  images.texels += uint64_t(level->width) * uint64_t(level->height);
  if (images.texels > images.maxTexels) {
    if (err) *err += fmt::format("{}: the images exceed {} texels\n", name, images.maxTexels);
    return false;
  }
  images.levels[index] = std::move(level.value());
  return true;
}

// --- Accessors (spec 3.6.2). ---

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    default:
      return 0;
  }
}

// A checked window onto an accessor's elements: element i starts at data + i·stride and has
// `components` components of `componentType`, all inside the buffer.
struct AccessorView {
  const unsigned char* data = nullptr;
  size_t count = 0;
  size_t stride = 0;
  int componentType = 0;
  int components = 0;
  bool normalized = false;

  // Component c of element i as float, with the spec's normalization (3.11) when `normalized`.
  float get(size_t i, int c) const {
    const unsigned char* p = data + i * stride + size_t(c) * size_t(componentSize(componentType));
    switch (componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float x;
        std::memcpy(&x, p, 4);
        return x;
      }
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t x;
        std::memcpy(&x, p, 1);
        return normalized ? std::max(x / 127.0f, -1.0f) : float(x);
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? *p / 255.0f : float(*p);
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t x;
        std::memcpy(&x, p, 2);
        return normalized ? std::max(x / 32767.0f, -1.0f) : float(x);
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t x;
        std::memcpy(&x, p, 2);
        return normalized ? x / 65535.0f : float(x);
      }
      default:
        return 0;
    }
  }
  // Element i of a scalar unsigned integer accessor (indices).
  uint32_t index(size_t i) const {
    const unsigned char* p = data + i * stride;
    switch (componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return *p;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t x;
        std::memcpy(&x, p, 2);
        return x;
      }
      default: {
        uint32_t x;
        std::memcpy(&x, p, 4);
        return x;
      }
    }
  }
};

class GltfConverter {
 public:
  GltfConverter(const tinygltf::Model& model, const LoadOptions& options, DecodedImages& images)
      : model_(model), options_(options), images_(images) {}

  Scene convert();

 private:
  AccessorView accessor(int index, const std::string& where, std::initializer_list<int> types,
                        std::initializer_list<int> componentTypes) const;
  void convertMaterials();
  int textureFor(int gltfTexture, const std::string& where);
  const std::vector<int>& meshesOf(int gltfMesh);
  Mesh convertPrimitive(const tinygltf::Primitive& primitive, const std::string& where) const;
  // A KHR_draco_mesh_compression primitive: its bufferView decoded by libdraco.
  Mesh convertDracoPrimitive(const tinygltf::Primitive& primitive, const std::string& where) const;
  // The bytes of bufferView `index`, checked to lie inside its buffer.
  std::pair<const unsigned char*, size_t> bufferViewBytes(int index,
                                                          const std::string& where) const;
  // KHR_texture_transform of the primitive's material on its uvs.
  void transformUvs(const tinygltf::Primitive& primitive, std::vector<Vec2>& uvs) const;
  int materialOf(const tinygltf::Primitive& primitive, const std::string& where) const;
  Mat4 localMatrix(const tinygltf::Node& node, const std::string& where) const;
  // EXT_mesh_gpu_instancing: the node's instances' transforms (T·R·S each), or none.
  std::vector<Mat4> gpuInstances(const tinygltf::Node& node, const std::string& where) const;
  // KHR_texture_transform on material `material`'s base colour texture, as u' = a·u + b·v + c,
  // v' = d·u + e·v + f; absent for none.
  struct UvTransform {
    float a = 1, b = 0, c = 0, d = 0, e = 1, f = 0;
  };
  std::map<int, UvTransform> uvTransforms_;
  // POINTS and LINE* primitives by glTF mesh: where a node places them, a points mesh's vertices
  // become light points, a lines mesh's index pairs line segments.
  struct Aside {
    Mesh mesh;
    bool lines = false;
  };
  std::map<int, std::vector<Aside>> asideMeshes_;
  std::map<std::array<float, 3>, uint32_t> pointLooks_;  // light appearance by colour
  void placeAside(int gltfMesh, const Mat4& world, const std::string& where);
  // MSFT_lod: the level-of-detail group of the node's levels (its mesh first, then the meshes of
  // the nodes its `ids` name), or −1 — with a warning — when a level is not one primitive.
  int lodGroupOf(const tinygltf::Node& node, const std::string& where);
  // The nodes MSFT_lod names as coarser levels: drawn only as levels, never as nodes of their own.
  std::vector<uint8_t> lodLevelNode_;
  Camera convertCamera(const tinygltf::Node& node, const Mat4& world,
                       const std::string& where) const;
  void walkNodes();

  const tinygltf::Model& model_;
  const LoadOptions& options_;
  DecodedImages& images_;
  Scene scene_;
  std::map<std::tuple<int, int, int>, int> textures_;  // (image, wrapS, wrapT) → Scene::textures
  uint64_t triangles_ = 0;
  std::map<int, std::vector<int>> meshes_;  // glTF mesh → our meshes, one per primitive
};

AccessorView GltfConverter::accessor(int index, const std::string& where,
                                     std::initializer_list<int> types,
                                     std::initializer_list<int> componentTypes) const {
  if (index < 0 || size_t(index) >= model_.accessors.size())
    fail(fmt::format("{}: accessor {} does not exist ({} accessors)", where, index,
                     model_.accessors.size()));
  const tinygltf::Accessor& a = model_.accessors[size_t(index)];
  const std::string name = fmt::format("{}: accessors[{}]", where, index);
  if (a.sparse.isSparse) fail(name + ": sparse accessors are not supported");
  if (std::find(types.begin(), types.end(), a.type) == types.end())
    fail(fmt::format("{}: unexpected element type {}", name, a.type));
  if (std::find(componentTypes.begin(), componentTypes.end(), a.componentType) ==
      componentTypes.end())
    fail(fmt::format("{}: unexpected component type {}", name, a.componentType));
  // Step 1: the buffer view inside its buffer.
  const auto [viewBytes, viewLength] = bufferViewBytes(a.bufferView, name);
  const tinygltf::BufferView& view = model_.bufferViews[size_t(a.bufferView)];

  // Step 2: the elements inside the buffer view. Element i occupies
  // [byteOffset + i·stride, byteOffset + i·stride + elementSize).
  AccessorView out;
  out.componentType = a.componentType;
  out.components = componentCount(a.type);
  out.normalized = a.normalized;
  out.count = a.count;
  const size_t elementSize = size_t(componentSize(a.componentType)) * size_t(out.components);
  out.stride = view.byteStride ? view.byteStride : elementSize;
  if (view.byteStride && (view.byteStride < elementSize || view.byteStride > 252))
    fail(fmt::format("{}: byteStride {} is invalid for {}-byte elements", name, view.byteStride,
                     elementSize));
  if (a.count > 0) {
    const size_t room = a.byteOffset <= viewLength ? viewLength - a.byteOffset : 0;
    if (a.byteOffset > viewLength || room < elementSize ||
        (a.count - 1) > (room - elementSize) / out.stride)
      fail(fmt::format(
          "{}: {} elements of {} bytes (stride {}, offset {}) do not fit in "
          "bufferViews[{}] ({} bytes)",
          name, a.count, elementSize, out.stride, a.byteOffset, a.bufferView, viewLength));
    out.data = viewBytes + a.byteOffset;
  }
  return out;
}

void GltfConverter::convertMaterials() {
  for (size_t i = 0; i < model_.materials.size(); ++i) {
    const tinygltf::Material& gm = model_.materials[i];
    Material m;
    m.name = gm.name;
    const std::vector<double>& f = gm.pbrMetallicRoughness.baseColorFactor;
    if (f.size() == 4) {
      for (double x : f)
        if (!std::isfinite(x)) fail(fmt::format("materials[{}]: baseColorFactor is not finite", i));
      m.baseColor = {float(f[0]), float(f[1]), float(f[2]), float(f[3])};
    } else if (!f.empty()) {
      fail(fmt::format("materials[{}]: baseColorFactor must have 4 numbers, has {}", i, f.size()));
    }
    m.doubleSided = gm.doubleSided;
    m.unlit = gm.extensions.count("KHR_materials_unlit") > 0;
    const std::string where = fmt::format("materials[{}]", i);
    const tinygltf::TextureInfo& base = gm.pbrMetallicRoughness.baseColorTexture;
    if (base.index >= 0) {
      if (base.texCoord != 0)
        fail(fmt::format("{}: baseColorTexture uses TEXCOORD_{}; only TEXCOORD_0 is supported",
                         where, base.texCoord));
      m.texture = textureFor(base.index, where + ".baseColorTexture");
      // KHR_texture_transform: uv' = offset + R(rotation)·(scale ⊙ uv), R turning
      // counter-clockwise (the extension's GLSL: columns (cos, sin) and (−sin, cos)). Built into
      // the uvs of the primitives that use the material (convertPrimitive).
      const auto ext = base.extensions.find("KHR_texture_transform");
      if (ext != base.extensions.end()) {
        const std::string tw = where + ".baseColorTexture.KHR_texture_transform";
        const tinygltf::Value& t = ext->second;
        if (!t.IsObject()) fail(tw + ": expected an object");
        auto pair = [&](const char* key, double fallback, double out[2]) {
          out[0] = out[1] = fallback;
          if (!t.Has(key)) return;
          const tinygltf::Value& v = t.Get(key);
          if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber())
            fail(fmt::format("{}.{}: expected two numbers", tw, key));
          out[0] = v.Get(0).GetNumberAsDouble(), out[1] = v.Get(1).GetNumberAsDouble();
        };
        double offset[2], scale[2], rotation = 0;
        pair("offset", 0, offset);
        pair("scale", 1, scale);
        if (t.Has("rotation")) {
          if (!t.Get("rotation").IsNumber()) fail(tw + ".rotation: expected a number");
          rotation = t.Get("rotation").GetNumberAsDouble();
        }
        if (t.Has("texCoord") && (!t.Get("texCoord").IsInt() || t.Get("texCoord").Get<int>() != 0))
          fail(tw + ".texCoord: only TEXCOORD_0 is supported");
        for (double x : {offset[0], offset[1], scale[0], scale[1], rotation})
          if (!(std::fabs(x) <= 1e6)) fail(tw + ": a value is not finite or is out of range");
        const double c = std::cos(rotation), sn = std::sin(rotation);
        uvTransforms_[int(i)] = {float(c * scale[0]),  float(-sn * scale[1]), float(offset[0]),
                                 float(sn * scale[0]), float(c * scale[1]),   float(offset[1])};
      }
    }
    // glTF 2.0 §3.9.4: OPAQUE ignores alpha, MASK cuts at alphaCutoff, BLEND composites.
    if (gm.alphaMode == "BLEND")
      m.alphaMode = AlphaMode::blend;
    else if (gm.alphaMode == "MASK")
      m.alphaMode = AlphaMode::mask;
    else if (gm.alphaMode != "OPAQUE" && !gm.alphaMode.empty())
      fail(fmt::format("{}: unknown alphaMode '{}'", where, gm.alphaMode));
    if (!std::isfinite(gm.alphaCutoff) || gm.alphaCutoff < 0)
      fail(fmt::format("{}: alphaCutoff must be a number ≥ 0", where));
    m.alphaCutoff = float(gm.alphaCutoff);
    scene_.materials.push_back(std::move(m));
  }
}

texture::Wrap wrapOf(int mode, const std::string& where) {
  switch (mode) {  // glTF 2.0 §5.26 (sampler.wrapS / wrapT)
    case 10497:
      return texture::Wrap::repeat;
    case 33071:
      return texture::Wrap::clamp;
    case 33648:
      return texture::Wrap::mirror;
  }
  fail(fmt::format("{}: unknown wrap mode {}", where, mode));
}

// The scene texture for glTF texture `gltfTexture`: its image with its sampler's wrap modes, one
// pyramid per (image, wrap modes). The sampler's filters are not used: the frame's or the
// material's texture filter decides (RenderOptions::textureFilter).
int GltfConverter::textureFor(int gltfTexture, const std::string& where) {
  if (size_t(gltfTexture) >= model_.textures.size())
    fail(fmt::format("{}: texture {} does not exist ({} textures)", where, gltfTexture,
                     model_.textures.size()));
  const tinygltf::Texture& t = model_.textures[size_t(gltfTexture)];
  const std::string tw = fmt::format("textures[{}]", gltfTexture);
  if (t.source < 0 || size_t(t.source) >= model_.images.size())
    fail(fmt::format("{}: image {} does not exist", tw, t.source));
  int wrapS = 10497, wrapT = 10497;
  if (t.sampler >= 0) {
    if (size_t(t.sampler) >= model_.samplers.size())
      fail(fmt::format("{}: sampler {} does not exist", tw, t.sampler));
    wrapS = model_.samplers[size_t(t.sampler)].wrapS;
    wrapT = model_.samplers[size_t(t.sampler)].wrapT;
  }
  const auto key = std::make_tuple(t.source, wrapS, wrapT);
  if (auto it = textures_.find(key); it != textures_.end()) return it->second;
  auto level = images_.levels.find(t.source);
  const tinygltf::Image& image = model_.images[size_t(t.source)];
  if (level == images_.levels.end())
    fail(fmt::format("images[{}]{}: could not be read{}", t.source,
                     image.uri.empty() ? "" : " ('" + image.uri + "')",
                     options_.followReferences ? "" : " (references to other files are disabled)"));
  TextureMap map;
  map.name = !image.name.empty() ? image.name
             : !image.uri.empty() && image.uri.rfind("data:", 0) != 0
                 ? image.uri
                 : fmt::format("images[{}]", t.source);
  map.texture = std::make_shared<texture::Texture>(
      level->second, wrapOf(wrapS, tw + ".sampler.wrapS"), wrapOf(wrapT, tw + ".sampler.wrapT"));
  scene_.textures.push_back(std::move(map));
  const int index = int(scene_.textures.size()) - 1;
  textures_.emplace(key, index);
  return index;
}

void GltfConverter::transformUvs(const tinygltf::Primitive& primitive,
                                 std::vector<Vec2>& uvs) const {
  if (const auto t = uvTransforms_.find(primitive.material); t != uvTransforms_.end())
    for (Vec2& uv : uvs) {
      const UvTransform& m = t->second;
      uv = {m.a * uv.x + m.b * uv.y + m.c, m.d * uv.x + m.e * uv.y + m.f};
    }
}

std::pair<const unsigned char*, size_t> GltfConverter::bufferViewBytes(
    int index, const std::string& where) const {
  if (index < 0 || size_t(index) >= model_.bufferViews.size())
    fail(fmt::format("{}: bufferView {} does not exist", where, index));
  const tinygltf::BufferView& view = model_.bufferViews[size_t(index)];
  if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
    fail(fmt::format("{}: bufferViews[{}] refers to buffer {}, which does not exist", where, index,
                     view.buffer));
  const std::vector<unsigned char>& buffer = model_.buffers[size_t(view.buffer)].data;
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
    fail(fmt::format(
        "{}: bufferViews[{}] (offset {}, length {}) lies outside buffers[{}] ({} bytes)", where,
        index, view.byteOffset, view.byteLength, view.buffer, buffer.size()));
  return {buffer.data() + view.byteOffset, view.byteLength};
}

Mesh GltfConverter::convertDracoPrimitive(const tinygltf::Primitive& primitive,
                                          const std::string& where) const {
  const std::string w = where + ".KHR_draco_mesh_compression";
  const tinygltf::Value& e = primitive.extensions.at("KHR_draco_mesh_compression");
  if (!e.IsObject() || !e.Has("bufferView") || !e.Get("bufferView").IsInt() ||
      !e.Has("attributes") || !e.Get("attributes").IsObject())
    fail(w + ": expected an object with 'bufferView' and 'attributes'");
  if (primitive.mode != TINYGLTF_MODE_TRIANGLES)
    fail(fmt::format("{}: mode {} (Draco meshes are triangles)", w, primitive.mode));
  const tinygltf::Value& attributes = e.Get("attributes");
  auto id = [&](const char* name) {
    if (!attributes.Has(name)) return -1;
    if (!attributes.Get(name).IsInt() || attributes.Get(name).Get<int>() < 0)
      fail(fmt::format("{}.attributes.{}: expected an attribute id", w, name));
    return attributes.Get(name).Get<int>();
  };
  const DracoAttributes ids{id("POSITION"), id("NORMAL"), id("COLOR_0"), id("TEXCOORD_0")};
  const auto [bytes, size] = bufferViewBytes(e.Get("bufferView").Get<int>(), w);
  Result<DracoMesh> decoded = decodeDracoMesh(
      bytes, size, ids, std::numeric_limits<uint32_t>::max(), options_.maxTriangles);
  if (!decoded) fail(fmt::format("{}: {}", w, decoded.error().message));
  Mesh mesh;
  mesh.positions = std::move(decoded->positions);
  mesh.normals = std::move(decoded->normals);
  mesh.colors = std::move(decoded->colors);
  mesh.uvs = std::move(decoded->uvs);
  transformUvs(primitive, mesh.uvs);
  mesh.indices = std::move(decoded->indices);
  mesh.material = materialOf(primitive, where);
  return mesh;
}

int GltfConverter::materialOf(const tinygltf::Primitive& primitive,
                              const std::string& where) const {
  if (primitive.material >= 0 && size_t(primitive.material) >= scene_.materials.size())
    fail(fmt::format("{}: material {} does not exist ({} materials)", where, primitive.material,
                     scene_.materials.size()));
  return primitive.material;
}

Mesh GltfConverter::convertPrimitive(const tinygltf::Primitive& primitive,
                                     const std::string& where) const {
  if (primitive.extensions.count("KHR_draco_mesh_compression"))
    return convertDracoPrimitive(primitive, where);
  constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
  constexpr int kByte = TINYGLTF_COMPONENT_TYPE_BYTE,
                kUByte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  constexpr int kShort = TINYGLTF_COMPONENT_TYPE_SHORT;
  constexpr int kUShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  constexpr int kUInt = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  Mesh mesh;

  // Step 1: vertex attributes. Integer types are allowed where KHR_mesh_quantization allows them.
  auto attribute = [&](const char* name) -> const int* {
    auto it = primitive.attributes.find(name);
    return it == primitive.attributes.end() ? nullptr : &it->second;
  };
  const int* positionIndex = attribute("POSITION");
  if (!positionIndex) fail(where + ": has no POSITION attribute");
  AccessorView positions = accessor(*positionIndex, where + ".attributes.POSITION",
                                    {TINYGLTF_TYPE_VEC3}, {kFloat, kByte, kUByte, kShort, kUShort});
  const size_t n = positions.count;
  if (n > std::numeric_limits<uint32_t>::max()) fail(where + ": too many vertices");
  mesh.positions.resize(n);
  for (size_t i = 0; i < n; ++i)
    mesh.positions[i] = {positions.get(i, 0), positions.get(i, 1), positions.get(i, 2)};

  auto sameCount = [&](const AccessorView& v, const char* name) {
    if (v.count != n)
      fail(fmt::format("{}.attributes.{}: {} elements, but POSITION has {}", where, name, v.count,
                       n));
  };
  if (const int* index = attribute("NORMAL")) {
    AccessorView v = accessor(*index, where + ".attributes.NORMAL", {TINYGLTF_TYPE_VEC3},
                              {kFloat, kByte, kShort});
    sameCount(v, "NORMAL");
    mesh.normals.resize(n);
    for (size_t i = 0; i < n; ++i) mesh.normals[i] = {v.get(i, 0), v.get(i, 1), v.get(i, 2)};
  }
  if (const int* index = attribute("COLOR_0")) {
    AccessorView v = accessor(*index, where + ".attributes.COLOR_0",
                              {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, {kFloat, kUByte, kUShort});
    sameCount(v, "COLOR_0");
    // Integer colours are normalized by definition (spec 3.7.2.1), whatever the flag says.
    v.normalized = true;
    mesh.colors.resize(n);
    for (size_t i = 0; i < n; ++i)
      mesh.colors[i] = {v.get(i, 0), v.get(i, 1), v.get(i, 2),
                        v.components == 4 ? v.get(i, 3) : 1.0f};
  }
  if (const int* index = attribute("TEXCOORD_0")) {
    AccessorView v = accessor(*index, where + ".attributes.TEXCOORD_0", {TINYGLTF_TYPE_VEC2},
                              {kFloat, kByte, kUByte, kShort, kUShort});
    sameCount(v, "TEXCOORD_0");
    mesh.uvs.resize(n);
    for (size_t i = 0; i < n; ++i) mesh.uvs[i] = {v.get(i, 0), v.get(i, 1)};
    transformUvs(primitive, mesh.uvs);
  }

  // Step 2: the index sequence, given or implied (0, 1, 2, …), each checked against n.
  std::vector<uint32_t> sequence;
  if (primitive.indices >= 0) {
    AccessorView v = accessor(primitive.indices, where + ".indices", {TINYGLTF_TYPE_SCALAR},
                              {kUByte, kUShort, kUInt});
    sequence.resize(v.count);
    for (size_t i = 0; i < v.count; ++i) {
      sequence[i] = v.index(i);
      if (sequence[i] >= n)
        fail(fmt::format("{}.indices: index {} at position {} is out of range ({} vertices)", where,
                         sequence[i], i, n));
    }
  } else {
    sequence.resize(n);
    for (size_t i = 0; i < n; ++i) sequence[i] = uint32_t(i);
  }

  // Step 3: triangles from the sequence (spec 3.7.2.1, "Topology types"). An incomplete last
  // triangle is dropped; strips and fans skip the degenerate triangles used as restarts.
  const size_t m = sequence.size();
  std::vector<uint32_t>& out = mesh.indices;
  auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (a != b && b != c && a != c) out.insert(out.end(), {a, b, c});
  };
  switch (primitive.mode) {
    case TINYGLTF_MODE_TRIANGLES:
      out.reserve(m - m % 3);
      for (size_t i = 0; i + 2 < m; i += 3)
        out.insert(out.end(), {sequence[i], sequence[i + 1], sequence[i + 2]});
      break;
    case TINYGLTF_MODE_TRIANGLE_STRIP:
      // Odd triangles swap their first two vertices to keep the winding.
      for (size_t i = 0; i + 2 < m; ++i)
        if (i % 2 == 0)
          emit(sequence[i], sequence[i + 1], sequence[i + 2]);
        else
          emit(sequence[i + 1], sequence[i], sequence[i + 2]);
      break;
    case TINYGLTF_MODE_TRIANGLE_FAN:
      for (size_t i = 1; i + 1 < m; ++i) emit(sequence[0], sequence[i], sequence[i + 1]);
      break;
    // Lines: segments as index pairs (placeAside draws them as lines).
    case TINYGLTF_MODE_LINE:
      out.reserve(m - m % 2);
      for (size_t i = 0; i + 1 < m; i += 2) out.insert(out.end(), {sequence[i], sequence[i + 1]});
      break;
    case TINYGLTF_MODE_LINE_STRIP:
    case TINYGLTF_MODE_LINE_LOOP:
      for (size_t i = 0; i + 1 < m; ++i) out.insert(out.end(), {sequence[i], sequence[i + 1]});
      if (primitive.mode == TINYGLTF_MODE_LINE_LOOP && m > 2)
        out.insert(out.end(), {sequence[m - 1], sequence[0]});
      break;
    default:
      break;  // points have no triangles
  }

  mesh.material = materialOf(primitive, where);
  return mesh;
}

const std::vector<int>& GltfConverter::meshesOf(int gltfMesh) {
  auto it = meshes_.find(gltfMesh);
  if (it != meshes_.end()) return it->second;
  std::vector<int> ours;
  const tinygltf::Mesh& gm = model_.meshes[size_t(gltfMesh)];
  for (size_t k = 0; k < gm.primitives.size(); ++k) {
    const tinygltf::Primitive& primitive = gm.primitives[k];
    const std::string where = fmt::format("meshes[{}].primitives[{}]", gltfMesh, k);
    switch (primitive.mode) {
      case TINYGLTF_MODE_TRIANGLES:
      case TINYGLTF_MODE_TRIANGLE_STRIP:
      case TINYGLTF_MODE_TRIANGLE_FAN:
        break;
      case TINYGLTF_MODE_POINTS:
      case TINYGLTF_MODE_LINE:
      case TINYGLTF_MODE_LINE_LOOP:
      case TINYGLTF_MODE_LINE_STRIP: {
        // Points are light points (SPEC §13), lines the line pass's: kept aside, placed with the
        // node (walkNodes, placeAside). A points mesh has no indices; a lines mesh index pairs.
        asideMeshes_[gltfMesh].push_back(
            {convertPrimitive(primitive, where), primitive.mode != TINYGLTF_MODE_POINTS});
        continue;
      }
      default:
        fail(fmt::format("{}: unknown mode {}", where, primitive.mode));
    }
    Mesh mesh = convertPrimitive(primitive, where);
    mesh.name = gm.primitives.size() == 1 ? gm.name : fmt::format("{}[{}]", gm.name, k);
    scene_.meshes.push_back(std::move(mesh));
    ours.push_back(int(scene_.meshes.size() - 1));
  }
  return meshes_.emplace(gltfMesh, std::move(ours)).first->second;
}

// Where a node places glTF mesh `gltfMesh`, its POINTS and LINE* primitives: a light point at every
// vertex of a points primitive (omnidirectional, of the default intensity, one appearance per
// colour), a line segment for every index pair of a lines primitive — each in the vertex colour
// (a segment's two averaged) times the material's base colour.
void GltfConverter::placeAside(int gltfMesh, const Mat4& world, const std::string& where) {
  auto it = asideMeshes_.find(gltfMesh);
  if (it == asideMeshes_.end()) return;
  for (const Aside& aside : it->second) {
    const Mesh& mesh = aside.mesh;  // (not a structured binding: lambdas below capture it)
    const Vec4 base = scene_.materialAt(mesh.material).baseColor;
    auto colorAt = [&](uint32_t i) {
      const Vec4 c = mesh.colors.empty() ? Vec4{1, 1, 1, 1} : mesh.colors[i];
      return std::array<float, 3>{std::clamp(c.x * base.x, 0.0f, 1.0f),
                                  std::clamp(c.y * base.y, 0.0f, 1.0f),
                                  std::clamp(c.z * base.z, 0.0f, 1.0f)};
    };
    auto placed = [&](uint32_t i) {
      const Vec3 p = world.transformPoint(mesh.positions[i]);
      if (!isFinite(p)) fail(fmt::format("{}: a vertex's position is not finite", where));
      return p;
    };
    if (aside.lines) {
      if (scene_.lines.size() + mesh.indices.size() / 2 > kMaxLines)
        fail(fmt::format("{}: more than {} line segments", where, kMaxLines));
      for (size_t k = 0; k + 1 < mesh.indices.size(); k += 2) {
        const uint32_t a = mesh.indices[k], b = mesh.indices[k + 1];
        const std::array<float, 3> ca = colorAt(a), cb = colorAt(b);
        scene_.lines.push_back(
            {placed(a),
             placed(b),
             {0.5f * (ca[0] + cb[0]), 0.5f * (ca[1] + cb[1]), 0.5f * (ca[2] + cb[2])}});
      }
      continue;
    }
    for (uint32_t i = 0; i < uint32_t(mesh.positions.size()); ++i) {
      const std::array<float, 3> color = colorAt(i);
      auto look = pointLooks_.find(color);
      if (look == pointLooks_.end()) {
        LightAppearance a;
        a.name = fmt::format("glTF points {} {} {}", color[0], color[1], color[2]);
        a.color = {color[0], color[1], color[2]};
        scene_.lightAppearances.push_back(a);
        look = pointLooks_.emplace(color, uint32_t(scene_.lightAppearances.size() - 1)).first;
      }
      if (scene_.lightPoints.size() >= kMaxLightPoints)
        fail(fmt::format("{}: more than {} light points", where, kMaxLightPoints));
      scene_.lightPoints.push_back({placed(i), look->second, 0, -1});
    }
  }
}

// Unit quaternion (x, y, z, w) to matrix; normalized first, since files often store quaternions
// with a little rounding.
Mat4 rotationOf(double x, double y, double z, double w, const std::string& where) {
  const double len = std::sqrt(x * x + y * y + z * z + w * w);
  if (!(len > 0) || !std::isfinite(len)) fail(where + ": zero or non-finite quaternion");
  x /= len, y /= len, z /= len, w /= len;
  Mat4 r;
  r.m[0] = {float(1 - 2 * (y * y + z * z)), float(2 * (x * y + z * w)), float(2 * (x * z - y * w)),
            0};
  r.m[1] = {float(2 * (x * y - z * w)), float(1 - 2 * (x * x + z * z)), float(2 * (y * z + x * w)),
            0};
  r.m[2] = {float(2 * (x * z + y * w)), float(2 * (y * z - x * w)), float(1 - 2 * (x * x + y * y)),
            0};
  return r;
}

std::vector<Mat4> GltfConverter::gpuInstances(const tinygltf::Node& node,
                                              const std::string& where) const {
  const auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == node.extensions.end()) return {};
  const std::string w = where + ".EXT_mesh_gpu_instancing";
  const tinygltf::Value& e = ext->second;
  if (!e.IsObject() || !e.Has("attributes") || !e.Get("attributes").IsObject())
    fail(w + ": expected an object with 'attributes'");
  const tinygltf::Value& attributes = e.Get("attributes");
  // TRANSLATION, ROTATION (a unit quaternion) and SCALE, each optional, all of one count.
  std::optional<AccessorView> views[3];
  const char* names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  size_t count = 0;
  for (int k = 0; k < 3; ++k) {
    if (!attributes.Has(names[k])) continue;
    const tinygltf::Value& a = attributes.Get(names[k]);
    if (!a.IsInt()) fail(fmt::format("{}.{}: expected an accessor index", w, names[k]));
    views[k] = accessor(a.Get<int>(), fmt::format("{}.{}", w, names[k]),
                        {k == 1 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3},
                        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                         TINYGLTF_COMPONENT_TYPE_SHORT});
    if (count && views[k]->count != count)
      fail(fmt::format("{}: {} has {} elements, another attribute {}", w, names[k], views[k]->count,
                       count));
    count = views[k]->count;
  }
  if (!count) fail(w + ": no TRANSLATION, ROTATION or SCALE");
  std::vector<Mat4> out(count);
  for (size_t i = 0; i < count; ++i) {
    Mat4 t, r, s;
    if (views[0])
      t = Mat4::translation({views[0]->get(i, 0), views[0]->get(i, 1), views[0]->get(i, 2)});
    if (views[1])
      r = rotationOf(views[1]->get(i, 0), views[1]->get(i, 1), views[1]->get(i, 2),
                     views[1]->get(i, 3), fmt::format("{}.ROTATION[{}]", w, i));
    if (views[2])
      s = Mat4::scaling({views[2]->get(i, 0), views[2]->get(i, 1), views[2]->get(i, 2)});
    out[i] = t * r * s;
    for (const auto& column : out[i].m)
      for (float x : column)
        if (!std::isfinite(x)) fail(fmt::format("{}: instance {} is not finite", w, i));
  }
  return out;
}

int GltfConverter::lodGroupOf(const tinygltf::Node& node, const std::string& where) {
  const std::string w = where + ".MSFT_lod";
  const tinygltf::Value& e = node.extensions.at("MSFT_lod");
  if (!e.IsObject() || !e.Has("ids") || !e.Get("ids").IsArray())
    fail(w + ": expected an object with 'ids'");
  const tinygltf::Value& ids = e.Get("ids");
  std::vector<int> levels = {node.mesh};
  for (size_t k = 0; k < ids.ArrayLen(); ++k) {
    const tinygltf::Value& id = ids.Get(int(k));
    if (!id.IsInt() || id.Get<int>() < 0 || size_t(id.Get<int>()) >= model_.nodes.size())
      fail(fmt::format("{}.ids[{}]: not a node", w, k));
    const tinygltf::Node& level = model_.nodes[size_t(id.Get<int>())];
    if (level.mesh < 0 || size_t(level.mesh) >= model_.meshes.size())
      fail(fmt::format("{}.ids[{}]: node {} has no mesh", w, k, id.Get<int>()));
    levels.push_back(level.mesh);
  }
  if (levels.size() > kMaxLodLevels)
    fail(fmt::format("{}: {} levels (at most {})", w, levels.size(), kMaxLodLevels));
  // A level of detail is one mesh (scene.h LodGroup): a level of several primitives is drawn at
  // full detail instead, and said so.
  LodGroup g;
  g.name = model_.meshes[size_t(node.mesh)].name;
  for (int mesh : levels) {
    const std::vector<int>& ours = meshesOf(mesh);
    if (ours.size() != 1) {
      scene_.warnings.push_back(fmt::format(
          "{}: a level of {} primitives; drawn at full detail (levels of one primitive only)", w,
          ours.size()));
      return -1;
    }
    g.levels.push_back({ours[0], 1e30f});
  }
  // MSFT_screencoverage (the node's extras): level i while the model covers at least c_i of the
  // screen. Coverage is taken as the area of the disc its bounding sphere projects to over a
  // square screen's area, under the 60° view that ranges refer to: c = π·ρ²/4 with
  // ρ = R/(d·tan 30°), so c_i ↔ the range d_i = R/(tan 30° · 2·sqrt(c_i/π)). Without it each level
  // covers a quarter of the one before: from c = 0.25 down.
  const auto [lo, hi] = scene_.meshes[size_t(g.levels[0].mesh)].bounds();
  const double radius = std::max(0.5 * double(length(hi - lo)), 1e-6);
  std::vector<double> coverage;
  if (node.extras.IsObject() && node.extras.Has("MSFT_screencoverage")) {
    const tinygltf::Value& c = node.extras.Get("MSFT_screencoverage");
    if (!c.IsArray()) fail(where + ".extras.MSFT_screencoverage: expected an array of numbers");
    for (size_t k = 0; k < c.ArrayLen(); ++k) {
      if (!c.Get(int(k)).IsNumber() || !(c.Get(int(k)).GetNumberAsDouble() > 0))
        fail(fmt::format("{}.extras.MSFT_screencoverage[{}]: expected a number > 0", where, k));
      coverage.push_back(c.Get(int(k)).GetNumberAsDouble());
    }
  } else {
    for (size_t k = 0; k + 1 < g.levels.size(); ++k) coverage.push_back(0.25 / std::pow(4.0, k));
  }
  const double tan30 = std::tan(std::numbers::pi / 6);
  double from = 0;
  for (size_t k = 0; k < g.levels.size() && k < coverage.size(); ++k) {
    const double range = radius / (tan30 * 2 * std::sqrt(coverage[k] / std::numbers::pi));
    if (!(range > from) || !std::isfinite(range))
      fail(fmt::format("{}.extras.MSFT_screencoverage: must decrease level by level", where));
    g.levels[k].to = float(std::min(range, 1e30));
    from = range;
  }
  scene_.lodGroups.push_back(std::move(g));
  return int(scene_.lodGroups.size() - 1);
}

Mat4 GltfConverter::localMatrix(const tinygltf::Node& node, const std::string& where) const {
  auto finite = [&](const std::vector<double>& v, const char* what) {
    for (double x : v)
      if (!std::isfinite(x)) fail(fmt::format("{}.{}: not finite", where, what));
  };
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16)
      fail(fmt::format("{}.matrix: expected 16 numbers, got {}", where, node.matrix.size()));
    finite(node.matrix, "matrix");
    float m[16];
    for (int i = 0; i < 16; ++i) m[i] = float(node.matrix[size_t(i)]);
    return Mat4::fromColumnMajor(m);
  }
  // T·R·S (spec 3.5.3).
  Mat4 t, r, s;
  if (!node.translation.empty()) {
    if (node.translation.size() != 3) fail(where + ".translation: expected 3 numbers");
    finite(node.translation, "translation");
    t = Mat4::translation(
        {float(node.translation[0]), float(node.translation[1]), float(node.translation[2])});
  }
  if (!node.rotation.empty()) {
    if (node.rotation.size() != 4) fail(where + ".rotation: expected 4 numbers");
    finite(node.rotation, "rotation");
    // Unit quaternion (x, y, z, w) to matrix; normalized first, since files often store
    // quaternions with a little rounding.
    r = rotationOf(node.rotation[0], node.rotation[1], node.rotation[2], node.rotation[3],
                   where + ".rotation");
  }
  if (!node.scale.empty()) {
    if (node.scale.size() != 3) fail(where + ".scale: expected 3 numbers");
    finite(node.scale, "scale");
    s = Mat4::scaling({float(node.scale[0]), float(node.scale[1]), float(node.scale[2])});
  }
  return t * r * s;
}

Camera GltfConverter::convertCamera(const tinygltf::Node& node, const Mat4& world,
                                    const std::string& where) const {
  const tinygltf::Camera& gc = model_.cameras[size_t(node.camera)];
  const tinygltf::PerspectiveCamera& p = gc.perspective;
  if (!std::isfinite(p.yfov) || !(p.yfov > 0) || !(p.yfov < std::numbers::pi) ||
      !std::isfinite(p.znear) || !(p.znear > 0) || !std::isfinite(p.zfar) || p.zfar < 0)
    fail(fmt::format("{}: cameras[{}] has an invalid perspective (yfov {}, znear {}, zfar {})",
                     where, node.camera, p.yfov, p.znear, p.zfar));
  // A glTF camera looks down its local −Z with +Y up (spec 3.10.1).
  Camera c;
  c.name = gc.name.empty() ? node.name : gc.name;
  c.position = world.transformPoint({0, 0, 0});
  c.target = c.position + normalize(world.transformDirection({0, 0, -1}));
  c.up = normalize(world.transformDirection({0, 1, 0}));
  c.yfovDegrees = float(p.yfov * 180 / std::numbers::pi);
  c.znear = float(p.znear);
  // zfar 0 means an infinite projection in glTF; synthvis needs a far plane.
  c.zfar = p.zfar > 0 ? float(p.zfar) : 1000.0f;
  if (!(c.zfar > c.znear)) c.zfar = c.znear * 1000;
  return c;
}

void GltfConverter::walkNodes() {
  const size_t nodeCount = model_.nodes.size();
  // Step 1: check child indices and count parents: the hierarchy must be a forest (spec 3.5.1),
  // which also guarantees the walk below visits each node once and terminates.
  std::vector<uint8_t> hasParent(nodeCount, 0);
  for (size_t i = 0; i < nodeCount; ++i)
    for (int child : model_.nodes[i].children) {
      if (child < 0 || size_t(child) >= nodeCount)
        fail(fmt::format("nodes[{}]: child {} does not exist ({} nodes)", i, child, nodeCount));
      if (hasParent[size_t(child)]++)
        fail(fmt::format("nodes[{}]: has more than one parent (the node hierarchy must be a tree)",
                         child));
    }

  // MSFT_lod's level nodes are levels of another node, not nodes of the scene.
  lodLevelNode_.assign(nodeCount, 0);
  for (size_t i = 0; i < nodeCount; ++i) {
    const auto ext = model_.nodes[i].extensions.find("MSFT_lod");
    if (ext == model_.nodes[i].extensions.end() || !ext->second.Has("ids")) continue;
    const tinygltf::Value& ids = ext->second.Get("ids");
    for (size_t k = 0; ids.IsArray() && k < ids.ArrayLen(); ++k)
      if (ids.Get(int(k)).IsInt()) {
        const int id = ids.Get(int(k)).Get<int>();
        if (id >= 0 && size_t(id) < nodeCount) lodLevelNode_[size_t(id)] = 1;
      }
  }

  // Step 2: the roots — the default scene's, or every parentless node.
  std::vector<int> roots;
  if (model_.defaultScene >= 0) {
    if (size_t(model_.defaultScene) >= model_.scenes.size())
      fail(fmt::format("scene {} does not exist ({} scenes)", model_.defaultScene,
                       model_.scenes.size()));
    roots = model_.scenes[size_t(model_.defaultScene)].nodes;
  } else {
    for (size_t i = 0; i < nodeCount; ++i)
      if (!hasParent[i] && !lodLevelNode_[i]) roots.push_back(int(i));
  }

  // Step 3: depth-first with an explicit stack (a hostile file may nest nodes very deep).
  std::vector<uint8_t> visited(nodeCount, 0);
  std::vector<std::pair<int, Mat4>> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, Mat4{}});
  while (!stack.empty()) {
    auto [index, parent] = stack.back();
    stack.pop_back();
    if (index < 0 || size_t(index) >= nodeCount)
      fail(fmt::format("scenes[{}]: node {} does not exist", model_.defaultScene, index));
    if (visited[size_t(index)]++)
      fail(fmt::format("nodes[{}]: reached twice (the node hierarchy must be a tree)", index));
    const tinygltf::Node& node = model_.nodes[size_t(index)];
    const std::string where = fmt::format("nodes[{}]", index);
    const Mat4 world = parent * localMatrix(node, where);

    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size())
        fail(fmt::format("{}: mesh {} does not exist ({} meshes)", where, node.mesh,
                         model_.meshes.size()));
      // Without EXT_mesh_gpu_instancing one placement, the node's; with it, one per instance
      // (each under the node's transform), the meshes shared.
      std::vector<Mat4> placements = gpuInstances(node, where);
      if (placements.empty()) placements.push_back(Mat4{});
      const int lod = node.extensions.count("MSFT_lod") ? lodGroupOf(node, where) : -1;
      for (const Mat4& placement : placements)
        for (int mesh : meshesOf(node.mesh)) {
          uint64_t t = scene_.meshes[size_t(mesh)].triangleCount();
          if (t > options_.maxTriangles - triangles_)
            fail(fmt::format("{}: the scene would have more than {} triangles", where,
                             options_.maxTriangles));
          triangles_ += t;
          scene_.instances.push_back({mesh, world * placement, 0, lod});
        }
      for (const Mat4& placement : placements) placeAside(node.mesh, world * placement, where);
    } else if (node.mesh < -1) {
      fail(fmt::format("{}: mesh {} does not exist", where, node.mesh));
    }
    if (node.camera >= 0) {
      if (size_t(node.camera) >= model_.cameras.size())
        fail(fmt::format("{}: camera {} does not exist ({} cameras)", where, node.camera,
                         model_.cameras.size()));
      // Orthographic cameras have no equivalent in Camera; they are left out.
      if (model_.cameras[size_t(node.camera)].type == "perspective")
        scene_.cameras.push_back(convertCamera(node, world, where));
    }
    for (auto child = node.children.rbegin(); child != node.children.rend(); ++child)
      stack.push_back({*child, world});
  }
}

Scene GltfConverter::convert() {
  // glTF 1.0 parses as JSON but its objects are dictionaries, not the arrays of 2.0: read as 2.0 it
  // would be an empty scene.
  const std::string& version = model_.asset.version;
  if (version.empty() || version[0] != '2' || (version.size() > 1 && version[1] != '.'))
    fail(fmt::format("glTF version '{}' is not supported (glTF 2.0 only)", version));
  for (const std::string& extension : model_.extensionsRequired) {
    bool supported = false;
    for (const char* known : kSupportedRequiredExtensions) supported |= extension == known;
    if (!supported) fail(fmt::format("requires the unsupported extension '{}'", extension));
  }
  convertMaterials();
  walkNodes();
  return std::move(scene_);
}

}  // namespace
}  // namespace detail

Result<Scene> loadGltfFromMemory(const std::string& bytes, const std::string& path,
                                 const LoadOptions& options) {
  using namespace detail;
  try {
    // Step 1: our own checks of the container and its JSON (see the file comment).
    const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    if (bytes.size() > kMaxFileBytes)
      return Error{path, "", fmt::format("input is too large ({} bytes)", bytes.size())};
    const char* json = bytes.data();
    size_t jsonSize = bytes.size();
    if (binary) {
      std::string problem = glbProblem(bytes);
      if (!problem.empty()) return Error{path, "", problem};
      json = bytes.data() + 20;
      jsonSize = readU32(bytes, 12);
    }
    if (!nestingWithin(json, jsonSize, kMaxGltfJsonDepth))
      return Error{
          path, "",
          fmt::format("JSON values are nested more than {} levels deep", kMaxGltfJsonDepth)};

    // Step 2: tinygltf parses, with file access routed through readFile and images skipped.
    const std::optional<std::string> rewritten = withoutDracoIndices(bytes, binary, json, jsonSize);
    const std::string& input = rewritten ? *rewritten : bytes;
    bool follow = options.followReferences;
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks(
        {&fsFileExists, &fsExpandFilePath, &fsReadWholeFile, &fsWriteWholeFile, &follow});
    DecodedImages images;
    images.maxTexels = options.maxTexels;
    loader.SetImageLoader(&decodeImage, &images);
    tinygltf::Model model;
    std::string err, warn;
    const std::string baseDir = directoryOf(path);
    bool ok =
        binary ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                             reinterpret_cast<const unsigned char*>(input.data()),
                                             static_cast<unsigned int>(input.size()), baseDir)
               : loader.LoadASCIIFromString(&model, &err, &warn, input.data(),
                                            static_cast<unsigned int>(input.size()), baseDir);
    if (!ok)
      return Error{path, "",
                   fmt::format("invalid glTF: {}", err.empty() ? "parse failed" : oneLine(err))};

    // Step 3: the model, checked as it is converted.
    Scene scene = GltfConverter(model, options, images).convert();
    for (std::string& w : scene.warnings) w = fmt::format("{}: {}", path, w);
    Status valid = validate(scene, path);
    if (!valid) return valid.error();
    return scene;
  } catch (const GltfProblem& p) {
    return Error{path, "", p.message};
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  } catch (const std::exception& e) {
    // tinygltf can throw from std::vector::at on some malformed files.
    return Error{path, "", fmt::format("invalid glTF: {}", oneLine(e.what()))};
  }
}

Result<Scene> loadGltf(const std::string& path) {
  try {
    Result<std::string> bytes = detail::readFile(path);
    if (!bytes) return bytes.error();
    return loadGltfFromMemory(bytes.value(), path, LoadOptions{});
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  }
}

}  // namespace sv::formats
