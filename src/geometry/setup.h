// Triangle setup: clip-space vertices → edge functions and rational parameter functions.
//
// Based on: SPEC §2 (seeds 000, 004): projective transform without perspective divide;
// Olano & Greer 1997, "Triangle scan conversion using 2D homogeneous coordinates".
//
// The output, TriangleSetup, is the plain draw packet the rasterizer consumes: it knows nothing of
// scenes, meshes or materials.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sv::geometry {

// The fill rule, owned here alone (STYLE.md habit 8): whether a pixel centre exactly on the edge
// a·x + b·y + c = 0 (inside ≥ 0) belongs to the triangle. Raster y grows downward. It belongs to
// the triangle that lies to the right of the edge (a > 0: a *left* edge) or, for a horizontal
// edge, below it (a = 0, b > 0: a *top* edge) — the top-left rule. It is antisymmetric: (a, b) and
// (−a, −b) never both own the centre, and one of them always does, so two triangles sharing an
// edge neither both draw nor both miss a pixel on it. Setup folds it into each edge's constant
// (setup.cpp; in SIMD lanes setup_batch.cpp, checked bit for bit against it), the anti-aliased
// leaf takes it back out (raster/descent-inl.h), and the coverage tables decide their ties by it.
template <class T>
constexpr bool ownsBoundary(T a, T b) {
  return a > T(0) || (a == T(0) && b > T(0));
}

// ---- Fixed-point budget (RASTER-NOTES.md pitfall 1) ------------------------------------------
// Positions are snapped to 1/256 pixel (24.8). Exact integer edges are used for vertices in front
// of the eye whose projection lies within the guard band |x|, |y| < 2^15 px; the raster itself is
// at most 8192 × 8192 (2^13). Budget, with F = 8 sub-pixel bits:
//   snapped coordinate           |x_f| < 2^(15+8)            = 2^23
//   edge coefficient A = y_i − y_j  |A| < 2^24;  per-pixel step 2^8·A < 2^32
//   constant C = x_i·y_j − x_j·y_i  |C| < 2^47
//   value anywhere on the raster |C| + |A|·2^21 + |B|·2^21 < 2^47 + 2^46 < 2^48
// Homogeneous edges (for vertices behind the eye or outside the guard band) are scaled so that
// max(|A|, |B|) ≤ 2^23 and |C| is clamped to 2^46 (beyond which the line cannot cross the raster),
// which keeps them inside the same budget. Everything fits int64_t with 15 bits to spare.
inline constexpr int kSubPixelBits = 8;
inline constexpr int kSmallExtent = 96;  // pixels
inline constexpr int kSubPixelScale = 1 << kSubPixelBits;
inline constexpr int kMaxRasterLog2 = 13;
inline constexpr int kMaxRasterSize = 1 << kMaxRasterLog2;
inline constexpr int kGuardBandLog2 = 15;
inline constexpr int kMaxEdges = 5;  // three sides, the near plane and the far plane
// Budget of the int32 path: |A|, |B| ≤ 96·2^8; the rasterizer evaluates edges only at pixel
// centres of a 64-px tile that meets the box (widened by 1 px for the anti-aliasing aperture), so
// within 96 + 65 px of every vertex on each axis; |e| ≤ 2·(96·2^8)·(161·2^8) ≈ 2.026·10^9, and the
// aperture's constants add at most 128·(|A| + |B|) ≈ 6.3·10^6: below 2^31 with 5 % to spare.
// (64 px before; 96 px moved tris 10k × 1000 px from the int64 to the int32 path,
// docs/performance.md.)
static_assert(2.0 * (kSmallExtent * 256.0) * ((kSmallExtent + 65) * 256.0) +
                      128.0 * 2 * kSmallExtent * 256.0 <
                  2147483647.0,
              "small triangles' edge values must fit int32_t");
static_assert(kGuardBandLog2 + kSubPixelBits + 1 + kSubPixelBits + kMaxRasterLog2 + 1 < 62,
              "edge values must fit int64_t");

// A vertex after the projective transform (SPEC §2): homogeneous clip coordinates (OpenGL
// convention: visible when −w ≤ x, y, z ≤ w) and the parameters to interpolate.
struct ClipVertex {
  float x, y, z, w;
  float r, g, b, a;  // linear colour
};

// e(px, py) = c + stepX·px + stepY·py at the centre of pixel (px, py); the pixel is inside the
// edge's half-plane iff e ≥ 0. The fill rule is already folded into c (see setup.cpp). The steps
// are 256·a and 256·b, with a, b the coefficients per sub-pixel unit (|a|, |b| < 2^24).
struct EdgeFunction {
  int64_t c;
  int32_t a, b;
  int64_t stepX() const { return int64_t(a) * kSubPixelScale; }
  int64_t stepY() const { return int64_t(b) * kSubPixelScale; }
};

// A parameter as a linear function of the pixel position: value = c0 + dx·(px − refX) +
// dy·(py − refY) at the centre of pixel (px, py), evaluated in float in exactly this order.
struct Plane {
  float c0, dx, dy;
};

// A plane's value at the centre of pixel (x, y) of a triangle whose box starts at (minX, minY), in
// the tile kernel's float operations and order (raster/kernel_common-inl.h, blockBases): the 4×4
// block's base (c0 + dx·X) + dy·Y at its top-left pixel, plus the lane's offset dx·lx + dy·ly.
// The scalar form, for what must match the kernel bit for bit: the brute-force reference
// (tests/support) and the segment pipeline (render/segment_renderer.cpp).
inline float planeAtPixel(const Plane& p, int x, int y, int minX, int minY) {
  const float bx = float((x & ~3) - minX), by = float((y & ~3) - minY);
  const float base = (p.c0 + p.dx * bx) + p.dy * by;
  const float offset = p.dx * float(x & 3) + p.dy * float(y & 3);
  return base + offset;
}

enum class CullMode : uint8_t { none, back, front };

struct Viewport {
  int width = 0;   // 1 … kMaxRasterSize
  int height = 0;  // 1 … kMaxRasterSize
  // Anti-aliasing (SPEC §3.2, aperture α = β = 1): a triangle reaches every pixel whose square it
  // touches — where its sub-pixel samples lie — rather than only those whose centre it covers.
  // Widens the bounding box (and so the binning) by up to one pixel on each side.
  bool pixelAperture = false;
};

// The bounding box of pixels a triangle can reach spans [ceil((x0 − low)/256), floor((x1 − high)/
// 256)] for snapped extremes x0, x1 (24.8): centres at 256·p + 128 give low = high = 128; pixel
// squares [256·p, 256·p + 256) with samples strictly inside give low = 255, high = 1.
inline int boxInsetLow(const Viewport& v) {
  return v.pixelAperture ? kSubPixelScale - 1 : kSubPixelScale / 2;
}
inline int boxInsetHigh(const Viewport& v) { return kSubPixelScale - boxInsetLow(v); }

// Object-space culling (SPEC §4, seed 004): the screen box and nearest depth of a whole object,
// which every sample of every triangle of it lies within. The tiles test it against their occupied
// windows before touching the object's triangles (raster::TileWork::objects).
struct ObjectBound {
  int minX = 0, minY = 0, maxX = -1, maxY = -1;  // inclusive pixels, clipped to the raster
  float zmin = 0;  // window depth (0 … 1) no sample of the object is nearer than
};

// 160 bytes: the record the tiles read for every triangle, so kept small (cache misses on it are
// a large part of the cost of small triangles).
struct TriangleSetup {
  EdgeFunction edges[kMaxEdges];
  // Depth in [0, 1] (window z, linear in screen space); 1/w; colour/w (perspective-correct colour
  // is the ratio colour/w ÷ 1/w, SPEC §2's shared denominator). Origin: pixel (minX, minY).
  Plane depth, invW, red, green, blue;
  int16_t minX, minY, maxX, maxY;  // inclusive pixel bounding box, clipped to the raster
  // The triangle's number in its draw packets (setupTriangles' firstTriangle + its position): which
  // triangle a record is, once binning has reordered the records (for tests and debugging; the
  // pipeline finds a record's attribute planes by its storage index, TileWork::attributes).
  uint32_t triangle;
  uint8_t edgeCount;
  // True when the triangle is small (three integer edges, bounding box ≤ kSmallExtent pixels):
  // then edge values fit int32 wherever the rasterizer evaluates them (budget above).
  bool small;
};

enum class SetupOutcome : uint8_t {  // numbered from 0, in this order
  drawn,
  culledFacing,      // back (or front) face
  culledOutside,     // no pixel centre of the raster can be covered
  culledDegenerate,  // zero area, or its plane passes through the eye
  culledInvalid,     // NaN or infinite coordinates
};

// Sets up one triangle for `viewport`. Returns `drawn` and fills `out` (all but `triangle`), or a
// culling reason.
// Front faces are counter-clockwise in normalized device coordinates (the OpenGL default).
SetupOutcome setupTriangle(const ClipVertex& v0, const ClipVertex& v1, const ClipVertex& v2,
                           const Viewport& viewport, CullMode cull, TriangleSetup& out);

// Pixel shading's extra planes (attributePlanes'), asked of setupTriangles for the triangles it
// draws. Vertex v's value of attribute a is values[v·valueStride + slots[a]] (strides in floats;
// without `slots`, + a: every attribute stored); drawn record r's planes go to out + r·outStride (a
// stride in bytes, so that they may sit in a larger record), the planes not in `used` set to zero.
// Only the slots of the attributes in `used` are read.
struct AttributeRequest {
  const float* values = nullptr;
  size_t valueStride = 0;
  int count = 0;  // ≤ kMaxAttributePlanes
  unsigned used = 0;
  Plane* out = nullptr;
  size_t outStride = 0;
  const uint8_t* slots = nullptr;  // [count], or null for slots[a] = a
};
inline constexpr int kMaxAttributePlanes = 16;

// The same for `count` triangles (indices: 3 per triangle into `vertices`), several at once in
// SIMD lanes (setup_batch.cpp); records bit-identical to setupTriangle's. The drawn triangles'
// records go to out[0, returned count) in order, `triangle` set to firstTriangle + their position
// in `indices`; outcomes[o] is incremented per triangle with outcome o. With `attributes`, each
// drawn triangle's attribute planes too, bit-identical to attributePlanes'.
inline constexpr int kSetupOutcomes = 5;
size_t setupTriangles(const ClipVertex* vertices, const uint32_t* indices, size_t count,
                      const Viewport& viewport, CullMode cull, TriangleSetup* out,
                      uint64_t outcomes[kSetupOutcomes], uint32_t firstTriangle = 0,
                      const AttributeRequest* attributes = nullptr);

// Pixel shading's extra parameters (SPEC §2): `count` planes of value/w for per-vertex values
// values[k][slots[a]] of vertex k (slots null: values[k][a]), a ∈ [0, count), relative to the same
// origin (minX, minY) as `setup`'s planes — the functions setupTriangle gives the colour. `setup`
// is the triangle's drawn record. Only the planes whose bit is set in `used` are computed; the
// others are set to zero (nothing reads them).
void attributePlanes(const ClipVertex& v0, const ClipVertex& v1, const ClipVertex& v2,
                     const Viewport& viewport, const TriangleSetup& setup,
                     const float* const values[3], int count, Plane* out, unsigned used = ~0u,
                     const uint8_t* slots = nullptr);

}  // namespace sv::geometry
