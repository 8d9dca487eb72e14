// The attributes the vertex stage hands pixel shading (SPEC §2, §7–§8): what each vertex carries
// besides its clip-space position and colour, and how a frame packs them.
#pragma once

#include <cstdint>

namespace sv::geometry {

// Attributes interpolated for pixel shading, each carried as value/w (a §2 plane; the value is
// the plane ÷ the 1/w plane): texture coordinates, the eye-space normal and position, and alpha.
enum Attribute {
  kU,
  kV,
  kNormalX,
  kNormalY,
  kNormalZ,
  kEyeX,
  kEyeY,
  kEyeZ,
  kAlpha,
  kAttributeCount
};

// Where a vertex's attributes sit in the vertex stage's output (render::DrawPackets): only those in
// `stored` — the union of what the frame's materials read (shade::attributesUsed) — packed in
// Attribute order, `stride` floats a vertex, attribute a at slot[a] (0 for those not stored, never
// read). A textured, unlit frame stores 2 floats a vertex instead of 9, and the vertex stage and
// setup move that much less memory (docs/performance.md).
struct AttributeLayout {
  unsigned stored = 0;
  int stride = 0;
  uint8_t slot[kAttributeCount] = {};

  static AttributeLayout of(unsigned stored) {
    AttributeLayout l;
    l.stored = stored & ((1u << kAttributeCount) - 1);
    for (int a = 0; a < kAttributeCount; ++a)
      if (l.stored >> a & 1) l.slot[a] = uint8_t(l.stride++);
    return l;
  }
};

}  // namespace sv::geometry
