// Pixel shading (SPEC §8, with §7's texture): what a covered pixel of a textured, Phong-lit,
// fogged or translucent material looks like. The tile kernel (raster/material_blocks-inl.h,
// deferred_shading-inl.h) interpolates the attributes below for up to 16 pixels of one triangle and hands them here; the result is the
// pixel's premultiplied linear colour, which the kernel depth-tests, blends and stores.
//
// Based on: SPEC §8 (seed 003's Phong weighting, seed 002's fog 2^(−βz) and colour table), §7
// (seed 001's texture, level of detail from the pixel footprint), §2 (perspective-correct
// attributes as the ratio of two linear functions).
#pragma once

#include <cstdint>
#include <vector>

#include "geometry/attributes.h"
#include "synthvis/math.h"
#include "texture/texture.h"

namespace sv::shade {

// The attributes pixel shading interpolates (geometry::Attribute, laid out as the vertex stage
// stores them: geometry::AttributeLayout), named here as shading reads them.
using enum geometry::Attribute;

enum class AlphaUse : uint8_t { opaque, blend, mask };

// One material as the shading stage sees it (the renderer builds these from scene::Material).
struct MaterialShading {
  const texture::Texture* texture = nullptr;  // base-colour map, or none
  texture::Filter filter = texture::Filter::trilinear;
  bool anisotropic = false;  // probes along the footprint (Texture::anisotropic) instead of filter
  bool levelZero = false;    // always the full-resolution level (the "point" reference filter)
  // Per-pixel Phong lighting (otherwise the vertex colour already carries the Gouraud light).
  bool phong = false;
  bool twoSided = false;  // light the back face as if it were the front (normal turned to the eye)
  float specular = 0, shininess = 32;
  AlphaUse alpha = AlphaUse::opaque;
  float alphaCutoff = 0.5f;
  // The pixels of every screen-aligned 4×4 block drawn (bit x + 4y), the others cut away as by an
  // alpha mask: a level of detail dissolving into the next (render/traversal.h). 0xFFFF: all.
  uint16_t door = 0xFFFF;
};

struct PointLightEye {
  Vec3 position, color;  // eye space
};

// The frame's lights and fog, in eye space (the camera at the origin looking down −z).
struct Environment {
  bool lightOn = false;
  Vec3 toLight{0, 0, 1};  // unit, toward the directional light
  Vec3 lightColor{1, 1, 1};
  float ambient = 0.25f;  // Q_amb; Q_diff = 1 − Q_amb
  std::vector<PointLightEye> points;
  bool fog = false;
  Vec3 fogColor{0, 0, 0};
  float fogBeta = 0;
};

inline constexpr int kMaxFragments = 16;

// Up to 16 pixels of one triangle.
struct Fragments {
  int count = 0;
  alignas(64) float q[kMaxFragments];         // 1/w
  alignas(64) float color[3][kMaxFragments];  // vertex colour, perspective-correct
  alignas(64) float attribute[kAttributeCount][kMaxFragments];  // attribute/w
  // Per-pixel gradients of q, U = u/w and V = v/w (constant over the triangle): the footprint.
  float qdx = 0, qdy = 0, udx = 0, udy = 0, vdx = 0, vdy = 0;
};

// The attributes shadeFragments reads for `m` under `env`, a bit per shade::Attribute (the others
// may be left unset in Fragments).
inline unsigned attributesUsed(const MaterialShading& m, const Environment& env) {
  unsigned used = 0;
  if (m.texture) used |= 1u << kU | 1u << kV;
  if (m.phong) used |= 1u << kNormalX | 1u << kNormalY | 1u << kNormalZ;
  if (m.phong || env.fog) used |= 1u << kEyeX | 1u << kEyeY | 1u << kEyeZ;
  if (m.alpha != AlphaUse::opaque) used |= 1u << kAlpha;
  return used;
}

// Shades `f` with material `m` under `env`: out[0…3][i] = premultiplied linear r, g, b, a of
// fragment i, each 0…1 (alpha 1 for opaque materials; for alpha-masked ones 0 where the pixel is
// cut away, else 1). `out` is 64-byte aligned (whole vectors are stored to it; SV_DCHECK). Runs the
// best SIMD target (Highway), bit-identical from run to run.
void shadeFragments(const MaterialShading& m, const Environment& env, const Fragments& f,
                    float out[4][kMaxFragments]);

// Shading in two steps, so that texture memory is requested well before it is read: first the
// texture coordinates (level-0 texels) and levels of detail of every fragment, with a prefetch of
// the texels they will read (unless `request` is false); later the shading with them. The result
// is shadeFragments's.
struct TexCoords {
  alignas(64) float lod[kMaxFragments];
  alignas(64) float x0[kMaxFragments];
  alignas(64) float y0[kMaxFragments];
};
void textureCoordinates(const MaterialShading& m, const Fragments& f, TexCoords& out,
                        bool request = true);
void shadeFragments(const MaterialShading& m, const Environment& env, const Fragments& f,
                    const TexCoords& coordinates, float out[4][kMaxFragments]);

// The fog factor 2^(−β·r) at range r (SPEC §8): the weight of the surface colour.
inline float fogFactor(float beta, float range) { return std::exp2(-beta * range); }

}  // namespace sv::shade
