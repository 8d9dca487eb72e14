// Based on: SPEC §8 (seed 002: Gouraud intensity, seed 003: the diffuse term n·l).
//
// Vertices are transformed several at once in SIMD lanes (Highway, dispatched per call), every
// operation lane by lane in IEEE order (no fused multiply-add), so every vertex gets the same bits
// on every target and in every split of a mesh into ranges (tests/geometry/vertex_stage_test.cpp);
// a range's last vertices, fewer than a vector, run in the same lanes on a padded copy.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "geometry/vertex_stage.cpp"
#include "geometry/vertex_stage.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"

#ifndef SV_GEOMETRY_VERTEX_RUN
#define SV_GEOMETRY_VERTEX_RUN
namespace sv::geometry {
namespace {

// What every vertex of one call shares.
struct VertexRun {
  VertexRun(const VertexArrays& mesh_, const VertexMaterial& material_, const Mat4& model_,
            const VertexContext& context_, const AttributeLayout* layout_)
      : mesh(mesh_),
        material(material_),
        model(model_),
        context(context_),
        layout(layout_),
        mvp(context_.viewProj * model_),
        light(context_.light) {
    const bool hasLights = light.enabled || !context.pointLights.empty();
    lit = hasLights && !material.unlit && mesh.normals != nullptr;
    vertexLit = lit && !material.phong;
    toLight = normalize(-light.direction);
    base = material.baseColor;
    // Only the matrices this call's vertices read (a city draws thousands of small instances).
    const unsigned stored = layout ? layout->stored : 0;
    if (vertexLit) normalToWorld = model.normalMatrix();
    if (stored & (1u << kEyeX | 1u << kEyeY | 1u << kEyeZ | 1u << kNormalX)) {
      modelView = context.view * model;
      if (lit && material.phong) normalToEye = modelView.normalMatrix();
    }
  }

  const VertexArrays& mesh;
  const VertexMaterial& material;
  const Mat4& model;
  const VertexContext& context;
  const AttributeLayout* layout;
  const Mat4 mvp;
  Mat4 modelView, normalToWorld, normalToEye;
  const DirectionalLight& light;
  bool lit = false, vertexLit = false;
  Vec3 toLight;
  Vec4 base;
};

}  // namespace
}  // namespace sv::geometry
#endif  // SV_GEOMETRY_VERTEX_RUN

HWY_BEFORE_NAMESPACE();
namespace sv::geometry {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

static_assert(sizeof(Vec2) == 2 * sizeof(float) && sizeof(Vec3) == 3 * sizeof(float) &&
                  sizeof(Vec4) == 4 * sizeof(float),
              "meshes' arrays are read as interleaved floats");
using DF = hn::CappedTag<float, 16>;
using VF = hn::Vec<DF>;

struct V3 {
  VF x, y, z;
};

// The scalar code's operations lane by lane (math.h): products summed left to right, std::max(0,
// v), std::clamp(v, 0, 1) and normalize as compare-and-select (their NaN results too).
HWY_INLINE V3 transform(DF df, const Mat4& m, const V3& v, float w) {
  // m·(x, y, z, w): m[3][r]·w is exact for w = 1, and ±0 for w = 0 (kept: it can turn −0 to +0).
  auto row = [&](int r) {
    return hn::Add(
        hn::Add(hn::Add(hn::Mul(hn::Set(df, m.m[0][r]), v.x), hn::Mul(hn::Set(df, m.m[1][r]), v.y)),
                hn::Mul(hn::Set(df, m.m[2][r]), v.z)),
        hn::Set(df, m.m[3][r] * w));
  };
  return {row(0), row(1), row(2)};
}
HWY_INLINE VF dot3(const V3& a, const V3& b) {
  return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z));
}
HWY_INLINE VF dot3(DF df, const V3& a, Vec3 b) {
  return dot3(a, V3{hn::Set(df, b.x), hn::Set(df, b.y), hn::Set(df, b.z)});
}
HWY_INLINE V3 normalized(DF df, const V3& a) {
  const VF l = hn::Sqrt(dot3(a, a));
  const VF inv = hn::Div(hn::Set(df, 1.0f), l);
  const auto positive = hn::Gt(l, hn::Zero(df));
  return {hn::IfThenElse(positive, hn::Mul(a.x, inv), a.x),
          hn::IfThenElse(positive, hn::Mul(a.y, inv), a.y),
          hn::IfThenElse(positive, hn::Mul(a.z, inv), a.z)};
}
HWY_INLINE VF positivePart(DF df, VF v) {  // std::max(0.0f, v)
  return hn::IfThenElse(hn::Lt(hn::Zero(df), v), v, hn::Zero(df));
}
HWY_INLINE VF unitClamp(DF df, VF v) {  // std::clamp(v, 0.0f, 1.0f)
  const VF one = hn::Set(df, 1.0f);
  return hn::IfThenElse(hn::Lt(v, hn::Zero(df)), hn::Zero(df),
                        hn::IfThenElse(hn::Lt(one, v), one, v));
}

bool TransformVertices(const VertexArrays& mesh, const VertexMaterial& material, const Mat4& model,
                       const VertexContext& context, size_t begin, size_t end, ClipVertex* out,
                       float* attributes, const AttributeLayout* layout) {
  const VertexRun run(mesh, material, model, context, layout);
  const DF df;
  const size_t N = hn::Lanes(df);
  const unsigned stored = attributes && layout ? layout->stored : 0;
  const size_t stride = stored ? size_t(layout->stride) : 0;
  const VF big = hn::Set(df, std::numeric_limits<float>::max());
  auto finiteLanes = hn::Eq(big, big);
  alignas(64) float position[4 * 16], color[4 * 16], attribute[kAttributeCount][16];
  // N vertices from m's index i on, written to o (and the attributes to dst); only the first
  // `count` of them kept (a tail run on a padded copy).
  auto run16 = [&](const VertexArrays& m, size_t i, ClipVertex* o, float* dst, size_t count) {
    V3 p;
    hn::LoadInterleaved3(df, &m.positions[i].x, p.x, p.y, p.z);
    finiteLanes = hn::And(finiteLanes,
                          hn::And(hn::Le(hn::Abs(p.x), big),
                                  hn::And(hn::Le(hn::Abs(p.y), big), hn::Le(hn::Abs(p.z), big))));
    const V3 c = transform(df, run.mvp, p, 1.0f);
    auto cw = hn::Add(hn::Add(hn::Add(hn::Mul(hn::Set(df, run.mvp.m[0][3]), p.x),
                                      hn::Mul(hn::Set(df, run.mvp.m[1][3]), p.y)),
                              hn::Mul(hn::Set(df, run.mvp.m[2][3]), p.z)),
                      hn::Set(df, run.mvp.m[3][3]));
    VF r = hn::Set(df, run.base.x), g = hn::Set(df, run.base.y), b = hn::Set(df, run.base.z),
       a = hn::Set(df, run.base.w);
    if (m.colors) {
      VF vr, vg, vb, va;
      hn::LoadInterleaved4(df, &m.colors[i].x, vr, vg, vb, va);
      r = hn::Mul(r, vr), g = hn::Mul(g, vg), b = hn::Mul(b, vb), a = hn::Mul(a, va);
    }
    if (run.vertexLit) {
      V3 n;
      hn::LoadInterleaved3(df, &m.normals[i].x, n.x, n.y, n.z);
      n = normalized(df, transform(df, run.normalToWorld, n, 0.0f));
      const DirectionalLight& light = run.light;
      V3 diffuse{hn::Zero(df), hn::Zero(df), hn::Zero(df)};
      if (light.enabled) {
        const VF d = positivePart(df, dot3(df, n, run.toLight));
        diffuse = {hn::Mul(hn::Set(df, light.color.x), d), hn::Mul(hn::Set(df, light.color.y), d),
                   hn::Mul(hn::Set(df, light.color.z), d)};
      }
      if (!context.pointLights.empty()) {
        const V3 world = transform(df, model, p, 1.0f);
        for (const PointLight& pl : context.pointLights) {
          const V3 l = normalized(df, V3{hn::Sub(hn::Set(df, pl.position.x), world.x),
                                         hn::Sub(hn::Set(df, pl.position.y), world.y),
                                         hn::Sub(hn::Set(df, pl.position.z), world.z)});
          const VF d = positivePart(df, dot3(n, l));
          diffuse = {hn::Add(diffuse.x, hn::Mul(hn::Set(df, pl.color.x), d)),
                     hn::Add(diffuse.y, hn::Mul(hn::Set(df, pl.color.y), d)),
                     hn::Add(diffuse.z, hn::Mul(hn::Set(df, pl.color.z), d))};
        }
      }
      const VF ambient = hn::Set(df, light.ambient), rest = hn::Set(df, 1 - light.ambient);
      r = hn::Mul(r, hn::Add(ambient, hn::Mul(diffuse.x, rest)));
      g = hn::Mul(g, hn::Add(ambient, hn::Mul(diffuse.y, rest)));
      b = hn::Mul(b, hn::Add(ambient, hn::Mul(diffuse.z, rest)));
    }
    // (Unlit: the scalar code's colour × 1, which is exact.)
    a = unitClamp(df, a);
    hn::StoreInterleaved4(c.x, c.y, c.z, cw, df, position);
    hn::StoreInterleaved4(unitClamp(df, r), unitClamp(df, g), unitClamp(df, b), a, df, color);
    for (size_t j = 0; j < count; ++j) {
      std::memcpy(&o[j].x, position + 4 * j, 4 * sizeof(float));
      std::memcpy(&o[j].r, color + 4 * j, 4 * sizeof(float));
    }
    if (!stored) return;
    auto put = [&](int k, VF v) {
      if (stored >> k & 1) hn::Store(v, df, attribute[k]);
    };
    if (stored & (1u << kU | 1u << kV)) {
      VF u = hn::Zero(df), v = hn::Zero(df);
      if (m.uvs) hn::LoadInterleaved2(df, &m.uvs[i].x, u, v);
      put(kU, hn::Mul(u, hn::Set(df, material.uvScale.x)));
      put(kV, hn::Mul(v, hn::Set(df, material.uvScale.y)));
    }
    if (stored & (1u << kNormalX | 1u << kNormalY | 1u << kNormalZ)) {
      V3 n{hn::Zero(df), hn::Zero(df), hn::Zero(df)};
      if (run.lit && material.phong) {
        hn::LoadInterleaved3(df, &m.normals[i].x, n.x, n.y, n.z);
        n = normalized(df, transform(df, run.normalToEye, n, 0.0f));
      }
      put(kNormalX, n.x);
      put(kNormalY, n.y);
      put(kNormalZ, n.z);
    }
    if (stored & (1u << kEyeX | 1u << kEyeY | 1u << kEyeZ)) {
      const V3 e = transform(df, run.modelView, p, 1.0f);
      put(kEyeX, e.x);
      put(kEyeY, e.y);
      put(kEyeZ, e.z);
    }
    put(kAlpha, a);
    for (int k = 0; k < kAttributeCount; ++k)
      if (stored >> k & 1)
        for (size_t j = 0; j < count; ++j) dst[j * stride + layout->slot[k]] = attribute[k][j];
  };
  size_t i = begin;
  for (; i + N <= end; i += N)
    run16(mesh, i, out + (i - begin), stored ? attributes + (i - begin) * stride : nullptr, N);
  if (i < end) {
    // The tail, fewer than N vertices: the same lanes on a copy padded with its last vertex (so
    // a mesh of a few vertices costs one vector pass, and computes exactly as the others).
    alignas(64) Vec3 positions[16], normals[16];
    alignas(64) Vec4 colors[16];
    alignas(64) Vec2 uvs[16];
    VertexArrays pad = mesh;
    const size_t count = end - i;
    for (size_t j = 0; j < N; ++j) {
      const size_t k = i + std::min(j, count - 1);
      positions[j] = mesh.positions[k];
      if (mesh.normals) normals[j] = mesh.normals[k];
      if (mesh.colors) colors[j] = mesh.colors[k];
      if (mesh.uvs) uvs[j] = mesh.uvs[k];
    }
    pad.positions = positions;
    pad.count = N;
    if (mesh.normals) pad.normals = normals;
    if (mesh.colors) pad.colors = colors;
    if (mesh.uvs) pad.uvs = uvs;
    run16(pad, 0, out + (i - begin), stored ? attributes + (i - begin) * stride : nullptr, count);
  }
  return hn::AllTrue(df, finiteLanes);
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::geometry
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sv::geometry {
HWY_EXPORT(TransformVertices);

bool transformVertices(const VertexArrays& mesh, const VertexMaterial& material, const Mat4& model,
                       const VertexContext& context, size_t begin, size_t end, ClipVertex* out,
                       float* attributes, const AttributeLayout* layout) {
  return HWY_DYNAMIC_DISPATCH(TransformVertices)(mesh, material, model, context, begin, end, out,
                                                 attributes, layout);
}

bool boundObject(const Mat4& mvp, Vec3 lo, Vec3 hi, const Viewport& viewport, ObjectBound& out) {
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL, z0 = HUGE_VAL;
  for (int c = 0; c < 8; ++c) {
    const double p[3] = {c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
    double clip[4];
    for (int r = 0; r < 4; ++r)
      clip[r] = double(mvp.m[0][r]) * p[0] + double(mvp.m[1][r]) * p[1] +
                double(mvp.m[2][r]) * p[2] + double(mvp.m[3][r]);
    // In front of the near plane (z ≥ −w, w > 0) the box's image is the hull of its corners'.
    if (!(clip[3] > 0) || !(clip[2] >= -clip[3]) || !std::isfinite(clip[0]) ||
        !std::isfinite(clip[1]))
      return false;
    const double invW = 1.0 / clip[3];
    // As setup.cpp maps clip space to pixels and window depth.
    const double px = (clip[0] + clip[3]) * (0.5 * viewport.width) * invW;
    const double py = (clip[3] - clip[1]) * (0.5 * viewport.height) * invW;
    x0 = std::min(x0, px), x1 = std::max(x1, px);
    y0 = std::min(y0, py), y1 = std::max(y1, py);
    z0 = std::min(z0, 0.5 * (clip[2] + clip[3]) * invW);
  }
  // Pixel p's square is [p, p + 1): two pixels of slack cover the float vertex transform's
  // rounding and the sample aperture of anti-aliasing.
  auto pixel = [](double v, int size) {
    return int(std::clamp(std::floor(v), -4.0, double(size) + 4));
  };
  out.minX = std::max(pixel(x0, viewport.width) - 2, 0);
  out.minY = std::max(pixel(y0, viewport.height) - 2, 0);
  out.maxX = std::min(pixel(x1, viewport.width) + 2, viewport.width - 1);
  out.maxY = std::min(pixel(y1, viewport.height) + 2, viewport.height - 1);
  // Depth planes are evaluated in float per sample; 2^-10 covers their rounding by a wide margin
  // for any triangle whose depth gradient is below ~10^4 per pixel (docs/hidden-surfaces.md).
  out.zmin = float(z0 - 0x1p-10);
  return true;
}

}  // namespace sv::geometry
#endif
