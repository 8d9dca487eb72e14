// Textures, fog, lights and the pixel-shading material keys in the scene loaders: glTF materials
// (baseColorTexture with its sampler's wrap modes, embedded and external PNG images, alphaMode),
// the JSON format's "textures", "fog", "pointLights", "colorTable" and material keys, OBJ's map_Kd.
#include <gtest/gtest.h>
#include <turbojpeg.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "formats/formats_test_util.h"
#include "synthvis/image.h"
#include "synthvis/scene.h"
#include "texture/texture.h"

namespace sv::formats {
namespace {

using testing::contains;
using testing::GltfBuilder;
using testing::oneTriangle;
using testing::TempDir;

// A 4 × 2 RGB PNG: texel (x, y) has red 60·x, green 200·y, blue 7 (sRGB-encoded bytes).
std::string pngBytes(const TempDir& dir) {
  Image img;
  img.width = 4;
  img.height = 2;
  img.rgb.resize(4 * 2 * 3);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      img.rgb[size_t(y * 4 + x) * 3 + 0] = uint8_t(60 * x);
      img.rgb[size_t(y * 4 + x) * 3 + 1] = uint8_t(200 * y);
      img.rgb[size_t(y * 4 + x) * 3 + 2] = 7;
    }
  const std::string path = dir.path("t.png");
  EXPECT_TRUE(writePng(img, path).ok());
  return testing::readText(path);
}

uint16_t srgbTo16(int byte) {
  const double v = byte / 255.0;
  return uint16_t(
      std::lround((v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4)) * 65535));
}

// One triangle whose material `material` uses texture 0; images and samplers as given.
GltfBuilder texturedTriangle(nlohmann::json material, nlohmann::json textures,
                             nlohmann::json images, nlohmann::json samplers) {
  GltfBuilder b;
  const int positions = b.addPositions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int uvs = b.addAccessor(std::vector<float>{0, 0, 1, 0, 0, 1}, 5126, "VEC2", 3);
  const int indices = b.addIndices({0, 1, 2});
  b.doc["materials"] = nlohmann::json::array({material});
  b.doc["textures"] = textures;
  b.doc["images"] = images;
  if (!samplers.is_null()) b.doc["samplers"] = samplers;
  const int mesh = b.addMesh({{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}}},
                              {"indices", indices},
                              {"material", 0}});
  b.addNode({{"mesh", mesh}});
  return b;
}

TEST(GltfTextures, BaseColorTextureWithItsSamplerAndAlphaModeMapToTheMaterial) {
  TempDir dir;
  const std::string uri = "data:image/png;base64," + testing::base64(pngBytes(dir));
  GltfBuilder b =
      texturedTriangle({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
                        {"alphaMode", "MASK"},
                        {"alphaCutoff", 0.3}},
                       nlohmann::json::array({{{"source", 0}, {"sampler", 0}}}),
                       nlohmann::json::array({{{"uri", uri}}}),
                       nlohmann::json::array({{{"wrapS", 33071}, {"wrapT", 33648}}}));
  Result<Scene> r = loadGltfFromMemory(b.gltf(), "t.gltf");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  ASSERT_EQ(s.textures.size(), 1u);
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.texture, 0);
  EXPECT_EQ(m.alphaMode, AlphaMode::mask);
  EXPECT_FLOAT_EQ(m.alphaCutoff, 0.3f);
  const texture::Texture& t = *s.textures[0].texture;
  EXPECT_EQ(t.wrapX(), texture::Wrap::clamp);
  EXPECT_EQ(t.wrapY(), texture::Wrap::mirror);
  ASSERT_EQ(t.level(0).width, 4);
  ASSERT_EQ(t.level(0).height, 2);
  // sRGB bytes decoded to linear 16-bit, then stored packed (texture.h); top row first.
  auto stored = [](uint16_t red, uint16_t green, uint16_t blue, uint16_t alpha) {
    return texture::packTexel({red, green, blue, alpha});
  };
  EXPECT_EQ(t.level(0).packed(2, 1) & 0xFFFF,
            stored(srgbTo16(120), srgbTo16(200), 0, 65535) & 0xFFFF);
  EXPECT_EQ(t.level(0).packed(3, 0) & 0xFFFF0000, stored(0, 0, srgbTo16(7), 65535) & 0xFFFF0000);
  EXPECT_EQ(s.meshes[0].uvs.size(), 3u);
}

TEST(GltfTextures, DefaultSamplerRepeatsAndOneImageServesTwoSamplersAsTwoTextures) {
  TempDir dir;
  const std::string uri = "data:image/png;base64," + testing::base64(pngBytes(dir));
  GltfBuilder b =
      texturedTriangle({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}},
                       nlohmann::json::array({{{"source", 0}}, {{"source", 0}, {"sampler", 0}}}),
                       nlohmann::json::array({{{"uri", uri}}}),
                       nlohmann::json::array({{{"wrapS", 33071}, {"wrapT", 33071}}}));
  b.doc["materials"].push_back(
      {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}, {"alphaMode", "BLEND"}});
  Result<Scene> r = loadGltfFromMemory(b.gltf(), "t.gltf");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->textures.size(), 2u);
  EXPECT_EQ(r->textures[size_t(r->materials[0].texture)].texture->wrapX(), texture::Wrap::clamp);
  EXPECT_EQ(r->textures[size_t(r->materials[1].texture)].texture->wrapX(), texture::Wrap::repeat);
  EXPECT_EQ(r->materials[1].alphaMode, AlphaMode::blend);
}

TEST(GltfTextures, ExternalImageIsReadRelativeToTheFile) {
  TempDir dir;
  dir.write("images/t.png", pngBytes(dir));
  GltfBuilder b =
      texturedTriangle({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}},
                       nlohmann::json::array({{{"source", 0}}}),
                       nlohmann::json::array({{{"uri", "images/t.png"}}}), nullptr);
  const std::string path = dir.write("m.gltf", b.gltf());
  Result<Scene> r = loadGltf(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->textures.size(), 1u);
  // With references disabled the image cannot be read, and the material says so.
  LoadOptions closed;
  closed.followReferences = false;
  Result<Scene> c = loadGltfFromMemory(b.gltf(), path, closed);
  ASSERT_FALSE(c.ok());
  EXPECT_TRUE(contains(c.error().str(), "images[0] ('images/t.png'): could not be read"));
}

TEST(GltfTextures, ProblemsAreNamed) {
  TempDir dir;
  const std::string png = "data:image/png;base64," + testing::base64(pngBytes(dir));
  auto error = [](const GltfBuilder& b) {
    Result<Scene> r = loadGltfFromMemory(b.gltf(), "t.gltf");
    return r.ok() ? std::string("loaded") : r.error().str();
  };
  const auto textures = nlohmann::json::array({{{"source", 0}}});
  EXPECT_TRUE(contains(
      error(texturedTriangle(
          {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}, textures,
          nlohmann::json::array({{{"uri", "data:image/jpeg;base64,/9j/4AAQSkZJRg=="}}}), nullptr)),
      "images[0]: invalid JPEG"));
  EXPECT_TRUE(
      contains(error(texturedTriangle(
                   {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}, textures,
                   nlohmann::json::array({{{"uri", "data:image/gif;base64,R0lGODlhAQABAAAAACw="}}}),
                   nullptr)),
               "only PNG and JPEG textures are supported"));
  EXPECT_TRUE(contains(
      error(texturedTriangle(
          {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"texCoord", 1}}}}}},
          textures, nlohmann::json::array({{{"uri", png}}}), nullptr)),
      "only TEXCOORD_0 is supported"));
  EXPECT_TRUE(contains(
      error(texturedTriangle({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 5}}}}}},
                             textures, nlohmann::json::array({{{"uri", png}}}), nullptr)),
      "texture 5 does not exist"));
  EXPECT_TRUE(contains(
      error(texturedTriangle({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}},
                             nlohmann::json::array({{{"source", 0}, {"sampler", 0}}}),
                             nlohmann::json::array({{{"uri", png}}}),
                             nlohmann::json::array({{{"wrapS", 1234}}}))),
      "unknown wrap mode 1234"));
}

// A scene of `body`'s keys beside the version.
Result<Scene> parseKeys(const std::string& body) {
  return parseJsonScene(R"({"synthvis": 1, )" + body + "}", "t.json");
}

TEST(JsonTextures, GeneratedTexturesFogLightsAndMaterialKeysAreRead) {
  Result<Scene> r = parseKeys(R"(
    "fog": {"color": [0.5, 0.6, 0.7], "beta": 0.25},
    "pointLights": [{"position": [1, 2, 3], "color": [2, 2, 2]}],
    "colorTable": [[1, 0, 0], [0.2, 0.4, 0.6]],
    "textures": [{"name": "n", "generate": "noise", "size": 16, "seed": 3, "wrap": ["clamp", "mirror"]},
                 {"generate": "squares", "size": 32}],
    "materials": [{"name": "a", "texture": "n", "textureFilter": "aniso", "textureScale": [4, 2],
                   "phong": true, "specular": 0.5, "shininess": 10, "opacity": 0.25},
                  {"colorCode": 1, "texture": 1, "alphaCutoff": 0.4}])");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  EXPECT_TRUE(s.fog.enabled);
  EXPECT_FLOAT_EQ(s.fog.beta, 0.25f);
  ASSERT_EQ(s.pointLights.size(), 1u);
  EXPECT_EQ(s.pointLights[0].color, (Vec3{2, 2, 2}));
  ASSERT_EQ(s.textures.size(), 2u);
  EXPECT_EQ(s.textures[0].texture->level(0).width, 16);
  EXPECT_EQ(s.textures[0].texture->wrapX(), texture::Wrap::clamp);
  EXPECT_EQ(s.textures[0].texture->wrapY(), texture::Wrap::mirror);
  const Material& a = s.materials[0];
  EXPECT_EQ(a.texture, 0);
  EXPECT_EQ(a.textureFilter, TextureFilter::anisotropic);
  EXPECT_FLOAT_EQ(a.uvScale.x, 4);
  EXPECT_TRUE(a.phong);
  EXPECT_FLOAT_EQ(a.specular, 0.5f);
  EXPECT_EQ(a.alphaMode, AlphaMode::blend);
  EXPECT_FLOAT_EQ(a.baseColor.w, 0.25f);
  const Material& b = s.materials[1];
  EXPECT_EQ(b.baseColor, (Vec4{0.2f, 0.4f, 0.6f, 1}));  // the table's entry 1
  EXPECT_EQ(b.texture, 1);
  EXPECT_EQ(b.alphaMode, AlphaMode::mask);
  // The same seed gives the same texels.
  Result<Scene> again = parseKeys(R"("textures": [{"generate": "noise", "size": 16, "seed": 3}])");
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->textures[0].texture->level(0).packed(5, 7),
            s.textures[0].texture->level(0).packed(5, 7));
}

TEST(JsonTextures, ProblemsAreNamed) {
  auto error = [](const std::string& body) {
    Result<Scene> r = parseKeys(body);
    return r.ok() ? std::string("loaded") : r.error().str();
  };
  EXPECT_TRUE(contains(error(R"("textures": [{"generate": "stripes"}])"),
                       "textures[0].generate: unknown pattern 'stripes'"));
  EXPECT_TRUE(contains(error(R"("textures": [{"file": "a.png", "generate": "noise"}])"),
                       "give either 'file'"));
  EXPECT_TRUE(contains(error(R"("textures": [{"file": "missing.png"}])"), "missing.png"));
  EXPECT_TRUE(contains(error(R"("textures": [{"generate": "noise", "wrap": "tile"}])"),
                       "unknown wrap mode 'tile'"));
  EXPECT_TRUE(contains(error(R"("materials": [{"texture": "nope"}])"), "no texture named 'nope'"));
  EXPECT_TRUE(contains(error(R"("materials": [{"textureFilter": "cubic"}])"),
                       "materials[0].textureFilter: unknown texture filter 'cubic'"));
  EXPECT_TRUE(contains(error(R"("materials": [{"colorCode": 0}])"), "no 'colorTable'"));
  EXPECT_TRUE(contains(error(R"("fog": {"beta": -1})"), "fog.beta"));
  EXPECT_TRUE(
      contains(error(R"("pointLights": [{"color": [1, 1, 1]}])"), "missing key 'position'"));
  // The texel budget: checked before a texture is generated.
  LoadOptions small;
  small.maxTexels = 5000;
  Result<Scene> r = parseJsonScene(
      R"({"synthvis": 1, "textures": [{"generate": "noise", "size": 64}, {"generate": "noise", "size": 64}]})",
      "t.json", small);
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().str(), "textures[1]: the scene's textures exceed 5000 texels"));
}

TEST(ObjTextures, MapKdIsReadAndVRunsDownTheImage) {
  TempDir dir;
  dir.write("t.png", pngBytes(dir));
  dir.write("m.mtl", "newmtl tex\nKd 1 1 1\nmap_Kd t.png\n");
  const std::string path = dir.write("m.obj",
                                     "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt "
                                     "0 1\nusemtl tex\nf 1/1 2/2 3/3\n");
  Result<Scene> r = loadObj(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->textures.size(), 1u);
  EXPECT_EQ(r->materials[0].texture, 0);
  ASSERT_EQ(r->meshes[0].uvs.size(), 3u);
  EXPECT_FLOAT_EQ(r->meshes[0].uvs[0].y, 1.0f);  // OBJ's v = 0 is the image's bottom row
  EXPECT_FLOAT_EQ(r->meshes[0].uvs[2].y, 0.0f);
}

// An 8 × 8 grey JPEG (libjpeg-turbo).
std::string jpegBytes() {
  const std::vector<unsigned char> rgb(8 * 8 * 3, 128);
  tjhandle tj = tjInitCompress();
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  EXPECT_EQ(tjCompress2(tj, rgb.data(), 8, 0, 8, TJPF_RGB, &jpeg, &size, TJSAMP_444, 90, 0), 0);
  std::string bytes(reinterpret_cast<char*>(jpeg), size);
  tjFree(jpeg);
  tjDestroy(tj);
  return bytes;
}

// A map_Kd written with Windows separators (".\t.jpg", as exporters on Windows write it) names
// the file beside the OBJ, as the other readers read such paths; a JPEG is read as one; and a
// missing file is named as a file that cannot be opened, not as a PNG that cannot be read.
TEST(ObjTextures, AWindowsPathToAJpegIsReadAndAMissingOneIsNamed) {
  TempDir dir;
  dir.write("t.jpg", jpegBytes());
  dir.write("m.mtl", "newmtl tex\nKd 1 1 1\nmap_Kd .\\t.jpg\n");
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl tex\n"
      "f 1/1 2/2 3/3\n";
  Result<Scene> r = loadObj(dir.write("m.obj", "mtllib m.mtl\n" + obj));
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->textures.size(), 1u);
  EXPECT_EQ(r->textures[0].texture->level(0).width, 8);
  dir.write("n.mtl", "newmtl tex\nKd 1 1 1\nmap_Kd .\\gone.jpg\n");
  Result<Scene> missing = loadObj(dir.write("n.obj", "mtllib n.mtl\n" + obj));
  ASSERT_FALSE(missing.ok());
  EXPECT_TRUE(contains(missing.error().str(), "gone.jpg: cannot open file"))
      << missing.error().str();
  EXPECT_FALSE(contains(missing.error().str(), "PNG"));
}

}  // namespace
}  // namespace sv::formats

namespace sv::formats {
namespace {

// KHR_texture_transform is built into the primitive's uvs: uv' = offset + R·(scale ⊙ uv), the
// rotation counter-clockwise as the extension's GLSL states it.
TEST(GltfTextures, TextureTransformIsBuiltIntoTheUvs) {
  TempDir dir;
  const std::string uri = "data:image/png;base64," + testing::base64(pngBytes(dir));
  const double quarter = std::numbers::pi / 2;
  GltfBuilder b = texturedTriangle(
      {{"pbrMetallicRoughness",
        {{"baseColorTexture",
          {{"index", 0},
           {"extensions",
            {{"KHR_texture_transform",
              {{"offset", {0.5, 0.25}}, {"rotation", quarter}, {"scale", {2, 3}}}}}}}}}}},
      nlohmann::json::array({{{"source", 0}}}), nlohmann::json::array({{{"uri", uri}}}), nullptr);
  b.doc["extensionsRequired"] = {"KHR_texture_transform"};
  b.doc["extensionsUsed"] = {"KHR_texture_transform"};
  Result<Scene> r = loadGltfFromMemory(b.gltf(), "t.gltf");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const std::vector<Vec2>& uv = r->meshes[0].uvs;
  ASSERT_EQ(uv.size(), 3u);
  // (0, 0) → the offset; (1, 0) → scaled (2, 0), turned a quarter to (0, 2), offset;
  // (0, 1) → (0, 3) turned to (−3, 0), offset.
  EXPECT_NEAR(uv[0].x, 0.5f, 1e-6f);
  EXPECT_NEAR(uv[0].y, 0.25f, 1e-6f);
  EXPECT_NEAR(uv[1].x, 0.5f, 1e-6f);
  EXPECT_NEAR(uv[1].y, 2.25f, 1e-6f);
  EXPECT_NEAR(uv[2].x, -2.5f, 1e-6f);
  EXPECT_NEAR(uv[2].y, 0.25f, 1e-6f);
}

// EXT_mesh_gpu_instancing: one instance of the node's meshes per element, each T·R·S under the
// node's own transform; the mesh is not copied.
TEST(Gltf, GpuInstancingMakesOneInstanceEach) {
  GltfBuilder b;
  const int positions = b.addPositions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int indices = b.addIndices({0, 1, 2});
  const int mesh = b.addMesh({{"attributes", {{"POSITION", positions}}}, {"indices", indices}});
  const int translation =
      b.addAccessor(std::vector<float>{1, 0, 0, 0, 2, 0, 0, 0, 3}, 5126, "VEC3", 3);
  const int rotation = b.addAccessor(
      std::vector<float>{0, 0, 0, 1, 0, 0, 0.70710678f, 0.70710678f, 0, 0, 0, 1}, 5126, "VEC4", 3);
  b.addNode({{"mesh", mesh},
             {"translation", {10, 0, 0}},
             {"extensions",
              {{"EXT_mesh_gpu_instancing",
                {{"attributes", {{"TRANSLATION", translation}, {"ROTATION", rotation}}}}}}}});
  b.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  Result<Scene> r = loadGltfFromMemory(b.gltf(), "t.gltf");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->meshes.size(), 1u);
  ASSERT_EQ(r->instances.size(), 3u);
  auto at = [&](size_t i, Vec3 p) { return r->instances[i].transform.transformPoint(p); };
  EXPECT_NEAR(at(0, {0, 0, 0}).x, 11, 1e-5f);
  EXPECT_NEAR(at(1, {0, 0, 0}).y, 2, 1e-5f);
  // Instance 1 turns a quarter about z: +x goes to +y.
  EXPECT_NEAR(at(1, {1, 0, 0}).x, 10, 1e-5f);
  EXPECT_NEAR(at(1, {1, 0, 0}).y, 3, 1e-5f);
  EXPECT_NEAR(at(2, {0, 0, 0}).z, 3, 1e-5f);
  // Mismatched counts are named.
  const int two = b.addAccessor(std::vector<float>{1, 1, 1, 2, 2, 2}, 5126, "VEC3", 2);
  b.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = two;
  Result<Scene> bad = loadGltfFromMemory(b.gltf(), "t.gltf");
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(testing::contains(bad.error().str(), "EXT_mesh_gpu_instancing: SCALE has 2 elements"))
      << bad.error().str();
}

}  // namespace
}  // namespace sv::formats
