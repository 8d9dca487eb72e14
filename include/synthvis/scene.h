// The scene database (SPEC §1, stage 1): what the readers (synthvis/formats.h) and generators
// build, and what the renderer consumes.
//
// A Scene is plain data: meshes (triangle lists with per-vertex attributes), materials, instances
// placing meshes in the world, cameras, one directional light and a background colour.
// Colours are linear-light RGB(A) in [0, 1].
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "synthvis/free_forms.h"
#include "synthvis/geodesy.h"
#include "synthvis/height_field.h"
#include "synthvis/light_points.h"
#include "synthvis/lines.h"
#include "synthvis/math.h"
#include "synthvis/result.h"
#include "synthvis/volumes.h"

namespace sv::texture {
class Texture;  // src/texture/texture.h: a decoded image, its MIP pyramid and wrap modes
}

namespace sv::scene {

// How a texture map is sampled (SPEC §7; docs/quality.md compares them): nearest texel; the seed's
// three-point interpolation ("tri3"); bilinear; the trilinear blends of those between pyramid
// levels ("trilinear3", "trilinear"); anisotropic (trilinear probes along the pixel footprint's
// major axis); `point`, the nearest texel of the full-resolution image, no pyramid (aliases: the
// reference that, supersampled, gives docs/quality.md's ground truth). `inherit` (materials only):
// the frame's choice, RenderOptions::textureFilter.
enum class TextureFilter : uint8_t {
  inherit,
  point,
  nearest,
  threePoint,
  bilinear,
  trilinearThreePoint,
  trilinear,
  anisotropic,
};

// By name, as the CLI's --texture-filter and the scene format's "textureFilter" write them:
// point, nearest, tri3, bilinear, trilinear3, trilinear, aniso.
Result<TextureFilter> parseTextureFilter(const std::string& name);
const char* textureFilterName(TextureFilter filter);

// How a material's alpha (base colour alpha × vertex alpha × texel alpha) is used (glTF's
// alphaMode): ignored; blended over what lies behind (translucency, SPEC §8); or a cut-out, the
// pixel drawn opaque where alpha ≥ alphaCutoff and not at all elsewhere.
enum class AlphaMode : uint8_t { opaque, blend, mask };

struct Material {
  std::string name;
  Vec4 baseColor{1, 1, 1, 1};  // linear RGBA, multiplies vertex colours (and the texture)
  bool doubleSided = false;    // if false, back faces are culled when culling is on
  bool unlit = false;          // if true, the lights are ignored (colour used as is)
  // Base-colour texture map, an index into Scene::textures (−1: none). Its colour multiplies the
  // base colour, at texture coordinates from the mesh's uvs (u right, v down the image, glTF's
  // convention); a mesh without uvs reads texel (0, 0).
  int texture = -1;
  TextureFilter textureFilter = TextureFilter::inherit;
  Vec2 uvScale{1, 1};  // multiplies the mesh's uvs (repeats the texture uvScale times)
  // Lighting per pixel (SPEC §8, seed 003's Phong weighting) instead of per vertex (Gouraud):
  //   C = (Q_amb·C_amb + Q_diff·C_diff + Q_spec·C_spec) / (Q_amb + Q_diff + Q_spec)
  // with Q_amb = the light's ambient, Q_diff = 1 − Q_amb, Q_spec = `specular`, and `shininess` the
  // exponent p of (r·v)^p. With specular = 0 it is the Gouraud formula evaluated per pixel.
  bool phong = false;
  float specular = 0;
  float shininess = 32;
  AlphaMode alphaMode = AlphaMode::opaque;
  float alphaCutoff = 0.5f;

  // True when pixels need more than the interpolated vertex colour: a texture, per-pixel light,
  // or an alpha that matters.
  bool needsPixelShading() const { return texture >= 0 || phong || alphaMode != AlphaMode::opaque; }
};

// A texture map shared by materials. Loaders decode images to linear light and build the pyramid
// once (texture.h); several materials, and several scenes, may share one.
struct TextureMap {
  std::string name;  // file name or glTF image name, for messages
  std::shared_ptr<const texture::Texture> texture;
};

// An indexed triangle list. `positions` is required; every other attribute array is either empty
// or has exactly positions.size() entries. `indices` holds 3 entries per triangle, each
// < positions.size(). Loaders guarantee these invariants (`validate` checks them).
struct Mesh {
  std::string name;
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;
  std::vector<Vec4> colors;  // linear RGBA
  std::vector<Vec2> uvs;
  std::vector<uint32_t> indices;
  int material = -1;  // index into Scene::materials, or −1 for the default white material

  size_t triangleCount() const { return indices.size() / 3; }
  // The smallest and largest coordinates of its positions, in its own space ({0, 0, 0} twice for
  // a mesh without positions).
  std::array<Vec3, 2> bounds() const;
};

// A mesh placed in the world.
struct Instance {
  int mesh = 0;  // index into Scene::meshes (with `lod`: its level 0, the full detail)
  Mat4 transform;
  // Priority for hidden-surface masking (SPEC §4, RenderOptions::hsr): opaque instances are drawn
  // in increasing priority, those of equal priority nearest first. 0 unless the scene says.
  int priority = 0;
  // Levels of detail (SPEC §1 traversal): an index into Scene::lodGroups, whose level 0 is `mesh`;
  // −1: `mesh` at every range.
  int lod = -1;
  // False: not drawn (a switch turned it off; applyArticulations sets it from Scene::switches).
  bool visible = true;
  // True: a degree of freedom moves it (applyArticulations sets its transform from Scene::dofs);
  // the instance tree leaves it out and it is culled on its own.
  bool articulated = false;
};

// Levels of detail shared by the instances that name the group (docs/scene-format.md "Levels of
// detail"). An instance draws level i while its range r lies in [levels[i−1].to, levels[i].to) and
// nothing beyond the last level's `to`; r is the distance from the eye to the centre of the box
// around all levels (in world units, through the instance's transform), times tan(v/2)/tan 30°
// for the view's vertical half-angle v — the same projected size under a zoomed view — and times
// RenderOptions::lodScale. Across the last `fade` units below each `to`, level i dissolves into
// level i+1 (or into nothing) by complementary screen-door patterns: every pixel is drawn by
// exactly one of the two, so nothing pops and nothing is drawn twice.
struct LodLevel {
  int mesh = 0;                  // index into Scene::meshes
  float to = 1e30f;              // the range at which this level gives way to the next, > 0
};
struct LodGroup {
  std::string name;
  std::vector<LodLevel> levels;  // 1 … kMaxLodLevels, `to` increasing
  float fade = 0;                // the dissolve band below each switch, ≥ 0, < each level's span
  // The point ranges are measured to, in the instance's own space (OpenFlight's LOD centre);
  // empty: the centre of the box around all levels.
  std::optional<Vec3> center;
};
inline constexpr size_t kMaxLodLevels = 8;

// A bounding-volume hierarchy over a scene's first `instanceCount` instances (their world boxes
// around all their levels of detail), which the renderer culls against each view before the vertex
// stage (SPEC §1 traversal). Those instances must not move, change mesh or change level of detail
// group while the tree is held (rebuild it: buildInstanceTree); instances after them are culled one
// by one.
struct InstanceTree {
  struct Node {
    Vec3 lo, hi;               // world box of everything below
    uint32_t first = 0;        // leaf: into `order`; inner: the first of two children, adjacent
    uint32_t count = 0;        // leaf: its instances (> 0); 0: an inner node
    uint64_t triangles = 0;    // below it, at full detail (statistics of what culling dropped)
  };
  std::vector<Node> nodes;     // nodes[0] the root (none for a scene without instances)
  std::vector<uint32_t> order;  // instance indices, each leaf's a contiguous range
  size_t instanceCount = 0;
  // The articulated instances below instanceCount, which the tree leaves out (they move).
  std::vector<uint32_t> loose;

  // Hierarchical levels of detail (mergeFarLevels): nearby instances' small far levels merged
  // into one mesh per cell, drawn as one when every member would draw that level alone (its range
  // within [from, until)) — a few hundred draws instead of thousands of ten-triangle ones. A cell
  // `beyond` its members' last level has no mesh: while all of them are beyond it, none is visited.
  struct Cell {
    bool beyond = false;
    Mesh mesh;          // the members' level meshes, their vertices placed in the world
    std::array<Vec3, 2> bounds;  // the mesh's (Mesh::bounds)
    Vec3 rangeLo, rangeHi;  // the box around the members' range points (LodGroup), world
    double from = 0, until = 0;  // the range band in which each member draws `level` alone
    int level = 0;
    int priority = 0;   // the members' Instance::priority
    uint32_t firstMember = 0, memberCount = 0;  // into `members`
    uint64_t fullTriangles = 0;  // the members' at full detail (statistics: what was not drawn)
  };
  std::vector<Cell> cells;
  std::vector<uint32_t> members;  // instance indices, each cell's a contiguous range
};

// Articulations (SPEC §1 traversal; docs/scene-format.md "Switches and degrees of freedom"): the
// parts of a model the host drives between frames — a switch chooses which of its children are
// drawn (damaged or intact, gear up or down), a degree of freedom moves its parts (a turret, a
// rudder, a door). Both hold instance indices; applyArticulations turns their current settings
// into Instance::visible and Instance::transform.
struct Switch {
  std::string name;
  std::vector<std::vector<uint32_t>> children;  // per child, the instances below it
  // Per mask, one flag per child (true: drawn); `current` indexes it. An instance below several
  // switches is drawn only where all of them draw it.
  std::vector<std::vector<bool>> masks;
  size_t current = 0;
};

// A degree of freedom: its parts move by M = T(translate) · R · S(scale) about its own frame, the
// rotation R = Rx(pitch) · Ry(roll) · Rz(yaw) in degrees — yaw applied first, as OpenSceneGraph
// reads OpenFlight's DOF records (axes: x right, y forward, z up, in the frame). The world transform of a part is A(d) · part, where
//   A(d) = A(parent) · place · frame · M · frame⁻¹,   A(−1) = identity,
// `place` taking the DOF node's space to the space its parent moves (or the world), `frame` the
// DOF's own origin and axes in the node's space.
struct DofMotion {
  Vec3 translate{0, 0, 0};
  Vec3 rotate{0, 0, 0};  // degrees: pitch (about x), roll (about y), yaw (about z)
  Vec3 scale{1, 1, 1};
};
struct Dof {
  std::string name;
  int parent = -1;  // the enclosing degree of freedom (an earlier index), or −1
  Mat4 place;
  Mat4 frame;       // rigid: orthonormal axes and an origin
  DofMotion current, min, max;  // current is clamped to [min, max] componentwise
  std::vector<std::pair<uint32_t, Mat4>> parts;  // instances, each with its transform in the node
};
// The motion matrix T·R·S of `m`.
Mat4 dofMatrix(const DofMotion& m);

// A free form placed in the world: rendered directly by multi-level ray casting (SPEC §12), never
// tessellated, in the same depth and frame buffer as the polygons.
struct FreeFormObject {
  std::string name;
  FreeFormNode form;
  Mat4 transform;     // object → world; affine (last row 0, 0, 0, 1) and invertible
  int material = -1;  // index into Scene::materials, or −1 for the default material
};

// A height-field ground (SPEC §11–§12; docs/terrain.md; the scene format's "terrain"): drawn by
// multi-level ray casting, never tessellated, in the same depth and samples as everything else.
// World placement: map east is +x, north is −z, height +y; the map position `origin` (metres)
// lies at the world origin. Base: the plane y = 0, or a sphere of radius `baseRadius` through
// the origin (centre (0, −baseRadius, 0)), heights along its radius.
struct Terrain {
  std::string name;
  std::shared_ptr<const HeightField> heights;  // the table (synthvis/height_field.h)
  double origin[2] = {0, 0};  // map (east, north), metres, at the world origin
  double baseRadius = 0;      // 0: a plane
  bool bicubic = false;       // interpolation below the finest level (else bilinear)
  int material = -1;          // colour (multiplies the image or ramp), light, texture filter
  // The draped image (seed 001's planar texture, SPEC §7): Scene::textures index, or −1; its
  // corners in map metres: west, south, east, north. Without one, `ramp` colours by height.
  int image = -1;
  double imageBounds[4] = {0, 0, 1, 1};
  // An optional detail texture repeated every detailSize metres, multiplying the colour by
  // 2·texel (a mid-grey detail leaves it unchanged on average).
  int detail = -1;
  double detailSize = 10;
  std::vector<TerrainColorStop> ramp;  // by height, ascending; empty: the default (terrain.md)
};

struct Camera {
  std::string name;
  Vec3 position{0, 0, 5};
  Vec3 target{0, 0, 0};
  Vec3 up{0, 1, 0};
  float yfovDegrees = 60.0f;  // vertical field of view
  float znear = 0.1f;
  float zfar = 1000.0f;
};

// A display channel (SPEC §9; docs/scene-format.md "Channels"): one of the N views that make a
// frame, all of one scene at one instant, each from the scene camera's eyepoint turned and moved by
// the channel's own orientation and offset, through its own (possibly asymmetric) frustum, at its
// own resolution. Renderer::renderChannels draws them all in one call.
struct ChannelFrustum {
  // Half-angles of the view window from the channel's axis, degrees in (−90, 90), signed: left and
  // down negative for a window around the axis; left < right, down < up.
  float leftDegrees = -30, rightDegrees = 30, downDegrees = -20, upDegrees = 20;
};
struct Channel {
  std::string name;  // letters, digits, '-' and '_' (it names the channel's image file)
  // Orientation relative to the scene camera's view, degrees, applied in this order about the
  // channel's own axes (heading, then pitch, then bank): yaw positive turns the view to the right
  // (−180…180), pitch positive up (−90…90), roll positive leans the image's up to the right
  // (−180…180).
  float yawDegrees = 0, pitchDegrees = 0, rollDegrees = 0;
  // The channel's eye in the camera's eye space (x right, y up, z toward the viewer), metres.
  Vec3 offset{0, 0, 0};
  // Empty: symmetric, from the camera's yfovDegrees and this channel's width / height.
  std::optional<ChannelFrustum> frustum;
  int width = 640, height = 480;  // pixels, 1 … 8192 each
};
inline constexpr size_t kMaxChannels = 16;  // per scene (seed 002's video channel had up to 8)

// `n` channels (1 … kMaxChannels) abutting in an arc of `totalHorizontalDegrees` (0 < total <
// 180·n, each channel < 180) centred on the camera's view: channel i spans
// [−total/2 + i·total/n, −total/2 + (i+1)·total/n], as a yaw to its centre and a symmetric window
// of ±total/(2n). Each is width × height pixels; its vertical window is ±verticalFovDegrees/2, or
// for verticalFovDegrees = 0 the one that makes pixels square (tan v/2 = tan(h/2)·height/width).
// Named "0", "1", … from the left.
std::vector<Channel> arcChannels(int n, float totalHorizontalDegrees, int width, int height,
                                 float verticalFovDegrees = 0);

// One directional light for Gouraud shading (SPEC §8): per-vertex intensity
// ambient + diffuse·max(0, n·l), interpolated across the triangle.
struct Light {
  Vec3 direction{-0.4f, -1.0f, -0.6f};  // the direction the light travels (toward the scene)
  Vec3 color{1, 1, 1};
  float ambient = 0.25f;
  bool enabled = true;
};

// A light at a point (no fall-off with distance), used by Phong materials per pixel and by Gouraud
// ones per vertex, in addition to the directional light.
struct PointLight {
  Vec3 position{0, 0, 0};  // world space
  Vec3 color{1, 1, 1};
};

// Fog / haze (SPEC §8, seed 002): C_s = C_c·2^(−β·r) + C_F·(1 − 2^(−β·r)), r the true distance
// from the eye to the point (not window depth), in scene units.
struct Fog {
  bool enabled = false;
  Vec3 color{0.6f, 0.65f, 0.7f};  // C_F, linear
  float beta = 0;                 // per scene unit; the colour halves every 1/β units
};

// Where the database lies on the Earth (docs/scene-format.md, "Geodetic frame"): the geodetic
// position of the world origin, and whether the ground curves with the Earth. Geographic height
// tables and draped images are placed by it, and the IG places its entities by it
// (synthvis/geodesy.h: one conversion for both).
struct Geodetic {
  GeoPoint origin;
  bool curved = false;
  GeoFrame frame() const { return GeoFrame(origin, curved); }
};

struct Scene {
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Instance> instances;
  std::vector<FreeFormObject> freeForms;
  std::vector<Terrain> terrains;
  std::vector<Camera> cameras;  // the first one is used unless another is chosen
  // The display channels (SPEC §9), at most kMaxChannels; empty: the classic single view.
  std::vector<Channel> channels;
  Light light;
  std::vector<PointLight> pointLights;
  Fog fog;
  std::vector<TextureMap> textures;
  Vec3 background{0.05f, 0.06f, 0.09f};
  std::vector<LodGroup> lodGroups;
  std::vector<Switch> switches;
  std::vector<Dof> dofs;
  // The hierarchy over the first instances (buildInstanceTree), shared by copies of the scene;
  // null: every instance is culled on its own.
  std::shared_ptr<const InstanceTree> instanceTree;
  // Light points (SPEC §13; synthvis/light_points.h): drawn last, over everything, depth-tested.
  std::vector<LightAppearance> lightAppearances;
  std::vector<LightPoint> lightPoints;
  std::vector<LightGroup> lightGroups;  // the host switches and dims them between frames
  LightSettings lightSettings;
  StarField stars;
  // Lines (LineSegment): drawn after the opaque surfaces, depth-tested and writing depth.
  std::vector<LineSegment> lines;
  LineSettings lineSettings;
  // Voxel volumes (synthvis/volumes.h): ray cast after the opaque surfaces, composited front to
  // back over them, before the translucent polygons.
  std::vector<VolumeObject> volumes;
  VolumeSettings volumeSettings;
  // Simulation time, seconds: what blinking, sequences and the stars' rotation are functions of.
  double time = 0;
  // The database's place on the Earth; nothing: not stated (a geographic table is then placed by
  // a frame at its own centre).
  std::optional<Geodetic> geodetic;
  // What a loader read but does not draw, one line each naming the file and the part ("…: 2
  // primitives of points are not drawn"), and "nothing to draw" for a file that holds nothing
  // drawable: never a silently empty image. The CLI prints them.
  std::vector<std::string> warnings;

  size_t triangleCount() const;  // over all instances
  // Material `index` (a Mesh's or a FreeFormObject's), or the default Material for −1 (none).
  const Material& materialAt(int index) const;
};

// Checks the invariants stated on Mesh and Instance; the error names `file`. `vertexData = false`
// leaves out the two checks that read every vertex and index (positions finite, indices in range):
// the renderer makes them as its vertex stage reads the data anyway, and asks for the full check
// only to name the offender.
Status validate(const Scene& scene, const std::string& file, bool vertexData = true);

// Sets every switched instance's `visible` and every articulated instance's transform from the
// switches' current masks and the degrees of freedom's current motions (clamped to their limits).
void applyArticulations(Scene& scene);

// Builds scene.instanceTree over all of its instances (valid meshes and transforms assumed: run
// validate first). Binned by the centres of the instances' world boxes, leaves of at most 8; with
// its merged cells (mergeFarLevels).
void buildInstanceTree(Scene& scene);
// Fills tree.cells for the instances the tree holds: for each level of detail beyond the first
// whose mesh is small (at most kMergeTriangles) and not translucent, the instances drawing it are
// grouped by their range band, material, priority, attributes and a grid cell of the band's
// quarter width (at most half its start); a cell of two or more members gets one mesh of all
// their level meshes placed in the world (at most kMergeVertices over all cells, in the order the
// cells are found). Beyond a group's last level (a finite `to`), cells of half its range without
// a mesh. Deterministic: the same cells on every run.
inline constexpr size_t kMergeTriangles = 32, kMergeVertices = size_t(1) << 22;
// `meshBounds`: meshBounds(scene).
void mergeFarLevels(const Scene& scene, InstanceTree& tree,
                    const std::vector<std::array<Vec3, 2>>& meshBounds);
// Every mesh's bounds (Mesh::bounds), in mesh order.
std::vector<std::array<Vec3, 2>> meshBounds(const Scene& scene);
// An instance's box in its own space around every level of detail it may draw.
std::array<Vec3, 2> instanceBounds(const Scene& scene, const Instance& instance,
                                   const std::vector<std::array<Vec3, 2>>& meshBounds);

// Appends `other`'s meshes and materials to `scene`, placing each of `other`'s instances under
// `transform`. Cameras and light of `other` are appended/ignored as documented in scene-format.md.
void appendScene(Scene& scene, Scene other, const Mat4& transform);

}  // namespace sv::scene
