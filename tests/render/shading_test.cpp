// Pixel shading through the public API (issue 5): perspective-correct texture coordinates against
// an analytic ray-plane intersection, translucency and cut-outs, Phong against its formula, fog,
// and identical bytes for any thread count.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <memory>

#include "support/test_scenes.h"
#include "synthvis/render.h"
#include "texture/texture.h"

namespace sv {
namespace {

constexpr double kTanHalf = 0.57735026918962576;  // tan(30°): the cameras below have a 60° yfov

uint16_t srgbTo16(int byte) {
  const double v = byte / 255.0;
  return uint16_t(
      std::lround((v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4)) * 65535));
}
double srgbToLinear(int byte) {
  const double v = byte / 255.0;
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

// A scene with the camera at the origin looking down −z (60° yfov), no light, black background.
scene::Scene emptyScene() { return tests::emptyScene(); }

// A quad o + s·e1 + t·e2, s, t ∈ [0, 1], with uv = (s, t), drawn with `material`.
void addQuad(scene::Scene& s, Vec3 o, Vec3 e1, Vec3 e2, int material, Vec4 color = {1, 1, 1, 1}) {
  scene::Mesh m;
  m.positions = {o, o + e1, o + e1 + e2, o + e2};
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.colors.assign(4, color);
  const Vec3 n = normalize(cross(e1, e2));
  m.normals.assign(4, n);
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = material;
  s.meshes.push_back(m);
  s.instances.push_back({int(s.meshes.size()) - 1, Mat4{}});
}

Image render(const scene::Scene& s, int w, int h, int threads = 2,
             scene::TextureFilter filter = scene::TextureFilter::trilinear, int samples = 1,
             RenderOptions::Hsr hsr = RenderOptions::Hsr::zbuffer) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.threads = threads;
  o.textureFilter = filter;
  o.samples = samples;
  o.hsr = hsr;
  Renderer r(o);
  Image img;
  const Status st = r.render(s, img);
  EXPECT_TRUE(st.ok()) << st.error().str();
  return img;
}

const uint8_t* pixel(const Image& img, int x, int y) {
  return &img.rgb[(size_t(y) * size_t(img.width) + size_t(x)) * 3];
}

TEST(Shading, TextureCoordinatesArePerspectiveCorrectOnATiltedQuad) {
  // A 16 × 16 texture whose texel (x, y) has red 16·x and green 16·y (sRGB bytes), seen nearest,
  // magnified (so level 0), on a quad tilted steeply away from the camera.
  texture::Level level;
  level.width = level.height = 16;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      level.texels.push_back({srgbTo16(16 * x), srgbTo16(16 * y), 0, 65535});
  scene::Scene s = emptyScene();
  s.textures.push_back({"coords", std::make_shared<texture::Texture>(level, texture::Wrap::clamp,
                                                                     texture::Wrap::clamp)});
  scene::Material mat;
  mat.texture = 0;
  mat.unlit = true;
  mat.doubleSided = true;
  s.materials.push_back(mat);
  const Vec3 o{-1.2f, -0.9f, -2.0f}, e1{2.4f, 0.3f, -0.4f}, e2{0.2f, 1.6f, -2.5f};
  addQuad(s, o, e1, e2, 0);
  const int w = 128, h = 96;
  const Image img = render(s, w, h, 2, scene::TextureFilter::nearest);
  int checked = 0, exact = 0;
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      // The ray through the pixel centre meets the plane at o + s·e1 + t·e2 = λ·d.
      const double dx = (2 * (px + 0.5) / w - 1) * kTanHalf * w / h;
      const double dy = (1 - 2 * (py + 0.5) / h) * kTanHalf;
      const double d[3] = {dx, dy, -1};
      // Solve s·e1 + t·e2 − λ·d = −o by Cramer's rule.
      const double a[3][3] = {{e1.x, e2.x, -d[0]}, {e1.y, e2.y, -d[1]}, {e1.z, e2.z, -d[2]}};
      const double b[3] = {-o.x, -o.y, -o.z};
      auto det3 = [](const double m[3][3]) {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
               m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
      };
      const double det = det3(a);
      double col[2];
      for (int c = 0; c < 2; ++c) {
        double m[3][3];
        for (int r = 0; r < 3; ++r)
          for (int k = 0; k < 3; ++k) m[r][k] = k == c ? b[r] : a[r][k];
        col[c] = det3(m) / det;
      }
      const double u = col[0], v = col[1];
      if (!(u > 0.01 && u < 0.99 && v > 0.01 && v < 0.99)) continue;
      // Skip centres within 2 % of a texel of a texel boundary (float rounding may go either way).
      const double tx = u * 16, ty = v * 16;
      if (std::fabs(tx - std::round(tx)) < 0.02 || std::fabs(ty - std::round(ty)) < 0.02) continue;
      ++checked;
      const uint8_t* p = pixel(img, px, py);
      EXPECT_EQ(p[0], 16 * int(tx)) << "pixel " << px << "," << py;
      EXPECT_EQ(p[1], 16 * int(ty)) << "pixel " << px << "," << py;
      exact += p[0] == 16 * int(tx) && p[1] == 16 * int(ty);
    }
  EXPECT_GT(checked, 1500);
  EXPECT_EQ(exact, checked);
}

TEST(Shading, TranslucentSurfacesBlendOverWhatIsBehindInLinearLight) {
  scene::Scene s = emptyScene();
  scene::Material back, glass;
  back.unlit = glass.unlit = true;
  back.baseColor = {0, 0, 1, 1};
  glass.baseColor = {1, 0, 0, 0.25f};
  glass.alphaMode = scene::AlphaMode::blend;
  s.materials = {back, glass};
  // Submitted in front first: translucent draws still come after the opaque ones.
  addQuad(s, {-1, -1, -2}, {2, 0, 0}, {0, 2, 0}, 1);
  addQuad(s, {-5, -5, -4}, {10, 0, 0}, {0, 10, 0}, 0);
  const Image img = render(s, 32, 32);
  const uint8_t* p = pixel(img, 16, 16);
  auto encode = [](double linear) {
    return int(std::lround(
        255 * (linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055)));
  };
  EXPECT_NEAR(p[0], encode(0.25), 1);
  EXPECT_EQ(p[1], 0);
  EXPECT_NEAR(p[2], encode(0.75), 1);
  // Outside the glass: the blue quad alone.
  EXPECT_EQ(pixel(img, 1, 1)[2], 255);
  EXPECT_EQ(pixel(img, 1, 1)[0], 0);
}

// Two translucent quads blend in depth order whatever their submission order: the renderer
// draws translucent objects farthest first.
TEST(Shading, TranslucentObjectsBlendFarthestFirstInAnySubmissionOrder) {
  scene::Scene nearFirst = emptyScene();
  scene::Material red, green;
  red.unlit = green.unlit = true;
  red.baseColor = {1, 0, 0, 0.5f};
  green.baseColor = {0, 1, 0, 0.5f};
  red.alphaMode = green.alphaMode = scene::AlphaMode::blend;
  nearFirst.materials = {red, green};
  scene::Scene farFirst = nearFirst;
  addQuad(nearFirst, {-1, -1, -2}, {2, 0, 0}, {0, 2, 0}, 0);  // red, near
  addQuad(nearFirst, {-2, -2, -4}, {4, 0, 0}, {0, 4, 0}, 1);  // green, far
  addQuad(farFirst, {-2, -2, -4}, {4, 0, 0}, {0, 4, 0}, 1);
  addQuad(farFirst, {-1, -1, -2}, {2, 0, 0}, {0, 2, 0}, 0);
  const Image a = render(nearFirst, 32, 32), b = render(farFirst, 32, 32);
  EXPECT_EQ(a.rgb, b.rgb);
  // Red over (green over black): red 0.5, green 0.25 in linear light.
  EXPECT_GT(pixel(a, 16, 16)[0], pixel(a, 16, 16)[1]);
}

// Masking draws opaque objects nearest first (their boxes' nearest corners), so a scene given far
// to near renders as the Z-buffer does; an explicit priority overrides distance, and masking
// obeys it (the seeds' databases chose priorities; the Z-buffer ignores them).
TEST(Shading, MaskingOrdersObjectsNearestFirstUnlessPrioritiesSay) {
  scene::Scene s = emptyScene();
  scene::Material blue, red;
  blue.unlit = red.unlit = true;
  blue.baseColor = {0, 0, 1, 1};
  red.baseColor = {1, 0, 0, 1};
  s.materials = {blue, red};
  addQuad(s, {-5, -5, -6}, {10, 0, 0}, {0, 10, 0}, 0);  // far, blue, first
  addQuad(s, {-1, -1, -2}, {2, 0, 0}, {0, 2, 0}, 1);    // near, red
  const Image z = render(s, 48, 32);
  for (auto hsr : {RenderOptions::Hsr::priority, RenderOptions::Hsr::hybrid})
    for (int samples : {1, 16})
      EXPECT_EQ(render(s, 48, 32, 2, scene::TextureFilter::trilinear, samples, hsr).rgb,
                render(s, 48, 32, 2, scene::TextureFilter::trilinear, samples).rgb);
  EXPECT_EQ(pixel(z, 24, 16)[0], 255);
  s.instances[0].priority = -1;  // the far quad declared nearest
  const Image p =
      render(s, 48, 32, 2, scene::TextureFilter::trilinear, 1, RenderOptions::Hsr::priority);
  EXPECT_EQ(pixel(p, 24, 16)[2], 255);  // blue hides red: the order was trusted
  EXPECT_EQ(
      render(s, 48, 32, 2, scene::TextureFilter::trilinear, 1, RenderOptions::Hsr::hybrid).rgb,
      z.rgb);  // hybrid stays exact
}

TEST(Shading, AlphaCutOutsShowWhatIsBehindWhereAlphaIsBelowTheCutoff) {
  // A texture whose left half is transparent, on a red quad in front of a blue one.
  texture::Level level;
  level.width = level.height = 8;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      level.texels.push_back(x < 4 ? texture::Texel{0, 0, 0, 0}
                                   : texture::Texel{65535, 65535, 65535, 65535});
  scene::Scene s = emptyScene();
  s.textures.push_back({"half", std::make_shared<texture::Texture>(level, texture::Wrap::clamp,
                                                                   texture::Wrap::clamp)});
  scene::Material back, cut;
  back.unlit = cut.unlit = true;
  back.baseColor = {0, 0, 1, 1};
  cut.baseColor = {1, 0, 0, 1};
  cut.texture = 0;
  cut.alphaMode = scene::AlphaMode::mask;
  s.materials = {back, cut};
  addQuad(s, {-1, -1, -2}, {2, 0, 0}, {0, 2, 0}, 1);
  addQuad(s, {-5, -5, -4}, {10, 0, 0}, {0, 10, 0}, 0);
  const Image img = render(s, 64, 64, 2, scene::TextureFilter::nearest);
  // The quad spans about 55 px; u < 0.5 on its left half.
  const uint8_t* left = pixel(img, 20, 32);
  const uint8_t* right = pixel(img, 44, 32);
  EXPECT_EQ(left[0], 0);
  EXPECT_EQ(left[2], 255);
  EXPECT_EQ(right[0], 255);
  EXPECT_EQ(right[2], 0);
}

TEST(Shading, PhongFollowsSeed003sWeightingPerPixel) {
  // A plane facing the camera, a directional light at 60° from its normal and a point light:
  // C = (Q_amb·C + Q_diff·C·Σ(n·l)·L + Q_spec·Σ(r·v)^p·L) / (Q_amb + Q_diff + Q_spec).
  scene::Scene s = emptyScene();
  s.light.enabled = true;
  s.light.ambient = 0.2f;
  s.light.direction = {0, -std::sqrt(3.0f) / 2, -0.5f};  // n·l = cos 60° = 0.5 for n = +z
  s.light.color = {1, 1, 1};
  scene::Material m;
  m.phong = true;
  m.specular = 0.5f;
  m.shininess = 8;
  m.baseColor = {0.8f, 0.4f, 0.2f, 1};
  s.materials.push_back(m);
  addQuad(s, {-3, -3, -2}, {6, 0, 0}, {0, 6, 0}, 0);
  const int w = 65, h = 65;
  const Image img = render(s, w, h);
  // At the centre pixel: the point on the plane is (0, 0, −2) (up to half a pixel), v = +z.
  const double nl = 0.5;
  const double l[3] = {0, std::sqrt(3.0) / 2, 0.5};
  const double r[3] = {2 * nl * 0 - l[0], 2 * nl * 0 - l[1], 2 * nl * 1 - l[2]};  // 2(n·l)n − l
  const double rv = std::max(0.0, r[2]);
  const double spec = std::pow(rv, 8.0);
  const double surf[3] = {0.8, 0.4, 0.2};
  const uint8_t* p = pixel(img, 32, 32);
  for (int c = 0; c < 3; ++c) {
    const double expect = (0.2 * surf[c] + 0.8 * surf[c] * nl + 0.5 * spec) / 1.5;
    EXPECT_NEAR(srgbToLinear(p[c]), expect, 0.01) << "channel " << c;
  }
}

TEST(Shading, FogTakesTheFogColourWithDistance) {
  scene::Scene s = emptyScene();
  scene::Material m;
  m.unlit = true;
  m.baseColor = {1, 1, 1, 1};
  s.materials.push_back(m);
  s.fog = {true, {0, 0, 1}, 0.5f};                             // halves every 2 units of range
  addQuad(s, {-1, -1, -2}, {2, 0, 0}, {0, 2, 0}, 0);           // range ≈ 2 at the centre
  addQuad(s, {-100, -100, -90}, {200, 0, 0}, {0, 200, 0}, 0);  // range ≥ 90
  const Image img = render(s, 33, 33);
  const uint8_t* near = pixel(img, 16, 16);
  // f = 2^(−0.5·2) = 0.5: half white, half fog blue (linear).
  EXPECT_NEAR(srgbToLinear(near[0]), 0.5, 0.01);
  EXPECT_NEAR(srgbToLinear(near[2]), 1.0, 0.01);
  const uint8_t* far = pixel(img, 0, 0);
  EXPECT_EQ(far[0], 0);
  EXPECT_EQ(far[2], 255);
}

TEST(Shading, TexturedFramesAreIdenticalForAnyThreadCount) {
  scene::Scene s = emptyScene();
  texture::Level level =
      texture::generateTexture(texture::Pattern::noise, 64, {0, 0, 0, 1}, {1, 1, 1, 1}, 5);
  s.textures.push_back({"noise", std::make_shared<texture::Texture>(level, texture::Wrap::repeat,
                                                                    texture::Wrap::mirror)});
  scene::Material m;
  m.texture = 0;
  m.phong = true;
  m.specular = 0.3f;
  m.uvScale = {7, 5};
  s.light.enabled = true;
  s.fog = {true, {0.5f, 0.5f, 0.6f}, 0.05f};
  s.materials.push_back(m);
  scene::Material glass = m;
  glass.alphaMode = scene::AlphaMode::blend;
  glass.baseColor.w = 0.5f;
  s.materials.push_back(glass);
  for (int i = 0; i < 40; ++i) {
    const float a = float(i) * 0.7f;
    addQuad(s, {std::sin(a) * 3, std::cos(a * 1.3f) * 2, -4 - float(i % 7)},
            {1.5f * std::cos(a), 0.4f, 0.3f}, {0.2f, 1.2f, -0.8f * std::sin(a)},
            i % 5 == 0 ? 1 : 0);
  }
  for (int samples : {1, 4, 16})
    for (auto filter : {scene::TextureFilter::trilinear, scene::TextureFilter::anisotropic}) {
      const Image one = render(s, 200, 150, 1, filter, samples);
      for (int threads : {2, 8})
        EXPECT_EQ(render(s, 200, 150, threads, filter, samples).rgb, one.rgb)
            << threads << " threads, " << samples << " samples";
    }
}

// The frame statistics count each rasterized pixel once however it is shaded: deferred shading
// (which shades the visible pixels after the tile's triangles are drawn) adds no fragments of its
// own, so a textured frame reports the fragments of the same frame in Gouraud colours.
TEST(Shading, DeferredShadingCountsEachFragmentOnce) {
  scene::Scene s = emptyScene();
  texture::Level level =
      texture::generateTexture(texture::Pattern::noise, 64, {0, 0, 0, 1}, {1, 1, 1, 1}, 5);
  s.textures.push_back({"noise", std::make_shared<texture::Texture>(level, texture::Wrap::repeat,
                                                                    texture::Wrap::repeat)});
  scene::Material m;
  m.texture = 0;
  s.materials.push_back(m);
  for (int i = 0; i < 30; ++i) {
    const float a = float(i) * 0.9f;
    addQuad(s, {std::sin(a) * 2, std::cos(a * 1.3f) * 1.5f, -4 - float(i % 5)},
            {0.8f * std::cos(a), 0.3f, 0.2f}, {0.1f, 0.9f, -0.5f * std::sin(a)}, 0);
  }
  // (No material of the frame needs pixel shading: drawn in Gouraud colours as they are
  // rasterized.)
  scene::Scene plain = s;
  plain.materials = {scene::Material{}};
  plain.textures.clear();
  for (scene::Mesh& mesh : plain.meshes) mesh.material = 0;
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  FrameStats textured, gouraud;
  Image img;
  ASSERT_TRUE(Renderer(o).render(s, img, &textured).ok());
  ASSERT_TRUE(Renderer(o).render(plain, img, &gouraud).ok());
  EXPECT_GT(gouraud.fragments, 2000u);
  EXPECT_EQ(textured.fragments, gouraud.fragments)
      << textured.fragments << " " << gouraud.fragments;
  EXPECT_EQ(textured.hiddenFragments, gouraud.hiddenFragments);
}

// Deferred shading gathers the pixels of triangles too small to fill a batch into shared
// batches of one material. Tiny triangles, each reading a texel of its own (nearest, at the
// texel's centre), alternate between two materials whose textures hold the same colours with the
// channels rotated: every pixel must show its own triangle's texel of its own material's texture —
// as in the same frame drawn untextured with those colours as vertex colours (which is not pixel
// shaded) — on every SIMD target. Alone, some of the grid's tiles find each triangle's pixels from
// the list of the blocks it won; behind four screen-filling layers (drawn first, each hiding the
// one before), which fill that list's budget, all scan the tile: both ways must give that image.
TEST(Shading, TinyTrianglesKeepTheirOwnTexelAndMaterialInSharedBatches) {
  constexpr int kSide = 32;  // texels a side: 1024 colours
  texture::Level levels[2];
  for (int k = 0; k < 2; ++k) {
    levels[k].width = levels[k].height = kSide;
    for (int i = 0; i < kSide * kSide; ++i) {
      const uint16_t c[3] = {srgbTo16(8 * (i % kSide) + 4), srgbTo16(8 * (i / kSide) + 4),
                             srgbTo16(128)};
      // Material 1's texture: the channels rotated, so its colour always differs from 0's.
      levels[k].texels.push_back(k ? texture::Texel{c[2], c[0], c[1], 65535}
                                   : texture::Texel{c[0], c[1], c[2], 65535});
    }
  }
  auto build = [&](bool textured, int layers) {
    scene::Scene s = emptyScene();
    scene::Mesh meshes[2];
    for (int k = 0; k < 2; ++k) {
      if (textured)
        s.textures.push_back({k ? "rotated" : "plain",
                              std::make_shared<texture::Texture>(levels[k], texture::Wrap::repeat,
                                                                 texture::Wrap::repeat)});
      scene::Material m;
      m.texture = textured ? k : -1;
      m.unlit = true;
      s.materials.push_back(m);
      meshes[k].material = k;
    }
    // A vertex of mesh m reading texel `texel` (nearest, at its centre), or untextured, colour c.
    auto vertex = [&](scene::Mesh& m, const Vec3& p, int texel, const texture::Color4& c) {
      m.indices.push_back(uint32_t(m.positions.size()));
      m.positions.push_back(p);
      m.uvs.push_back(
          {(float(texel % kSide) + 0.5f) / kSide, (float(texel / kSide) + 0.5f) / kSide});
      m.colors.push_back(textured ? Vec4{1, 1, 1, 1} : Vec4{c.r, c.g, c.b, 1});
      m.normals.push_back({0, 0, 1});
    };
    // The layers behind: material 0's texel 5 all over, farthest first.
    const int backdrop = 5;
    const texture::Color4 b =
        texture::unpackTexel(texture::packTexel(levels[0].texels[size_t(backdrop)]));
    for (int l = 0; l < layers; ++l) {
      const float z = -6.0f + 0.5f * float(l);
      const Vec3 corner[4] = {{-20, -20, z}, {20, -20, z}, {20, 20, z}, {-20, 20, z}};
      for (int v : {0, 1, 2, 0, 2, 3}) vertex(meshes[0], corner[v], backdrop, b);
    }
    // A 40 × 30 grid of cells about 4 px wide, each cell's two triangles of different materials.
    const int nx = 40, ny = 30;
    int triangle = 0;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const float x0 = -1.6f + 3.2f * float(i) / nx, x1 = -1.6f + 3.2f * float(i + 1) / nx;
        const float y0 = -1.2f + 2.4f * float(j) / ny, y1 = -1.2f + 2.4f * float(j + 1) / ny;
        const Vec3 corner[4] = {{x0, y0, -2}, {x1, y0, -2}, {x1, y1, -2}, {x0, y1, -2}};
        const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
        for (int t = 0; t < 2; ++t, ++triangle) {
          const int k = (i + j + t) % 2;
          const int texel = (triangle * 37) % (kSide * kSide);
          const texture::Color4 c =
              texture::unpackTexel(texture::packTexel(levels[k].texels[size_t(texel)]));
          for (int v : tri[t]) vertex(meshes[k], corner[v], texel, c);
        }
      }
    for (scene::Mesh& m : meshes) {
      s.meshes.push_back(m);
      s.instances.push_back({int(s.meshes.size()) - 1, Mat4{}});
    }
    return s;
  };
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  o.threads = 2;
  o.textureFilter = scene::TextureFilter::nearest;
  int targets = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    ++targets;
    for (int layers : {0, 4}) {
      Image expected, img;
      FrameStats stats;
      ASSERT_TRUE(Renderer(o).render(build(false, layers), expected).ok());
      ASSERT_TRUE(Renderer(o).render(build(true, layers), img, &stats).ok());
      int differing = 0, lit = 0;
      for (size_t i = 0; i < img.rgb.size(); ++i) {
        differing += std::abs(int(img.rgb[i]) - int(expected.rgb[i])) > 1;
        lit += img.rgb[i] > 0;
      }
      EXPECT_EQ(differing, 0) << hwy::TargetName(target) << ", " << layers << " layers";
      EXPECT_GT(lit, int(img.rgb.size()) * 3 / 4) << hwy::TargetName(target);
      // Which way the six tiles found their pixels: alone, the narrow tiles of the right column
      // (32 px wide, ~260 triangles) from the list — the others hold too many triangles' blocks
      // and scan; behind the layers, all scan.
      EXPECT_EQ(stats.shadedByList + stats.shadedByScan, 6u);
      if (layers)
        EXPECT_EQ(stats.shadedByList, 0u);
      else
        EXPECT_GE(stats.shadedByList, 2u);
    }
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(targets, 1);
}

TEST(Shading, AntiAliasedTexturingAgreesWithPointSamplingInsideSurfaces) {
  // Pixel shading with sub-pixel masks (forward, colour once per pixel) against the deferred
  // shading of one sample: inside a textured, lit, fogged quad the two shade the same centres.
  scene::Scene s = emptyScene();
  texture::Level level = texture::generateTexture(texture::Pattern::checker, 64,
                                                  {0.1f, 0.2f, 0.3f, 1}, {0.9f, 0.8f, 0.2f, 1}, 1);
  s.textures.push_back({"checker", std::make_shared<texture::Texture>(level, texture::Wrap::repeat,
                                                                      texture::Wrap::repeat)});
  scene::Material m;
  m.texture = 0;
  m.phong = true;
  s.light.enabled = true;
  s.fog = {true, {0.5f, 0.5f, 0.6f}, 0.05f};
  s.materials.push_back(m);
  // A tilted quad that fills the whole view: no pixel is on an edge.
  addQuad(s, {-10, -10, -2}, {20, 0, -2}, {0, 20, -6}, 0);
  const Image one = render(s, 96, 72, 2, scene::TextureFilter::trilinear, 1);
  // 4 samples shade at pixel centres; 16 at the centroid of the covered samples where a pixel is
  // only partly covered — along the quad's diagonal, where its two triangles meet (≈ 1.5 % of
  // the pixels here).
  for (int samples : {4, 16}) {
    const Image aa = render(s, 96, 72, 2, scene::TextureFilter::trilinear, samples);
    int differing = 0;
    for (size_t i = 0; i < one.rgb.size(); i += 3) {
      int d = 0;
      for (int c = 0; c < 3; ++c)
        d = std::max(d, std::abs(int(one.rgb[i + c]) - int(aa.rgb[i + c])));
      differing += d > 1;
    }
    EXPECT_LE(differing, samples == 4 ? 0 : 96 * 72 / 40) << samples << " samples";
  }
}

}  // namespace
}  // namespace sv
