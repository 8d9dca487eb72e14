// The glTF 2.0 loader: the sample, node transforms, topology conversion, cameras and materials,
// and the malformed inputs tinygltf lets through (accessors past their buffers, bad indices,
// broken hierarchies, truncated GLB containers).
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>
#include <turbojpeg.h>

#include <cmath>
#include <numbers>
#include <string>

#include "formats/formats_test_util.h"
#include "synthvis/scene.h"
#include "texture/texture.h"

namespace sv::formats {
namespace {

using nlohmann::json;
using testing::contains;
using testing::dataPath;
using testing::expectLoadError;
using testing::GltfBuilder;
using testing::oneTriangle;
using testing::sourcePath;
using testing::TempDir;

Result<Scene> load(const GltfBuilder& b) { return loadGltfFromMemory(b.gltf(), "t.gltf"); }

std::string errorOf(const GltfBuilder& b) {
  Result<Scene> r = load(b);
  EXPECT_FALSE(r.ok());
  return r.ok() ? std::string() : r.error().str();
}

using testing::expectNear;

TEST(Gltf, LoadsTheSamplePyramidWithColoursMaterialAndNodeRotation) {
  Result<Scene> r = loadScene(sourcePath("scenes/pyramid.gltf"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  ASSERT_EQ(s.meshes.size(), 1u);
  const Mesh& m = s.meshes[0];
  EXPECT_EQ(m.name, "pyramid");
  EXPECT_EQ(m.triangleCount(), 6u);
  EXPECT_EQ(m.positions.size(), 16u);
  EXPECT_EQ(m.normals.size(), 16u);
  EXPECT_EQ(m.colors.size(), 16u);
  EXPECT_EQ(m.colors[0], (Vec4{0.9f, 0.2f, 0.15f, 1}));
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "painted");
  EXPECT_EQ(m.material, 0);
  // The node turns the pyramid 45° about +Y: the base corner (0.5, 0, 0.5) goes to (√2/2, 0, 0).
  ASSERT_EQ(s.instances.size(), 1u);
  expectNear(s.instances[0].transform.transformPoint({0.5f, 0, 0.5f}), {std::sqrt(0.5f), 0, 0});
  // Every triangle faces where its vertex normals point.
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
         c = m.positions[m.indices[3 * t + 2]];
    EXPECT_GT(dot(cross(b - a, c - a), m.normals[m.indices[3 * t]]), 0) << "triangle " << t;
  }
}

TEST(Gltf, LoadsTheSameModelFromGltfAndGlb) {
  TempDir dir;
  GltfBuilder b = oneTriangle();
  Result<Scene> text = loadScene(dir.write("a.gltf", b.gltf()));
  Result<Scene> binary = loadScene(dir.write("a.glb", b.glb()));
  ASSERT_TRUE(text.ok()) << text.error().str();
  ASSERT_TRUE(binary.ok()) << binary.error().str();
  EXPECT_EQ(text->meshes[0].positions, binary->meshes[0].positions);
  EXPECT_EQ(binary->meshes[0].indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(Gltf, RejectsTruncatedGlb) {
  TempDir dir;
  const std::string glb = oneTriangle().glb();
  // Cut inside the BIN chunk, inside the JSON chunk, and inside the header.
  for (size_t keep : {glb.size() - 5, size_t(40), size_t(10)}) {
    SCOPED_TRACE(keep);
    std::string path = dir.write("cut.glb", glb.substr(0, keep));
    Result<Scene> r = loadScene(path);
    ASSERT_FALSE(r.ok());
    EXPECT_TRUE(contains(r.error().str(), path + ": truncated GLB"));
  }
}

TEST(Gltf, RejectsBufferViewOutsideItsBuffer) {
  const std::string path = dataPath("scene/short_buffer.gltf");
  Result<Scene> r = loadScene(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().str(),
            path +
                ": meshes[0].primitives[0].attributes.POSITION: accessors[0]: "
                "bufferViews[0] (offset 0, length 48) lies outside buffers[0] (36 bytes)");
}

TEST(Gltf, RejectsAccessorPastTheEndOfItsBufferView) {
  GltfBuilder b = oneTriangle();
  b.doc["accessors"][0]["count"] = 4;  // the view holds 3 vertices
  EXPECT_TRUE(contains(errorOf(b),
                       "accessors[0]: 4 elements of 12 bytes (stride 12, offset 0) do not fit in "
                       "bufferViews[0] (36 bytes)"));
  b = oneTriangle();
  b.doc["accessors"][0]["byteOffset"] = 4;
  EXPECT_TRUE(contains(errorOf(b), "do not fit"));
  b = oneTriangle();
  b.doc["bufferViews"][0]["byteStride"] = 8;  // smaller than a VEC3 of floats
  EXPECT_TRUE(contains(errorOf(b), "byteStride 8 is invalid for 12-byte elements"));
  b = oneTriangle();
  b.doc["accessors"][0]["count"] = uint64_t(1) << 50;  // must not overflow the size arithmetic
  EXPECT_TRUE(contains(errorOf(b), "do not fit"));
}

TEST(Gltf, RejectsIndexOutOfRange) {
  GltfBuilder b;
  int positions = b.addPositions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  int indices = b.addIndices({0, 1, 3});
  b.addNode(
      {{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}}}, {"indices", indices}})}});
  EXPECT_EQ(errorOf(b),
            "t.gltf: meshes[0].primitives[0].indices: index 3 at position 2 is out of range (3 "
            "vertices)");
}

TEST(Gltf, RejectsBrokenReferencesAndHierarchies) {
  struct Row {
    const char* why;
    void (*breakIt)(GltfBuilder&);
    const char* expected;
  };
  const Row rows[] = {
      {"accessor index",
       [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9; },
       "accessor 9 does not exist"},
      {"no POSITION",
       [](GltfBuilder& b) {
         b.doc["meshes"][0]["primitives"][0]["attributes"] = json::object({{"NORMAL", 0}});
       },
       "has no POSITION attribute"},
      {"wrong element type", [](GltfBuilder& b) { b.doc["accessors"][0]["type"] = "VEC2"; },
       "unexpected element type"},
      {"unknown mode", [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["mode"] = 9; },
       "meshes[0].primitives[0]: unknown mode 9"},
      {"material index",
       [](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["material"] = 2; },
       "material 2 does not exist"},
      {"node mesh index", [](GltfBuilder& b) { b.doc["nodes"][0]["mesh"] = 7; },
       "nodes[0]: mesh 7 does not exist"},
      {"child index", [](GltfBuilder& b) { b.doc["nodes"][0]["children"] = {5}; },
       "nodes[0]: child 5 does not exist"},
      {"two parents",
       [](GltfBuilder& b) {
         b.addNode({{"children", {0}}});
         b.addNode({{"children", {0}}});
       },
       "nodes[0]: has more than one parent"},
      {"cycle",
       [](GltfBuilder& b) {
         b.doc["nodes"][0]["children"] = {0};
         b.doc["scene"] = 0;
         b.doc["scenes"] = {{{"nodes", {0}}}};
       },
       "nodes[0]: reached twice"},
      {"scene index", [](GltfBuilder& b) { b.doc["scene"] = 3; }, "scene 3 does not exist"},
      {"matrix size",
       [](GltfBuilder& b) {
         b.doc["nodes"][0]["matrix"] = {1, 0, 0};
       },
       "nodes[0].matrix: expected 16 numbers, got 3"},
      {"required extension",
       [](GltfBuilder& b) { b.doc["extensionsRequired"] = {"EXT_meshopt_compression"}; },
       "requires the unsupported extension 'EXT_meshopt_compression'"},
      {"sparse accessor",
       [](GltfBuilder& b) {
         b.doc["accessors"][0]["sparse"] = {
             {"count", 1},
             {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
             {"values", {{"bufferView", 0}}}};
       },
       "sparse accessors are not supported"},
  };
  for (const Row& row : rows) {
    SCOPED_TRACE(row.why);
    GltfBuilder b = oneTriangle();
    row.breakIt(b);
    std::string error = errorOf(b);
    EXPECT_TRUE(contains(error, "t.gltf: "));
    EXPECT_TRUE(contains(error, row.expected));
  }
}

TEST(Gltf, TinygltfErrorsBecomeOneLineNamingTheFile) {
  Result<Scene> r = loadGltfFromMemory(
      "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"byteLength\": 4}]}", "t.gltf");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().str(), "t.gltf: invalid glTF: "));
  EXPECT_EQ(r.error().str().find('\n'), std::string::npos);
  EXPECT_TRUE(contains(loadGltfFromMemory("{\"asset\": ", "t.gltf").error().str(),
                       "t.gltf: invalid glTF: "));
}

TEST(Gltf, AppliesNodeTransformsDownTheHierarchy) {
  GltfBuilder b = oneTriangle();
  // Node 1 (root): translate by (10, 0, 0); node 2: scale 2; node 0 (the mesh): matrix moving +Z.
  b.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 3, 1};
  b.addNode({{"translation", {10, 0, 0}}, {"children", {2}}});
  b.addNode({{"scale", {2, 2, 2}}, {"children", {0}}});
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->instances.size(), 1u);
  // (1, 0, 0) → (1, 0, 3) → (2, 0, 6) → (12, 0, 6).
  expectNear(r->instances[0].transform.transformPoint({1, 0, 0}), {12, 0, 6});
}

TEST(Gltf, WalksOnlyTheDefaultScene) {
  GltfBuilder b = oneTriangle();
  b.addNode({{"mesh", 0}, {"translation", {5, 0, 0}}});
  b.doc["scenes"] = {{{"nodes", {0}}}, {{"nodes", {1}}}};
  b.doc["scene"] = 1;
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->instances.size(), 1u);
  expectNear(r->instances[0].transform.transformPoint({0, 0, 0}), {5, 0, 0});
  // Without a default scene every root node is drawn, and a mesh used twice is converted once.
  b.doc.erase("scene");
  r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->instances.size(), 2u);
  EXPECT_EQ(r->meshes.size(), 1u);
}

TEST(Gltf, ConvertsStripsFansLinesAndPoints) {
  GltfBuilder b;
  int positions = b.addPositions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0});
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}}}, {"mode", 5}})}});
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}}}, {"mode", 6}})}});
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}}}, {"mode", 1}})}});
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}}}, {"mode", 0}})}});
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}}}, {"mode", 3}})},
             {"translation", {0, 0, 5}}});
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}}}, {"mode", 2}})}});
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->meshes.size(), 2u);
  // Strip 0 1 2 3 4: (0 1 2), (2 1 3) with the odd one's winding restored, (2 3 4).
  EXPECT_EQ(r->meshes[0].indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3, 2, 3, 4}));
  // Fan: (0 1 2), (0 2 3), (0 3 4).
  EXPECT_EQ(r->meshes[1].indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
  EXPECT_TRUE(r->warnings.empty());
  // Lines (0 1) (2 3), the fifth vertex unpaired; the strip's 4 segments, placed by its node;
  // the loop's 5 (closed).
  ASSERT_EQ(r->lines.size(), 2u + 4u + 5u);
  expectNear(r->lines[1].a, {0, 1, 0});
  expectNear(r->lines[1].b, {1, 1, 0});
  expectNear(r->lines[2].a, {0, 0, 5});
  expectNear(r->lines[5].b, {2, 0, 5});
  expectNear(r->lines[10].a, {2, 0, 0});
  expectNear(r->lines[10].b, {0, 0, 0});
  // The five points are light points.
  ASSERT_EQ(r->lightPoints.size(), 5u);
  EXPECT_FLOAT_EQ(r->lightPoints[3].position.x, 1);
  EXPECT_FLOAT_EQ(r->lightPoints[3].position.y, 1);
  ASSERT_EQ(r->lightAppearances.size(), 1u);
  EXPECT_FALSE(r->lightAppearances[0].directional);
}

// A line's colour: its two vertices' colours averaged, times the material's base colour.
TEST(Gltf, ColoursLinesByVertexAndMaterial) {
  GltfBuilder b;
  const int positions = b.addPositions({0, 0, 0, 1, 0, 0});
  const int colors = b.addAccessor(std::vector<float>{1, 0, 0, 1, 0, 1, 0, 1}, 5126, "VEC4", 2);
  b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0.5, 1, 1}}}}}};
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", positions}, {"COLOR_0", colors}}},
                                 {"mode", 1},
                                 {"material", 0}})}});
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->lines.size(), 1u);
  EXPECT_FLOAT_EQ(r->lines[0].color.x, 0.5f);
  EXPECT_FLOAT_EQ(r->lines[0].color.y, 0.25f);
  EXPECT_FLOAT_EQ(r->lines[0].color.z, 0.0f);
}

// Never silently empty: glTF 1.0 (whose objects are dictionaries) is refused by name, and a file
// with nothing drawable loads with a warning that says so.
TEST(Gltf, NamesWhatItCannotDrawInsteadOfAnEmptyImage) {
  GltfBuilder b = oneTriangle();
  b.doc["asset"]["version"] = "1.0";
  Result<Scene> old = load(b);
  ASSERT_FALSE(old.ok());
  EXPECT_EQ(old.error().str(), "t.gltf: glTF version '1.0' is not supported (glTF 2.0 only)");
  GltfBuilder empty;
  const int positions = empty.addPositions({0, 0, 0, 1, 0, 0});
  // Two points make one degenerate triangle-less primitive: nothing to draw.
  empty.addNode(
      {{"mesh", empty.addMesh({{"attributes", {{"POSITION", positions}}}, {"mode", 4}})}});
  testing::TempDir dir;
  const std::string path = dir.write("empty.gltf", empty.gltf());
  Result<Scene> r = loadScene(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->warnings.size(), 1u);
  EXPECT_EQ(r->warnings[0], path + ": nothing to draw");
  // A file of lines alone draws them: no warning.
  GltfBuilder lines;
  const int ends = lines.addPositions({0, 0, 0, 1, 0, 0});
  lines.addNode({{"mesh", lines.addMesh({{"attributes", {{"POSITION", ends}}}, {"mode", 1}})}});
  const std::string linesPath = dir.write("lines.gltf", lines.gltf());
  r = loadScene(linesPath);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_TRUE(r->warnings.empty());
  EXPECT_EQ(r->lines.size(), 1u);
}

TEST(Gltf, ReadsNormalizedIntegerColoursAndTexcoords) {
  GltfBuilder b = oneTriangle();
  int colors = b.addAccessor(std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0},
                             5121, "VEC4", 3);
  b.doc["accessors"][size_t(colors)]["normalized"] = true;
  int uvs = b.addAccessor(std::vector<uint16_t>{0, 0, 65535, 0, 0, 65535}, 5123, "VEC2", 3);
  b.doc["accessors"][size_t(uvs)]["normalized"] = true;
  b.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = colors;
  b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uvs;
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->meshes[0].colors[0], (Vec4{1, 0, 0, 1}));
  EXPECT_NEAR(r->meshes[0].colors[1].w, 128 / 255.0f, 1e-6f);
  EXPECT_EQ(r->meshes[0].uvs[1].x, 1.0f);
}

TEST(Gltf, ReadsMaterialsWithUnlitAndDoubleSided) {
  GltfBuilder b = oneTriangle();
  b.doc["materials"] = {{{"name", "flat"},
                         {"doubleSided", true},
                         {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.25, 1, 0.75}}}},
                         {"extensions", {{"KHR_materials_unlit", json::object()}}}}};
  b.doc["extensionsUsed"] = {"KHR_materials_unlit"};
  b.doc["extensionsRequired"] = {"KHR_materials_unlit"};
  b.doc["meshes"][0]["primitives"][0]["material"] = 0;
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Material& m = r->materials[0];
  EXPECT_EQ(m.name, "flat");
  EXPECT_EQ(m.baseColor, (Vec4{0.5f, 0.25f, 1, 0.75f}));
  EXPECT_TRUE(m.doubleSided);
  EXPECT_TRUE(m.unlit);
}

TEST(Gltf, ReadsPerspectiveCamerasFromNodes) {
  GltfBuilder b = oneTriangle();
  b.doc["cameras"] = {{{"type", "perspective"},
                       {"name", "eye"},
                       {"perspective", {{"yfov", std::numbers::pi / 3}, {"znear", 0.5}}}}};
  // At (0, 2, 10), turned 90° about +Y: looks along −X.
  b.addNode({{"camera", 0},
             {"translation", {0, 2, 10}},
             {"rotation", {0, std::sin(std::numbers::pi / 4), 0, std::cos(std::numbers::pi / 4)}}});
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->cameras.size(), 1u);
  const Camera& c = r->cameras[0];
  EXPECT_EQ(c.name, "eye");
  expectNear(c.position, {0, 2, 10});
  expectNear(c.target, {-1, 2, 10});
  expectNear(c.up, {0, 1, 0});
  EXPECT_NEAR(c.yfovDegrees, 60, 1e-4);
  EXPECT_EQ(c.znear, 0.5f);
  EXPECT_EQ(c.zfar, 1000.0f);  // absent zfar: infinite in glTF, our default far plane here
}

TEST(Gltf, ExternalBuffersLoadNextToTheFileUnlessReferencesAreOff) {
  TempDir dir;
  GltfBuilder b = oneTriangle();
  json doc = b.doc;
  doc["buffers"] = {{{"byteLength", b.buffer.size()}, {"uri", "tri.bin"}}};
  dir.write("tri.bin", b.buffer);
  std::string path = dir.write("tri.gltf", doc.dump());
  Result<Scene> r = loadGltf(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->triangleCount(), 1u);

  LoadOptions closed;
  closed.followReferences = false;
  Result<Scene> refused = loadGltfFromMemory(doc.dump(), path, closed);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(contains(refused.error().str(), "invalid glTF"));
}

}  // namespace
}  // namespace sv::formats

namespace sv::formats {
namespace {

// A glTF whose texture is a JPEG file beside it (issue 32: JPEG textures were refused): the
// crate sample with its PNG swapped for the same picture as a JPEG.
TEST(Gltf, ReadsJpegTextures) {
  const std::string crate = testing::readText(testing::sourcePath("scenes/crate.gltf"));
  nlohmann::json doc = nlohmann::json::parse(crate);
  ASSERT_FALSE(doc["images"].empty());
  // Decode the embedded PNG, re-encode it as a JPEG with TurboJPEG, point the image at it.
  Result<Scene> original = loadGltf(testing::sourcePath("scenes/crate.gltf"));
  ASSERT_TRUE(original.ok());
  const texture::LevelView png = original->textures[0].texture->level(0);
  const std::vector<uint8_t> rgba = texture::toSrgb8(png);
  tjhandle tj = tjInitCompress();
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  ASSERT_EQ(tjCompress2(tj, rgba.data(), png.width, 0, png.height, TJPF_RGBA, &jpeg, &size,
                        TJSAMP_444, 95, 0),
            0);
  testing::TempDir dir;
  dir.write("planks.jpg", std::string(reinterpret_cast<char*>(jpeg), size));
  tjFree(jpeg);
  tjDestroy(tj);
  doc["images"][0] = {{"uri", "planks.jpg"}};
  const std::string path = dir.write("crate.gltf", doc.dump());
  Result<Scene> s = loadGltf(path);
  ASSERT_TRUE(s.ok()) << s.error().str();
  ASSERT_EQ(s->textures.size(), 1u);
  EXPECT_EQ(s->textures[0].texture->level(0).width, png.width);
  EXPECT_EQ(s->textures[0].texture->level(0).height, png.height);
}

}  // namespace
}  // namespace sv::formats

namespace sv::formats {
namespace {

// MSFT_lod: the node's mesh and the meshes of the nodes its ids name become one level-of-detail
// group, the level nodes are not drawn on their own, and MSFT_screencoverage c becomes the range
// R/(tan 30° · 2·sqrt(c/π)) for the bounding radius R.
TEST(Gltf, MsftLodBecomesALevelOfDetailGroup) {
  GltfBuilder b;
  const int fine = b.addPositions({0, 0, 0, 2, 0, 0, 0, 2, 0});
  const int coarse = b.addPositions({0, 0, 0, 2, 0, 0, 0, 2, 1});
  const int indices = b.addIndices({0, 1, 2});
  const int meshA = b.addMesh({{"attributes", {{"POSITION", fine}}}, {"indices", indices}});
  const int meshB = b.addMesh({{"attributes", {{"POSITION", coarse}}}, {"indices", indices}});
  b.addNode({{"mesh", meshA},
             {"extensions", {{"MSFT_lod", {{"ids", {1}}}}}},
             {"extras", {{"MSFT_screencoverage", {0.5, 0.1}}}}});
  b.addNode({{"mesh", meshB}});
  b.doc["extensionsUsed"] = {"MSFT_lod"};
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->instances.size(), 1u);
  ASSERT_EQ(r->lodGroups.size(), 1u);
  const LodGroup& g = r->lodGroups[0];
  ASSERT_EQ(g.levels.size(), 2u);
  EXPECT_EQ(r->instances[0].lod, 0);
  EXPECT_EQ(r->instances[0].mesh, g.levels[0].mesh);
  const double radius = std::sqrt(8.0) / 2, tan30 = std::tan(std::numbers::pi / 6);
  EXPECT_NEAR(g.levels[0].to, radius / (tan30 * 2 * std::sqrt(0.5 / std::numbers::pi)), 1e-4);
  EXPECT_NEAR(g.levels[1].to, radius / (tan30 * 2 * std::sqrt(0.1 / std::numbers::pi)), 1e-4);
  EXPECT_TRUE(validate(r.value(), "t.gltf").ok());
  // A level of two primitives: drawn at full detail, and said so.
  b.doc["meshes"][1]["primitives"].push_back(b.doc["meshes"][1]["primitives"][0]);
  Result<Scene> two = load(b);
  ASSERT_TRUE(two.ok()) << two.error().str();
  EXPECT_EQ(two->instances[0].lod, -1);
  ASSERT_EQ(two->warnings.size(), 1u);
  EXPECT_TRUE(testing::contains(two->warnings[0], "nodes[0].MSFT_lod: a level of 2 primitives"));
}

}  // namespace
}  // namespace sv::formats

namespace sv::formats {
namespace {

// KHR_draco_mesh_compression: a primitive's Draco bufferView decodes (libdraco) to its triangles,
// positions within the quantization's step, texture coordinates too; corrupt data is named.
TEST(Gltf, ReadsDracoCompressedPrimitives) {
  // A 4 × 4 grid of quads in z = 0, with uvs, as a Draco mesh.
  std::vector<Vec3> corners;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (const auto& [dx, dy] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}})
        corners.push_back({float(x + dx), float(y + dy), 0});
  const int faces = int(corners.size() / 3);
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(faces);
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int tex = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  for (int f = 0; f < faces; ++f) {
    const Vec3* c = &corners[size_t(3 * f)];
    const float uv[3][2] = {
        {c[0].x / 4, c[0].y / 4}, {c[1].x / 4, c[1].y / 4}, {c[2].x / 4, c[2].y / 4}};
    builder.SetAttributeValuesForFace(pos, draco::FaceIndex(f), &c[0], &c[1], &c[2]);
    builder.SetAttributeValuesForFace(tex, draco::FaceIndex(f), uv[0], uv[1], uv[2]);
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  ASSERT_TRUE(mesh);
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 14);
  draco::EncoderBuffer encoded;
  ASSERT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &encoded).ok());

  GltfBuilder b;
  const size_t offset = b.buffer.size();
  b.buffer.append(encoded.data(), encoded.size());
  b.doc["bufferViews"].push_back(
      {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", encoded.size()}});
  b.doc["accessors"].push_back(
      {{"componentType", 5126}, {"count", mesh->num_points()}, {"type", "VEC3"}});
  b.doc["accessors"].push_back(
      {{"componentType", 5126}, {"count", mesh->num_points()}, {"type", "VEC2"}});
  b.addNode({{"mesh", b.addMesh({{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}},
                                 {"extensions",
                                  {{"KHR_draco_mesh_compression",
                                    {{"bufferView", 0},
                                     {"attributes",
                                      {{"POSITION", mesh->attribute(pos)->unique_id()},
                                       {"TEXCOORD_0", mesh->attribute(tex)->unique_id()}}}}}}}})}});
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  Result<Scene> r = load(b);
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->meshes.size(), 1u);
  const Mesh& m = r->meshes[0];
  ASSERT_EQ(m.triangleCount(), size_t(faces));
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  double area = 0;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const Vec3 a = m.positions[m.indices[t]], p = m.positions[m.indices[t + 1]],
               c = m.positions[m.indices[t + 2]];
    area += 0.5 * std::fabs(double(p.x - a.x) * (c.y - a.y) - double(p.y - a.y) * (c.x - a.x));
  }
  EXPECT_NEAR(area, 16, 1e-2);  // the grid's area, within the 14-bit quantization
  for (size_t i = 0; i < m.positions.size(); ++i) {
    EXPECT_NEAR(m.uvs[i].x, m.positions[i].x / 4, 1e-2);
    EXPECT_NEAR(m.uvs[i].y, m.positions[i].y / 4, 1e-2);
  }
  // With an indices accessor that has no bufferView — what Khronos' own sample (2CylinderEngine)
  // writes, valid for a Draco primitive and once refused ("accessor[2] invalid bufferView") —
  // the same mesh, from text and from GLB.
  GltfBuilder withIndices = b;
  withIndices.doc["accessors"].push_back(
      {{"componentType", 5125}, {"count", 3 * faces}, {"type", "SCALAR"}});
  withIndices.doc["meshes"][0]["primitives"][0]["indices"] = 2;
  TempDir dir;
  for (const std::string& path :
       {dir.write("d.gltf", withIndices.gltf()), dir.write("d.glb", withIndices.glb())}) {
    Result<Scene> r2 = loadScene(path);
    ASSERT_TRUE(r2.ok()) << r2.error().str();
    EXPECT_EQ(r2->meshes[0].positions, m.positions) << path;
    EXPECT_EQ(r2->meshes[0].indices, m.indices) << path;
  }
  // Corrupt bytes are refused with the place named.
  for (size_t i = 8; i < 24 && offset + i < b.buffer.size(); ++i) b.buffer[offset + i] = char(0xFF);
  Result<Scene> bad = load(b);
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(
      testing::contains(bad.error().str(), "meshes[0].primitives[0].KHR_draco_mesh_compression"))
      << bad.error().str();
}

}  // namespace
}  // namespace sv::formats
