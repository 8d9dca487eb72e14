// The prepared database (.svdb; docs/prep.md "The database file"): a scene written as its own
// arrays, read back by mapping the file — no parsing, one copy per array — after its header, size
// and checksum are checked.
// Based on: SPEC §1 (seed 004's database preparation system, whose output the image generator
// loads as is).
#include "formats/svdb.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <span>
#include <type_traits>

#include "formats/reader.h"
#include "synthvis/files.h"
#include "terrain/ground.h"
#include "texture/texture.h"

namespace sv::formats {
namespace {

constexpr char kMagic[8] = {'S', 'V', 'D', 'B', '\r', '\n', 0x1A, '\n'};
constexpr uint32_t kVersion = 3;             // 2: lines; 3: the geodetic frame
constexpr uint32_t kByteOrder = 0x01020304;  // as this machine writes it
constexpr size_t kHeaderBytes = detail::kDatabaseHeaderBytes;
constexpr size_t kAlign = 16;  // arrays start on 16-byte boundaries of the file

// Header: magic (8), version (4), byte order (4), payload bytes (8), payload checksum (8), zeros
// (database.h).

struct DbProblem {
  std::string message;
};
[[noreturn]] void fail(std::string message) { throw DbProblem{std::move(message)}; }

class Writer {
 public:
  std::string out;
  template <typename T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void str(const std::string& s) {
    pod(uint32_t(s.size()));
    out += s;
  }
  template <typename T>
  void array(const std::vector<T>& v) {
    array(std::span<const T>(v));
  }
  template <typename T>
  void array(std::span<const T> v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(uint64_t(v.size()));
    out.append((kAlign - out.size() % kAlign) % kAlign, '\0');
    if (!v.empty()) out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
};

class Reader {
 public:
  Reader(const char* data, size_t size) : p_(data), n_(size) {}
  template <typename T>
  T pod(const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, p_ + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  std::string str(const char* what) {
    const uint32_t n = pod<uint32_t>(what);
    need(n, what);
    std::string s(p_ + at_, n);
    at_ += n;
    return s;
  }
  template <typename T>
  std::vector<T> array(const char* what) {
    const uint64_t count = pod<uint64_t>(what);
    at_ += std::min((kAlign - at_ % kAlign) % kAlign, n_ - at_);
    // The count is bounded by the bytes that are there: no allocation beyond the file's size.
    if (count > (n_ - at_) / sizeof(T))
      fail(fmt::format("{}: {} elements run past the end", what, count));
    std::vector<T> v(static_cast<size_t>(count));
    if (count > 0) std::memcpy(v.data(), p_ + at_, size_t(count) * sizeof(T));
    at_ += size_t(count) * sizeof(T);
    return v;
  }
  // A count of records that follow, each at least `least` bytes.
  size_t count(const char* what, size_t least) {
    const uint64_t c = pod<uint64_t>(what);
    if (c > (n_ - at_) / least) fail(fmt::format("{}: {} records run past the end", what, c));
    return size_t(c);
  }
  bool done() const { return at_ == n_; }

 private:
  void need(size_t bytes, const char* what) const {
    if (bytes > n_ - at_) fail(fmt::format("{}: truncated at payload byte {}", what, at_));
  }
  const char* p_;
  size_t n_;
  size_t at_ = 0;
};

// --- The scene, field by field (the same order both ways) ---------------------------------------

void put(Writer& w, const Material& m) {
  w.str(m.name);
  w.pod(m.baseColor);
  w.pod(uint8_t(m.doubleSided)), w.pod(uint8_t(m.unlit));
  w.pod(int32_t(m.texture)), w.pod(m.textureFilter), w.pod(m.uvScale);
  w.pod(uint8_t(m.phong)), w.pod(m.specular), w.pod(m.shininess);
  w.pod(m.alphaMode), w.pod(m.alphaCutoff);
}
Material getMaterial(Reader& r) {
  Material m;
  m.name = r.str("material");
  m.baseColor = r.pod<Vec4>("material");
  m.doubleSided = r.pod<uint8_t>("material"), m.unlit = r.pod<uint8_t>("material");
  m.texture = r.pod<int32_t>("material");
  m.textureFilter = r.pod<TextureFilter>("material");
  if (uint8_t(m.textureFilter) > uint8_t(TextureFilter::anisotropic)) fail("material: bad filter");
  m.uvScale = r.pod<Vec2>("material");
  m.phong = r.pod<uint8_t>("material"), m.specular = r.pod<float>("material");
  m.shininess = r.pod<float>("material");
  m.alphaMode = r.pod<AlphaMode>("material");
  if (uint8_t(m.alphaMode) > uint8_t(AlphaMode::mask)) fail("material: bad alpha mode");
  m.alphaCutoff = r.pod<float>("material");
  return m;
}

void put(Writer& w, const FreeFormNode& n) {
  w.pod(n.quadric), w.pod(n.weight);
  w.array(n.clips);
  w.pod(uint64_t(n.perturbations.size()));
  for (const FreeFormNode& c : n.perturbations) put(w, c);
}
FreeFormNode getFreeForm(Reader& r, int depth) {
  if (depth > kMaxFreeFormDepth) fail("free form: perturbations nest too deep");
  FreeFormNode n;
  n.quadric = r.pod<std::array<double, 10>>("free form");
  n.weight = r.pod<double>("free form");
  n.clips = r.array<std::array<double, 10>>("free form clips");
  const size_t k = r.count("free form perturbations", 88);
  for (size_t i = 0; i < k; ++i) n.perturbations.push_back(getFreeForm(r, depth + 1));
  return n;
}

void put(Writer& w, const LightAppearance& a) {
  w.str(a.name);
  w.pod(a.color), w.pod(a.intensity), w.pod(uint8_t(a.directional)), w.pod(a.direction);
  w.pod(a.horizontalLobe), w.pod(a.verticalLobe), w.pod(a.falloff);
  w.pod(uint8_t(a.backLobe)), w.pod(a.backColor);
  w.pod(uint8_t(a.split)), w.pod(a.splitAngle), w.pod(a.splitWidth), w.pod(a.lowColor);
  w.pod(a.blink), w.pod(a.rotationPeriod);
}
LightAppearance getAppearance(Reader& r) {
  const char* what = "light appearance";
  LightAppearance a;
  a.name = r.str(what);
  a.color = r.pod<Vec3>(what), a.intensity = r.pod<float>(what);
  a.directional = r.pod<uint8_t>(what), a.direction = r.pod<Vec3>(what);
  a.horizontalLobe = r.pod<float>(what), a.verticalLobe = r.pod<float>(what);
  a.falloff = r.pod<float>(what);
  a.backLobe = r.pod<uint8_t>(what), a.backColor = r.pod<Vec3>(what);
  a.split = r.pod<uint8_t>(what), a.splitAngle = r.pod<float>(what);
  a.splitWidth = r.pod<float>(what), a.lowColor = r.pod<Vec3>(what);
  a.blink = r.pod<LightBlink>(what), a.rotationPeriod = r.pod<float>(what);
  return a;
}

void put(Writer& w, const DofMotion& m) { w.pod(m.translate), w.pod(m.rotate), w.pod(m.scale); }
DofMotion getMotion(Reader& r) {
  DofMotion m;
  m.translate = r.pod<Vec3>("dof"), m.rotate = r.pod<Vec3>("dof"), m.scale = r.pod<Vec3>("dof");
  return m;
}

// Terrain: the height table (its codes and placement) and how the scene draws it. The pyramid is
// not stored: it is built on load, as the other loaders build it (part of loading, not of the
// first frame).
void put(Writer& w, const Terrain& t) {
  w.str(t.name);
  const HeightField& f = *t.heights;
  w.pod(int32_t(f.width)), w.pod(int32_t(f.height));
  w.pod(f.originU), w.pod(f.originV), w.pod(f.spacingU), w.pod(f.spacingV);
  w.pod(f.offset), w.pod(f.scale);
  w.str(f.source);
  const auto& g = f.geographic;
  w.pod(uint8_t(g.on)), w.pod(g.lon0), w.pod(g.lat0), w.pod(g.dLon), w.pod(g.dLat);
  w.pod(g.radiansPerUnit);
  w.array(f.q);
  w.pod(t.origin[0]), w.pod(t.origin[1]), w.pod(t.baseRadius), w.pod(uint8_t(t.bicubic));
  w.pod(int32_t(t.material)), w.pod(int32_t(t.image));
  for (double b : t.imageBounds) w.pod(b);
  w.pod(int32_t(t.detail)), w.pod(t.detailSize);
  w.pod(uint64_t(t.ramp.size()));
  for (const TerrainColorStop& c : t.ramp) w.pod(c.height), w.pod(c.color);
}
Terrain getTerrain(Reader& r, const Scene& s, uint64_t& texels, const LoadOptions& options) {
  Terrain t;
  t.name = r.str("terrain");
  HeightField f;
  f.width = r.pod<int32_t>("terrain"), f.height = r.pod<int32_t>("terrain");
  if (f.width < 2 || f.height < 2 || f.width > kMaxHeightSide || f.height > kMaxHeightSide)
    fail(fmt::format("terrain '{}': a {}×{} table (2 … 16384 a side)", t.name, f.width, f.height));
  f.originU = r.pod<double>("terrain"), f.originV = r.pod<double>("terrain");
  f.spacingU = r.pod<double>("terrain"), f.spacingV = r.pod<double>("terrain");
  f.offset = r.pod<double>("terrain"), f.scale = r.pod<double>("terrain");
  f.source = r.str("terrain");
  auto& g = f.geographic;
  g.on = r.pod<uint8_t>("terrain"), g.lon0 = r.pod<double>("terrain");
  g.lat0 = r.pod<double>("terrain"), g.dLon = r.pod<double>("terrain");
  g.dLat = r.pod<double>("terrain"), g.radiansPerUnit = r.pod<double>("terrain");
  f.q = r.array<uint16_t>("terrain heights");
  if (f.q.size() != size_t(f.width) * size_t(f.height))
    fail(fmt::format("terrain '{}': {} heights for a {}×{} table", t.name, f.q.size(), f.width,
                     f.height));
  texels += f.q.size();
  if (texels > options.maxTexels)
    fail(fmt::format("the textures and terrains exceed {} texels", options.maxTexels));
  t.origin[0] = r.pod<double>("terrain"), t.origin[1] = r.pod<double>("terrain");
  t.baseRadius = r.pod<double>("terrain"), t.bicubic = r.pod<uint8_t>("terrain");
  t.material = r.pod<int32_t>("terrain"), t.image = r.pod<int32_t>("terrain");
  for (double& b : t.imageBounds) b = r.pod<double>("terrain");
  t.detail = r.pod<int32_t>("terrain"), t.detailSize = r.pod<double>("terrain");
  for (size_t k = r.count("terrain ramp", 20); k > 0; --k) {
    TerrainColorStop c;
    c.height = r.pod<double>("terrain ramp"), c.color = r.pod<Vec3>("terrain ramp");
    t.ramp.push_back(c);
  }
  // What the renderer relies on, as the scene file's reader checks it.
  auto finite = [](std::initializer_list<double> v) {
    for (double x : v)
      if (!std::isfinite(x) || std::fabs(x) > 1e30) return false;
    return true;
  };
  const int textures = int(s.textures.size()), materials = int(s.materials.size());
  bool ok = finite({f.originU, f.originV, f.spacingU, f.spacingV, f.offset, f.scale, t.origin[0],
                    t.origin[1], t.baseRadius, t.detailSize, t.imageBounds[0], t.imageBounds[1],
                    t.imageBounds[2], t.imageBounds[3]}) &&
            f.spacingU > 0 && f.spacingV > 0 && t.baseRadius >= 0 && t.detailSize > 0 &&
            t.imageBounds[2] > t.imageBounds[0] && t.imageBounds[3] > t.imageBounds[1] &&
            t.material >= -1 && t.material < materials && t.image >= -1 && t.image < textures &&
            t.detail >= -1 && t.detail < textures && t.ramp.size() <= 64;
  for (size_t k = 0; k < t.ramp.size(); ++k)
    ok &= finite({t.ramp[k].height}) && isFinite(t.ramp[k].color) &&
          (k == 0 || t.ramp[k].height > t.ramp[k - 1].height);
  if (!ok) fail(fmt::format("terrain '{}': a value is not finite or out of range", t.name));
  t.heights = terrain::prepareGround(
      std::move(f), t.bicubic ? terrain::Interpolation::bicubic : terrain::Interpolation::bilinear);
  return t;
}

std::string encode(const Scene& s) {
  // Not silently dropped: a database cannot hold volumes yet (their grids belong in the mapping
  // beside the meshes; issue 33).
  if (!s.volumes.empty())
    throw DbProblem{
        fmt::format("{} volumes: a database does not hold volumes yet (render the "
                    "scene file)",
                    s.volumes.size())};
  Writer w;
  // Structures with padding or bools go field by field (the file's bytes are all defined, and
  // every bool read back is 0 or 1).
  w.pod(s.background);
  w.pod(s.light.direction), w.pod(s.light.color), w.pod(s.light.ambient);
  w.pod(uint8_t(s.light.enabled));
  w.pod(uint8_t(s.fog.enabled)), w.pod(s.fog.color), w.pod(s.fog.beta);
  w.pod(s.time), w.pod(s.lightSettings);
  w.pod(uint8_t(s.geodetic.has_value()));
  if (s.geodetic) {
    const GeoPoint& o = s.geodetic->origin;
    w.pod(o.lat), w.pod(o.lon), w.pod(o.alt), w.pod(uint8_t(s.geodetic->curved));
  }
  w.pod(uint64_t(s.textures.size()));
  for (const TextureMap& t : s.textures) {
    w.str(t.name);
    const texture::Texture& tex = *t.texture;
    w.pod(int32_t(tex.level(0).width)), w.pod(int32_t(tex.level(0).height));
    w.pod(tex.wrapX()), w.pod(tex.wrapY());
    w.array(tex.allTexels());
  }
  w.pod(uint64_t(s.materials.size()));
  for (const Material& m : s.materials) put(w, m);
  w.pod(uint64_t(s.meshes.size()));
  for (const Mesh& m : s.meshes) {
    w.str(m.name), w.pod(int32_t(m.material));
    w.array(m.positions), w.array(m.normals), w.array(m.colors), w.array(m.uvs);
    w.array(m.indices);
  }
  w.pod(uint64_t(s.instances.size()));
  for (const Instance& i : s.instances) {
    w.pod(int32_t(i.mesh)), w.pod(i.transform), w.pod(int32_t(i.priority)), w.pod(int32_t(i.lod));
    w.pod(uint8_t(i.visible)), w.pod(uint8_t(i.articulated));
  }
  w.pod(uint64_t(s.lodGroups.size()));
  for (const LodGroup& g : s.lodGroups) {
    w.str(g.name), w.pod(g.fade), w.pod(uint8_t(g.center.has_value()));
    w.pod(g.center.value_or(Vec3{0, 0, 0}));
    w.array(g.levels);
  }
  w.pod(uint64_t(s.switches.size()));
  for (const Switch& sw : s.switches) {
    w.str(sw.name), w.pod(uint64_t(sw.current));
    w.pod(uint64_t(sw.children.size()));
    for (const auto& c : sw.children) w.array(c);
    w.pod(uint64_t(sw.masks.size()));
    for (const auto& m : sw.masks) w.array(std::vector<uint8_t>(m.begin(), m.end()));
  }
  w.pod(uint64_t(s.dofs.size()));
  for (const Dof& d : s.dofs) {
    w.str(d.name), w.pod(int32_t(d.parent)), w.pod(d.place), w.pod(d.frame);
    put(w, d.current), put(w, d.min), put(w, d.max);
    std::vector<uint32_t> parts;
    std::vector<Mat4> transforms;
    for (const auto& [i, m] : d.parts) parts.push_back(i), transforms.push_back(m);
    w.array(parts), w.array(transforms);
  }
  // The instance tree, as built: loading does not rebuild it.
  w.pod(uint8_t(s.instanceTree != nullptr));
  if (s.instanceTree) {
    w.array(s.instanceTree->nodes), w.array(s.instanceTree->order);
    w.array(s.instanceTree->loose), w.pod(uint64_t(s.instanceTree->instanceCount));
  }
  w.pod(uint64_t(s.terrains.size()));
  for (const Terrain& t : s.terrains) put(w, t);
  w.pod(uint64_t(s.freeForms.size()));
  for (const FreeFormObject& f : s.freeForms) {
    w.str(f.name), put(w, f.form), w.pod(f.transform), w.pod(int32_t(f.material));
  }
  w.pod(uint64_t(s.cameras.size()));
  for (const Camera& c : s.cameras) {
    w.str(c.name), w.pod(c.position), w.pod(c.target), w.pod(c.up);
    w.pod(c.yfovDegrees), w.pod(c.znear), w.pod(c.zfar);
  }
  w.pod(uint64_t(s.channels.size()));
  for (const Channel& c : s.channels) {
    w.str(c.name), w.pod(c.yawDegrees), w.pod(c.pitchDegrees), w.pod(c.rollDegrees);
    w.pod(c.offset), w.pod(uint8_t(c.frustum.has_value()));
    w.pod(c.frustum.value_or(ChannelFrustum{})), w.pod(int32_t(c.width)), w.pod(int32_t(c.height));
  }
  w.array(s.pointLights);
  w.pod(uint64_t(s.lightAppearances.size()));
  for (const LightAppearance& a : s.lightAppearances) put(w, a);
  w.array(s.lightPoints);
  w.pod(uint64_t(s.lightGroups.size()));
  for (const LightGroup& g : s.lightGroups) w.str(g.name), w.pod(uint8_t(g.on)), w.pod(g.dim);
  w.array(s.stars.stars);
  w.pod(s.stars.latitude), w.pod(s.stars.siderealTime), w.pod(s.stars.brightness);
  w.pod(s.stars.limit);
  w.array(s.lines);
  w.pod(s.lineSettings);
  w.pod(uint64_t(s.warnings.size()));
  for (const std::string& warning : s.warnings) w.str(warning);
  return std::move(w.out);
}

// --- The scene's other records, read back (encode writes them in line) ---------------------------

// The background, the light, the fog, the time and the geodetic frame.
void getEnvironment(Reader& r, Scene& s) {
  s.background = r.pod<Vec3>("background");
  s.light.direction = r.pod<Vec3>("light"), s.light.color = r.pod<Vec3>("light");
  s.light.ambient = r.pod<float>("light"), s.light.enabled = r.pod<uint8_t>("light");
  s.fog.enabled = r.pod<uint8_t>("fog"), s.fog.color = r.pod<Vec3>("fog");
  s.fog.beta = r.pod<float>("fog");
  s.time = r.pod<double>("time");
  s.lightSettings = r.pod<LightSettings>("light settings");
  if (r.pod<uint8_t>("geodetic frame")) {
    Geodetic g;
    g.origin.lat = r.pod<double>("geodetic frame"), g.origin.lon = r.pod<double>("geodetic frame");
    g.origin.alt = r.pod<double>("geodetic frame"), g.curved = r.pod<uint8_t>("geodetic frame");
    if (!(std::fabs(g.origin.lat) <= 89) || !(std::fabs(g.origin.lon) <= 180) ||
        !(std::fabs(g.origin.alt) <= 1e5))
      fail("the geodetic frame's origin is not finite or out of range");
    s.geodetic = g;
  }
}

// A texture and its pyramid; its level 0 counted into `texels` against the options' limit.
TextureMap getTexture(Reader& r, uint64_t& texels, const LoadOptions& options) {
  TextureMap t;
  t.name = r.str("texture");
  const int32_t width = r.pod<int32_t>("texture"), height = r.pod<int32_t>("texture");
  const auto wx = r.pod<texture::Wrap>("texture"), wy = r.pod<texture::Wrap>("texture");
  if (width < 1 || height < 1 || width > texture::kMaxTextureSide ||
      height > texture::kMaxTextureSide || uint8_t(wx) > 2 || uint8_t(wy) > 2)
    fail(fmt::format("texture '{}': size {}×{} or wrap modes out of range", t.name, width, height));
  std::vector<texture::PackedTexel> pyramid = r.array<texture::PackedTexel>("texture texels");
  if (pyramid.size() != texture::Texture::pyramidTexels(width, height))
    fail(fmt::format("texture '{}': {} texels for a {}×{} pyramid", t.name, pyramid.size(), width,
                     height));
  texels += uint64_t(width) * uint64_t(height);
  if (texels > options.maxTexels)
    fail(fmt::format("the textures exceed {} texels", options.maxTexels));
  t.texture = std::make_shared<texture::Texture>(width, height, wx, wy, std::move(pyramid));
  return t;
}

Mesh getMesh(Reader& r) {
  Mesh m;
  m.name = r.str("mesh"), m.material = r.pod<int32_t>("mesh");
  m.positions = r.array<Vec3>("positions"), m.normals = r.array<Vec3>("normals");
  m.colors = r.array<Vec4>("colors"), m.uvs = r.array<Vec2>("uvs");
  m.indices = r.array<uint32_t>("indices");
  return m;
}

Instance getInstance(Reader& r) {
  Instance i;
  i.mesh = r.pod<int32_t>("instance"), i.transform = r.pod<Mat4>("instance");
  i.priority = r.pod<int32_t>("instance"), i.lod = r.pod<int32_t>("instance");
  i.visible = r.pod<uint8_t>("instance"), i.articulated = r.pod<uint8_t>("instance");
  return i;
}

LodGroup getLodGroup(Reader& r) {
  LodGroup g;
  g.name = r.str("LOD group"), g.fade = r.pod<float>("LOD group");
  const bool centred = r.pod<uint8_t>("LOD group");
  const Vec3 c = r.pod<Vec3>("LOD group");
  if (centred) g.center = c;
  g.levels = r.array<LodLevel>("LOD levels");
  return g;
}

Switch getSwitch(Reader& r) {
  Switch sw;
  sw.name = r.str("switch"), sw.current = size_t(r.pod<uint64_t>("switch"));
  for (size_t c = r.count("switch children", 8); c > 0; --c)
    sw.children.push_back(r.array<uint32_t>("switch child"));
  for (size_t m = r.count("switch masks", 8); m > 0; --m) {
    const std::vector<uint8_t> flags = r.array<uint8_t>("switch mask");
    sw.masks.emplace_back(flags.begin(), flags.end());
  }
  return sw;
}

Dof getDof(Reader& r) {
  Dof d;
  d.name = r.str("dof"), d.parent = r.pod<int32_t>("dof");
  d.place = r.pod<Mat4>("dof"), d.frame = r.pod<Mat4>("dof");
  d.current = getMotion(r), d.min = getMotion(r), d.max = getMotion(r);
  const std::vector<uint32_t> parts = r.array<uint32_t>("dof parts");
  const std::vector<Mat4> transforms = r.array<Mat4>("dof parts");
  if (parts.size() != transforms.size()) fail("dof: parts and transforms differ in number");
  for (size_t i = 0; i < parts.size(); ++i) d.parts.push_back({parts[i], transforms[i]});
  return d;
}

// The instance tree over `instances` instances, every index checked in range so that a
// traversal of a damaged tree stays inside its arrays.
std::shared_ptr<InstanceTree> getInstanceTree(Reader& r, size_t instances) {
  auto tree = std::make_shared<InstanceTree>();
  tree->nodes = r.array<InstanceTree::Node>("instance tree nodes");
  tree->order = r.array<uint32_t>("instance tree order");
  tree->loose = r.array<uint32_t>("instance tree loose");
  tree->instanceCount = size_t(r.pod<uint64_t>("instance tree"));
  for (const InstanceTree::Node& n : tree->nodes)
    if ((n.count > 0 && (n.first > tree->order.size() || n.count > tree->order.size() - n.first)) ||
        (n.count == 0 &&
         (n.first + 1ull >= tree->nodes.size() || n.first <= size_t(&n - tree->nodes.data()))))
      fail("instance tree: a node's range is out of bounds");
  for (uint32_t i : tree->order)
    if (i >= instances) fail("instance tree: an instance out of range");
  for (uint32_t i : tree->loose)
    if (i >= instances) fail("instance tree: an instance out of range");
  return tree;
}

FreeFormObject getFreeFormObject(Reader& r) {
  FreeFormObject f;
  f.name = r.str("free form"), f.form = getFreeForm(r, 0);
  f.transform = r.pod<Mat4>("free form"), f.material = r.pod<int32_t>("free form");
  return f;
}

Camera getCamera(Reader& r) {
  Camera c;
  c.name = r.str("camera"), c.position = r.pod<Vec3>("camera"), c.target = r.pod<Vec3>("camera");
  c.up = r.pod<Vec3>("camera"), c.yfovDegrees = r.pod<float>("camera");
  c.znear = r.pod<float>("camera"), c.zfar = r.pod<float>("camera");
  return c;
}

Channel getChannel(Reader& r) {
  Channel c;
  c.name = r.str("channel"), c.yawDegrees = r.pod<float>("channel");
  c.pitchDegrees = r.pod<float>("channel"), c.rollDegrees = r.pod<float>("channel");
  c.offset = r.pod<Vec3>("channel");
  const bool framed = r.pod<uint8_t>("channel");
  const ChannelFrustum f = r.pod<ChannelFrustum>("channel");
  if (framed) c.frustum = f;
  c.width = r.pod<int32_t>("channel"), c.height = r.pod<int32_t>("channel");
  return c;
}

LightGroup getLightGroup(Reader& r) {
  LightGroup g;
  g.name = r.str("light group"), g.on = r.pod<uint8_t>("light group");
  g.dim = r.pod<float>("light group");
  return g;
}

// The payload as encode wrote it, record by record, each count bounded by the bytes left (at
// least the record's smallest size each).
Scene decode(const char* data, size_t size, const LoadOptions& options) {
  Reader r(data, size);
  Scene s;
  getEnvironment(r, s);
  uint64_t texels = 0;
  for (size_t k = r.count("textures", 24); k > 0; --k)
    s.textures.push_back(getTexture(r, texels, options));
  for (size_t k = r.count("materials", 40); k > 0; --k) s.materials.push_back(getMaterial(r));
  uint64_t triangles = 0;
  for (size_t k = r.count("meshes", 48); k > 0; --k) {
    s.meshes.push_back(getMesh(r));
    // The limit counts the triangles stored (its meshes'), not their placements: a database of
    // instances and levels of detail stands for far more than it holds.
    triangles += s.meshes.back().triangleCount();
  }
  for (size_t k = r.count("instances", 78); k > 0; --k) s.instances.push_back(getInstance(r));
  if (triangles > options.maxTriangles)
    fail(fmt::format("more than {} triangles", options.maxTriangles));
  for (size_t k = r.count("LOD groups", 25); k > 0; --k) s.lodGroups.push_back(getLodGroup(r));
  for (size_t k = r.count("switches", 28); k > 0; --k) s.switches.push_back(getSwitch(r));
  for (size_t k = r.count("degrees of freedom", 250); k > 0; --k) s.dofs.push_back(getDof(r));
  if (r.pod<uint8_t>("instance tree")) s.instanceTree = getInstanceTree(r, s.instances.size());
  const size_t terrains = r.count("terrains", 120);
  if (terrains > 64) fail(fmt::format("{} terrains (at most 64)", terrains));
  for (size_t k = 0; k < terrains; ++k) s.terrains.push_back(getTerrain(r, s, texels, options));
  for (size_t k = r.count("free forms", 100); k > 0; --k)
    s.freeForms.push_back(getFreeFormObject(r));
  for (size_t k = r.count("cameras", 52); k > 0; --k) s.cameras.push_back(getCamera(r));
  for (size_t k = r.count("channels", 53); k > 0; --k) s.channels.push_back(getChannel(r));
  s.pointLights = r.array<PointLight>("point lights");
  for (size_t k = r.count("light appearances", 90); k > 0; --k)
    s.lightAppearances.push_back(getAppearance(r));
  s.lightPoints = r.array<LightPoint>("light points");
  for (size_t k = r.count("light groups", 9); k > 0; --k) s.lightGroups.push_back(getLightGroup(r));
  s.stars.stars = r.array<Star>("stars");
  s.stars.latitude = r.pod<float>("stars"), s.stars.siderealTime = r.pod<float>("stars");
  s.stars.brightness = r.pod<float>("stars"), s.stars.limit = r.pod<float>("stars");
  s.lines = r.array<LineSegment>("lines");
  s.lineSettings = r.pod<LineSettings>("line settings");
  for (size_t k = r.count("warnings", 4); k > 0; --k) s.warnings.push_back(r.str("warning"));
  if (!r.done()) fail("bytes after the last record");
  return s;
}

// The mapping of a whole file, unmapped on scope exit.
struct Mapping {
  void* at = MAP_FAILED;
  size_t size = 0;
  ~Mapping() {
    if (at != MAP_FAILED) munmap(at, size);
  }
};

}  // namespace

uint64_t detail::databaseChecksum(const char* p, size_t n) {
  uint64_t h = 14695981039346656037ull;
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = (h ^ w) * 1099511628211ull;
  }
  if (i < n) {
    uint64_t w = 0;
    std::memcpy(&w, p + i, n - i);
    h = (h ^ w) * 1099511628211ull;
  }
  return h ^ (h >> 29);
}

Status saveDatabase(const Scene& scene, const std::string& path) {
  std::string payload;
  try {
    payload = encode(scene);
  } catch (const DbProblem& p) {
    return Error{path, "", p.message};
  }
  char header[kHeaderBytes] = {};
  std::memcpy(header, kMagic, 8);
  const uint64_t bytes = payload.size(),
                 sum = detail::databaseChecksum(payload.data(), payload.size());
  std::memcpy(header + 8, &kVersion, 4);
  std::memcpy(header + 12, &kByteOrder, 4);
  std::memcpy(header + detail::kDatabasePayloadBytesAt, &bytes, 8);
  std::memcpy(header + detail::kDatabaseChecksumAt, &sum, 8);
  // Written beside the target and renamed over it: a reader never maps a half-written file.
  const std::string temporary = path + ".partial";
  if (Status s = core::writeFile(temporary, {core::bytesOf(header, kHeaderBytes),
                                             core::bytesOf(payload.data(), payload.size())});
      !s) {
    std::remove(temporary.c_str());
    return Error{path, "", s.error().message};
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    std::remove(temporary.c_str());
    return Error{path, "", fmt::format("cannot write: {}", std::strerror(error))};
  }
  return {};
}

Result<Scene> parseDatabase(const char* data, size_t size, const std::string& path,
                            const LoadOptions& options) {
  try {
    if (size < kHeaderBytes || std::memcmp(data, kMagic, 8) != 0)
      return Error{path, "", "not a synthvis database (no SVDB header)"};
    uint32_t version, order;
    uint64_t bytes, sum;
    std::memcpy(&version, data + 8, 4);
    std::memcpy(&order, data + 12, 4);
    std::memcpy(&bytes, data + detail::kDatabasePayloadBytesAt, 8);
    std::memcpy(&sum, data + detail::kDatabaseChecksumAt, 8);
    if (order != kByteOrder)
      return Error{path, "", "database written on a machine of the other byte order"};
    if (version != kVersion)
      return Error{path, "",
                   fmt::format("database version {}, this synthvis reads version {} (run "
                               "`synthvis prep` again on the source)",
                               version, kVersion)};
    if (bytes != size - kHeaderBytes)
      return Error{path, "",
                   fmt::format("database is {} bytes, its header says {} (truncated or "
                               "appended to)",
                               size, bytes + kHeaderBytes)};
    if (detail::databaseChecksum(data + kHeaderBytes, bytes) != sum)
      return Error{path, "", "database is damaged (its checksum does not match)"};
    Scene scene = decode(data + kHeaderBytes, size_t(bytes), options);
    if (Status s = validate(scene, path); !s) return s.error();
    // The merged cells are not stored: made again from the valid instances, as buildInstanceTree
    // made them for the source (the same cells, so the same image). The tree was made here.
    if (scene.instanceTree)
      mergeFarLevels(scene, *std::const_pointer_cast<InstanceTree>(scene.instanceTree),
                     meshBounds(scene));
    return scene;
  } catch (const DbProblem& p) {
    return Error{path, "", "database: " + p.message};
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  }
}

Result<Scene> loadDatabase(const std::string& path, const LoadOptions& options) {
  // Opened and checked like every loader's file (a regular file within the size limit), then
  // mapped rather than read.
  struct stat st;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Error{path, "", fmt::format("cannot open file: {}", std::strerror(errno))};
  Mapping map;
  const bool regular = fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  if (regular && uint64_t(st.st_size) <= detail::kMaxFileBytes && st.st_size > 0) {
    map.size = size_t(st.st_size);
    map.at = mmap(nullptr, map.size, PROT_READ, MAP_PRIVATE, fd, 0);
  }
  ::close(fd);
  if (!regular) return Error{path, "", "cannot open file: not a regular file"};
  if (uint64_t(st.st_size) > detail::kMaxFileBytes)
    return Error{path, "",
                 fmt::format("file is too large ({} bytes, the limit is {})", st.st_size,
                             detail::kMaxFileBytes)};
  if (st.st_size == 0) return Error{path, "", "not a synthvis database (empty file)"};
  if (map.at == MAP_FAILED)
    return Error{path, "", fmt::format("cannot map file: {}", std::strerror(errno))};
  madvise(map.at, map.size, MADV_SEQUENTIAL);
  return parseDatabase(static_cast<const char*>(map.at), map.size, path, options);
}

}  // namespace sv::formats
