// OpenFlight reader (.flt), revisions 15.0 to 16.x.
// Based on: Presagis, "OpenFlight Scene Description Database Specification", version 16.x —
// the record layouts (big-endian; a 2-byte opcode and 2-byte length before each record), the
// push/pop hierarchy, the vertex palette addressed by byte offset, the colour palette's
// index·128 + intensity encoding, the bit numbering of flag words from the most significant bit.
//
// The file becomes meshes placed by instances: every node with faces (or mesh records) directly
// below it gives one mesh per material and texture, placed by the transforms above it. Levels of
// detail become scene LodGroups with the LOD record's centre, switches and degrees of freedom the
// scene's articulations (scene.h), light point records and light-drawn faces light points.
// OpenFlight's z-up world is turned into synthvis' y-up one (north, +y, becomes −z, as the terrain
// maps it) and its units into metres.
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <deque>
#include <map>
#include <new>
#include <numbers>
#include <optional>
#include <tuple>
#include <unordered_map>

#include "formats/reader.h"
#include "texture/texture.h"

namespace sv::formats {
namespace detail {
namespace {

struct FltProblem {
  std::string message;
};
[[noreturn]] void fail(std::string message) { throw FltProblem{std::move(message)}; }

// Opcodes (specification, "Record Types").
enum Op : uint16_t {
  kHeader = 1,
  kGroup = 2,
  kObject = 4,
  kFace = 5,
  kPush = 10,
  kPop = 11,
  kDof = 14,
  kPushSubface = 19,
  kPopSubface = 20,
  kPushExtension = 21,
  kPopExtension = 22,
  kContinuation = 23,
  kLongId = 33,
  kMatrix = 49,
  kBsp = 55,
  kInstanceReference = 61,
  kInstanceDefinition = 62,
  kExternalReference = 63,
  kTexturePalette = 64,
  kVertexPalette = 67,
  kVertexColor = 68,
  kVertexColorNormal = 69,
  kVertexColorNormalUv = 70,
  kVertexColorUv = 71,
  kVertexList = 72,
  kLod = 73,
  kMesh = 84,
  kLocalVertexPool = 85,
  kMeshPrimitive = 86,
  kRoadSegment = 87,
  kMorphVertexList = 89,
  kSound = 91,
  kText = 95,
  kSwitch = 96,
  kClipRegion = 98,
  kLightSource = 101,
  kLightPoint = 111,
  kMaterialPalette = 113,
  kCat = 115,
  kPushAttribute = 122,
  kPopAttribute = 123,
  kCurve = 126,
  kRoadConstruction = 127,
  kLightPointAppearancePalette = 128,
  kLightPointAnimationPalette = 129,
  kIndexedLightPoint = 130,
  kLightPointSystem = 131,
};
constexpr uint16_t kColorPalette = 32;

// Nodes of the hierarchy. Records not listed are palettes or data the image does not use.
bool isGroupLike(uint16_t op) {
  return op == kGroup || op == kObject || op == kBsp || op == kLightSource ||
         op == kLightPointSystem;
}
bool isNode(uint16_t op) {
  return isGroupLike(op) || op == kFace || op == kMesh || op == kDof || op == kLod ||
         op == kSwitch || op == kExternalReference || op == kLightPoint ||
         op == kInstanceReference || op == kInstanceDefinition || op == kRoadSegment ||
         op == kSound || op == kText || op == kClipRegion || op == kCat || op == kCurve ||
         op == kRoadConstruction || op == kIndexedLightPoint;
}
const char* unsupportedName(uint16_t op) {
  switch (op) {
    case kRoadSegment:
      return "road segment";
    case kRoadConstruction:
      return "road construction";
    case kSound:
      return "sound";
    case kText:
      return "text";
    case kClipRegion:
      return "clip region";
    case kCat:
      return "continuously adaptive terrain";
    case kCurve:
      return "curve";
    default:
      return nullptr;
  }
}

constexpr int kMaxDepth = 128;             // nesting of push/pop, instance and file references
constexpr uint64_t kMaxVisits = 1u << 24;  // nodes visited, instance references expanded
constexpr size_t kMaxFaceVertices = 8192;  // as the OBJ reader's

// One record: its opcode, where it starts in the file, and its bytes (header included;
// continuation records already appended).
struct Record {
  uint16_t op = 0;
  size_t at = 0;
  std::string_view data;
};

// Big-endian fields of one record. Fields past its end read as zero: older revisions write
// shorter records, and a reader checks the length it needs with need().
class Fields {
 public:
  explicit Fields(const Record& r) : r_(r) {}
  void need(size_t bytes, const char* what) const {
    if (r_.data.size() < bytes)
      fail(fmt::format("{} record at byte {} is {} bytes long, {} are needed", what, r_.at,
                       r_.data.size(), bytes));
  }
  uint64_t raw(size_t at, size_t n) const {
    uint64_t v = 0;
    if (at + n > r_.data.size()) return 0;
    for (size_t i = 0; i < n; ++i) v = v << 8 | uint8_t(r_.data[at + i]);
    return v;
  }
  uint8_t u8(size_t at) const { return uint8_t(raw(at, 1)); }
  uint16_t u16(size_t at) const { return uint16_t(raw(at, 2)); }
  int16_t i16(size_t at) const { return int16_t(u16(at)); }
  uint32_t u32(size_t at) const { return uint32_t(raw(at, 4)); }
  int32_t i32(size_t at) const { return int32_t(u32(at)); }
  float f32(size_t at) const { return std::bit_cast<float>(u32(at)); }
  double f64(size_t at) const { return std::bit_cast<double>(raw(at, 8)); }
  std::string text(size_t at, size_t n) const {
    if (at >= r_.data.size()) return {};
    std::string_view s = r_.data.substr(at, std::min(n, r_.data.size() - at));
    return std::string(s.substr(0, s.find('\0')));
  }
  size_t size() const { return r_.data.size(); }
  size_t at() const { return r_.at; }

 private:
  const Record& r_;
};

// The colour of a packed ABGR word (alpha ignored, as modelling tools leave it unset).
Vec4 packedColor(uint32_t abgr) {
  return {float(abgr & 0xFF) / 255.0f, float(abgr >> 8 & 0xFF) / 255.0f,
          float(abgr >> 16 & 0xFF) / 255.0f, 1.0f};
}

// A node of the hierarchy: a primary record and what follows it.
struct Node {
  uint32_t record = 0;
  std::string name;
  std::vector<uint32_t> children;   // nodes
  std::vector<uint32_t> ancillary;  // records: vertex lists, local vertex pools, primitives
  std::optional<Mat4> matrix;
};

// A vertex of the palette or a local pool, decoded.
struct Vertex {
  double p[3] = {0, 0, 0};
  std::optional<Vec3> normal;
  std::optional<Vec2> uv;
  std::optional<Vec4> color;  // none: the face's colour
};

// One polygon with its face's attributes.
struct FaceAttributes {
  int material = -1;  // material palette index
  int texture = -1;   // texture palette pattern index
  bool doubleSided = false;
  bool lit = true;
  bool vertexColors = false;
  Vec4 color{1, 1, 1, 1};
  float alpha = 1;
  bool blend = false;  // alpha blending asked for (billboard template 1)
};

// What a light point record (111), or an indexed light point's (130) appearance (128) with its
// animation (129), says of its lights.
struct LightLook {
  std::string name;
  int32_t directionality = 0;  // 0 omnidirectional, 1 one way, 2 both ways
  float intensity = 1, backIntensity = 0;
  float horizontalLobe = 30, verticalLobe = 15, falloff = 1;
  Vec4 back{1, 1, 1, 1};
  float period = 0, delay = 0, enabled = 0;  // seconds
  bool flashing = false, rotating = false;
};
struct LightAnimation {
  float period = 0, delay = 0, enabled = 0;
  int32_t type = 1;  // 0 flashing sequence, 1 rotating, 2 strobe, 3 Morse code
};

// What the level of detail above a node says: draw in [near, far) of the range to `center`
// (given in the space of `fromLod`'s start).
struct LodContext {
  std::string name;
  double near = 0, far = 1e30, fade = 0;
  Vec3 center{0, 0, 0};
};

// The state of the walk at one node.
struct Place {
  Mat4 toWorld;   // through the axis and unit change at the root
  Mat4 sinceLod;  // from the innermost LOD node's space
  Mat4 sinceDof;  // from the innermost DOF node's space (or the world)
  std::optional<LodContext> lod;
  int dof = -1;
  std::vector<std::pair<size_t, size_t>> switches;  // (switch, child) memberships
  int depth = 0;
};

// The inverse of an affine matrix (last row 0, 0, 0, 1); nothing when singular.
std::optional<Mat4> inverseOf(const Mat4& m) {
  double inv[3][4];
  if (!affineInverse(m, inv)) return std::nullopt;
  Mat4 r;
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < 4; ++c) r.m[c][row] = float(inv[row][c]);
  return r;
}

class Reader {
 public:
  Reader(const std::string& bytes, const std::string& path, LoadContext& context)
      : bytes_(bytes), path_(path), context_(context) {}

  Scene read() {
    splitRecords();
    readHeader();
    readPalettes();
    buildHierarchy();
    Place root;
    root.toWorld = root_;
    root.sinceDof = root_;
    visit(0, root);
    for (const auto& [what, count] : skipped_)
      scene_.warnings.push_back(
          fmt::format("{}: {} {} record{} not drawn", path_, count, what, count == 1 ? "" : "s"));
    if (morse_)
      scene_.warnings.push_back(
          fmt::format("{}: {} light point record{} animated by Morse code drawn steady", path_,
                      morse_, morse_ == 1 ? "" : "s"));
    applyArticulations(scene_);
    if (scene_.lightPoints.size() > kMaxLightPoints)
      fail(fmt::format("more than {} light points", kMaxLightPoints));
    // Matrices and DOF values that are finite can still multiply past the float range.
    for (const Instance& inst : scene_.instances)
      if (!isFinite(inst.transform))
        fail(fmt::format("the transforms of mesh '{}' multiply to values that are not finite",
                         scene_.meshes[size_t(inst.mesh)].name));
    return std::move(scene_);
  }

 private:
  // Step 1: the records, continuations joined to the record they continue.
  void splitRecords() {
    size_t at = 0;
    while (at < bytes_.size()) {
      if (bytes_.size() - at < 4)
        fail(
            fmt::format("{} stray bytes at the end of the file (byte {})", bytes_.size() - at, at));
      const uint16_t op = uint16_t(uint8_t(bytes_[at]) << 8 | uint8_t(bytes_[at + 1]));
      const size_t length = size_t(uint8_t(bytes_[at + 2]) << 8 | uint8_t(bytes_[at + 3]));
      if (length < 4)
        fail(fmt::format("record at byte {} (opcode {}) has length {}", at, op, length));
      if (length > bytes_.size() - at)
        fail(fmt::format("record at byte {} (opcode {}) runs past the end of the file", at, op));
      const std::string_view data(bytes_.data() + at, length);
      if (op == kContinuation) {
        if (records_.empty()) fail("the file begins with a continuation record");
        Record& last = records_.back();
        // Joined in a copy of its own, grown in place by further continuations.
        if (owned_.empty() || last.data.data() != owned_.back().data())
          owned_.emplace_back(last.data);
        owned_.back().append(data.substr(4));
        last.data = owned_.back();
      } else {
        records_.push_back({op, at, data});
      }
      at += length;
    }
    if (records_.empty() || records_[0].op != kHeader)
      fail("not an OpenFlight file (it does not begin with a header record)");
  }

  // Step 2: the header — revision and units.
  void readHeader() {
    Fields h(records_[0]);
    h.need(64, "header");
    const int32_t revision = h.i32(12);
    if (revision < 1500 || revision >= 1700)
      fail(fmt::format("OpenFlight revision {} is not supported (15.0 to 16.x are; format code {})",
                       revision >= 1000 ? fmt::format("{}.{}", revision / 100, revision % 100 / 10)
                                        : std::to_string(revision),
                       revision));
    double metres = 1;
    switch (h.u8(62)) {
      case 0:
        metres = 1;
        break;
      case 1:
        metres = 1000;
        break;
      case 4:
        metres = 0.3048;
        break;
      case 5:
        metres = 0.0254;
        break;
      case 8:
        metres = 1852;
        break;
      default:
        fail(fmt::format("header: unknown units code {}", h.u8(62)));
    }
    unitScale_ = metres;
    // (x, y, z) of OpenFlight, z up and y north, to synthvis' (x, z, −y), in metres.
    root_.m[0] = {float(metres), 0, 0, 0};
    root_.m[1] = {0, 0, float(-metres), 0};
    root_.m[2] = {0, float(metres), 0, 0};
    rootInverse_ = *inverseOf(root_);
  }

  // Step 3: the palettes — colours, materials, textures, vertices.
  void readPalettes() {
    std::optional<size_t> paletteStart;
    for (uint32_t i = 0; i < records_.size(); ++i) {
      const Record& r = records_[i];
      Fields f(r);
      switch (r.op) {
        case kColorPalette: {
          const size_t n = std::min<size_t>(1024, f.size() >= 132 ? (f.size() - 132) / 4 : 0);
          colors_.resize(n);
          for (size_t k = 0; k < n; ++k) colors_[k] = packedColor(f.u32(132 + 4 * k));
          break;
        }
        case kMaterialPalette: {
          f.need(80, "material palette");
          FltMaterial m;
          m.name = f.text(8, 12);
          m.diffuse = {f.f32(36), f.f32(40), f.f32(44)};
          m.alpha = f.f32(76);
          if (!isFinite(m.diffuse) || !std::isfinite(m.alpha))
            fail(fmt::format("material palette at byte {}: colour is not finite", r.at));
          materials_[f.i32(4)] = m;
          break;
        }
        case kLightPointAppearancePalette: {
          // What a light point record says, by appearance (OpenFlight 15.8+): intensities, back
          // colour (a colour index), directionality, lobes.
          f.need(372, "light point appearance palette");
          LightLook look;
          look.name = f.text(8, 256);
          look.back = indexedColor(f.u32(272));
          look.intensity = f.f32(280), look.backIntensity = f.f32(284);
          look.directionality = f.i32(352);
          look.horizontalLobe = f.f32(356), look.verticalLobe = f.f32(360);
          look.falloff = f.f32(368);
          lightLooks_[f.i32(264)] = look;
          break;
        }
        case kLightPointAnimationPalette: {
          // Rotating (1) and strobe (2) beacons by period, phase delay and time lit; a flashing
          // sequence (0) by its pulses (lit while on: their on time over their sum); Morse code
          // (3) is not drawn as such (steady, counted in the warnings).
          f.need(300, "light point animation palette");
          LightAnimation a;
          a.period = f.f32(268), a.delay = f.f32(272), a.enabled = f.f32(276);
          a.type = f.i32(296);
          if (a.type == 0 && f.size() >= 1340) {
            const size_t n = std::min<size_t>(f.u32(1336), (f.size() - 1340) / 12);
            float total = 0, lit = 0;
            for (size_t k = 0; k < n; ++k) {
              const float d = f.f32(1340 + 12 * k + 4);
              if (!(d >= 0 && d < 1e6f)) continue;
              total += d;
              if (f.u32(1340 + 12 * k) != 1) lit += d;  // states: 0 on, 1 off, 2 colour change
            }
            a.period = total, a.enabled = lit;
          }
          animations_[f.i32(264)] = a;
          break;
        }
        case kTexturePalette:
          f.need(208, "texture palette");
          textureFiles_[f.i32(204)] = f.text(4, 200);
          break;
        case kVertexPalette:
          paletteStart = r.at;
          break;
        case kVertexColor:
        case kVertexColorNormal:
        case kVertexColorNormalUv:
        case kVertexColorUv:
          if (!paletteStart)
            fail(fmt::format("vertex record at byte {} before the vertex palette", r.at));
          vertexAt_[r.at - *paletteStart] = i;
          break;
        default:
          break;
      }
    }
  }

  // Step 4: the hierarchy of nodes under the header, by push and pop.
  void buildHierarchy() {
    nodes_.push_back({0, "", {}, {}, {}});
    std::vector<uint32_t> parents{0};
    uint32_t last = 0;
    for (uint32_t i = 1; i < records_.size(); ++i) {
      const Record& r = records_[i];
      switch (r.op) {
        case kPush:
        case kPushSubface:
          if (parents.size() > size_t(kMaxDepth))
            fail(fmt::format("nesting deeper than {} levels at byte {}", kMaxDepth, r.at));
          parents.push_back(last);
          break;
        case kPop:
        case kPopSubface:
          if (parents.size() <= 1) fail(fmt::format("pop record at byte {} without a push", r.at));
          // Records after a pop (other than a new node) belong to the enclosing node: an
          // ancillary record follows its own node directly, before any push.
          parents.pop_back();
          last = parents.back();
          break;
        case kPushExtension:
        case kPushAttribute: {
          // Vendor extensions and attribute blocks: skipped whole.
          const uint16_t open = r.op,
                         close = r.op == kPushExtension ? kPopExtension : kPopAttribute;
          int depth = 1;
          while (depth > 0) {
            if (++i >= records_.size())
              fail(fmt::format("record at byte {} (opcode {}) is never closed", r.at, open));
            depth += records_[i].op == open ? 1 : records_[i].op == close ? -1 : 0;
          }
          break;
        }
        case kLongId: {
          Fields f(r);
          nodes_[last].name = f.text(4, f.size() - 4);
          break;
        }
        case kMatrix: {
          Fields f(r);
          f.need(68, "matrix");
          // Sixteen floats, row-major for row vectors: the column-major layout of column vectors.
          float v[16];
          for (int k = 0; k < 16; ++k) v[k] = f.f32(4 + 4 * k);
          const Mat4 m = Mat4::fromColumnMajor(v);
          if (!isFinite(m)) fail(fmt::format("matrix at byte {} is not finite", r.at));
          // The header takes no transform (OpenSceneGraph's exporter writes one there, which its
          // reader, like this one, ignores).
          // A second matrix on one node goes above the first (as OpenSceneGraph composes them).
          if (last != 0) nodes_[last].matrix = nodes_[last].matrix ? m * *nodes_[last].matrix : m;
          break;
        }
        case kVertexList:
        case kMorphVertexList:
        case kLocalVertexPool:
        case kMeshPrimitive:
          nodes_[last].ancillary.push_back(i);
          break;
        default:
          if (!isNode(r.op)) break;
          nodes_.push_back({i, Fields(r).text(4, 8), {}, {}, {}});
          last = uint32_t(nodes_.size() - 1);
          nodes_[parents.back()].children.push_back(last);
          if (r.op == kInstanceDefinition) definitions_[Fields(r).i16(6)] = last;
          break;
      }
    }
  }

  // Step 5: the walk. Geometry is built at each node holding faces, placed by `at`.
  void visit(uint32_t index, Place at) {
    if (++visits_ > kMaxVisits)
      fail(fmt::format("the hierarchy expands to more than {} nodes (instance references)",
                       kMaxVisits));
    if (at.depth > kMaxDepth) fail(fmt::format("references nest deeper than {} levels", kMaxDepth));
    const Node& node = nodes_[index];
    const Record& r = records_[node.record];
    Fields f(r);
    if (node.matrix) {
      at.toWorld = at.toWorld * *node.matrix;
      at.sinceLod = at.sinceLod * *node.matrix;
      at.sinceDof = at.sinceDof * *node.matrix;
    }
    if (const char* what = unsupportedName(r.op)) {
      ++skipped_[what];
      return;
    }
    switch (r.op) {
      case kInstanceDefinition:
        return;  // drawn where referenced
      case kInstanceReference: {
        auto def = definitions_.find(f.i16(6));
        if (def == definitions_.end())
          fail(fmt::format("instance reference at byte {}: no instance definition {}", r.at,
                           f.i16(6)));
        ++at.depth;
        if (const std::optional<Mat4>& m = nodes_[def->second].matrix) {
          at.toWorld = at.toWorld * *m;
          at.sinceLod = at.sinceLod * *m;
          at.sinceDof = at.sinceDof * *m;
        }
        placeGeometry(def->second, at);
        for (uint32_t child : nodes_[def->second].children) visit(child, at);
        return;
      }
      case kLod: {
        f.need(64, "level of detail");
        LodContext lod{node.name,
                       f.f64(24),
                       f.f64(16),
                       f.size() >= 72 ? f.f64(64) : 0,
                       {float(f.f64(40)), float(f.f64(48)), float(f.f64(56))}};
        if (!std::isfinite(lod.near) || !std::isfinite(lod.far) || !isFinite(lod.center))
          fail(fmt::format("level of detail at byte {}: a distance is not finite", r.at));
        // Nested levels of detail: the intersection of their ranges, to the inner centre.
        if (at.lod) {
          lod.near = std::max(lod.near, at.lod->near);
          lod.far = std::min(lod.far, at.lod->far);
        }
        at.lod = lod;
        at.sinceLod = Mat4::identity();
        break;
      }
      case kSwitch: {
        f.need(28, "switch");
        const int32_t masks = f.i32(20), words = f.i32(24);
        if (masks < 0 || words < 0 || size_t(28) + size_t(masks) * size_t(words) * 4 > f.size())
          fail(fmt::format("switch at byte {}: {} masks of {} words do not fit its record", r.at,
                           masks, words));
        // One flag per mask and child, for every switch placed: bounded like the nodes visited.
        // A mask counts as one flag at least: masks of no words are not bounded by the record's
        // size, and each is still stored.
        switchFlags_ +=
            uint64_t(std::max(masks, 1)) * uint64_t(std::max<size_t>(node.children.size(), 1));
        if (switchFlags_ > kMaxVisits)
          fail(fmt::format("switches hold more than {} mask flags", kMaxVisits));
        Switch s;
        s.name = node.name;
        s.children.resize(node.children.size());
        for (int32_t m = 0; m < masks; ++m) {
          std::vector<bool> mask(node.children.size());
          for (size_t c = 0; c < mask.size(); ++c)
            mask[c] = c / 32 < size_t(words) &&
                      (f.u32(28 + 4 * (size_t(m) * size_t(words) + c / 32)) >> (c % 32) & 1);
          s.masks.push_back(std::move(mask));
        }
        const int32_t current = f.i32(16);
        if (masks > 0 && (current < 0 || current >= masks))
          fail(fmt::format("switch at byte {}: current mask {} of {}", r.at, current, masks));
        // Without masks every child is drawn: one mask of all of them, current whatever the
        // record's (then meaningless) current-mask field says.
        if (masks == 0) s.masks.push_back(std::vector<bool>(node.children.size(), true));
        s.current = masks == 0 ? 0 : size_t(current);
        scene_.switches.push_back(std::move(s));
        const size_t sw = scene_.switches.size() - 1;
        for (size_t c = 0; c < node.children.size(); ++c) {
          Place child = at;
          child.switches.push_back({sw, c});
          visit(node.children[c], child);
        }
        return;
      }
      case kDof: {
        f.need(380, "degree of freedom");
        at = enterDof(f, node, at);
        break;
      }
      case kExternalReference: {
        f.need(204, "external reference");
        placeReference(f.text(4, 200), at);
        return;
      }
      case kLightPoint: {
        f.need(156, "light point");
        placeLightPoints(index, lightLookOf(f), at);
        return;
      }
      case kIndexedLightPoint: {
        f.need(20, "indexed light point");
        auto look = lightLooks_.find(f.i32(12));
        if (look == lightLooks_.end()) {
          ++skipped_["indexed light point (its appearance not in the palette)"];
          return;
        }
        LightLook l = look->second;
        auto animation = animations_.find(f.i32(16));
        if (animation != animations_.end()) {
          const LightAnimation& a = animation->second;
          if (a.type == 3) ++morse_;
          l.flashing = a.type == 0 || a.type == 2;
          l.rotating = a.type == 1;
          l.period = a.period, l.delay = a.delay, l.enabled = a.enabled;
        }
        placeLightPoints(index, l, at);
        return;
      }
      case kFace:
      case kMesh:
        return;  // gathered by their parent (placeGeometry)
      default:
        break;
    }
    placeGeometry(index, at);
    for (uint32_t child : node.children) visit(child, at);
  }

  Place enterDof(const Fields& f, const Node& node, Place at) {
    auto vec = [&](size_t o) { return DVec{f.f64(o), f.f64(o + 8), f.f64(o + 16)}; };
    DVec origin = vec(16), onX = vec(40), inXy = vec(64);
    Dof d;
    d.name = node.name;
    d.parent = at.dof;
    // The local frame from its origin and two points (specification: x toward the first, the
    // second in the xy plane); degenerate or unset (−1e8) points give the node's own axes.
    DVec x = onX - origin, xy = inXy - origin;
    DVec z = cross(x, xy), y = cross(z, x);
    auto usable = [](const DVec& v) { return v.norm() > 0 && std::isfinite(v.norm()); };
    const bool valid =
        usable(x) && usable(z) && usable(y) && origin.finite() && onX.finite() && inXy.finite();
    if (!valid) x = {1, 0, 0}, y = {0, 1, 0}, z = {0, 0, 1};
    x = x.unit(), y = y.unit(), z = z.unit();
    if (!valid && !origin.finite()) origin = {0, 0, 0};
    Mat4 frame;
    const DVec axes[3] = {x, y, z};
    for (int c = 0; c < 3; ++c)
      frame.m[c] = {float(axes[c].v[0]), float(axes[c].v[1]), float(axes[c].v[2]), 0};
    frame.m[3] = {float(origin.v[0]), float(origin.v[1]), float(origin.v[2]), 1};
    d.frame = frame;
    d.place = at.sinceDof;
    // Points finite in double, or the product of the matrices above, may lie beyond float's
    // range: refused rather than made an infinite transform.
    if (!isFinite(d.frame) || !isFinite(d.place))
      fail(
          fmt::format("degree of freedom at byte {}: its frame lies beyond float's range", f.at()));
    // Ranges (min, max, current, increment) in the order z, y, x, pitch, roll, yaw, scale z, y, x.
    auto read = [&](int k, int field) { return f.f64(88 + 32 * size_t(k) + 8 * size_t(field)); };
    for (int field = 0; field < 3; ++field) {
      DofMotion& m = field == 0 ? d.min : field == 1 ? d.max : d.current;
      m.translate = {float(read(2, field)), float(read(1, field)), float(read(0, field))};
      m.rotate = {float(read(3, field)), float(read(4, field)), float(read(5, field))};
      m.scale = {float(read(8, field)), float(read(7, field)), float(read(6, field))};
      if (!isFinite(m.translate) || !isFinite(m.rotate) || !isFinite(m.scale))
        fail(fmt::format("degree of freedom at byte {}: a value is not finite", f.at()));
    }
    // Limits only where the flags ask for them (bits 0–8: x, y, z, pitch, roll, yaw, scale x, y,
    // z); elsewhere the motion is free. The current value always lies within.
    const uint32_t flags = f.u32(376);
    auto limit = [&](int bit, float& lo, float& hi, float current) {
      if (!(flags >> (31 - bit) & 1)) lo = -1e30f, hi = 1e30f;
      lo = std::min(lo, current), hi = std::max(hi, current);
    };
    limit(0, d.min.translate.x, d.max.translate.x, d.current.translate.x);
    limit(1, d.min.translate.y, d.max.translate.y, d.current.translate.y);
    limit(2, d.min.translate.z, d.max.translate.z, d.current.translate.z);
    limit(3, d.min.rotate.x, d.max.rotate.x, d.current.rotate.x);
    limit(4, d.min.rotate.y, d.max.rotate.y, d.current.rotate.y);
    limit(5, d.min.rotate.z, d.max.rotate.z, d.current.rotate.z);
    limit(6, d.min.scale.x, d.max.scale.x, d.current.scale.x);
    limit(7, d.min.scale.y, d.max.scale.y, d.current.scale.y);
    limit(8, d.min.scale.z, d.max.scale.z, d.current.scale.z);
    scene_.dofs.push_back(std::move(d));
    at.dof = int(scene_.dofs.size() - 1);
    at.sinceDof = Mat4::identity();
    return at;
  }

  // A 3-vector in double for the DOF frame.
  struct DVec {
    double v[3];
    DVec operator-(const DVec& o) const { return {v[0] - o.v[0], v[1] - o.v[1], v[2] - o.v[2]}; }
    double norm() const { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
    DVec unit() const {
      const double n = norm();
      return {v[0] / n, v[1] / n, v[2] / n};
    }
    bool finite() const {
      return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) &&
             std::fabs(v[0] + 1e8) + std::fabs(v[1] + 1e8) + std::fabs(v[2] + 1e8) > 1e-7;
    }
  };
  static DVec cross(const DVec& a, const DVec& b) {
    return {a.v[1] * b.v[2] - a.v[2] * b.v[1], a.v[2] * b.v[0] - a.v[0] * b.v[2],
            a.v[0] * b.v[1] - a.v[1] * b.v[0]};
  }

  // An external reference: the file loaded (once per load) and placed here, in its own units.
  void placeReference(std::string name, const Place& at) {
    // "file.flt<node>" names one node of the file; only whole files are read.
    if (const size_t lt = name.find('<'); lt != std::string::npos) {
      scene_.warnings.push_back(fmt::format(
          "{}: external reference '{}': only whole files are referenced, the node name is ignored",
          path_, name));
      name.resize(lt);
    }
    if (name.empty()) fail("an external reference without a file name");
    if (!context_.options.followReferences)
      fail(
          fmt::format("cannot open external reference '{}' (references to other files are "
                      "disabled)",
                      name));
    if (at.depth + int(context_.openScenes.size()) >= context_.options.maxNesting)
      fail(fmt::format("external reference '{}': references nest deeper than {} files", name,
                       context_.options.maxNesting));
    const std::string file = resolvePath(directoryOf(path_), name);
    const std::string key = canonicalKey(file);
    for (const std::string& open : context_.openScenes)
      if (open == key) fail(fmt::format("external reference '{}' refers back to itself", name));
    auto loaded = context_.loaded.find(key);
    if (loaded == context_.loaded.end()) {
      Result<Scene> s = loadFile(file, context_);
      if (!s) fail(fmt::format("external reference '{}': {}", name, s.error().str()));
      loaded = context_.loaded.emplace(key, std::move(s.value())).first;
    }
    const Scene& referenced = loaded->second;
    // Every placement copies the file's meshes: they count against the budget each time.
    triangles_ += referenced.triangleCount();
    if (triangles_ > context_.options.maxTriangles)
      fail(fmt::format("more than {} triangles (external reference '{}')",
                       context_.options.maxTriangles, name));
    const size_t firstInstance = scene_.instances.size(), firstDof = scene_.dofs.size();
    // The file is already in metres and y up: its root change undone, then the path to here.
    const Mat4 toNode = at.sinceDof * rootInverse_;
    appendScene(scene_, referenced, at.toWorld * rootInverse_);
    for (size_t k = 0; k < referenced.instances.size(); ++k) {
      const uint32_t i = uint32_t(firstInstance + k);
      for (const auto& [sw, child] : at.switches) scene_.switches[sw].children[child].push_back(i);
      // Under a degree of freedom here: parts of it, unless one of the file's own moves them.
      if (at.dof >= 0 && !referenced.instances[k].articulated) {
        scene_.instances[i].articulated = true;
        scene_.dofs[size_t(at.dof)].parts.push_back(
            {i, toNode * referenced.instances[k].transform});
      }
    }
    if (at.dof >= 0)
      for (size_t d = firstDof; d < scene_.dofs.size(); ++d)
        if (referenced.dofs[d - firstDof].parent < 0) {
          scene_.dofs[d].parent = at.dof;
          scene_.dofs[d].place = toNode * referenced.dofs[d - firstDof].place;
        }
  }

  // The faces and meshes directly below `index`, as meshes placed by `at`.
  void placeGeometry(uint32_t index, const Place& at) {
    auto built = builtOf_.find(index);
    if (built == builtOf_.end()) built = builtOf_.emplace(index, build(index)).first;
    for (const AsideFace& face : built->second.aside)
      if (face.drawType == 2 || face.drawType == 3)
        placeWireFace(face, at);
      else
        placeLightFace(face, at);
    for (int mesh : built->second.meshes) {
      const uint64_t triangles = scene_.meshes[size_t(mesh)].triangleCount();
      triangles_ += triangles;
      if (triangles_ > context_.options.maxTriangles)
        fail(fmt::format("more than {} triangles", context_.options.maxTriangles));
      Instance inst;
      inst.mesh = mesh;
      inst.transform = at.toWorld;
      if (at.lod) {
        const int group = lodGroup(mesh, *at.lod, at.sinceLod);
        if (group == -2) continue;  // a range that is empty: never drawn
        if (group >= 0) {
          inst.lod = group;
          inst.mesh = scene_.lodGroups[size_t(group)].levels[0].mesh;
        }
      }
      scene_.instances.push_back(inst);
      const uint32_t i = uint32_t(scene_.instances.size() - 1);
      for (const auto& [sw, child] : at.switches) scene_.switches[sw].children[child].push_back(i);
      if (at.dof >= 0) {
        scene_.instances[i].articulated = true;
        scene_.dofs[size_t(at.dof)].parts.push_back({i, at.sinceDof});
      }
    }
  }

  // The level-of-detail group for `mesh` drawn in [near, far): −1 for none needed (the whole
  // range), −2 for never drawn.
  int lodGroup(int mesh, const LodContext& lod, const Mat4& sinceLod) {
    // In float, as the ranges are kept and compared (a range that rounds to nothing is empty).
    float near = float(std::clamp(lod.near * unitScale_, 0.0, 1e30));
    const float far = float(std::clamp(lod.far * unitScale_, 0.0, 1e30));
    if (!(far > near)) return -2;
    if (near == 0 && far >= 1e30f) return -1;
    LodGroup g;
    g.name = lod.name;
    if (near > 0) g.levels.push_back({emptyMesh(), near});
    g.levels.push_back({mesh, far});
    // The transition range as the fade, where it fits every level's span (scene.h LodGroup).
    float fade = float(lod.fade * unitScale_);
    if (!(fade > 0 && fade < 1e30f)) fade = 0;
    float from = 0;
    for (const LodLevel& l : g.levels) {
      if (!(l.to - fade >= from)) fade = 0;
      from = l.to;
    }
    g.fade = fade;
    // The centre, given in the LOD node's space, in the mesh's own.
    const std::optional<Mat4> back = inverseOf(sinceLod);
    const Vec3 c = back ? back->transformPoint(lod.center) : lod.center;
    g.center = isFinite(c) ? c : lod.center;
    scene_.lodGroups.push_back(std::move(g));
    return int(scene_.lodGroups.size() - 1);
  }

  int emptyMesh() {
    if (emptyMesh_ < 0) {
      Mesh empty;
      empty.name = "(nothing: out of range)";
      scene_.meshes.push_back(std::move(empty));
      emptyMesh_ = int(scene_.meshes.size() - 1);
    }
    return emptyMesh_;
  }

  // --- Faces and meshes to triangles ---------------------------------------------------------

  struct MaterialKey {
    int material, texture;
    bool doubleSided, lit, blend;
    float alpha;
    auto tie() const { return std::tie(material, texture, doubleSided, lit, blend, alpha); }
    bool operator<(const MaterialKey& o) const { return tie() < o.tie(); }
  };

  // A face drawn as lines (draw types 2, closed, and 3) or lights (8, 9, 10: a light at each
  // vertex).
  struct AsideFace {
    std::vector<Vertex> vertices;
    FaceAttributes attributes;
    int drawType = 8;
    Vec3 normal{0, 0, 1};
  };
  // What a node's own faces make: meshes (built once, placed by every path to the node), and the
  // faces drawn as lines or lights.
  struct Built {
    std::vector<int> meshes;
    std::vector<AsideFace> aside;
  };

  Built build(uint32_t index) {
    std::map<MaterialKey, Mesh> buckets;
    Built out;
    gatherFaces(index, buckets, out.aside, 0);
    for (auto& [key, mesh] : buckets) {
      if (mesh.indices.empty()) continue;
      mesh.name = nodes_[index].name;
      mesh.material = materialFor(key);
      scene_.meshes.push_back(std::move(mesh));
      out.meshes.push_back(int(scene_.meshes.size() - 1));
    }
    return out;
  }

  void gatherFaces(uint32_t index, std::map<MaterialKey, Mesh>& buckets,
                   std::vector<AsideFace>& aside, int depth) {
    if (depth > kMaxDepth) fail(fmt::format("subfaces nest deeper than {} levels", kMaxDepth));
    for (uint32_t child : nodes_[index].children) {
      const Record& r = records_[nodes_[child].record];
      if (r.op == kFace) {
        addFace(child, buckets, aside);
        gatherFaces(child, buckets, aside, depth + 1);  // subfaces
      } else if (r.op == kMesh) {
        addMesh(child, buckets, aside);
      }
    }
  }

  // The attributes shared by the face (5) and mesh (84) records, whose layouts differ by a
  // 4-byte shift after the ID (`s`).
  FaceAttributes faceAttributes(const Fields& f, size_t s, bool& hidden, int& drawType) {
    FaceAttributes a;
    drawType = int(int8_t(f.u8(18 + s)));
    const bool textureWhite = f.u8(19 + s) != 0;
    a.texture = f.i16(28 + s);
    a.material = f.i16(30 + s);
    const uint16_t transparency = f.u16(40 + s);
    const uint32_t flags = f.u32(44 + s);
    const uint8_t lightMode = f.u8(48 + s);
    const uint8_t billboard = f.u8(25 + s);
    hidden = flags & 0x04000000u;  // bit 5: hidden
    a.doubleSided = drawType == 1;
    a.lit = lightMode == 2 || lightMode == 3;
    a.vertexColors = lightMode == 1 || lightMode == 3;
    if (flags & 0x40000000u)
      a.color = {1, 1, 1, 1};  // bit 1: no colour
    else if (flags & 0x10000000u)
      a.color = packedColor(f.u32(56 + s));  // bit 3: packed
    else
      a.color = indexedColor(f.size() >= 72 + s ? f.u32(68 + s) : f.u16(20 + s));
    if (textureWhite && a.texture >= 0) a.color = {1, 1, 1, 1};
    a.alpha = 1.0f - float(transparency) / 65535.0f;
    a.blend = billboard == 1;
    return a;
  }

  Vec4 indexedColor(uint32_t index) const {
    if (index == 0xFFFFFFFFu || index == 0xFFFF) return {1, 1, 1, 1};
    const size_t entry = index >> 7;
    if (entry >= colors_.size()) return {1, 1, 1, 1};
    const float intensity = float(index & 127) / 127.0f;
    const Vec4 c = colors_[entry];
    return {c.x * intensity, c.y * intensity, c.z * intensity, 1};
  }

  Vertex paletteVertex(int32_t offset, size_t at) const {
    auto it = vertexAt_.find(uint32_t(offset));
    if (offset < 0 || it == vertexAt_.end())
      fail(fmt::format("vertex list at byte {}: no vertex at palette offset {}", at, offset));
    const Record& r = records_[it->second];
    Fields f(r);
    Vertex v;
    f.need(r.op == kVertexColor         ? 40
           : r.op == kVertexColorUv     ? 48
           : r.op == kVertexColorNormal ? 52
                                        : 60,
           "vertex");
    for (int k = 0; k < 3; ++k) v.p[k] = f.f64(8 + 8 * size_t(k));
    size_t o = 32;
    if (r.op == kVertexColorNormal || r.op == kVertexColorNormalUv) {
      v.normal = Vec3{f.f32(o), f.f32(o + 4), f.f32(o + 8)};
      o += 12;
    }
    if (r.op == kVertexColorNormalUv || r.op == kVertexColorUv) {
      v.uv = Vec2{f.f32(o), f.f32(o + 4)};
      o += 8;
    }
    const uint16_t flags = f.u16(6);
    if (!(flags & 0x2000)) {                            // bit 2: no colour
      v.color = flags & 0x1000 ? packedColor(f.u32(o))  // bit 3: packed colour
                               : indexedColor(f.size() >= o + 8 ? f.u32(o + 4) : f.u16(4));
    }
    return v;
  }

  // The face's vertices from its vertex lists (morph lists: their first, 0 % weight, vertices).
  std::vector<Vertex> faceVertices(const Node& node) const {
    std::vector<Vertex> out;
    for (uint32_t a : node.ancillary) {
      const Record& r = records_[a];
      Fields f(r);
      const size_t step = r.op == kMorphVertexList ? 8 : 4;
      if (r.op != kVertexList && r.op != kMorphVertexList) continue;
      for (size_t o = 4; o + 4 <= f.size(); o += step) {
        if (out.size() >= kMaxFaceVertices)
          fail(fmt::format("face at byte {} has more than {} vertices", records_[node.record].at,
                           kMaxFaceVertices));
        out.push_back(paletteVertex(f.i32(o), r.at));
      }
    }
    return out;
  }

  void addFace(uint32_t index, std::map<MaterialKey, Mesh>& buckets,
               std::vector<AsideFace>& aside) {
    const Node& node = nodes_[index];
    const Record& r = records_[node.record];
    Fields f(r);
    f.need(48, "face");
    bool hidden = false;
    int drawType = 0;
    const FaceAttributes a = faceAttributes(f, 0, hidden, drawType);
    if (hidden) return;
    std::vector<Vertex> vertices = faceVertices(node);
    bake(node, vertices);
    if (drawnAside(drawType, vertices, a, aside)) return;
    if (vertices.size() < 3) return;
    addPolygon(vertices, triangulate(vertices), a, buckets);
  }

  // Draw types that are not polygons: wireframes (2, 3) and lights (8–10), kept for placeGeometry.
  // True when `v` went aside.
  static bool drawnAside(int drawType, const std::vector<Vertex>& v, const FaceAttributes& a,
                         std::vector<AsideFace>& aside) {
    if (drawType == 2 || drawType == 3 || (drawType >= 8 && drawType <= 10)) {
      aside.push_back({v, a, drawType, newellNormal(v)});
      return true;
    }
    return false;
  }

  // A face's or mesh's own matrix, applied to its vertices (positions in double).
  static void bake(const Node& node, std::vector<Vertex>& vertices) {
    if (!node.matrix) return;
    const auto& m = node.matrix->m;
    const Mat4 normals = node.matrix->normalMatrix();
    for (Vertex& v : vertices) {
      const double x = v.p[0], y = v.p[1], z = v.p[2];
      for (int r = 0; r < 3; ++r) v.p[r] = m[0][r] * x + m[1][r] * y + m[2][r] * z + m[3][r];
      if (v.normal) v.normal = normals.transformDirection(*v.normal);
    }
  }

  // The polygon's unit normal by Newell's method, in double; +z when it has no area.
  static Vec3 newellNormal(const std::vector<Vertex>& v) {
    double n[3] = {0, 0, 0};
    for (size_t k = 0; k < v.size(); ++k) {
      const double* p = v[k].p;
      const double* q = v[(k + 1) % v.size()].p;
      n[0] += (p[1] - q[1]) * (p[2] + q[2]);
      n[1] += (p[2] - q[2]) * (p[0] + q[0]);
      n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return len > 0 ? Vec3{float(n[0] / len), float(n[1] / len), float(n[2] / len)} : Vec3{0, 0, 1};
  }

  std::vector<uint32_t> triangulate(const std::vector<Vertex>& v) const {
    if (v.size() == 3) return {0, 1, 2};
    std::vector<Vec3> p(v.size());
    for (size_t k = 0; k < v.size(); ++k)
      p[k] = {float(v[k].p[0]), float(v[k].p[1]), float(v[k].p[2])};
    return triangulatePolygon(p);
  }

  // Triangles `tri` (indices into `v`) into the bucket of the face's material.
  void addPolygon(const std::vector<Vertex>& v, const std::vector<uint32_t>& tri,
                  const FaceAttributes& a, std::map<MaterialKey, Mesh>& buckets) {
    if (tri.empty()) return;
    const int texture = a.texture >= 0 ? textureIndex(a.texture) : -1;
    const FltMaterial* fm = nullptr;
    if (a.material >= 0) {
      auto it = materials_.find(a.material);
      if (it != materials_.end()) fm = &it->second;
    }
    float alpha = a.alpha * (fm ? std::clamp(fm->alpha, 0.0f, 1.0f) : 1.0f);
    // Material alpha 0 is what some exporters write for "unset".
    if (fm && fm->alpha == 0) alpha = a.alpha;
    const MaterialKey key{fm ? a.material : -1,    texture, a.doubleSided, a.lit,
                          a.blend && texture >= 0, alpha};
    Mesh& mesh = buckets[key];
    const Vec3 faceNormal = newellNormal(v);  // for vertices without one
    const uint32_t base = uint32_t(mesh.positions.size());
    for (const Vertex& x : v) {
      const Vec3 p{float(x.p[0]), float(x.p[1]), float(x.p[2])};
      if (!isFinite(p)) fail("a vertex position is not finite");
      mesh.positions.push_back(p);
      Vec3 normal = x.normal && isFinite(*x.normal) && length(*x.normal) > 0 ? normalize(*x.normal)
                                                                             : faceNormal;
      mesh.normals.push_back(normal);
      const Vec4 c = a.vertexColors && x.color ? *x.color : a.color;
      mesh.colors.push_back(c);
      if (texture >= 0) {
        const Vec2 uv =
            x.uv && std::isfinite(x.uv->x) && std::isfinite(x.uv->y) ? *x.uv : Vec2{0, 0};
        mesh.uvs.push_back({uv.x, 1.0f - uv.y});  // OpenFlight's t runs up the image
      }
    }
    for (uint32_t k : tri) mesh.indices.push_back(base + k);
  }

  // A mesh record: its local vertex pool and primitives.
  void addMesh(uint32_t index, std::map<MaterialKey, Mesh>& buckets,
               std::vector<AsideFace>& aside) {
    const Node& node = nodes_[index];
    Fields f(records_[node.record]);
    f.need(52, "mesh");
    bool hidden = false;
    int drawType = 0;
    const FaceAttributes a = faceAttributes(f, 4, hidden, drawType);
    if (hidden) return;
    std::vector<Vertex> pool;
    for (uint32_t anc : node.ancillary) {
      const Record& r = records_[anc];
      Fields p(r);
      if (r.op == kLocalVertexPool) {
        p.need(12, "local vertex pool");
        pool = localPool(p);
        bake(node, pool);
      } else if (r.op == kMeshPrimitive) {
        p.need(12, "mesh primitive");
        const int16_t type = p.i16(4);
        const uint16_t size = p.u16(6);
        const uint32_t count = p.u32(8);
        if (size != 1 && size != 2 && size != 4)
          fail(fmt::format("mesh primitive at byte {}: index size {}", r.at, size));
        if (uint64_t(count) * size > p.size() - 12)
          fail(fmt::format("mesh primitive at byte {}: {} indices do not fit its record", r.at,
                           count));
        std::vector<Vertex> v(count);
        for (uint32_t k = 0; k < count; ++k) {
          const uint32_t i = uint32_t(p.raw(12 + size_t(k) * size, size));
          if (i >= pool.size())
            fail(
                fmt::format("mesh primitive at byte {}: index {} past the {} vertices of its "
                            "pool",
                            r.at, i, pool.size()));
          v[k] = pool[i];
        }
        if (drawnAside(drawType, v, a, aside)) continue;
        std::vector<uint32_t> tri;
        switch (type) {
          case 1:  // triangle strip, every other triangle turned to keep the winding
            for (uint32_t k = 2; k < count; ++k)
              if (k % 2)
                tri.insert(tri.end(), {k - 1, k - 2, k});
              else
                tri.insert(tri.end(), {k - 2, k - 1, k});
            break;
          case 2:  // triangle fan
            for (uint32_t k = 2; k < count; ++k) tri.insert(tri.end(), {0, k - 1, k});
            break;
          case 3:  // quadrilateral strip: quads (2k, 2k+1, 2k+3, 2k+2)
            for (uint32_t k = 0; k + 3 < count; k += 2)
              tri.insert(tri.end(), {k, k + 1, k + 3, k, k + 3, k + 2});
            break;
          case 4:  // indexed polygon
            if (count > kMaxFaceVertices)
              fail(fmt::format("mesh primitive at byte {} has more than {} vertices", r.at,
                               kMaxFaceVertices));
            if (count >= 3) tri = triangulate(v);
            break;
          default:
            fail(fmt::format("mesh primitive at byte {}: unknown type {}", r.at, type));
        }
        addPolygon(v, tri, a, buckets);
      }
    }
  }

  std::vector<Vertex> localPool(const Fields& p) const {
    const uint32_t count = p.u32(4), mask = p.u32(8);
    const bool position = mask & 0x80000000u, colorIndex = mask & 0x40000000u,
               rgba = mask & 0x20000000u, normal = mask & 0x10000000u, uv = mask & 0x08000000u;
    // uv layers 1–7 follow (bits 5–11), 8 bytes each.
    const size_t layers = size_t(std::popcount(mask & 0x07F00000u));
    const size_t stride = (position ? 24 : 0) + (colorIndex || rgba ? 4 : 0) + (normal ? 12 : 0) +
                          (uv ? 8 : 0) + 8 * layers;
    if (stride == 0 || uint64_t(count) * stride > p.size() - 12)
      fail(fmt::format("local vertex pool at byte {}: {} vertices do not fit its record", p.at(),
                       count));
    std::vector<Vertex> pool(count);
    for (uint32_t k = 0; k < count; ++k) {
      size_t o = 12 + size_t(k) * stride;
      Vertex& v = pool[k];
      if (position) {
        for (int c = 0; c < 3; ++c) v.p[c] = p.f64(o + 8 * size_t(c));
        o += 24;
      }
      if (colorIndex)
        v.color = indexedColor(p.u32(o)), o += 4;
      else if (rgba)
        v.color = packedColor(p.u32(o)), o += 4;
      if (normal) v.normal = Vec3{p.f32(o), p.f32(o + 4), p.f32(o + 8)}, o += 12;
      if (uv) v.uv = Vec2{p.f32(o), p.f32(o + 4)};
    }
    return pool;
  }

  // --- Light points ---------------------------------------------------------------------------

  // One light per vertex of a light-drawn face: omnidirectional (8), or shining along the vertex
  // normal (the face's without one) one way (9) or both ways (10), in the vertex or face colour.
  void placeLightFace(const AsideFace& face, const Place& at) {
    LightAppearance look;
    look.directional = face.drawType != 8;
    look.backLobe = face.drawType == 10;
    for (const Vertex& v : face.vertices) {
      const Vec4 c = face.attributes.vertexColors && v.color ? *v.color : face.attributes.color;
      const Vec3 n =
          v.normal && isFinite(*v.normal) && length(*v.normal) > 0 ? *v.normal : face.normal;
      addLight(look, {c.x, c.y, c.z}, n, v, at);
    }
  }

  // A wireframe face: a line along each edge, the last vertex back to the first when closed
  // (draw type 2), in the vertex colours (averaged) or the face's colour.
  void placeWireFace(const AsideFace& face, const Place& at) {
    const std::vector<Vertex>& v = face.vertices;
    const size_t n = v.size();
    const size_t edges = n < 2 ? 0 : face.drawType == 2 && n > 2 ? n : n - 1;
    if (scene_.lines.size() + edges > kMaxLines)
      fail(fmt::format("more than {} line segments", kMaxLines));
    auto point = [&](const Vertex& x) {
      const Vec3 p = at.toWorld.transformPoint({float(x.p[0]), float(x.p[1]), float(x.p[2])});
      if (!isFinite(p)) fail("a wireframe vertex's position is not finite");
      return p;
    };
    auto color = [&](const Vertex& x) {
      const Vec4 c = face.attributes.vertexColors && x.color ? *x.color : face.attributes.color;
      return Vec3{c.x, c.y, c.z};
    };
    for (size_t k = 0; k < edges; ++k) {
      const Vertex& a = v[k];
      const Vertex& b = v[(k + 1) % n];
      scene_.lines.push_back({point(a), point(b), (color(a) + color(b)) * 0.5f});
    }
  }

  // A light at `v` placed by `at`, with `look`'s appearance in colour `color` facing `normal`
  // (appearances shared by lights that look alike).
  void addLight(const LightAppearance& look, Vec3 color, Vec3 normal, const Vertex& v,
                const Place& at) {
    LightAppearance a = look;
    a.color = color;
    if (a.directional) {
      const Vec3 d = at.toWorld.transformDirection(normal);
      // A normal that is zero or not finite leaves the light omnidirectional.
      if (isFinite(d) && length(d) > 0)
        a.direction = normalize(d);
      else
        a.directional = a.backLobe = false;
    }
    const auto key = std::make_tuple(look.name, a.color.x, a.color.y, a.color.z, a.direction.x,
                                     a.direction.y, a.direction.z, a.intensity, a.directional,
                                     a.backLobe, a.blink.period, a.rotationPeriod);
    auto it = appearances_.find(key);
    if (it == appearances_.end()) {
      scene_.lightAppearances.push_back(a);
      it = appearances_.emplace(key, uint32_t(scene_.lightAppearances.size() - 1)).first;
    }
    const Vec3 p = at.toWorld.transformPoint({float(v.p[0]), float(v.p[1]), float(v.p[2])});
    if (!isFinite(p)) fail("a light's position is not finite");
    if (scene_.lightPoints.size() >= kMaxLightPoints)
      fail(fmt::format("more than {} light points", kMaxLightPoints));
    scene_.lightPoints.push_back({p, it->second, 0, -1});
  }

  // A light point record (111) as the look its lights share.
  static LightLook lightLookOf(const Fields& f) {
    LightLook l;
    l.back = packedColor(f.u32(16));
    l.intensity = f.f32(24), l.backIntensity = f.f32(28);
    l.directionality = f.i32(48);
    l.horizontalLobe = f.f32(100), l.verticalLobe = f.f32(104), l.falloff = f.f32(112);
    l.period = f.f32(120), l.delay = f.f32(124), l.enabled = f.f32(128);
    // Flags bits 13 and 12 (from the most significant): flashing, rotating.
    const uint32_t flags = f.u32(140);
    l.flashing = flags & 0x00040000u, l.rotating = flags & 0x00080000u;
    return l;
  }

  // A light at each vertex of light point node `index` (a 111 or 130 record), as `l` says.
  void placeLightPoints(uint32_t index, const LightLook& l, const Place& at) {
    const Node& node = nodes_[index];
    // Each value within what the light pass accepts; one that is not a number gets the default.
    auto sane = [](float v, float lo, float hi, float otherwise) {
      return std::isfinite(v) ? std::clamp(v, lo, hi) : otherwise;
    };
    LightAppearance look;
    look.name = node.name;
    const float intensity = sane(l.intensity, 0, 1e6f, 1);
    const float backIntensity = sane(l.backIntensity, 0, 1e6f, 0);
    look.horizontalLobe = sane(l.horizontalLobe, 1, 179, 30);
    look.verticalLobe = sane(l.verticalLobe, 1, 179, 15);
    look.falloff = sane(l.falloff, 0, 64, 1);
    const float period = sane(l.period, 0, 1e6f, 0), delay = sane(l.delay, -1e6f, 1e6f, 0),
                enabled = sane(l.enabled, 0, 1e6f, 0);
    // OpenFlight's intensities are relative (1: the modeller's full brightness); full brightness
    // is taken as the scene format's default light of 200 candela.
    constexpr float kFullCandela = 200;
    look.intensity = kFullCandela * intensity;
    look.directional = l.directionality == 1 || l.directionality == 2;  // 0 omni, 1/2 one/two-way
    look.backLobe = l.directionality == 2 && backIntensity > 0;
    // The back lobe's colour, dimmed by its intensity relative to the front's.
    const float backScale = intensity > 0 ? std::min(1.0f, backIntensity / intensity) : 0;
    look.backColor = Vec3{l.back.x, l.back.y, l.back.z} * backScale;
    if (l.flashing && period > 0 && enabled > 0) {
      look.blink.period = period;
      look.blink.onFraction = std::clamp(enabled / period, 0.01f, 1.0f);
      look.blink.phase = std::fmod(delay / period, 1.0f);
    }
    if (l.rotating && period > 0) look.rotationPeriod = period;
    for (const Vertex& v : faceVertices(node)) {
      const Vec4 c = v.color.value_or(Vec4{1, 1, 1, 1});
      addLight(look, {c.x, c.y, c.z}, v.normal.value_or(Vec3{0, 0, 1}), v, at);
    }
  }

  // --- Materials and textures -----------------------------------------------------------------

  int textureIndex(int pattern) {
    auto known = textureByPattern_.find(pattern);
    if (known != textureByPattern_.end()) return known->second;
    int index = -1;
    auto file = textureFiles_.find(pattern);
    if (file == textureFiles_.end()) {
      scene_.warnings.push_back(fmt::format(
          "{}: texture pattern {} is not in the texture palette; its faces are drawn without it",
          path_, pattern));
    } else if (!context_.options.followReferences) {
      fail(fmt::format("cannot open texture '{}' (references to other files are disabled)",
                       file->second));
    } else {
      Result<texture::Level> level =
          texture::readTextureImage(resolvePath(directoryOf(path_), file->second));
      if (!level) {
        scene_.warnings.push_back(
            fmt::format("{}: texture '{}': {}; its faces are drawn without it", path_, file->second,
                        level.error().str()));
      } else {
        texels_ += uint64_t(level->width) * uint64_t(level->height);
        if (texels_ > context_.options.maxTexels)
          fail(fmt::format("the textures exceed {} texels", context_.options.maxTexels));
        scene_.textures.push_back(
            {file->second,
             std::make_shared<texture::Texture>(std::move(level.value()), texture::Wrap::repeat,
                                                texture::Wrap::repeat)});
        index = int(scene_.textures.size() - 1);
      }
    }
    textureByPattern_[pattern] = index;
    return index;
  }

  int materialFor(const MaterialKey& key) {
    auto it = materialIndex_.find(key);
    if (it != materialIndex_.end()) return it->second;
    Material m;
    Vec3 diffuse{1, 1, 1};
    if (key.material >= 0) {
      const FltMaterial& fm = materials_.at(key.material);
      m.name = fm.name;
      diffuse = fm.diffuse;
    }
    auto unit = [](float x) { return std::clamp(x, 0.0f, 1.0f); };
    m.baseColor = {unit(diffuse.x), unit(diffuse.y), unit(diffuse.z), unit(key.alpha)};
    m.doubleSided = key.doubleSided;
    m.unlit = !key.lit;
    m.texture = key.texture;
    if (key.alpha < 1 || key.blend) m.alphaMode = AlphaMode::blend;
    scene_.materials.push_back(std::move(m));
    return materialIndex_[key] = int(scene_.materials.size() - 1);
  }

  struct FltMaterial {
    std::string name;
    Vec3 diffuse{1, 1, 1};
    float alpha = 1;
  };

  const std::string& bytes_;
  const std::string& path_;
  LoadContext& context_;
  Scene scene_;
  std::vector<Record> records_;
  std::deque<std::string> owned_;
  std::vector<Node> nodes_;
  std::vector<Vec4> colors_;
  std::map<int32_t, FltMaterial> materials_;
  std::map<int32_t, LightLook> lightLooks_;       // light point appearance palette
  std::map<int32_t, LightAnimation> animations_;  // light point animation palette
  std::map<int32_t, std::string> textureFiles_;
  std::unordered_map<uint32_t, uint32_t> vertexAt_;  // palette offset → record
  std::map<int16_t, uint32_t> definitions_;          // instance definitions → node
  std::map<uint32_t, Built> builtOf_;  // node → its meshes and aside faces, built once
  std::map<std::tuple<std::string, float, float, float, float, float, float, float, bool, bool,
                      float, float>,
           uint32_t>
      appearances_;
  std::map<int, int> textureByPattern_;
  std::map<MaterialKey, int> materialIndex_;
  std::map<std::string, size_t> skipped_;
  size_t morse_ = 0;  // indexed light points whose animation is Morse code (drawn steady)
  Mat4 root_, rootInverse_;
  double unitScale_ = 1;
  int emptyMesh_ = -1;
  uint64_t visits_ = 0, triangles_ = 0, texels_ = 0, switchFlags_ = 0;
};

}  // namespace

Result<Scene> parseOpenFlightIn(const std::string& bytes, const std::string& path,
                                LoadContext& context) {
  context.openScenes.push_back(canonicalKey(path));
  struct Pop {
    LoadContext& c;
    ~Pop() { c.openScenes.pop_back(); }
  } pop{context};
  try {
    return Reader(bytes, path, context).read();
  } catch (const FltProblem& p) {
    return Error{path, "", p.message};
  }
}

}  // namespace detail

Result<Scene> parseOpenFlight(const std::string& bytes, const std::string& path,
                              const LoadOptions& options) {
  try {
    detail::LoadContext context{options, {}, {}};
    Result<Scene> scene = detail::parseOpenFlightIn(bytes, path, context);
    if (scene) buildInstanceTree(scene.value());
    return scene;
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  }
}

}  // namespace sv::formats
