// The JSON scene format (docs/scene-format.md): values land where they should, and every class
// of malformed input gives one error line naming the file, the place and the problem.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "formats/formats_test_util.h"
#include "synthvis/scene.h"

namespace sv::formats {
namespace {

using testing::contains;
using testing::dataPath;
using testing::expectLoadError;
using testing::sourcePath;
using testing::TempDir;

Result<Scene> parse(const std::string& body) { return parseJsonScene(body, "t.json"); }

// The error line of a text that must not parse.
std::string errorOf(const std::string& text) {
  Result<Scene> r = parse(text);
  EXPECT_FALSE(r.ok()) << "parsed: " << text;
  return r.ok() ? std::string() : r.error().str();
}

// `objects` spliced into a minimal valid scene.
std::string withObjects(const std::string& objects) {
  return R"({"synthvis": 1, "objects": [)" + objects + "]}";
}

using testing::expectNear;

// --- Values ---

TEST(JsonScene, ReadsEveryTopLevelSection) {
  Result<Scene> r = parse(R"({
    "synthvis": 1,
    "description": "all sections",
    "background": [0.1, 0.2, 0.3],
    "camera": {"name": "main", "position": [1, 2, 3], "target": [0, 1, 0], "up": [0, 0, 1],
               "yfov": 40, "near": 0.5, "far": 50},
    "light": {"direction": [0, -2, 0], "color": [2, 1, 0.5], "ambient": 0.1, "enabled": false},
    "materials": [{"name": "glass", "color": [0.5, 0.6, 0.7, 0.4], "doubleSided": true,
                   "unlit": true}],
    "objects": [{"name": "cube", "primitive": "box", "material": "glass"}]
  })");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  EXPECT_EQ(s.background, (Vec3{0.1f, 0.2f, 0.3f}));
  ASSERT_EQ(s.cameras.size(), 1u);
  const Camera& c = s.cameras[0];
  EXPECT_EQ(c.name, "main");
  EXPECT_EQ(c.position, (Vec3{1, 2, 3}));
  EXPECT_EQ(c.target, (Vec3{0, 1, 0}));
  EXPECT_EQ(c.up, (Vec3{0, 0, 1}));
  EXPECT_EQ(c.yfovDegrees, 40);
  EXPECT_EQ(c.znear, 0.5f);
  EXPECT_EQ(c.zfar, 50);
  EXPECT_EQ(s.light.direction, (Vec3{0, -1, 0}));  // normalized
  EXPECT_EQ(s.light.color, (Vec3{2, 1, 0.5f}));
  EXPECT_EQ(s.light.ambient, 0.1f);
  EXPECT_FALSE(s.light.enabled);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "glass");
  EXPECT_EQ(s.materials[0].baseColor, (Vec4{0.5f, 0.6f, 0.7f, 0.4f}));
  EXPECT_TRUE(s.materials[0].doubleSided);
  EXPECT_TRUE(s.materials[0].unlit);
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].name, "cube");
  EXPECT_EQ(s.meshes[0].material, 0);
  EXPECT_EQ(s.triangleCount(), 12u);
}

// A free-form object (SPEC §11): the convenience quadrics become their coefficients (inside
// F ≥ 0), perturbations keep their weights and nesting, and the material and transform apply.
TEST(JsonScene, ReadsFreeFormObjects) {
  const Result<Scene> r = parse(R"({"synthvis": 1, "materials": [{"name": "clay"}], "objects": [
    {"name": "blob", "material": "clay", "transform": {"translate": [1, 2, 3]}, "priority": 4,
     "freeform": {"quadric": "sphere", "center": [1, 0, 0], "radius": 2,
       "perturbations": [
         {"quadric": "ellipsoid", "radii": [1, 2, 4], "weight": -3,
          "perturbations": [{"quadric": "plane", "normal": [0, 2, 0], "d": 1}]},
         {"quadric": "general", "coefficients": [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}],
       "clip": [{"quadric": "plane", "normal": [0, 1, 0], "d": 0.5}]}}]})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r.value().freeForms.size(), 1u);
  const FreeFormObject& f = r.value().freeForms[0];
  EXPECT_EQ(f.name, "blob");
  EXPECT_EQ(f.material, 0);
  EXPECT_EQ(f.transform.m[3][1], 2.0f);
  // 1 − ((x − 1)² + y² + z²)/4
  const std::array<double, 10> sphere = {-0.25, -0.25, -0.25, 0, 0, 0, 0.5, 0, 0, 0.75};
  for (size_t i = 0; i < 10; ++i) EXPECT_NEAR(f.form.quadric[i], sphere[i], 1e-12) << i;
  ASSERT_EQ(f.form.perturbations.size(), 2u);
  const FreeFormNode& e = f.form.perturbations[0];
  EXPECT_EQ(e.weight, -3);
  EXPECT_NEAR(e.quadric[1], -0.25, 1e-12);  // 1 − x² − y²/4 − z²/16
  EXPECT_NEAR(e.quadric[2], -1.0 / 16, 1e-12);
  ASSERT_EQ(e.perturbations.size(), 1u);
  EXPECT_NEAR(e.perturbations[0].quadric[7], -1, 1e-12);  // 1 − y (the normal normalized)
  EXPECT_NEAR(e.perturbations[0].quadric[9], 0.5, 1e-12);
  EXPECT_EQ(f.form.perturbations[1].quadric[9], 10);
  ASSERT_EQ(f.form.clips.size(), 1u);
  EXPECT_NEAR(f.form.clips[0][9], 0.5, 1e-12);
  EXPECT_EQ(f.form.quadricCount(), 5);
}

TEST(JsonScene, DefaultsMatchTheSceneTypes) {
  Result<Scene> r = parse(R"({"synthvis": 1})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_TRUE(r->meshes.empty());
  EXPECT_TRUE(r->cameras.empty());
  EXPECT_EQ(r->background, Scene{}.background);
  EXPECT_EQ(r->light.direction, Light{}.direction);
}

// "lines": polylines (open, and closed back to their first point) and the settings.
TEST(JsonScene, ReadsPolylines) {
  Result<Scene> r = parse(R"({"synthvis": 1, "lines": {"width": 2, "depthBias": 0.01,
      "polylines": [{"points": [[0, 0, 0], [1, 0, 0], [1, 1, 0]], "color": [1, 0, 0]},
                    {"points": [[0, 0, 5], [1, 0, 5], [1, 1, 5]], "closed": true}]}})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->lines.size(), 2u + 3u);
  EXPECT_EQ(r->lines[1].a, (Vec3{1, 0, 0}));
  EXPECT_EQ(r->lines[1].b, (Vec3{1, 1, 0}));
  EXPECT_EQ(r->lines[0].color, (Vec3{1, 0, 0}));
  EXPECT_EQ(r->lines[4].a, (Vec3{1, 1, 5}));
  EXPECT_EQ(r->lines[4].b, (Vec3{0, 0, 5}));
  EXPECT_EQ(r->lines[4].color, (Vec3{1, 1, 1}));
  EXPECT_EQ(r->lineSettings.width, 2);
  EXPECT_FLOAT_EQ(r->lineSettings.depthBias, 0.01f);
}

// "volumes": settings, a generated volume placed by its transform, its transfer function; the
// errors name the key.
TEST(JsonScene, ReadsVolumes) {
  Result<Scene> r = parse(R"({"synthvis": 1, "volumes": {"step": 0.25, "termination": 0.01,
      "skipEmpty": false, "objects": [{"name": "ml", "generate": {"kind": "marschner-lobb",
      "size": 9}, "transform": {"translate": [1, 2, 3]}, "transfer": [{"value": 0.2,
      "color": [1, 0, 0], "opacity": 0}, {"value": 0.8, "opacity": 0.5}], "opacityUnit": 0.1,
      "shaded": false, "shell": {"quadric": "sphere", "center": [1, 1, 1], "radius": 1.2,
      "clip": [{"quadric": "plane", "normal": [0, 1, 0]}]}},
      {"generate": {"kind": "cloud", "size": 16, "seed": 7},
      "transfer": [{"value": 0, "opacity": 0.1}]}]}})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->volumes.size(), 2u);
  const VolumeObject& v = r->volumes[0];
  EXPECT_EQ(v.name, "ml");
  EXPECT_EQ(v.grid->nx, 9);
  EXPECT_EQ(v.transform.transformPoint({0, 0, 0}), (Vec3{1, 2, 3}));
  ASSERT_EQ(v.transfer.size(), 2u);
  EXPECT_EQ(v.transfer[0].color, (Vec3{1, 0, 0}));
  EXPECT_FLOAT_EQ(v.transfer[1].opacity, 0.5f);
  EXPECT_FLOAT_EQ(v.opacityUnit, 0.1f);
  EXPECT_FALSE(v.shaded);
  ASSERT_EQ(v.shell.size(), 2u);  // the sphere and its clip
  EXPECT_LT(v.shell[0][0], 0);    // r² − |q − c|², up to a positive factor
  EXPECT_NEAR(v.shell[0][9] / -v.shell[0][0], 1.44 - 3, 1e-5);
  EXPECT_EQ(r->volumes[1].name, "cloud");
  EXPECT_EQ(r->volumes[1].grid->ny, 4);
  EXPECT_FLOAT_EQ(r->volumeSettings.step, 0.25f);
  EXPECT_FALSE(r->volumeSettings.skipEmpty);
  auto error = [](const std::string& body) {
    Result<Scene> e = parse(R"({"synthvis": 1, "volumes": {"objects": [)" + body + "]}}");
    return e.ok() ? std::string("loaded") : e.error().str();
  };
  EXPECT_TRUE(contains(error(R"({"transfer": [{"value": 0}]})"), "one of 'file' and 'generate'"));
  EXPECT_TRUE(contains(error(R"({"generate": {"kind": "smoke"}, "transfer": [{"value": 0}]})"),
                       "unknown volume generator 'smoke'"));
  EXPECT_TRUE(contains(error(R"({"generate": {"kind": "cloud"}})"), "missing key 'transfer'"));
  EXPECT_TRUE(contains(error(R"({"generate": {"kind": "cloud"}, "transfer": [{"value": 1},
      {"value": 0}]})"),
                       "values must increase"));
  EXPECT_TRUE(contains(error(R"({"file": "x.nii", "transfer": [{"value": 0}]})"), "x.nii"));
  EXPECT_TRUE(contains(error(R"({"generate": {"kind": "cloud"}, "transfer": [{"value": 0}],
      "shell": {"quadric": "sphere", "perturbations": [{"quadric": "sphere", "weight": "x"}]}})"),
                       "weight"));
}

// A perturbed shell is the volume's free-form shell (it clips; a plain one bounds).
TEST(JsonScene, ReadsAFreeFormShell) {
  Result<Scene> r = parse(R"({"synthvis": 1, "volumes": {"objects": [{"generate": {"kind":
      "cloud", "size": 16}, "transfer": [{"value": 0, "opacity": 0.1}], "shell": {"quadric":
      "sphere", "radius": 0.5, "perturbations": [{"quadric": "sphere", "center": [0.5, 0, 0],
      "radius": 0.2, "weight": -2}]}}]}})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const VolumeObject& v = r->volumes[0];
  EXPECT_TRUE(v.shell.empty());
  ASSERT_TRUE(v.freeFormShell.has_value());
  ASSERT_EQ(v.freeFormShell->perturbations.size(), 1u);
  EXPECT_EQ(v.freeFormShell->perturbations[0].weight, -2);
}

TEST(JsonScene, ReadsACameraList) {
  Result<Scene> r =
      parse(R"({"synthvis": 1, "cameras": [{"name": "a"}, {"name": "b", "yfov": 30}]})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->cameras.size(), 2u);
  EXPECT_EQ(r->cameras[1].name, "b");
  EXPECT_EQ(r->cameras[1].yfovDegrees, 30);
}

TEST(JsonScene, ComposesTranslateRotateScaleAsTRS) {
  Result<Scene> r = parse(withObjects(R"({"primitive": "box", "transform": {
      "translate": [10, 0, 0], "rotate": {"axis": [0, 0, 1], "degrees": 90}, "scale": 2}})"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  // Scale (1,0,0) to (2,0,0), turn it to (0,2,0), then move it to (10,2,0).
  expectNear(r->instances[0].transform.transformPoint({1, 0, 0}), {10, 2, 0});
}

TEST(JsonScene, EulerAnglesTurnAboutXThenYThenZ) {
  Result<Scene> r =
      parse(withObjects(R"({"primitive": "box", "transform": {"rotate": [90, 90, 0]}})"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  // X by 90°: +Y → +Z; then Y by 90°: +Z → +X.
  expectNear(r->instances[0].transform.transformPoint({0, 1, 0}), {1, 0, 0});
}

TEST(JsonScene, MatrixIsColumnMajor) {
  Result<Scene> r = parse(withObjects(R"({"primitive": "box", "transform": {"matrix":
      [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  4, 5, 6, 1]}})"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  expectNear(r->instances[0].transform.transformPoint({0, 0, 0}), {4, 5, 6});
}

TEST(JsonScene, InlineMeshKeepsItsAttributes) {
  Result<Scene> r = parse(withObjects(R"({"name": "quad", "mesh": {
      "positions": [0, 0, 0,  1, 0, 0,  1, 1, 0,  0, 1, 0],
      "indices": [0, 1, 2,  0, 2, 3],
      "normals": [0, 0, 1,  0, 0, 1,  0, 0, 1,  0, 0, 1],
      "colors": [1, 0, 0, 1,  0, 1, 0, 1,  0, 0, 1, 0.5,  1, 1, 1, 1],
      "uvs": [0, 0,  1, 0,  1, 1,  0, 1]}})"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Mesh& m = r->meshes[0];
  EXPECT_EQ(m.name, "quad");
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(m.normals[3], (Vec3{0, 0, 1}));
  EXPECT_EQ(m.colors[2], (Vec4{0, 0, 1, 0.5f}));  // four numbers per vertex: RGBA
  EXPECT_EQ(m.uvs[2].x, 1);
}

TEST(JsonScene, InlineMeshWithoutIndicesUsesConsecutiveTriples) {
  Result<Scene> r = parse(withObjects(R"({"mesh": {
      "positions": [0, 0, 0,  1, 0, 0,  0, 1, 0,  0, 0, 1,  1, 0, 1,  0, 1, 1],
      "colors": [1, 0, 0,  1, 0, 0,  1, 0, 0,  0, 1, 0,  0, 1, 0,  0, 1, 0]}})"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->meshes[0].indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(r->meshes[0].colors[3], (Vec4{0, 1, 0, 1}));  // three numbers per vertex: RGB, a = 1
}

TEST(JsonScene, ObjectColourMakesOneSharedDerivedMaterial) {
  Result<Scene> r = parse(R"({"synthvis": 1,
      "materials": [{"name": "shiny", "doubleSided": true}],
      "objects": [{"primitive": "box", "material": "shiny", "color": [1, 0, 0]},
                  {"primitive": "box", "material": 0, "color": [1, 0, 0]},
                  {"primitive": "box", "color": [0, 1, 0]}]})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->materials.size(),
            3u);  // shiny, shiny in red (shared by two boxes), default in green
  EXPECT_EQ(r->meshes[0].material, r->meshes[1].material);
  const Material& red = r->materials[size_t(r->meshes[0].material)];
  EXPECT_EQ(red.baseColor, (Vec4{1, 0, 0, 1}));
  EXPECT_TRUE(red.doubleSided);  // everything but the colour comes from the named material
  EXPECT_EQ(r->materials[size_t(r->meshes[2].material)].baseColor, (Vec4{0, 1, 0, 1}));
}

// A colour's alpha below 1 is translucency, as "opacity" is — the format's own example calls such
// a material "glass" — on a material and on an object's colour; an alpha of 1 stays opaque, and a
// cut-out stays a cut-out.
TEST(JsonScene, AColoursAlphaBelowOneIsTranslucent) {
  Result<Scene> r = parse(R"({"synthvis": 1,
      "materials": [{"name": "glass", "color": [0.6, 0.7, 0.8, 0.5]},
                    {"name": "solid", "color": [0.6, 0.7, 0.8, 1]},
                    {"name": "leaf", "color": [1, 1, 1, 0.4], "alphaCutoff": 0.3}],
      "objects": [{"primitive": "box", "material": "solid", "color": [1, 0, 0, 0.25]}]})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->materials[0].alphaMode, AlphaMode::blend);
  EXPECT_FLOAT_EQ(r->materials[0].baseColor.w, 0.5f);
  EXPECT_EQ(r->materials[1].alphaMode, AlphaMode::opaque);
  EXPECT_EQ(r->materials[2].alphaMode, AlphaMode::mask);
  EXPECT_EQ(r->materials[size_t(r->meshes[0].material)].alphaMode, AlphaMode::blend);
}

TEST(JsonScene, EveryPrimitiveKindLoadsWithItsParameters) {
  Result<Scene> r = parse(withObjects(R"(
      {"primitive": "box", "size": [1, 2, 3]},
      {"primitive": "sphere", "radius": 2, "segments": 8, "rings": 4},
      {"primitive": "plane", "size": [4, 2], "subdivisions": [2, 3]},
      {"primitive": "checker", "size": 6, "squares": 3, "colors": [[1, 1, 1], [0, 0, 0, 1]]},
      {"primitive": "cylinder", "radius": 0.2, "height": 3, "segments": 5, "caps": false},
      {"primitive": "cone", "radius": 1, "height": 1, "segments": 6},
      {"primitive": "torus", "radius": 2, "tube": 0.5, "segments": 7, "sides": 4})"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  std::vector<size_t> triangles;
  for (const Mesh& m : r->meshes) triangles.push_back(m.triangleCount());
  EXPECT_EQ(triangles,
            (std::vector<size_t>{12, 2 * 8 * 3, 2 * 2 * 3, 2 * 9, 2 * 5, 2 * 6, 2 * 7 * 4}));
  EXPECT_EQ(r->meshes[3].colors.size(), 4u * 9u);
}

TEST(JsonScene, AllowsComments) {
  Result<Scene> r = parse("// a scene\n{\"synthvis\": 1 /* version */}");
  EXPECT_TRUE(r.ok()) << r.error().str();
}

// --- Errors: each class of malformed input ---

TEST(JsonScene, RejectsTruncatedFileWithLineAndColumn) {
  const std::string path = dataPath("scene/truncated.json");
  Result<Scene> r = loadScene(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().position, "5:1");
  EXPECT_TRUE(contains(r.error().str(), path + ":5:1: syntax error"));
  EXPECT_TRUE(contains(r.error().str(), "unexpected end of input"));
}

TEST(JsonScene, SyntaxErrorPointsAtTheOffendingCharacter) {
  Result<Scene> r = parse("{\n  \"synthvis\": 1,\n  \"objects\" []\n}");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().position, "3:13");
  EXPECT_TRUE(contains(r.error().str(), "t.json:3:13: "));
}

TEST(JsonScene, RejectsWrongTypeNamingThePath) {
  expectLoadError("scene/wrong_type.json",
                  "objects[2].transform.translate: expected an array of 3 numbers, got a string");
}

TEST(JsonScene, RejectsUnknownKeyAndSuggestsTheIntendedOne) {
  expectLoadError("scene/unknown_key.json",
                  "camera: unknown key 'postion' (did you mean 'position'?)");
}

TEST(JsonScene, RejectsMissingReferencedFile) {
  expectLoadError("scene/missing_mesh.json",
                  "objects[0].mesh: cannot open 'no_such_model.glb': no such file");
}

TEST(JsonScene, RejectsOtherFormatVersions) {
  expectLoadError("scene/version2.json",
                  "synthvis: unsupported format version 2 (this reader understands version 1)");
  EXPECT_TRUE(contains(errorOf(R"({"objects": []})"), "t.json: missing key 'synthvis'"));
  EXPECT_TRUE(contains(errorOf(R"({"synthvis": "1"})"), "unsupported format version \"1\""));
}

TEST(JsonScene, RejectsNonFiniteNumberWithItsPosition) {
  const std::string path = dataPath("scene/overflow.json");
  Result<Scene> r = loadScene(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().str(), path + ":3:51: number 1e999 is out of range (numbers must be finite)");
  // Finite in double but not in float, or simply absurd: refused by the limit on magnitude.
  EXPECT_TRUE(contains(errorOf(withObjects(R"({"primitive": "sphere", "radius": 1e300})")),
                       "objects[0].radius: 1e+300 is out of range"));
}

TEST(JsonScene, RejectsAbsurdSegments) {
  expectLoadError("scene/absurd_segments.json",
                  "objects[0].segments: 100000000 is out of range 3..4096");
  EXPECT_TRUE(contains(errorOf(withObjects(R"({"primitive": "torus", "sides": 2})")),
                       "objects[0].sides: 2 is out of range 3..4096"));
  EXPECT_TRUE(contains(errorOf(withObjects(R"({"primitive": "checker", "squares": [4, 0]})")),
                       "objects[0].squares[1]: 0 is out of range 1..4096"));
  EXPECT_TRUE(contains(errorOf(withObjects(R"({"primitive": "sphere", "segments": 12.5})")),
                       "objects[0].segments: expected an integer, got a number"));
}

// Malformed inputs the data files do not cover, one row each, with the reason.
// "priority" orders objects for hidden-surface masking: every instance an object makes gets it.
TEST(JsonScene, ObjectPriorityReachesEveryInstanceItMakes) {
  Result<Scene> r = parse(withObjects(
      R"({"primitive": "box", "priority": -3}, {"primitive": "sphere"},
         {"mesh": {"positions": [0,0,0, 1,0,0, 0,1,0], "indices": [0,1,2]}, "priority": 7})"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->instances.size(), 3u);
  EXPECT_EQ(r->instances[0].priority, -3);
  EXPECT_EQ(r->instances[1].priority, 0);
  EXPECT_EQ(r->instances[2].priority, 7);
  EXPECT_NE(errorOf(withObjects(R"({"primitive": "box", "priority": 1.5})"))
                .find("objects[0].priority: expected an integer"),
            std::string::npos);
}

TEST(JsonScene, RejectsEachMalformedClassWithAClearMessage) {
  struct Row {
    const char* text;
    const char* expected;
  };
  const Row rows[] = {
      // The top level must be an object.
      {"[1, 2]", "t.json: expected a JSON object at the top level, got an array"},
      // Two keys with one name: nlohmann would keep the last; a typo is likelier.
      {R"({"synthvis": 1, "light": {"ambient": 0.1, "ambient": 0.2}})",
       "t.json: light: duplicate key 'ambient'"},
      {R"({"synthvis": 1, "camera": {}, "cameras": []})", "use either 'camera' or 'cameras'"},
      {R"({"synthvis": 1, "background": [1, 1]})",
       "background: expected a colour [r, g, b] with components 0..1, got 2 elements"},
      {R"({"synthvis": 1, "background": [1, 2, 1]})", "background[1]: 2 is out of range 0..1"},
      {R"({"synthvis": 1, "camera": {"yfov": 180}})",
       "camera.yfov: 180 is out of range (0, 180) degrees"},
      {R"({"synthvis": 1, "camera": {"near": 10, "far": 5}})",
       "camera: far (5) must be greater than near (10)"},
      {R"({"synthvis": 1, "camera": {"position": [0, 0, 0]}})",
       "camera: position and target must differ"},
      {R"({"synthvis": 1, "camera": {"up": [0, 0, 1]}})", "camera: up must not be parallel"},
      {R"({"synthvis": 1, "light": {"direction": [0, 0, 0]}})",
       "light.direction: expected a non-zero vector"},
      {R"({"synthvis": 1, "light": {"enabled": 1}})",
       "light.enabled: expected true or false, got an integer"},
      {R"({"synthvis": 1, "materials": [{"name": "a"}, {"name": "a"}]})",
       "materials[1].name: duplicate material name 'a'"},
      {R"({"synthvis": 1, "materials": [{"name": "red"}], "objects": [{"primitive": "box", "material": "rde"}]})",
       "objects[0].material: no material named 'rde' (did you mean 'red'?)"},
      {R"({"synthvis": 1, "objects": [{"primitive": "box", "material": 0}]})",
       "objects[0].material: there are no materials"},
      {R"({"synthvis": 1, "objects": {}})", "objects: expected an array, got an object"},
      {R"({"synthvis": 1, "objects": [{}]})",
       "objects[0]: missing key 'mesh', 'primitive' or 'freeform'"},
      {R"({"synthvis": 1, "objects": [{"mesh": "a.obj", "primitive": "box"}]})",
       "one of 'mesh', 'primitive' or 'freeform', not several"},
      // Free forms (SPEC §11).
      {R"({"synthvis": 1, "objects": [{"freeform": {}}]})",
       "objects[0].freeform: missing key 'quadric'"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "torus"}}]})",
       "objects[0].freeform.quadric: unknown quadric 'torus'"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "sphere", "radius": -1}}]})",
       "objects[0].freeform.radius: expected a number greater than 0"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "sphere", "radii": [1, 1, 1]}}]})",
       "objects[0].freeform: unknown key 'radii'"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "sphere", "weight": 2}}]})",
       "objects[0].freeform.weight: 'weight' belongs to perturbations"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "cone", "angle": 90}}]})",
       "objects[0].freeform.angle: 90 is out of range"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "cylinder", "axis": [0, 0, 0]}}]})",
       "objects[0].freeform.axis: expected a non-zero vector"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "general", "coefficients": [1, 2]}}]})",
       "objects[0].freeform.coefficients: expected an array of 10 numbers, got 2 elements"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "sphere", "perturbations": [{"quadric": "sphere", "weight": "x"}]}}]})",
       "objects[0].freeform.perturbations[0].weight: expected a number, got a string"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "sphere", "perturbations": [{"quadric": "sphere", "clip": []}]}}]})",
       "objects[0].freeform.perturbations[0].clip: 'clip' belongs to the base quadric"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "cylinder", "clip": [{"quadric": "plane", "weight": 2}]}}]})",
       "objects[0].freeform.clip[0]: a clip is a plain quadric"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "sphere"}, "primitive": "box"}]})",
       "not several"},
      {R"({"synthvis": 1, "objects": [{"freeform": {"quadric": "sphere"}, "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,0,0, 0,0,0,1]}}]})",
       "freeForms[0]: transform is singular"},
      {R"({"synthvis": 1, "objects": [{"primitive": "teapot"}]})",
       "objects[0].primitive: unknown primitive 'teapot'"},
      {R"({"synthvis": 1, "objects": [{"primitive": "box", "radius": 1}]})",
       "objects[0]: unknown key 'radius'"},
      {R"({"synthvis": 1, "objects": [{"primitive": "sphere", "radius": -1}]})",
       "objects[0].radius: expected a number greater than 0, got -1"},
      {R"({"synthvis": 1, "objects": [{"primitive": "box", "transform": {"matrix": [1], "scale": 2}}]})",
       "'matrix' cannot be combined"},
      {R"({"synthvis": 1, "objects": [{"primitive": "box", "transform": {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,2]}}]})",
       "objects[0].transform.matrix: the last row (elements 3, 7, 11, 15) must be 0, 0, 0, 1"},
      {R"({"synthvis": 1, "objects": [{"primitive": "box", "transform": {"rotate": {"axis": [0, 1, 0]}}}]})",
       "objects[0].transform.rotate: expected {\"axis\""},
      {R"({"synthvis": 1, "objects": [{"mesh": {"positions": [0, 0, 0, 1, 0]}}]})",
       "objects[0].mesh.positions: expected a multiple of 3 numbers, got 5"},
      {R"({"synthvis": 1, "objects": [{"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "indices": [0, 1, 3]}}]})",
       "objects[0].mesh.indices[2]: expected a vertex index 0..2, got 3"},
      {R"({"synthvis": 1, "objects": [{"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "normals": [0, 0, 1]}}]})",
       "objects[0].mesh.normals: expected 9 numbers (3 per vertex), got 3"},
      {R"({"synthvis": 1, "objects": [{"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, "x"]}}]})",
       "objects[0].mesh.positions[8]: expected a number, got a string"},
      {R"({"synthvis": 1, "objects": [{"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "colors": [0,0,0, 0,0,0, 0,0,2]}}]})",
       "objects[0].mesh.colors[6]: value out of range 0..1"},
      {R"({"synthvis": 1, "objects": [{"mesh": ""}]})",
       "objects[0].mesh: expected a file path, got an empty string"},
      {R"({"synthvis": 1, "objects": [{"mesh": "model.fbx"}]})",
       "objects[0].mesh: cannot open 'model.fbx'"},
      {R"({"synthvis": 1, "lines": {"polylines": [{"points": [[0, 0, 0]]}]}})",
       "lines.polylines[0].points: a polyline needs at least 2 points"},
      {R"({"synthvis": 1, "lines": {"width": 0}})", "lines.width: "},
      {R"({"synthvis": 1, "lines": {"polylines": [{"color": [1, 0, 0]}]}})",
       "lines.polylines[0]: missing key 'points'"},
  };
  for (const Row& row : rows) {
    SCOPED_TRACE(row.text);
    EXPECT_TRUE(contains(errorOf(row.text), row.expected));
  }
}

TEST(JsonScene, RejectsNestingDeeperThanSixtyFourLevels) {
  std::string deep =
      R"({"synthvis": 1, "description": )" + std::string(100, '[') + std::string(100, ']') + "}";
  EXPECT_TRUE(contains(errorOf(deep), "nested more than 64 levels"));
}

TEST(JsonScene, RejectsScenesOverTheTriangleBudgetBeforeBuildingThem) {
  LoadOptions options;
  options.maxTriangles = 1000;
  Result<Scene> r = parseJsonScene(withObjects(R"({"primitive": "box"},
      {"primitive": "sphere", "segments": 64})"),
                                   "t.json", options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().str(), "t.json: objects[1]: the scene would have more than 1000 triangles");
}

// --- Referenced files ---

TEST(JsonScene, LoadsMeshesReferencedRelativeToTheSceneFile) {
  Result<Scene> r = loadScene(sourcePath("scenes/mixed.json"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_TRUE(validate(r.value(), "mixed").ok());
  // The checker, the house (2 meshes), the pyramid with its own material and again with "grey",
  // and the sphere.
  EXPECT_EQ(r->meshes.size(), 6u);
  EXPECT_EQ(r->triangleCount(), 2u * 144 + 16 + 6 + 6 + 2 * 48 * 23);
}

TEST(JsonScene, ReferencedFileIsLoadedOnceAndInstanced) {
  TempDir dir;
  dir.write("tri.gltf", testing::oneTriangle().gltf());
  std::string path = dir.write("s.json", withObjects(R"(
      {"mesh": "tri.gltf"},
      {"mesh": "tri.gltf", "transform": {"translate": [1, 0, 0]}},
      {"mesh": "tri.gltf", "transform": {"translate": [2, 0, 0]}})"));
  Result<Scene> r = loadScene(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->meshes.size(), 1u);
  ASSERT_EQ(r->instances.size(), 3u);
  EXPECT_EQ(r->instances[2].transform.transformPoint({0, 0, 0}), (Vec3{2, 0, 0}));
  EXPECT_EQ(r->triangleCount(), 3u);
}

TEST(JsonScene, NestedErrorsAreChainedIntoOneLine) {
  TempDir dir;
  dir.write("sub/inner.json", "{\n  \"synthvis\": 1,\n  \"objects\": 5\n}");
  std::string path = dir.write("outer.json", withObjects(R"({"mesh": "sub/inner.json"})"));
  Result<Scene> r = loadScene(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().str(), path + ": objects[0].mesh: cannot load 'sub/inner.json': " +
                                 dir.path("sub/inner.json") +
                                 ": objects: expected an array, got an integer");
}

TEST(JsonScene, RejectsReferenceCycles) {
  TempDir dir;
  dir.write("a.json", withObjects(R"({"mesh": "b.json"})"));
  dir.write("b.json", withObjects(R"({"mesh": "a.json"})"));
  Result<Scene> r = loadScene(dir.path("a.json"));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(
      contains(r.error().str(),
               "'a.json' refers back to a scene that is being loaded (a.json → b.json → a.json)"));
  // A file that includes itself.
  dir.write("self.json", withObjects(R"({"mesh": "./self.json"})"));
  EXPECT_TRUE(contains(loadScene(dir.path("self.json")).error().str(), "refers back"));
}

TEST(JsonScene, AllowsEightLevelsOfNestingButNotNine) {
  TempDir dir;
  // level0.json → level1.json → … → level9.json, the last one holding a box.
  for (int i = 0; i < 9; ++i)
    dir.write("level" + std::to_string(i) + ".json",
              withObjects(R"({"mesh": "level)" + std::to_string(i + 1) + R"(.json"})"));
  dir.write("level9.json", withObjects(R"({"primitive": "box"})"));
  Result<Scene> deepest = loadScene(dir.path("level1.json"));  // 8 references below it
  ASSERT_TRUE(deepest.ok()) << deepest.error().str();
  EXPECT_EQ(deepest->triangleCount(), 12u);
  Result<Scene> tooDeep = loadScene(dir.path("level0.json"));  // 9 references below it
  ASSERT_FALSE(tooDeep.ok());
  EXPECT_TRUE(contains(tooDeep.error().str(), "scene files are nested more than 8 deep"));
}

TEST(JsonScene, RefusesAllFilesWhenReferencesAreDisabled) {
  LoadOptions options;
  options.followReferences = false;
  Result<Scene> r = parseJsonScene(withObjects(R"({"mesh": "pyramid.gltf"})"),
                                   sourcePath("scenes/x.json"), options);
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(
      r.error().str(),
      "objects[0].mesh: cannot open 'pyramid.gltf' (references to other files are disabled)"));
}

TEST(JsonScene, MaterialOverrideAppliesToEveryMeshOfAReferencedFile) {
  Result<Scene> r = parseJsonScene(R"({"synthvis": 1, "materials": [{"name": "grey"}],
      "objects": [{"mesh": "house.obj", "material": "grey"}]})",
                                   sourcePath("scenes/x.json"));
  ASSERT_TRUE(r.ok()) << r.error().str();
  EXPECT_EQ(r->materials.size(), 1u);  // the house's own materials are not needed
  for (const Mesh& m : r->meshes) EXPECT_EQ(m.material, 0);
}

}  // namespace
}  // namespace sv::formats

namespace sv::formats {
namespace {

// "lodGroups" and objects with "lod" (docs/scene-format.md#levels-of-detail): one mesh a level,
// its own placement built in; every placement of "at" an instance of the group's level 0; and on
// the ground with "onGround".
TEST(JsonScene, ReadsLevelOfDetailGroupsAndTheirPlacements) {
  Result<Scene> r = parse(R"({"synthvis": 1,
    "terrain": [{"generate": {"size": 65, "spacing": 10, "relief": 50, "seed": 4}}],
    "lodGroups": {"tree": {"fade": 5, "levels": [
      {"to": 50, "primitive": "sphere", "radius": 2, "transform": {"translate": [0, 3, 0]}},
      {"to": 200, "primitive": "box", "size": [1, 1, 1], "color": [0, 1, 0]}]}},
    "objects": [
      {"lod": "tree", "at": [[1, 0, 2], [10, 5, -20, 90, 2]]},
      {"lod": "tree", "onGround": true, "at": [[30, 1.5, 40]]},
      {"lod": "tree", "transform": {"translate": [7, 8, 9]}}]})");
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  ASSERT_EQ(s.lodGroups.size(), 1u);
  const LodGroup& g = s.lodGroups[0];
  EXPECT_EQ(g.name, "tree");
  EXPECT_EQ(g.fade, 5);
  ASSERT_EQ(g.levels.size(), 2u);
  EXPECT_EQ(g.levels[0].to, 50);
  EXPECT_EQ(g.levels[1].to, 200);
  // Level 0's translate is built into its mesh: the sphere's centre at y = 3.
  const auto box = s.meshes[size_t(g.levels[0].mesh)].bounds();
  EXPECT_NEAR((box[0].y + box[1].y) / 2, 3, 1e-5);
  ASSERT_EQ(s.instances.size(), 4u);
  for (const Instance& i : s.instances) {
    EXPECT_EQ(i.lod, 0);
    EXPECT_EQ(i.mesh, g.levels[0].mesh);
  }
  expectNear(s.instances[0].transform.transformPoint({0, 0, 0}), {1, 0, 2});
  // Heading 90° about +y, scale 2: +x goes to −z, twice as far.
  expectNear(s.instances[1].transform.transformPoint({1, 0, 0}), {10, 5, -22});
  // On the ground: 1.5 m above the terrain's surface there.
  const Vec3 onGround = s.instances[2].transform.transformPoint({0, 0, 0});
  EXPECT_EQ(onGround.x, 30);
  EXPECT_EQ(onGround.z, 40);
  EXPECT_NE(onGround.y, 1.5f);
  EXPECT_LE(std::fabs(onGround.y - 1.5f), 50.0f);  // within the relief
  expectNear(s.instances[3].transform.transformPoint({0, 0, 0}), {7, 8, 9});
  EXPECT_TRUE(validate(s, "t.json").ok());

  // Mistakes, each named.
  const std::string group = R"("lodGroups": {"g": {"levels": [{"to": 10, "primitive": "box"}]}})";
  EXPECT_TRUE(contains(errorOf(R"({"synthvis": 1, )" + group + R"(, "objects": [{"lod": "h"}]})"),
                       "t.json: objects[0].lod: no level-of-detail group 'h' in 'lodGroups'"));
  EXPECT_TRUE(contains(errorOf(R"({"synthvis": 1, "lodGroups": {"g": {"levels": [
      {"to": 10, "primitive": "box"}, {"to": 5, "primitive": "box"}]}}})"),
                       "lodGroups.g.levels[1].to: must exceed 10"));
  EXPECT_TRUE(contains(errorOf(R"({"synthvis": 1, "lodGroups": {"g": {"fade": 8, "levels": [
      {"to": 10, "primitive": "box"}, {"to": 15, "primitive": "box"}]}}})"),
                       "8 is longer than level 1's span [10, 15)"));
  EXPECT_TRUE(contains(errorOf(R"({"synthvis": 1, "lodGroups": {"g": {"levels": [
      {"primitive": "box"}]}}})"),
                       "lodGroups.g.levels[0]: missing key 'to'"));
  EXPECT_TRUE(contains(errorOf(R"({"synthvis": 1, "lodGroups": {"g": {"levels": [
      {"to": 3, "freeform": {"quadric": "sphere"}}]}}})"),
                       "a level of detail is a mesh, not a free form"));
  EXPECT_TRUE(contains(
      errorOf(R"({"synthvis": 1, )" + group + R"(, "objects": [{"lod": "g", "onGround": true}]})"),
      "objects[0]: no terrain under (0, 0) to stand on"));
  EXPECT_TRUE(contains(
      errorOf(R"({"synthvis": 1, )" + group + R"(, "objects": [{"lod": "g", "at": [[1, 2]]}]})"),
      "objects[0].at[0]: expected [x, y, z]"));
  EXPECT_TRUE(contains(errorOf(R"({"synthvis": 1, )" + group +
                               R"(, "objects": [{"lod": "g", "primitive": "box"}]})"),
                       "one of 'mesh', 'primitive', 'freeform' or 'lod'"));
}

}  // namespace
}  // namespace sv::formats

namespace sv::formats {
namespace {

// A scene file placed by another keeps its levels of detail: its groups come along, renumbered,
// and its instances still name them (a database of tiles referencing tiles).
TEST(JsonScene, AReferencedFileKeepsItsLevelsOfDetail) {
  TempDir dir;
  dir.write("tile.json", R"({"synthvis": 1,
    "lodGroups": {"tree": {"levels": [{"to": 50, "primitive": "sphere"},
                                      {"to": 200, "primitive": "box"}]}},
    "objects": [{"lod": "tree", "at": [[0, 0, 0], [5, 0, 0]]}]})");
  const std::string path = dir.write("world.json", R"({"synthvis": 1,
    "objects": [{"primitive": "box"},
                {"mesh": "tile.json", "transform": {"translate": [100, 0, 0]}},
                {"mesh": "tile.json", "transform": {"translate": [200, 0, 0]}}]})");
  Result<Scene> r = loadScene(path);
  ASSERT_TRUE(r.ok()) << r.error().str();
  const Scene& s = r.value();
  ASSERT_EQ(s.lodGroups.size(), 1u);  // placed once, instanced twice
  ASSERT_EQ(s.instances.size(), 5u);
  EXPECT_EQ(s.instances[0].lod, -1);
  for (size_t i = 1; i < 5; ++i) {
    EXPECT_EQ(s.instances[i].lod, 0);
    EXPECT_EQ(s.instances[i].mesh, s.lodGroups[0].levels[0].mesh);
  }
  EXPECT_NE(s.lodGroups[0].levels[0].mesh, 0);  // renumbered after the box
  EXPECT_TRUE(validate(s, path).ok());
}

}  // namespace
}  // namespace sv::formats
