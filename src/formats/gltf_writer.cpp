// Writing a Scene as glTF 2.0 (.glb, or .gltf with the buffer embedded), so that generated
// benchmark scenes can be rendered by other tools (`synthvis gen`).
//
// What is written is what the loader reads back (docs/scene-format.md, "glTF and OBJ files"):
// one glTF mesh per Mesh (POSITION with min/max, NORMAL, COLOR_0 as float VEC4, TEXCOORD_0 —
// multiplied by its material's uvScale, which glTF cannot state —, 32-bit indices), one material
// per Material (baseColorFactor, doubleSided, KHR_materials_unlit, alphaMode and alphaCutoff,
// baseColorTexture), one image per texture (its level 0 as an 8-bit sRGB RGBA PNG in the buffer,
// glTF's encoding for base colour) with a sampler of its wrap modes, one node per Instance (its
// matrix), one node per Camera (camera-to-world matrix, looking down −Z with +Y up; yfov in
// radians), the lines as one LINES primitive in world coordinates (COLOR_0 each segment's colour).
// Not written, as glTF core has no place for them: lights, fog, the background, Phong and specular
// terms, the colour table, the line settings.
#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <sstream>

#include "formats/reader.h"
#include "synthvis/files.h"
#include "texture/texture.h"

namespace sv::formats {
namespace {

// Appends `count` elements of `bytes` each to the buffer as a new view + accessor.
int addAccessor(tinygltf::Model& model, const void* data, size_t count, size_t bytes, int type,
                int componentType, int target) {
  auto& buffer = model.buffers[0].data;
  while (buffer.size() % 4) buffer.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = count * bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), p, p + count * bytes);
  model.bufferViews.push_back(view);
  tinygltf::Accessor a;
  a.bufferView = int(model.bufferViews.size()) - 1;
  a.count = count;
  a.type = type;
  a.componentType = componentType;
  model.accessors.push_back(a);
  return int(model.accessors.size()) - 1;
}

std::vector<double> columnMajor(const Mat4& m) {
  std::vector<double> v;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) v.push_back(m.m[size_t(c)][size_t(r)]);
  return v;
}

// The bounds the specification requires on a POSITION accessor.
void setBounds(tinygltf::Model& model, int accessor, Vec3 lo, Vec3 hi) {
  model.accessors[size_t(accessor)].minValues = {lo.x, lo.y, lo.z};
  model.accessors[size_t(accessor)].maxValues = {hi.x, hi.y, hi.z};
}

// Appends `node` to the model and to the scene's root nodes.
void addRootNode(tinygltf::Model& model, tinygltf::Scene& root, tinygltf::Node node) {
  model.nodes.push_back(std::move(node));
  root.nodes.push_back(int(model.nodes.size()) - 1);
}

int gltfWrap(texture::Wrap w) {
  return w == texture::Wrap::clamp    ? TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE
         : w == texture::Wrap::mirror ? TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT
                                      : TINYGLTF_TEXTURE_WRAP_REPEAT;
}

// Texture i as image i (its level 0 as a PNG in the buffer), sampler i and texture i.
Status addTextures(const Scene& scene, const std::string& path, tinygltf::Model& model) {
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const texture::Texture& t = *scene.textures[i].texture;
    auto png = texture::encodeTexturePng(t.level(0), path);
    if (!png.ok()) return png.error();
    auto& buffer = model.buffers[0].data;
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = png.value().size();
    buffer.insert(buffer.end(), png.value().begin(), png.value().end());
    model.bufferViews.push_back(view);
    tinygltf::Image image;
    image.name = scene.textures[i].name;
    image.mimeType = "image/png";
    image.bufferView = int(model.bufferViews.size()) - 1;
    model.images.push_back(image);
    tinygltf::Sampler sampler;
    sampler.wrapS = gltfWrap(t.wrapX());
    sampler.wrapT = gltfWrap(t.wrapY());
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    model.samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.source = int(i);
    texture.sampler = int(i);
    model.textures.push_back(texture);
  }
  return {};
}

// Material i as material i; KHR_materials_unlit declared when one uses it.
void addMaterials(const Scene& scene, tinygltf::Model& model) {
  bool unlitUsed = false;
  for (const Material& m : scene.materials) {
    tinygltf::Material out;
    out.name = m.name;
    out.pbrMetallicRoughness.baseColorFactor = {m.baseColor.x, m.baseColor.y, m.baseColor.z,
                                                m.baseColor.w};
    out.pbrMetallicRoughness.metallicFactor = 0;
    out.doubleSided = m.doubleSided;
    if (m.texture >= 0) out.pbrMetallicRoughness.baseColorTexture.index = m.texture;
    if (m.alphaMode == AlphaMode::blend) out.alphaMode = "BLEND";
    if (m.alphaMode == AlphaMode::mask) {
      out.alphaMode = "MASK";
      out.alphaCutoff = m.alphaCutoff;
    }
    if (m.unlit) {
      out.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
      unlitUsed = true;
    }
    model.materials.push_back(out);
  }
  if (unlitUsed) model.extensionsUsed.push_back("KHR_materials_unlit");
}

// Mesh i as glTF mesh i: one triangle primitive of its arrays, the UVs times the material's
// uvScale.
void addMeshes(const Scene& scene, tinygltf::Model& model) {
  for (const Mesh& m : scene.meshes) {
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.material = m.material;
    const int pos =
        addAccessor(model, m.positions.data(), m.positions.size(), sizeof(Vec3), TINYGLTF_TYPE_VEC3,
                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    const auto [lo, hi] = m.bounds();
    setBounds(model, pos, lo, hi);
    prim.attributes["POSITION"] = pos;
    if (!m.normals.empty())
      prim.attributes["NORMAL"] =
          addAccessor(model, m.normals.data(), m.normals.size(), sizeof(Vec3), TINYGLTF_TYPE_VEC3,
                      TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!m.colors.empty())
      prim.attributes["COLOR_0"] =
          addAccessor(model, m.colors.data(), m.colors.size(), sizeof(Vec4), TINYGLTF_TYPE_VEC4,
                      TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!m.uvs.empty()) {
      const Vec2 scale = m.material >= 0 ? scene.materials[size_t(m.material)].uvScale : Vec2{1, 1};
      std::vector<Vec2> uvs(m.uvs);
      for (Vec2& uv : uvs) uv = {uv.x * scale.x, uv.y * scale.y};
      prim.attributes["TEXCOORD_0"] =
          addAccessor(model, uvs.data(), uvs.size(), sizeof(uvs[0]), TINYGLTF_TYPE_VEC2,
                      TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    }
    prim.indices = addAccessor(model, m.indices.data(), m.indices.size(), sizeof(uint32_t),
                               TINYGLTF_TYPE_SCALAR, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                               TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Mesh out;
    out.name = m.name;
    out.primitives.push_back(prim);
    model.meshes.push_back(out);
  }
}

// Each instance as a root node of its mesh and matrix.
void addInstances(const Scene& scene, tinygltf::Model& model, tinygltf::Scene& root) {
  for (const Instance& inst : scene.instances) {
    tinygltf::Node node;
    node.mesh = inst.mesh;
    node.matrix = columnMajor(inst.transform);
    addRootNode(model, root, std::move(node));
  }
}

// The lines: one LINES primitive in world coordinates, each segment's colour on both its ends,
// as a mesh of its own under a root node.
void addLines(const Scene& scene, tinygltf::Model& model, tinygltf::Scene& root) {
  if (scene.lines.empty()) return;
  std::vector<Vec3> positions;
  std::vector<Vec4> colors;
  for (const LineSegment& l : scene.lines) {
    positions.insert(positions.end(), {l.a, l.b});
    const Vec4 c{l.color.x, l.color.y, l.color.z, 1};
    colors.insert(colors.end(), {c, c});
  }
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_LINE;
  const int pos =
      addAccessor(model, positions.data(), positions.size(), sizeof(Vec3), TINYGLTF_TYPE_VEC3,
                  TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  Vec3 lo = positions[0], hi = positions[0];
  for (const Vec3& p : positions) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  setBounds(model, pos, lo, hi);
  prim.attributes["POSITION"] = pos;
  prim.attributes["COLOR_0"] =
      addAccessor(model, colors.data(), colors.size(), sizeof(Vec4), TINYGLTF_TYPE_VEC4,
                  TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
  tinygltf::Mesh lines;
  lines.name = "lines";
  lines.primitives.push_back(prim);
  model.meshes.push_back(lines);
  tinygltf::Node node;
  node.mesh = int(model.meshes.size()) - 1;
  addRootNode(model, root, std::move(node));
}

// Each camera as a perspective camera under a root node of its camera-to-world matrix.
void addCameras(const Scene& scene, tinygltf::Model& model, tinygltf::Scene& root) {
  for (const Camera& c : scene.cameras) {
    tinygltf::Camera cam;
    cam.type = "perspective";
    cam.name = c.name;
    cam.perspective.yfov = c.yfovDegrees * std::numbers::pi / 180.0;
    cam.perspective.znear = c.znear;
    cam.perspective.zfar = c.zfar;
    model.cameras.push_back(cam);
    // Camera to world: right, up, back (the view looks down −Z), position.
    const Vec3 forward = normalize(c.target - c.position);
    const Vec3 right = normalize(cross(forward, c.up));
    const Vec3 up = cross(right, forward);
    Mat4 m;
    m.m[0] = {right.x, right.y, right.z, 0};
    m.m[1] = {up.x, up.y, up.z, 0};
    m.m[2] = {-forward.x, -forward.y, -forward.z, 0};
    m.m[3] = {c.position.x, c.position.y, c.position.z, 1};
    tinygltf::Node node;
    node.name = c.name;
    node.camera = int(model.cameras.size()) - 1;
    node.matrix = columnMajor(m);
    addRootNode(model, root, std::move(node));
  }
}

}  // namespace

Status saveGltf(const Scene& scene, const std::string& path) {
  if (Status s = validate(scene, path); !s) return s;
  const bool binary = path.size() >= 4 && path.compare(path.size() - 4, 4, ".glb") == 0;
  const bool text = path.size() >= 5 && path.compare(path.size() - 5, 5, ".gltf") == 0;
  if (!binary && !text) return Error{path, "", "the file name must end in .glb or .gltf"};
  if (!scene.freeForms.empty())
    return Error{path, "",
                 fmt::format("glTF holds triangles: the scene's {} free forms cannot be written "
                             "(render or bench them directly)",
                             scene.freeForms.size())};

  // The model, in the order the indices between its parts assume: textures before the
  // materials naming them, meshes before the nodes placing them.
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "synthvis";
  model.buffers.resize(1);
  if (Status s = addTextures(scene, path, model); !s) return s;
  addMaterials(scene, model);
  addMeshes(scene, model);
  tinygltf::Scene root;
  addInstances(scene, model, root);
  addLines(scene, model, root);
  addCameras(scene, model, root);
  model.scenes.push_back(root);
  model.defaultScene = 0;
  model.buffers[0].uri.clear();

  tinygltf::TinyGLTF writer;
  // Into memory, then out through writeFile: tinygltf's own file writer checks neither that a .glb
  // opened nor that it was written. The stream writer embeds the buffer (.gltf: as a data: URI)
  // and the images.
  std::ostringstream bytes;
  if (!writer.WriteGltfSceneToStream(&model, bytes, /*prettyPrint=*/!binary,
                                     /*writeBinary=*/binary))
    return Error{path, "", "cannot encode glTF"};
  return core::writeFile(path, {bytes.view()});
}

}  // namespace sv::formats
