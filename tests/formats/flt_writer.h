// A minimal OpenFlight writer for tests and fuzz seeds: records in the layouts of the OpenFlight
// 16.x specification (big-endian), so that tests can build files with exactly the records they
// exercise. Not a general exporter: the caller orders the records (header, palettes, vertices,
// then the hierarchy) as a file must have them.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sv::formats::testing {

class FltWriter {
 public:
  struct Bytes {
    std::string b;
    Bytes& u8(uint8_t v) { return b.push_back(char(v)), *this; }
    Bytes& u16(uint16_t v) { return u8(uint8_t(v >> 8)).u8(uint8_t(v)); }
    Bytes& u32(uint32_t v) { return u16(uint16_t(v >> 16)).u16(uint16_t(v)); }
    Bytes& i16(int16_t v) { return u16(uint16_t(v)); }
    Bytes& i32(int32_t v) { return u32(uint32_t(v)); }
    Bytes& f32(float v) { return u32(std::bit_cast<uint32_t>(v)); }
    Bytes& f64(double v) {
      const uint64_t x = std::bit_cast<uint64_t>(v);
      return u32(uint32_t(x >> 32)).u32(uint32_t(x));
    }
    Bytes& text(const std::string& s, size_t n) {
      for (size_t i = 0; i < n; ++i) u8(i < s.size() ? uint8_t(s[i]) : 0);
      return *this;
    }
    Bytes& zeros(size_t n) { return b.append(n, '\0'), *this; }
    // Pads (or fails to, if already longer) to `n` bytes of payload.
    Bytes& to(size_t n) {
      if (b.size() < n) zeros(n - b.size());
      return *this;
    }
  };

  std::string bytes;

  // A record of opcode `op` with `payload` (everything after the 4-byte header). Payloads longer
  // than a record holds go on in continuation records (opcode 23).
  void record(uint16_t op, const Bytes& payload) {
    size_t at = 0;
    uint16_t code = op;
    do {
      const size_t n = std::min<size_t>(payload.b.size() - at, 65535 - 4);
      Bytes h;
      h.u16(code).u16(uint16_t(n + 4));
      bytes += h.b + payload.b.substr(at, n);
      at += n;
      code = 23;
    } while (at < payload.b.size());
  }

  void header(int32_t revision = 1610, uint8_t units = 0) {
    Bytes p;
    // ID, format and edit revisions, date, four next-node IDs, units multiplier; units at 62.
    p.text("db", 8).i32(revision).i32(0).zeros(32).zeros(8).i16(0).u8(units).u8(0);
    record(1, p.to(324 - 4));
  }
  void colorPalette(const std::vector<uint32_t>& abgr) {
    Bytes p;
    p.zeros(128);
    for (size_t i = 0; i < 1024; ++i) p.u32(i < abgr.size() ? abgr[i] : 0);
    record(32, p);
  }
  void material(int32_t index, float r, float g, float b, float alpha, const std::string& name) {
    Bytes p;
    p.i32(index).text(name, 12).u32(0);
    p.f32(0.2f).f32(0.2f).f32(0.2f).f32(r).f32(g).f32(b).zeros(24).f32(8).f32(alpha);
    record(113, p.to(84 - 4));
  }
  void texture(int32_t pattern, const std::string& file) {
    Bytes p;
    p.text(file, 200).i32(pattern).i32(0).i32(0);
    record(64, p);
  }

  // The vertex palette: call vertexPalette() once, then add vertices; each returns its offset.
  void vertexPalette() {
    paletteStart_ = bytes.size();
    Bytes p;
    p.i32(8);
    record(67, p);
  }
  // The palette's size field (its record plus every vertex record) kept up to date.
  void patchPaletteSize() {
    const uint32_t n = uint32_t(bytes.size() - paletteStart_);
    for (int k = 0; k < 4; ++k) bytes[paletteStart_ + 4 + size_t(k)] = char(n >> (24 - 8 * k));
  }
  struct V {
    double x = 0, y = 0, z = 0;
    std::optional<std::array<float, 3>> normal;
    std::optional<std::array<float, 2>> uv;
    std::optional<uint32_t> packed;  // ABGR; none: "no colour"
    static V at(double x, double y, double z, std::optional<std::array<float, 3>> normal = {},
                std::optional<uint32_t> packed = {}) {
      V v;
      v.x = x, v.y = y, v.z = z, v.normal = normal, v.packed = packed;
      return v;
    }
  };
  int32_t vertex(const V& v) {
    const int32_t offset = int32_t(bytes.size() - paletteStart_);
    const uint16_t op = v.normal ? (v.uv ? 70 : 69) : (v.uv ? 71 : 68);
    Bytes p;
    p.u16(0).u16(v.packed ? 0x1000 : 0x2000).f64(v.x).f64(v.y).f64(v.z);
    if (v.normal) p.f32((*v.normal)[0]).f32((*v.normal)[1]).f32((*v.normal)[2]);
    if (v.uv) p.f32((*v.uv)[0]).f32((*v.uv)[1]);
    p.u32(v.packed.value_or(0)).u32(0);
    if (op == 69 || op == 70) p.u32(0);  // reserved
    record(op, p);
    patchPaletteSize();
    return offset;
  }

  void push() { record(10, Bytes{}); }
  void pop() { record(11, Bytes{}); }
  void pushSubface() { record(19, Bytes{}); }
  void popSubface() { record(20, Bytes{}); }

  void group(const std::string& name) {
    Bytes p;
    record(2, p.text(name, 8).to(44 - 4));
  }
  void object(const std::string& name) {
    Bytes p;
    record(4, p.text(name, 8).to(28 - 4));
  }
  // A matrix (column-major 16 floats, translation in 12–14), after the node it transforms.
  void matrix(const std::array<float, 16>& m) {
    Bytes p;
    for (float x : m) p.f32(x);
    record(49, p);
  }
  static std::array<float, 16> translation(float x, float y, float z) {
    return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x, y, z, 1};
  }

  struct Face {
    std::string name = "f";
    int8_t drawType = 0;  // 0 one-sided, 1 two-sided, 2/3 wireframe, 8–10 lights
    int16_t texture = -1, material = -1;
    uint16_t transparency = 0;
    uint8_t lightMode = 2;           // 0 face colour, 1 vertex colours, 2/3 the same lit
    std::optional<uint32_t> packed;  // ABGR; else colorIndex
    uint32_t colorIndex = 0xFFFFFFFF;
    bool hidden = false;
    Face& draw(int8_t d) { return drawType = d, *this; }
    Face& mat(int16_t m) { return material = m, *this; }
    Face& light(uint8_t l) { return lightMode = l, *this; }
    Face& rgb(uint32_t abgr) { return packed = abgr, *this; }
    Face& index(uint32_t i) { return colorIndex = i, *this; }
    Face& hide() { return hidden = true, *this; }
  };
  Bytes faceFields(const Face& f, bool mesh) {
    Bytes p;
    p.text(f.name, 8);
    if (mesh) p.u32(0);
    p.i32(0).i16(0).u8(uint8_t(f.drawType)).u8(0).u16(0xFFFF).u16(0xFFFF).u8(0).u8(0);
    p.i16(-1).i16(f.texture).i16(f.material).i16(0).i16(0).i32(0).u16(f.transparency).u8(0).u8(0);
    const uint32_t flags = (f.packed ? 0x10000000u : 0) | (f.hidden ? 0x04000000u : 0);
    p.u32(flags).u8(f.lightMode).zeros(7).u32(f.packed.value_or(0)).u32(0).i16(-1).i16(0);
    p.u32(f.colorIndex).u32(0xFFFFFFFF).i16(0).i16(-1);
    return p;
  }
  void face(const Face& f) { record(5, faceFields(f, false)); }
  void vertexList(const std::vector<int32_t>& offsets) {
    Bytes p;
    for (int32_t o : offsets) p.i32(o);
    record(72, p);
  }
  // A face and its vertex list, in push/pop.
  void polygon(const Face& f, const std::vector<int32_t>& offsets) {
    face(f);
    push();
    vertexList(offsets);
    pop();
  }

  void mesh(const Face& f) { record(84, faceFields(f, true)); }
  // A local vertex pool of positions (and normals, when given for every vertex).
  void localPool(const std::vector<std::array<double, 3>>& p,
                 const std::vector<std::array<float, 3>>& normals = {}) {
    Bytes b;
    b.u32(uint32_t(p.size())).u32(0x80000000u | (normals.empty() ? 0 : 0x10000000u));
    for (size_t i = 0; i < p.size(); ++i) {
      b.f64(p[i][0]).f64(p[i][1]).f64(p[i][2]);
      if (!normals.empty()) b.f32(normals[i][0]).f32(normals[i][1]).f32(normals[i][2]);
    }
    record(85, b);
  }
  void meshPrimitive(int16_t type, const std::vector<uint32_t>& indices, uint16_t size = 4) {
    Bytes b;
    b.i16(type).u16(size).u32(uint32_t(indices.size()));
    for (uint32_t i : indices)
      size == 1 ? b.u8(uint8_t(i)) : size == 2 ? b.u16(uint16_t(i)) : b.u32(i);
    record(86, b);
  }

  void lod(const std::string& name, double switchIn, double switchOut,
           std::array<double, 3> center = {0, 0, 0}, double transition = 0) {
    Bytes p;
    p.text(name, 8).i32(0).f64(switchIn).f64(switchOut).i16(0).i16(0).u32(0);
    p.f64(center[0]).f64(center[1]).f64(center[2]).f64(transition).f64(0);
    record(73, p);
  }
  // `masks` one word each, or (a malformed record) `declaredMasks` of `words` words declared
  // while the words written are still `masks`.
  void switchNode(const std::string& name, int32_t current,
                  const std::vector<uint32_t>& masks /* one word each */,
                  int32_t declaredMasks = -1, int32_t words = 1) {
    Bytes p;
    p.text(name, 8).i32(0).i32(current);
    p.i32(declaredMasks < 0 ? int32_t(masks.size()) : declaredMasks).i32(words);
    for (uint32_t m : masks) p.u32(m);
    record(96, p);
  }
  struct DofRanges {
    // (min, max, current) for x, y, z, pitch, roll, yaw, scale x, y, z; flags: limits.
    std::array<std::array<double, 3>, 9> r{};
    uint32_t flags = 0;
  };
  void dof(const std::string& name, std::array<double, 3> origin, std::array<double, 3> onX,
           std::array<double, 3> inXy, DofRanges ranges) {
    for (int k = 6; k < 9; ++k)
      if (ranges.r[size_t(k)] == std::array<double, 3>{0, 0, 0}) ranges.r[size_t(k)] = {1, 1, 1};
    Bytes p;
    p.text(name, 8).i32(0);
    for (auto* v : {&origin, &onX, &inXy}) p.f64((*v)[0]).f64((*v)[1]).f64((*v)[2]);
    // Order in the record: z, y, x, pitch, roll, yaw, scale z, y, x.
    for (int k : {2, 1, 0, 3, 4, 5, 8, 7, 6})
      p.f64(ranges.r[size_t(k)][0]).f64(ranges.r[size_t(k)][1]).f64(ranges.r[size_t(k)][2]).f64(0);
    p.u32(ranges.flags);
    record(14, p.to(384 - 4));
  }
  void externalReference(const std::string& file) {
    Bytes p;
    p.text(file, 200).i32(0).u32(0).i16(0).i16(0);
    record(63, p.to(216 - 4));
  }
  void instanceDefinition(int16_t n) {
    Bytes p;
    record(62, p.i16(0).i16(n));
  }
  void instanceReference(int16_t n) {
    Bytes p;
    record(61, p.i16(0).i16(n));
  }
  // A light point record (111): directional 0 omni, 1 one-way, 2 two-way.
  void lightPoint(const std::string& name, float intensity, int32_t directional, float period = 0,
                  float enabled = 0, bool flashing = false) {
    Bytes p;
    p.text(name, 8).i16(0).i16(0).u32(0xFF0000FFu).i32(0).f32(intensity).f32(0);
    p.to(48 - 4).i32(directional).to(100 - 4).f32(30).f32(15).f32(0).f32(1).f32(0);
    p.f32(period).f32(0).f32(enabled).to(140 - 4).u32(flashing ? 0x00040000u : 0);
    record(111, p.to(156 - 4));
  }
  // A light point appearance palette entry (128): directional 0 omni, 1 one-way, 2 two-way.
  void lightPointAppearance(int32_t index, float intensity, int32_t directional,
                            uint32_t backColorIndex = 0xFFFFFFFFu, float backIntensity = 0) {
    Bytes p;
    p.zeros(4).text("look", 256).i32(index).i16(0).i16(0).u32(backColorIndex).i32(0);
    p.f32(intensity).f32(backIntensity).to(352 - 4).i32(directional).f32(40).f32(10).f32(0);
    p.f32(1);
    record(128, p.to(412 - 4));
  }
  // A light point animation palette entry (129): type 0 flashing sequence (pulses: state 0 on,
  // 1 off, and duration), 1 rotating, 2 strobe, 3 Morse code.
  void lightPointAnimation(int32_t index, int32_t type, float period, float delay, float enabled,
                           const std::vector<std::pair<uint32_t, float>>& pulses = {}) {
    Bytes p;
    p.zeros(4).text("anim", 256).i32(index).f32(period).f32(delay).f32(enabled);
    p.f32(0).f32(0).f32(1).u32(0).i32(type).to(1336 - 4).i32(int32_t(pulses.size()));
    for (const auto& [state, duration] : pulses) p.u32(state).f32(duration).u32(0xFFFFFFFFu);
    record(129, p);
  }
  // An indexed light point (130) of appearance `appearance` and animation `animation` (−1: none).
  void indexedLightPoint(const std::string& name, int32_t appearance, int32_t animation = -1) {
    Bytes p;
    record(130, p.text(name, 8).i32(appearance).i32(animation).i32(0).to(28 - 4));
  }

 private:
  size_t paletteStart_ = 0;
};

// A file with one of every node the reader handles, in metres:
//   group "g" (moved +10 in x) { object "o" { red quad, grey triangle },
//     lod "hi" [0, 100) { triangle }, lod "lo" [100, 1000) { triangle },
//     switch "sw" (masks 01, 10) { object "a", object "b" },
//     dof "d" (origin (5, 0, 0), yaw 90°, pitch 30°) { triangle },
//     mesh { strip of 4, fan of 5, quad strip of 6, polygon of 5 },
//     light point { 3 lights } }
inline std::string everyNodeFlt() {
  FltWriter w;
  w.header();
  w.colorPalette({0xFF000000u, 0xFF808080u});  // entry 1: grey (ABGR)
  w.material(0, 0.5f, 1.0f, 1.0f, 1.0f, "cyan");
  w.vertexPalette();
  std::vector<int32_t> quad, tri, hi, lo, a, b, d, lights;
  for (auto [x, y] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}})
    quad.push_back(w.vertex(FltWriter::V::at(x, y, 0, std::array<float, 3>{0, 0, 1})));
  for (double x : {2.0, 3.0, 2.5})
    tri.push_back(w.vertex(FltWriter::V::at(x, x == 2.5 ? 1 : 0, 0.5)));
  for (double x : {0.0, 1.0, 0.5}) hi.push_back(w.vertex(FltWriter::V::at(x, 2, x)));
  for (double x : {0.0, 1.0, 0.5}) lo.push_back(w.vertex(FltWriter::V::at(x, 3, 1 + x)));
  for (double x : {0.0, 1.0, 0.5}) a.push_back(w.vertex(FltWriter::V::at(x, 4, x)));
  for (double x : {0.0, 1.0, 0.5}) b.push_back(w.vertex(FltWriter::V::at(x, 5, x)));
  for (double x : {6.0, 7.0, 6.5})
    d.push_back(w.vertex(FltWriter::V::at(x, x == 6.5 ? 1 : 0, 0.25)));
  for (double x : {0.0, 1.0, 2.0})
    lights.push_back(w.vertex(FltWriter::V::at(x, -1, 3, {}, 0xFF00FFFFu)));  // yellow
  w.push();
  w.group("g");
  w.matrix(FltWriter::translation(10, 0, 0));
  w.push();
  w.object("o");
  w.push();
  w.polygon(FltWriter::Face().mat(0).rgb(0xFF0000FFu), quad);  // red × cyan material
  w.polygon(FltWriter::Face().draw(1).light(0).index(1 * 128 + 127), tri);
  w.pop();
  w.lod("hi", 100, 0, {0.5, 2, 0});
  w.push();
  w.object("hio");
  w.push();
  w.polygon({}, hi);
  w.pop();
  w.pop();
  w.lod("lo", 1000, 100, {0.5, 2, 0}, 10);
  w.push();
  w.object("loo");
  w.push();
  w.polygon({}, lo);
  w.pop();
  w.pop();
  w.switchNode("sw", 0, {0b01, 0b10});
  w.push();
  w.object("a");
  w.push();
  w.polygon({}, a);
  w.pop();
  w.object("b");
  w.push();
  w.polygon({}, b);
  w.pop();
  w.pop();
  FltWriter::DofRanges r;
  r.r[5] = {-180, 180, 90};  // yaw
  r.r[3] = {-45, 45, 30};    // pitch
  r.flags = 0x80000000u >> 3 | 0x80000000u >> 5;
  w.dof("d", {5, 0, 0}, {6, 0, 0}, {5, 1, 0}, r);
  w.push();
  w.object("dofo");
  w.push();
  w.polygon({}, d);
  w.pop();
  w.pop();
  w.mesh({});
  w.push();
  std::vector<std::array<double, 3>> pool;
  for (int k = 0; k < 20; ++k) pool.push_back({double(k % 5), 8.0 + k / 5, 0.1 * k});
  w.localPool(pool);
  w.meshPrimitive(1, {0, 1, 5, 6});               // strip: 2 triangles
  w.meshPrimitive(2, {10, 11, 12, 13, 14}, 2);    // fan: 3
  w.meshPrimitive(3, {15, 16, 17, 18, 0, 1}, 1);  // quad strip: 2 quads, 4 triangles
  w.meshPrimitive(4, {2, 3, 4, 9, 8});            // polygon: 3
  w.pop();
  w.lightPoint("lp", 1.0f, 0);
  w.push();
  w.vertexList(lights);
  w.pop();
  w.pop();
  w.pop();
  return w.bytes;
}

}  // namespace sv::formats::testing
