// The vertex stage (SPEC §1 stage 3, §8): every vertex gets the same bits in a range of any length
// (a range shorter than a vector runs on a padded copy) and on every SIMD target, for every
// combination of colours, lights, Phong normals and stored attributes.
#include "geometry/vertex_stage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "hwy/targets.h"
#include "synthvis/math.h"

namespace sv {
namespace {

using geometry::AttributeLayout;
using geometry::ClipVertex;
using enum geometry::Attribute;

// The vertex stage stores only the attributes some material reads, packed in Attribute order.
TEST(AttributeLayout, PacksTheStoredAttributesInOrder) {
  const AttributeLayout none = AttributeLayout::of(0);
  EXPECT_EQ(none.stride, 0);
  const AttributeLayout uv = AttributeLayout::of(1u << kU | 1u << kV);
  EXPECT_EQ(uv.stride, 2);
  EXPECT_EQ(uv.slot[kU], 0);
  EXPECT_EQ(uv.slot[kV], 1);
  const AttributeLayout fogged =
      AttributeLayout::of(1u << kAlpha | 1u << kEyeX | 1u << kEyeY | 1u << kEyeZ | 1u << kV);
  EXPECT_EQ(fogged.stride, 5);
  EXPECT_EQ(fogged.slot[kV], 0);
  EXPECT_EQ(fogged.slot[kEyeX], 1);
  EXPECT_EQ(fogged.slot[kEyeZ], 3);
  EXPECT_EQ(fogged.slot[kAlpha], 4);
  EXPECT_EQ(AttributeLayout::of(~0u).stride, kAttributeCount);  // bits beyond the last ignored
}

// A mesh's arrays, and the vertex stage's view of them.
struct Mesh {
  std::vector<Vec3> positions, normals;
  std::vector<Vec4> colors;
  std::vector<Vec2> uvs;
  operator geometry::VertexArrays() const {
    return {positions.data(), positions.size(), normals.empty() ? nullptr : normals.data(),
            colors.empty() ? nullptr : colors.data(), uvs.empty() ? nullptr : uvs.data()};
  }
};

Mesh randomMesh(std::mt19937& rng, size_t n, bool colors, bool normals, bool uvs) {
  std::uniform_real_distribution<float> pos(-3, 3), unit(0, 1), dir(-1, 1);
  Mesh m;
  for (size_t i = 0; i < n; ++i) {
    m.positions.push_back({pos(rng), pos(rng), pos(rng) - 8});
    if (colors) m.colors.push_back({unit(rng), unit(rng), unit(rng), 1.5f * unit(rng) - 0.25f});
    if (normals) m.normals.push_back({dir(rng), dir(rng), dir(rng)});
    if (uvs) m.uvs.push_back({4 * unit(rng), 4 * unit(rng)});
  }
  // Values that test the exact-bits cases: a zero normal (normalize leaves it), negative zeros.
  if (normals) m.normals[3] = {0, 0, 0};
  m.positions[5] = {-0.0f, 0.0f, -4.0f};
  if (normals) m.normals[7] = {-0.0f, 1.0f, -0.0f};
  return m;
}

TEST(VertexStage, EveryVertexGetsTheSameBitsInAnyRangeOnEveryTarget) {
  std::mt19937 rng(7);
  const size_t n = 77;  // several vectors of every width and a tail
  const Mat4 view = Mat4::lookAt({1, 2, 3}, {0, 0, -8}, {0, 1, 0});
  const Mat4 proj = Mat4::perspective(1.0f, 1.5f, 0.1f, 100.0f);
  const Mat4 model = Mat4::translation({0.5f, -0.25f, 1}) * Mat4::rotation({1, 2, 0.5f}, 0.7f) *
                     Mat4::scaling({1.5f, 0.75f, 1.25f});
  const std::vector<geometry::PointLight> points = {{{2, 3, -5}, {0.8f, 0.5f, 0.3f}},
                                                    {{-4, 1, -9}, {0.2f, 0.9f, 0.6f}}};
  int cases = 0;
  // The first target's results, which every other target must reproduce.
  std::vector<std::vector<ClipVertex>> firstVertices;
  std::vector<std::vector<float>> firstAttributes;
  bool first = true;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    rng.seed(7);
    size_t k = 0;
    for (int variant = 0; variant < 32; ++variant) {
      const bool colors = variant & 1, normals = variant & 2, phong = variant & 4,
                 lightOn = variant & 8, withPoints = variant & 16;
      const Mesh mesh = randomMesh(rng, n, colors, normals, variant % 3 != 0);
      geometry::VertexMaterial material;
      material.baseColor = {0.9f, 0.7f, 0.5f, 0.8f};
      material.phong = phong;
      material.uvScale = {2.5f, 0.75f};
      geometry::DirectionalLight light;
      light.direction = {-0.4f, -1.0f, -0.6f};
      light.enabled = lightOn;
      const geometry::VertexContext context{view, proj * view, light,
                                            withPoints
                                                ? std::span<const geometry::PointLight>(points)
                                                : std::span<const geometry::PointLight>()};
      for (unsigned stored : {0u, (1u << kU) | (1u << kV), (1u << kAttributeCount) - 1}) {
        const AttributeLayout layout = AttributeLayout::of(stored);
        const size_t stride = size_t(layout.stride);
        std::vector<ClipVertex> lanes(n), one(n);
        std::vector<float> lanesA(n * stride + 1, -1), oneA(n * stride + 1, -1);
        ASSERT_TRUE(geometry::transformVertices(mesh, material, model, context, 0, n, lanes.data(),
                                                stride ? lanesA.data() : nullptr, &layout));
        for (size_t i = 0; i < n; ++i)
          ASSERT_TRUE(geometry::transformVertices(mesh, material, model, context, i, i + 1, &one[i],
                                                  stride ? &oneA[i * stride] : nullptr, &layout));
        for (size_t i = 0; i < n; ++i)
          ASSERT_EQ(std::memcmp(&lanes[i], &one[i], sizeof(ClipVertex)), 0)
              << hwy::TargetName(target) << " variant " << variant << " vertex " << i;
        ASSERT_EQ(std::memcmp(lanesA.data(), oneA.data(), lanesA.size() * sizeof(float)), 0)
            << hwy::TargetName(target) << " variant " << variant << " attributes " << stored;
        if (first) {
          firstVertices.push_back(lanes);
          firstAttributes.push_back(lanesA);
        } else {
          ASSERT_EQ(std::memcmp(lanes.data(), firstVertices[k].data(), n * sizeof(ClipVertex)), 0)
              << hwy::TargetName(target) << " variant " << variant << " differs from the first";
          ASSERT_EQ(std::memcmp(lanesA.data(), firstAttributes[k].data(),
                                lanesA.size() * sizeof(float)),
                    0)
              << hwy::TargetName(target) << " variant " << variant << " attributes " << stored;
        }
        ++k;
        ++cases;
      }
    }
    first = false;
  }
  hwy::SetSupportedTargetsForTest(0);
  EXPECT_GE(cases, 96);
}

TEST(VertexStage, ANonFinitePositionIsReportedFromTheLanesAndTheTail) {
  std::mt19937 rng(3);
  const Mat4 view = Mat4::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
  const geometry::VertexContext lit{
      view, Mat4::perspective(1.0f, 1.0f, 0.1f, 100.0f) * view, {}, {}};
  for (size_t bad : {size_t(2), size_t(40), size_t(63)}) {
    Mesh mesh = randomMesh(rng, 64, true, false, false);
    mesh.positions[bad].y = bad == 40 ? std::nanf("") : INFINITY;
    std::vector<ClipVertex> out(64);
    EXPECT_FALSE(geometry::transformVertices(mesh, geometry::VertexMaterial{}, Mat4::identity(),
                                             lit, 0, 64, out.data()))
        << bad;
    EXPECT_TRUE(geometry::transformVertices(mesh, geometry::VertexMaterial{}, Mat4::identity(), lit,
                                            0, bad, out.data()))
        << bad;
  }
}

}  // namespace
}  // namespace sv
