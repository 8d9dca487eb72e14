#include "texture/texture.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>

#include "synthvis/files.h"
#include "texture/jpeg.h"
#include "texture/png.h"
#include "texture/sgi.h"

namespace sv::texture {

int wrapIndex(int i, int size, Wrap wrap) {
  switch (wrap) {
    case Wrap::clamp:
      return std::clamp(i, 0, size - 1);
    case Wrap::mirror: {
      const int period = 2 * size;
      const int m = ((i % period) + period) % period;
      return m < size ? m : period - 1 - m;
    }
    case Wrap::repeat:
    default:
      return ((i % size) + size) % size;
  }
}

PackedTexel packTexel(const Texel& t) {
  const uint32_t a = uint32_t(std::lround(t.a * (255.0 / 65535.0)));
  const float alpha = float(a) * (1.0f / 255.0f);
  auto colour = [alpha](uint16_t v) {
    uint32_t c = uint32_t(std::lround(std::sqrt(v / 65535.0) * 255.0));
    // Premultiplied: the colour read back never exceeds the alpha read back.
    while (c > 0 && float(c * c) * (1.0f / 65025.0f) > alpha) --c;
    return c;
  };
  return colour(t.r) | colour(t.g) << 8 | colour(t.b) << 16 | a << 24;
}

Color4 unpackTexel(PackedTexel p) {
  // (code · code) is exact in float; the SIMD samplers do the same two steps (sample_block-inl.h).
  auto colour = [p](int shift) {
    const uint32_t c = p >> shift & 0xFF;
    return float(c * c) * (1.0f / 65025.0f);
  };
  return {colour(0), colour(8), colour(16), float(p >> 24) * (1.0f / 255.0f)};
}

namespace {

Color4 mix(const Color4& a, float wa, const Color4& b, float wb) {
  return {a.r * wa + b.r * wb, a.g * wa + b.g * wb, a.b * wa + b.b * wb, a.a * wa + b.a * wb};
}

Color4 mix3(const Color4& a, float wa, const Color4& b, float wb, const Color4& c, float wc) {
  return {a.r * wa + b.r * wb + c.r * wc, a.g * wa + b.g * wb + c.g * wc,
          a.b * wa + b.b * wb + c.b * wc, a.a * wa + b.a * wb + c.a * wc};
}

}  // namespace

// Level k + 1 from level k (the constructor's comment): the 3×3 triangle filter centred on every
// other texel, weights 1 2 1 / 2 4 2 / 1 2 1 over 16, rounded to nearest.
Level nextLevel(const Level& src, Wrap wrapX, Wrap wrapY) {
  Level dst;
  dst.width = (src.width + 1) / 2;
  dst.height = (src.height + 1) / 2;
  dst.texels.resize(size_t(dst.width) * size_t(dst.height));
  static constexpr uint32_t kWeight[3] = {1, 2, 1};
  for (int y = 0; y < dst.height; ++y)
    for (int x = 0; x < dst.width; ++x) {
      uint32_t sum[4] = {8, 8, 8, 8};  // + 8: round to nearest on the division by 16
      for (int dy = -1; dy <= 1; ++dy) {
        const int sy = wrapIndex(2 * y + dy, src.height, wrapY);
        for (int dx = -1; dx <= 1; ++dx) {
          const Texel& t = src.at(wrapIndex(2 * x + dx, src.width, wrapX), sy);
          const uint32_t w = kWeight[dx + 1] * kWeight[dy + 1];
          sum[0] += w * t.r;
          sum[1] += w * t.g;
          sum[2] += w * t.b;
          sum[3] += w * t.a;
        }
      }
      dst.texels[size_t(y) * size_t(dst.width) + size_t(x)] = {
          uint16_t(sum[0] >> 4), uint16_t(sum[1] >> 4), uint16_t(sum[2] >> 4),
          uint16_t(sum[3] >> 4)};
    }
  return dst;
}

size_t Texture::pyramidTexels(int width, int height) {
  size_t total = 0;
  for (int w = width, h = height;; w = (w + 1) / 2, h = (h + 1) / 2) {
    total += (size_t(w) + 1) * size_t(h);
    if (w <= 1 && h <= 1) break;
  }
  return total;
}

Texture::Texture(Level base, Wrap wrapX, Wrap wrapY) : wrapX_(wrapX), wrapY_(wrapY) {
  const int width = base.width, height = base.height;
  texels_.reserve(pyramidTexels(width, height));
  // One 16-bit level at a time: packed into the array, then filtered into the next.
  Level level = std::move(base);
  for (;;) {
    const int border = level.width > 0 ? wrapIndex(level.width, level.width, wrapX_) : 0;
    for (int y = 0; y < level.height; ++y) {
      for (int x = 0; x < level.width; ++x) texels_.push_back(packTexel(level.at(x, y)));
      texels_.push_back(level.width > 0 ? packTexel(level.at(border, y)) : 0);
    }
    if (level.width <= 1 && level.height <= 1) break;
    level = nextLevel(level, wrapX_, wrapY_);
  }
  index(width, height);
}

Texture::Texture(int width, int height, Wrap wrapX, Wrap wrapY, std::vector<PackedTexel> pyramid)
    : texels_(std::move(pyramid)), wrapX_(wrapX), wrapY_(wrapY) {
  index(width, height);
}

void Texture::index(int width, int height) {
  int32_t offset = 0;  // < 2^27 (kMaxTextureTexels)
  for (int w = width, h = height;; w = (w + 1) / 2, h = (h + 1) / 2) {
    info_.push_back({w, h, offset});
    offset += int32_t((w + 1) * h);
    if (w <= 1 && h <= 1) break;
  }
  for (size_t k = 0; k < info_.size() && k < size_t(kMaxLevels); ++k) {
    table_.width[k] = info_[k].width;
    table_.height[k] = info_[k].height;
    table_.offset[k] = info_[k].offset;
  }
  auto pow2 = [](int n) { return (n & (n - 1)) == 0; };
  powerOfTwo_ = pow2(info_[0].width) && pow2(info_[0].height);
  opaque_ =
      std::all_of(texels_.begin(), texels_.end(), [](PackedTexel p) { return p >> 24 == 255; });
}

LevelView Texture::level(int k) const {
  const LevelInfo& l = info_[size_t(k)];
  return {l.width, l.height,
          std::span<const PackedTexel>(texels_.data() + l.offset,
                                       (size_t(l.width) + 1) * size_t(l.height))};
}

PackedTexel Texture::packed(int k, int x, int y) const {
  const LevelInfo& l = info_[size_t(k)];
  return texels_[size_t(l.offset) + size_t(wrapIndex(y, l.height, wrapY_)) * (size_t(l.width) + 1) +
                 size_t(wrapIndex(x, l.width, wrapX_))];
}

namespace {

// Texel coordinates the samplers accept (texture.h, kMaxTexelCoordinate).
float saneCoordinate(float x) { return std::fabs(x) <= kMaxTexelCoordinate ? x : 0.0f; }

}  // namespace

Color4 Texture::nearest(int k, float x, float y) const {
  x = saneCoordinate(x);
  y = saneCoordinate(y);
  return opaqueAlpha(texel(k, int(std::floor(x + 0.5f)), int(std::floor(y + 0.5f))));
}

namespace {

// The texel cell around (x, y): its corner (x0, y0) and the fractional parts γ, Θ.
struct Cell {
  int x0, y0;
  float g, t;
};

Cell cellAt(float x, float y) {
  x = saneCoordinate(x);
  y = saneCoordinate(y);
  const float fx = std::floor(x), fy = std::floor(y);
  return {int(fx), int(fy), x - fx, y - fy};
}

}  // namespace

Color4 Texture::bilinear(int k, float x, float y) const {
  // SPEC §7: R = γ(ΘR3 + (1−Θ)R2) + (1−γ)(ΘR4 + (1−Θ)R1), with R1…R4 the texels at (0,0),
  // (1,0), (1,1), (0,1) of the cell and γ, Θ the fractional parts.
  const auto [x0, y0, g, t] = cellAt(x, y);
  const Color4 r1 = texel(k, x0, y0), r2 = texel(k, x0 + 1, y0);
  const Color4 r3 = texel(k, x0 + 1, y0 + 1), r4 = texel(k, x0, y0 + 1);
  return opaqueAlpha(mix(mix(r3, t, r2, 1 - t), g, mix(r4, t, r1, 1 - t), 1 - g));
}

Color4 Texture::threePoint(int k, float x, float y) const {
  // SPEC §7, seed 001: the cell split along its diagonal from R1 to R3;
  //   Θ ≥ γ: R = γ·R3 + (Θ − γ)·R4 + (1 − Θ)·R1;   Θ < γ: R = Θ·R3 + (γ − Θ)·R2 + (1 − γ)·R1.
  const auto [x0, y0, g, t] = cellAt(x, y);
  const Color4 r1 = texel(k, x0, y0), r3 = texel(k, x0 + 1, y0 + 1);
  if (t >= g) return opaqueAlpha(mix3(r3, g, texel(k, x0, y0 + 1), t - g, r1, 1 - t));
  return opaqueAlpha(mix3(r3, t, texel(k, x0 + 1, y0), g - t, r1, 1 - g));
}

namespace {

// Level k's coordinates of level-0 position (x0, y0): texel i of level k sits at level 0's 2^k·i.
template <class Sample>
Color4 blendLevels(const Texture& tex, float lod, float x0, float y0, Sample sample) {
  lod = std::clamp(lod, 0.0f, float(tex.levelCount() - 1));
  if (!(lod >= 0)) lod = 0;  // NaN
  x0 = saneCoordinate(x0);
  y0 = saneCoordinate(y0);
  const int k = std::min(int(lod), tex.levelCount() - 1);
  const float scale = std::ldexp(1.0f, -k);
  const Color4 a = sample(k, x0 * scale, y0 * scale);
  const float t = lod - float(k);
  if (t == 0 || k + 1 >= tex.levelCount()) return a;
  const Color4 b = sample(k + 1, x0 * scale * 0.5f, y0 * scale * 0.5f);
  return mix(a, 1 - t, b, t);
}

}  // namespace

Color4 Texture::sample(Filter filter, float lod, float x0, float y0) const {
  if (filter == Filter::trilinear) return trilinear(lod, x0, y0);
  if (filter == Filter::trilinearThreePoint) return trilinearThreePoint(lod, x0, y0);
  lod = std::clamp(lod, 0.0f, float(levelCount() - 1));  // NaN stays NaN: level 0 below
  const int k = lod >= 0 ? std::min(int(lod + 0.5f), levelCount() - 1) : 0;
  const float scale = std::ldexp(1.0f, -k);
  x0 = saneCoordinate(x0) * scale;
  y0 = saneCoordinate(y0) * scale;
  if (filter == Filter::nearest) return nearest(k, x0, y0);
  if (filter == Filter::threePoint) return threePoint(k, x0, y0);
  return bilinear(k, x0, y0);
}

Color4 Texture::trilinear(float lod, float x0, float y0) const {
  return opaqueAlpha(
      blendLevels(*this, lod, x0, y0, [&](int k, float x, float y) { return bilinear(k, x, y); }));
}

Color4 Texture::trilinearThreePoint(float lod, float x0, float y0) const {
  return opaqueAlpha(blendLevels(*this, lod, x0, y0,
                                 [&](int k, float x, float y) { return threePoint(k, x, y); }));
}

int anisotropicProbes(const Footprint& f, float x0, float y0, float& lod, float* x, float* y) {
  const double major = std::max(f.major, 1e-9), minor = std::max(f.minor, 1e-9);
  const int n = int(std::clamp(std::ceil(major / minor), 1.0, double(Texture::kMaxProbes)));
  lod = float(std::max(0.0, std::log2(std::max(minor, major / n))));
  for (int i = 0; i < n; ++i) {
    const double s = ((i + 0.5) / n - 0.5) * major;
    x[i] = float(x0 + s * f.axisX);
    y[i] = float(y0 + s * f.axisY);
  }
  return n;
}

Color4 Texture::anisotropic(const Footprint& f, float x0, float y0) const {
  float lod, x[kMaxProbes], y[kMaxProbes];
  const int n = anisotropicProbes(f, x0, y0, lod, x, y);
  Color4 sum;
  for (int i = 0; i < n; ++i) sum = mix(sum, 1.0f, trilinear(lod, x[i], y[i]), 1.0f);
  const float w = 1.0f / float(n);
  return opaqueAlpha({sum.r * w, sum.g * w, sum.b * w, sum.a * w});
}

namespace {

// A texture map's pixels as linear, premultiplied texels: 16-bit files are libpng's linear RGBA
// with premultiplied alpha already (their samples are linear unless a gAMA chunk says otherwise,
// which libpng then undoes); 8-bit ones are sRGB-encoded RGBA (libpng re-encodes another stated
// gamma as sRGB), decoded here by the exact IEC 61966-2-1 curve — libpng's own linear output uses
// a 2.2 power law — and premultiplied by alpha.
Level toLevel(const PngPixels& png) {
  Level level;
  level.width = png.width;
  level.height = png.height;
  level.texels.resize(size_t(png.width) * size_t(png.height));
  static_assert(sizeof(Texel) == 4 * sizeof(uint16_t));
  if (png.linear16) {
    std::memcpy(level.texels.data(), png.data.data(), level.texels.size() * sizeof(Texel));
    return level;
  }
  static const auto decode = [] {
    std::array<double, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double e = i / 255.0;
      t[size_t(i)] = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
    }
    return t;
  }();
  for (size_t i = 0; i < level.texels.size(); ++i) {
    const uint8_t* p = &png.data[4 * i];
    const double alpha = p[3] / 255.0;
    auto channel = [&](uint8_t c) { return uint16_t(std::lround(decode[c] * alpha * 65535.0)); };
    level.texels[i] = {channel(p[0]), channel(p[1]), channel(p[2]),
                       uint16_t(std::lround(alpha * 65535.0))};
  }
  return level;
}

constexpr PngLimits kTextureLimits{kMaxTextureSide, kMaxTextureTexels};

}  // namespace

Result<Level> readTextureImage(const std::string& path) {
  // The kind is recognised by the first bytes, whatever the name says (a short read; the decoder
  // reads the whole file): a file that cannot be opened is named as such, not as a bad PNG.
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return Error{path, "", fmt::format("cannot open file: {}", std::strerror(errno))};
  unsigned char magic[8] = {};
  const size_t got = std::fread(magic, 1, sizeof magic, f);
  std::fclose(f);
  if (looksLikeJpeg(magic, got) || looksLikeSgi(magic, got)) {
    Result<std::string> bytes = core::readFile(path);
    if (!bytes) return bytes.error();
    return decodeTextureImage(bytes->data(), bytes->size(), path);
  }
  constexpr unsigned char kPngMagic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (got < sizeof magic || std::memcmp(magic, kPngMagic, sizeof magic) != 0)
    return Error{path, "", "not a PNG, JPEG or SGI image"};
  auto png = readPng(path, PngLayout::rgba8OrLinear16, kTextureLimits);
  if (!png.ok()) return png.error();
  return toLevel(png.value());
}

Result<Level> decodeTextureImage(const void* data, size_t size, const std::string& name) {
  // JPEG and SGI decode to 8-bit sRGB-encoded RGBA with straight alpha: an 8-bit PNG's samples.
  auto asPng = [](auto pixels) {
    PngPixels png;
    png.width = pixels.width;
    png.height = pixels.height;
    png.data = std::move(pixels.rgba);
    return toLevel(png);
  };
  if (looksLikeJpeg(data, size)) {
    auto jpeg = decodeJpeg(data, size, name, kTextureLimits.maxSide, kTextureLimits.maxPixels);
    if (!jpeg.ok()) return jpeg.error();
    return asPng(std::move(jpeg.value()));
  }
  if (looksLikeSgi(data, size)) {
    auto sgi = decodeSgi(data, size, name, kTextureLimits.maxSide, kTextureLimits.maxPixels);
    if (!sgi.ok()) return sgi.error();
    return asPng(std::move(sgi.value()));
  }
  auto png = decodePng(data, size, name, PngLayout::rgba8OrLinear16, kTextureLimits);
  if (!png.ok()) return png.error();
  return toLevel(png.value());
}

}  // namespace sv::texture

namespace sv::texture {

Level generateTexture(Pattern pattern, int size, const Color4& a, const Color4& b, uint32_t seed) {
  size = std::clamp(size, 1, kMaxGeneratedSide);
  Level level;
  level.width = level.height = size;
  level.texels.resize(size_t(size) * size_t(size));
  auto texel = [&a, &b](float t) {
    auto q = [](float v) { return uint16_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 65535.0f)); };
    return Texel{q(a.r + (b.r - a.r) * t), q(a.g + (b.g - a.g) * t), q(a.b + (b.b - a.b) * t),
                 65535};
  };
  // A 32-bit mix of (seed, index) (the finalizer of MurmurHash3): the texels do not depend on any
  // library's random number engine.
  auto hash = [seed](uint32_t i) {
    uint32_t h = i * 0x9E3779B1u ^ seed * 0x85EBCA77u;
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    return h ^ (h >> 16);
  };
  const int cell = std::max(1, size / 8);
  const int line = std::max(1, cell / 8);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float t = 0;
      switch (pattern) {
        case Pattern::noise:
          t = float(hash(uint32_t(y * size + x)) >> 8) / float(1 << 24);
          break;
        case Pattern::squares:
          t = (x % cell < line || y % cell < line) ? 1.0f : 0.0f;
          break;
        case Pattern::checker:
          t = float((x / cell + y / cell) & 1);
          break;
      }
      level.texels[size_t(y) * size_t(size) + size_t(x)] = texel(t);
    }
  return level;
}

std::vector<uint8_t> toSrgb8(const LevelView& level) {
  std::vector<uint8_t> rgba(size_t(level.width) * size_t(level.height) * 4);
  uint8_t* out = rgba.data();
  for (int y = 0; y < level.height; ++y)
    for (int x = 0; x < level.width; ++x, out += 4) {
      const Color4 c = level.at(x, y);
      const double a = c.a;
      auto encode = [a](float premultiplied) {
        const double v = a > 0 ? std::min(1.0, premultiplied / a) : 0.0;
        const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
        return uint8_t(std::lround(e * 255));
      };
      out[0] = encode(c.r);
      out[1] = encode(c.g);
      out[2] = encode(c.b);
      out[3] = uint8_t(std::lround(a * 255));
    }
  return rgba;
}

Result<std::vector<uint8_t>> encodeTexturePng(const LevelView& level, const std::string& name) {
  const std::vector<uint8_t> rgba = toSrgb8(level);
  return encodePng(name, level.width, level.height, 4, rgba.data());
}

}  // namespace sv::texture
