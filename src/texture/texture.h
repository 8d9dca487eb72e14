// Texture maps (SPEC §7, seed 001): images in linear light, the MIP pyramid built the seed's way,
// and the samplers — nearest, the seed's three-point interpolation, bilinear, and the trilinear
// blends of the last two between pyramid levels. Scalar reference code: the tile kernel's SIMD
// texturing (issue 5) must give the same values.
//
// Based on: SPEC §7 (seed 001: pyramid by a 3×3-texel triangle filter and decimation by 2, the
// three-point interpolation); pbrt-v4's src/pbrt/util/mipmap.cpp for the structure (not its code).
//
// Coordinates. A level is addressed in continuous texel coordinates (x, y): texel (i, j) is centred
// at (i, j), so level 0's texel centres sit at integer positions and a texture coordinate
// u ∈ [0, 1] maps to x = u·width − ½. Level k's texel i is the filtered level k − 1 at texel 2i, so it is
// centred where level 0's texel 2^k·i is: a position x₀ on level 0 is x₀ / 2^k on level k. (This
// is the seed's "filter, then keep every other texel"; the usual box pyramid centres level k's
// texels between level k − 1's instead.)
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "synthvis/result.h"
#include "texture/footprint.h"

namespace sv::texture {

// What a coordinate outside [0, size) means: repeat the image, clamp to its edge texels, or
// mirror it (…, 1, 0, 0, 1, …, n − 1, n − 1, n − 2, …).
enum class Wrap : uint8_t { repeat, clamp, mirror };

// Maps a texel index to [0, size) by `wrap`.
int wrapIndex(int i, int size, Wrap wrap);

// Four channels, linear light, alpha premultiplied, 0 … 65535.
struct Texel {
  uint16_t r = 0, g = 0, b = 0, a = 0;
  bool operator==(const Texel&) const = default;
};

// A float texel, as the samplers return it (0 … 1).
struct Color4 {
  float r = 0, g = 0, b = 0, a = 0;
};

struct Level {
  int width = 0, height = 0;
  std::vector<Texel> texels;  // row-major, top row first
  const Texel& at(int x, int y) const { return texels[size_t(y) * size_t(width) + size_t(x)]; }
};

// How a Texture stores a texel: 8 bits a channel in one 32-bit word, r in the low byte, then g, b,
// a. The colour channels hold the square root of their linear, premultiplied value — a gamma of 2,
// near sRGB's 2.2, so that 8 bits keep the dark tones the precision of an sRGB8 texture — and alpha
// holds alpha:  r = code_r² / 255², … ,  a = code_a / 255.  Half the bytes of a Texel: twice the
// texels per cache line, and a texel with its right-hand neighbour is one 64-bit word, which the
// SIMD samplers gather as a pair (docs/performance.md, "Pixel shading and texture").
using PackedTexel = uint32_t;
// The nearest code of each channel (colour rounded in the square-root domain, never above alpha).
PackedTexel packTexel(const Texel& t);
// Its value, as the samplers read it: colour (code · code) · (1/255²), alpha code · (1/255), in
// float.
Color4 unpackTexel(PackedTexel p);

// A level inside a Texture, which keeps all its levels in one array (for the SIMD samplers). Each
// row is width + 1 texels: after its last texel comes a copy of the texel that wraps to column
// `width` (the first for repeat, the last for clamp and mirror), so that a texel's right-hand
// neighbour along x is always the next word.
struct LevelView {
  int width = 0, height = 0;
  std::span<const PackedTexel> texels;  // height rows of width + 1, top row first
  PackedTexel packed(int x, int y) const {
    return texels[size_t(y) * (size_t(width) + 1) + size_t(x)];
  }
  Color4 at(int x, int y) const { return unpackTexel(packed(x, y)); }
};

// The sampling methods (issue 5's --texture-filter): at the pyramid level nearest the level of
// detail — nearest texel, the seed's three-point interpolation, bilinear — or blended between the
// two levels around it with three-point or bilinear interpolation in each.
enum class Filter : uint8_t { nearest, threePoint, bilinear, trilinearThreePoint, trilinear };

// Coordinates beyond ±2^24 texels, and NaN, are read as 0 by every sampler (beyond that float
// cannot address single texels, and the integer texel index must not overflow).
inline constexpr float kMaxTexelCoordinate = 16777216.0f;

// The largest texture side accepted, and the most texels in level 0 (so a pyramid stays within
// 4/3 · 2^26 · 4 bytes ≈ 358 MB, and building it needs two 16-bit levels besides: 805 MB at most).
inline constexpr int kMaxTextureSide = 16384;
inline constexpr int64_t kMaxTextureTexels = int64_t(1) << 26;

class Texture {
 public:
  // Takes level 0 and builds the pyramid down to 1×1 (SPEC §7): level k + 1 is level k filtered
  // by the 3×3-texel triangle filter [1 2 1]ᵀ[1 2 1]/16 and decimated by 2 — texel i of level k + 1
  // is the filter centred on texel 2i of level k, edges continued by the wrap modes. A level of
  // odd size n gives ⌈n/2⌉ texels (its last texel keeps the image's last texel), so any size
  // works; each level halves until both sides are 1. The levels are filtered from one another in
  // 16 bits (nextLevel) and each is then stored packed (packTexel), so rounding does not accumulate
  // down the pyramid.
  Texture(Level base, Wrap wrapX, Wrap wrapY);
  // A pyramid as another Texture held it (texels(), allTexels()): level 0 width × height, every
  // level packed and bordered as above — what a prepared database stores. `pyramid` must have
  // pyramidTexels(width, height) entries (sides 1 … kMaxTextureSide, checked by the caller).
  Texture(int width, int height, Wrap wrapX, Wrap wrapY, std::vector<PackedTexel> pyramid);
  // The packed texels of a whole pyramid whose level 0 is width × height, borders included.
  static size_t pyramidTexels(int width, int height);
  std::span<const PackedTexel> allTexels() const { return texels_; }

  int levelCount() const { return int(info_.size()); }
  LevelView level(int k) const;
  Wrap wrapX() const { return wrapX_; }
  Wrap wrapY() const { return wrapY_; }

  // The texel at integer coordinates, wrapped, as stored and as read.
  PackedTexel packed(int k, int x, int y) const;
  Color4 texel(int k, int x, int y) const { return unpackTexel(packed(k, x, y)); }

  // Samplers on level k at continuous texel coordinates of that level (texel centres at integers).
  Color4 nearest(int k, float x, float y) const;
  Color4 bilinear(int k, float x, float y) const;
  // SPEC §7, seed 001: the cell split along its diagonal, three texels per sample.
  Color4 threePoint(int k, float x, float y) const;
  // Between levels ⌊lod⌋ and ⌊lod⌋ + 1, at level-0 texel coordinates (x₀, y₀), with bilinear or
  // three-point interpolation in each level; lod is clamped to [0, levelCount − 1].
  Color4 trilinear(float lod, float x0, float y0) const;
  Color4 trilinearThreePoint(float lod, float x0, float y0) const;
  // By `filter`, at level-0 texel coordinates and level of detail lod: the single-level filters
  // use level ⌊lod + ½⌋ (clamped to the pyramid), the trilinear ones blend as above.
  Color4 sample(Filter filter, float lod, float x0, float y0) const;
  // Anisotropic filtering — the remedy for the grazing-angle blur the seed names as its open
  // problem (SPEC §7): n = min(kMaxProbes, ⌈major / minor⌉) trilinear probes spread evenly over
  // the footprint's major axis (at offsets (i + ½)/n − ½ of its length), each at the level of
  // detail of max(minor, major / n), averaged. (x0, y0) and the footprint are in level-0 texels.
  static constexpr int kMaxProbes = 16;
  Color4 anisotropic(const Footprint& footprint, float x0, float y0) const;

  // All levels in one array, level k at offset(k), rows of width(k) + 1 (LevelView): what the
  // SIMD samplers gather from.
  const PackedTexel* texels() const { return texels_.data(); }
  int32_t offset(int k) const { return info_[size_t(k)].offset; }

  // The levels' sizes and offsets side by side, for the SIMD samplers' per-lane gathers (a side of
  // at most 16384 gives at most 15 levels).
  static constexpr int kMaxLevels = 16;
  struct LevelTable {
    alignas(64) int32_t width[kMaxLevels] = {}, height[kMaxLevels] = {}, offset[kMaxLevels] = {};
  };
  const LevelTable& levelTable() const { return table_; }
  // True when level 0's sides are powers of two (then so are every level's, and wrapping is a
  // mask).
  bool powerOfTwo() const { return powerOfTwo_; }
  // True when every texel's alpha code is 255. Every sampler, scalar and SIMD, then returns alpha
  // exactly 1 — the SIMD sampler without unpacking or blending it, the scalar ones by setting it
  // after the blend: less work, and the seed's three-point blend of ones comes out an ulp off 1 at
  // some weights (shading divides the colour by alpha).
  bool opaque() const { return opaque_; }

 private:
  // c with alpha exactly 1 when the texture is opaque (opaque()).
  Color4 opaqueAlpha(Color4 c) const {
    if (opaque_) c.a = 1.0f;
    return c;
  }
  struct LevelInfo {
    int32_t width, height, offset;
  };
  // info_, table_ and the flags, from the sizes and texels_.
  void index(int width, int height);
  std::vector<PackedTexel> texels_;
  std::vector<LevelInfo> info_;
  LevelTable table_;
  bool powerOfTwo_ = false;
  bool opaque_ = false;
  Wrap wrapX_, wrapY_;
};

// The pyramid's next level in 16 bits (Texture's constructor): `level` filtered by the 3×3 triangle
// filter centred on every other texel, edges continued by the wrap modes, rounded to nearest.
Level nextLevel(const Level& level, Wrap wrapX, Wrap wrapY);

// SIMD sampling of up to 16 points at once (sample_block.cpp, Highway): r, g, b, a of point i to
// out[0…3][i], bit for bit what Texture::sample returns for each point, on every SIMD target.
void sampleBlock(const Texture& texture, Filter filter, const float* lod, const float* x0,
                 const float* y0, int count, float out[4][16]);

// The probes of Texture::anisotropic for `footprint` at (x0, y0): returns their number n
// (1…Texture::kMaxProbes) and writes their level of detail and level-0 positions x[0…n), y[0…n).
int anisotropicProbes(const Footprint& footprint, float x0, float y0, float& lod, float* x,
                      float* y);

// Anisotropic filtering of up to 16 pixels at once: every pixel's probes packed 16 to a
// sampleBlock call, so that the trilinear probes run in SIMD lanes. Bit for bit what
// Texture::anisotropic returns for each pixel.
void anisotropicBlock(const Texture& texture, const Footprint* footprints, const float* x0,
                      const float* y0, int count, float out[4][16]);

// Reads a PNG (8 or 16 bits; grey, grey + alpha, RGB or RGBA; palette) or a JPEG (texture/jpeg.h;
// recognised by its first bytes, opaque) into level 0 in linear light with premultiplied alpha.
// 8-bit samples are sRGB-encoded and decoded by the exact sRGB curve; 16-bit samples are linear
// (PNG's convention for them), either unless a gAMA chunk says otherwise.
// Errors name the file: unreadable, malformed, larger than the limits above, or shorter than the
// size its header states could compress to.
Result<Level> readTextureImage(const std::string& path);
Result<Level> decodeTextureImage(const void* data, size_t size, const std::string& name);

// A level as 8-bit sRGB-encoded RGBA with straight (not premultiplied) alpha, top row first: what
// an SRGB8_ALPHA8 GL texture and a glTF base-colour PNG hold (the inverse of the 8-bit decoding
// above, to within 8-bit rounding).
std::vector<uint8_t> toSrgb8(const LevelView& level);
// The same, as an RGBA PNG in memory (for glTF export); errors name `name`.
Result<std::vector<uint8_t>> encodeTexturePng(const LevelView& level, const std::string& name);

}  // namespace sv::texture

namespace sv::texture {

// Procedural images (for scenes, benchmarks and tests; docs/scene-format.md "textures"), `size` ×
// `size` texels from two linear colours a and b (alpha 1):
//   noise   — every texel a uniformly random mix of a and b (seed 001's random texture, fig. 6);
//   squares — an 8 × 8 grid of squares of colour a on lines of colour b (seed 001's figs. 7–9);
//   checker — 8 × 8 squares alternating a and b.
// The same (pattern, size, colours, seed) always gives the same texels.
enum class Pattern : uint8_t { noise, squares, checker };
inline constexpr int kMaxGeneratedSide = 4096;
Level generateTexture(Pattern pattern, int size, const Color4& a, const Color4& b, uint32_t seed);

}  // namespace sv::texture
