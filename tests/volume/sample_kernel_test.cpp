// The volume pass's sample kernel (volume/sample_kernel.h): every compiled SIMD target gives the
// same bits, and they are the trilinear value, the transfer function's entry, the step opacity and
// the two-sided weighting computed one sample at a time in double — within float rounding —, on
// a grid with a value that changes along every axis and positions inside, on the faces and beyond
// the box (clamped).
#include "volume/sample_kernel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "hwy/targets.h"

namespace sv::volume {
namespace {

constexpr int kNx = 9, kNy = 7, kNz = 5;

struct Fixture {
  std::vector<uint16_t> codes;
  std::vector<int8_t> normals;
  std::vector<uint16_t> padded;  // the codes with a border repeating the faces
  std::vector<uint8_t> padded8;  // the same a byte each (the codes are below 256), 4 bytes slack
  std::vector<float> table, stepOpacity;
  SampleSource source;

  // Codes below `codes` (256: they fit the bordered 8-bit codes).
  explicit Fixture(int codeRange = 4096) {
    codes.resize(kNx * kNy * kNz);
    normals.resize(codes.size() * 4);
    for (int k = 0; k < kNz; ++k)
      for (int j = 0; j < kNy; ++j)
        for (int i = 0; i < kNx; ++i) {
          const size_t at = (size_t(k) * kNy + size_t(j)) * kNx + size_t(i);
          codes[at] = uint16_t((i * 37 + j * j * 11 + k * 1000 + (i * j * k) % 13) % codeRange);
          normals[at * 4 + 0] = int8_t(i * 13 - 60);
          normals[at * 4 + 1] = int8_t(-j * 17 + 50);
          normals[at * 4 + 2] = int8_t(k * 29 - 127);
        }
    padded.resize(size_t(kNx + 2) * (kNy + 2) * (kNz + 2));
    for (int k = 0; k < kNz + 2; ++k)
      for (int j = 0; j < kNy + 2; ++j)
        for (int i = 0; i < kNx + 2; ++i)
          padded[(size_t(k) * (kNy + 2) + size_t(j)) * (kNx + 2) + size_t(i)] =
              codes[(size_t(std::clamp(k - 1, 0, kNz - 1)) * kNy + size_t(std::clamp(j - 1, 0, kNy - 1))) * kNx +
                    size_t(std::clamp(i - 1, 0, kNx - 1))];
    padded8.assign(padded.size() + 4, 0);
    for (size_t i = 0; i < padded.size(); ++i) padded8[i] = uint8_t(padded[i]);
    const int entries = 64;
    table.resize(entries * 4);
    stepOpacity.resize(entries);
    for (int e = 0; e < entries; ++e) {
      table[size_t(e) * 4 + 0] = float(e) / 63;
      table[size_t(e) * 4 + 1] = 1 - float(e) / 63;
      table[size_t(e) * 4 + 2] = float(e % 7) / 7;
      table[size_t(e) * 4 + 3] = e < 10 ? 0.0f : float(e) / 80;
      stepOpacity[size_t(e)] = float(e) / 100;
    }
    source.codes = codes.data();
    source.nx = kNx, source.ny = kNy, source.nz = kNz;
    const float spacing[3] = {0.5f, 1.0f, 2.0f};
    for (int a = 0; a < 3; ++a) source.spacing[a] = spacing[a], source.inverseSpacing[a] = 1 / spacing[a];
    source.table = table.data();
    source.entries = entries;
    source.codeScale = 63.0f / float(codeRange - 1);
    source.stepOpacity = stepOpacity.data();
    source.shade = true;
    const float m[3][3] = {{0.8f, 0.1f, 0}, {-0.2f, 1.1f, 0.3f}, {0, 0.4f, 0.9f}};
    std::memcpy(source.toWorld, m, sizeof m);
    source.toLight[0] = 0.48f, source.toLight[1] = 0.6f, source.toLight[2] = -0.64f;
    source.ambient = 0.3f;
    source.lightColor[0] = 1, source.lightColor[1] = 0.9f, source.lightColor[2] = 0.7f;
  }

  // The value at own-space (x, y, z), as Codes() reads it but in double.
  double code(double x, double y, double z) const {
    const double f[3] = {std::clamp(x / source.spacing[0], 0.0, kNx - 1.0),
                         std::clamp(y / source.spacing[1], 0.0, kNy - 1.0),
                         std::clamp(z / source.spacing[2], 0.0, kNz - 1.0)};
    const int n[3] = {kNx, kNy, kNz};
    int c[3];
    double t[3];
    for (int a = 0; a < 3; ++a) c[a] = std::min(int(f[a]), n[a] - 2), t[a] = f[a] - c[a];
    double v = 0;
    for (int corner = 0; corner < 8; ++corner) {
      const int i = c[0] + (corner & 1), j = c[1] + (corner >> 1 & 1), k = c[2] + (corner >> 2);
      const double w = ((corner & 1) ? t[0] : 1 - t[0]) * ((corner >> 1 & 1) ? t[1] : 1 - t[1]) *
                       ((corner >> 2) ? t[2] : 1 - t[2]);
      v += w * codes[(size_t(k) * kNy + size_t(j)) * kNx + size_t(i)];
    }
    return v;
  }
};

// Positions: inside, on the last faces, and outside (clamped into the box).
void positions(SampleBatch& b, int round) {
  for (int i = 0; i < kBatch; ++i) {
    const double u = (i * 7 + round * 5) % 17 / 16.0;
    b.x[i] = float(-0.3 + u * (kNx - 1) * 0.5 * 1.1);
    b.y[i] = float((i % 5) * 1.6 + round * 0.25);
    b.z[i] = float(((i * 3 + round) % 9) * 1.05 - 0.5);
  }
  b.x[3] = float((kNx - 1) * 0.5), b.y[3] = float(kNy - 1), b.z[3] = float((kNz - 1) * 2);
}

// Every target, every way of taking the gradient, and 8-bit codes as well as 16-bit ones.
TEST(SampleKernel, EveryTargetGivesTheSameBitsAndTheyAreTheScalarFormulas) {
  for (const int range : {4096, 256}) {
  Fixture f(range);
  // Gradients: precomputed, or central differences read from the bordered codes' cross (16-bit,
  // or 8-bit where they fit), or at the moved points clamped into the box.
  for (const int way : {0, 1, 2, 3}) {
    if (way == 3 && range > 256) continue;
    const bool precomputed = way == 0;
    f.source.normals = precomputed ? f.normals.data() : nullptr;
    f.source.padded = way == 1 ? f.padded.data() : nullptr;
    f.source.padded8 = way == 3 ? f.padded8.data() : nullptr;
    for (int round = 0; round < 4; ++round) {
      SampleBatch first{};
      bool have = false;
      int targets = 0;
      for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SampleBatch b{};
        positions(b, round);
        classifySamples(f.source, kBatch - round, b);
        ++targets;
        if (!have) {
          first = b, have = true;
          continue;
        }
        for (int i = 0; i < kBatch - round; ++i) {
          EXPECT_EQ(std::memcmp(&b.opacity[i], &first.opacity[i], 4), 0) << hwy::TargetName(target);
          EXPECT_EQ(std::memcmp(&b.w[i], &first.w[i], 4), 0) << hwy::TargetName(target);
          EXPECT_EQ(std::memcmp(&b.r[i], &first.r[i], 4), 0) << hwy::TargetName(target);
          EXPECT_EQ(std::memcmp(&b.g[i], &first.g[i], 4), 0) << hwy::TargetName(target);
          EXPECT_EQ(std::memcmp(&b.b[i], &first.b[i], 4), 0) << hwy::TargetName(target);
        }
      }
      hwy::SetSupportedTargetsForTest(0);
      EXPECT_GE(targets, 1);
      // Against the formulas in double.
      SampleBatch in{};
      positions(in, round);
      for (int i = 0; i < kBatch - round; ++i) {
        const double c = f.code(in.x[i], in.y[i], in.z[i]);
        const double pos = c * f.source.codeScale;
        const int e = std::min(int(pos), f.source.entries - 2);
        const double t = pos - e;
        auto lerp = [&](const float* v, size_t stride) {
          return v[size_t(e) * stride] + t * (v[size_t(e + 1) * stride] - v[size_t(e) * stride]);
        };
        EXPECT_NEAR(first.opacity[i], lerp(f.table.data() + 3, 4), 2e-4) << i;
        EXPECT_NEAR(first.w[i], lerp(f.stepOpacity.data(), 1), 2e-4) << i;
        double g[3];
        if (precomputed) {
          // The corners' bytes, trilinear.
          const double p[3] = {in.x[i], in.y[i], in.z[i]};
          const int n[3] = {kNx, kNy, kNz};
          int cell[3];
          double tt[3];
          for (int a = 0; a < 3; ++a) {
            const double fa = std::clamp(p[a] / f.source.spacing[a], 0.0, n[a] - 1.0);
            cell[a] = std::min(int(fa), n[a] - 2), tt[a] = fa - cell[a];
          }
          for (int a = 0; a < 3; ++a) {
            g[a] = 0;
            for (int corner = 0; corner < 8; ++corner) {
              const int ci = cell[0] + (corner & 1), cj = cell[1] + (corner >> 1 & 1),
                        ck = cell[2] + (corner >> 2);
              const double w = ((corner & 1) ? tt[0] : 1 - tt[0]) *
                               ((corner >> 1 & 1) ? tt[1] : 1 - tt[1]) *
                               ((corner >> 2) ? tt[2] : 1 - tt[2]);
              g[a] += w * f.normals[((size_t(ck) * kNy + size_t(cj)) * kNx + size_t(ci)) * 4 +
                                    size_t(a)];
            }
          }
        } else {
          // The bordered codes' differences are about the sample's point clamped into the box
          // (rays' samples lie in it; this test's also beyond it), the others' about the point.
          const int n[3] = {kNx, kNy, kNz};
          double p[3] = {in.x[i], in.y[i], in.z[i]};
          if (way == 1 || way == 3)
            for (int a = 0; a < 3; ++a)
              p[a] = std::clamp(p[a], 0.0, double(n[a] - 1) * f.source.spacing[a]);
          for (int a = 0; a < 3; ++a) {
            double up[3] = {p[0], p[1], p[2]}, down[3] = {p[0], p[1], p[2]};
            up[a] += f.source.spacing[a], down[a] -= f.source.spacing[a];
            g[a] = (f.code(up[0], up[1], up[2]) - f.code(down[0], down[1], down[2])) /
                   (2.0 * f.source.spacing[a]);
          }
        }
        double w[3], len2 = 0, toward = 0;
        for (int r = 0; r < 3; ++r) {
          w[r] = f.source.toWorld[r][0] * g[0] + f.source.toWorld[r][1] * g[1] +
                 f.source.toWorld[r][2] * g[2];
          len2 += w[r] * w[r];
          toward += w[r] * f.source.toLight[r];
        }
        const double cosine = len2 > 0 ? std::fabs(toward) / std::sqrt(len2) : 0;
        const double out[3] = {first.r[i], first.g[i], first.b[i]};
        for (int ch = 0; ch < 3; ++ch) {
          const double base = lerp(f.table.data() + ch, 4);
          const double lit = len2 > 0 ? base * (f.source.ambient + (1 - f.source.ambient) * cosine *
                                                                       f.source.lightColor[ch])
                                      : base;
          // A transparent sample is not composited: its colour is zero.
          EXPECT_NEAR(out[ch], first.opacity[i] > 0 ? lit : 0.0, 2e-3)
              << "sample " << i << " channel " << ch;
        }
      }
    }
  }
  }
}

// An unlit volume of 8-bit data reads its values from the bordered byte codes' cross as a lit one
// does: the bits the plain codes' four gathers a cell give (positions inside the box; beyond it
// the cross clamps the point, the plain codes the cell).
TEST(SampleKernel, UnlitEightBitValuesFromTheBorderedBytesAreThePlainCodesBits) {
  Fixture f(256);
  f.source.shade = false;
  f.source.normals = nullptr, f.source.padded = nullptr;
  for (int round = 0; round < 4; ++round) {
    SampleBatch plain{}, bytes{};
    positions(plain, round);
    for (int i = 0; i < kBatch; ++i) {  // inside the box
      plain.x[i] = std::clamp(plain.x[i], 0.0f, (kNx - 1) * f.source.spacing[0]);
      plain.y[i] = std::clamp(plain.y[i], 0.0f, (kNy - 1) * f.source.spacing[1]);
      plain.z[i] = std::clamp(plain.z[i], 0.0f, (kNz - 1) * f.source.spacing[2]);
    }
    std::memcpy(bytes.x, plain.x, sizeof plain.x);
    std::memcpy(bytes.y, plain.y, sizeof plain.y);
    std::memcpy(bytes.z, plain.z, sizeof plain.z);
    f.source.padded8 = nullptr;
    classifySamples(f.source, kBatch, plain);
    f.source.padded8 = f.padded8.data();
    classifySamples(f.source, kBatch, bytes);
    for (int i = 0; i < kBatch; ++i) {
      EXPECT_EQ(std::memcmp(&plain.opacity[i], &bytes.opacity[i], 4), 0) << round << " " << i;
      EXPECT_EQ(std::memcmp(&plain.w[i], &bytes.w[i], 4), 0) << i;
      EXPECT_EQ(std::memcmp(&plain.r[i], &bytes.r[i], 4), 0) << i;
    }
  }
}

// Without the tabled step opacity (a transform that is not a similarity), a ray's step opacity
// 1 − (1 − W)^e is taken in the lanes: the same bits on every target, and the formula in double
// within 10⁻⁴ (the lanes' log2 is within 2·10⁻⁵; the table's linear reading, the other way, within
// 2·10⁻⁴) — for steps shorter and longer than the unit, and opaque samples staying opaque.
TEST(SampleKernel, ARaysOwnStepOpacityIsTakenInTheLanes) {
  Fixture f;
  f.source.stepOpacity = nullptr;
  f.table[size_t(40) * 4 + 3] = 1;  // an opaque entry among the others
  for (const float exponent : {0.37f, 1.0f, 2.5f, 11.0f}) {
    for (int round = 0; round < 4; ++round) {
      SampleBatch first{};
      bool have = false;
      for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
        hwy::SetSupportedTargetsForTest(target);
        SampleBatch b{};
        positions(b, round);
        b.exponent = exponent;
        classifySamples(f.source, kBatch, b);
        if (!have) {
          first = b, have = true;
          continue;
        }
        EXPECT_EQ(std::memcmp(b.w, first.w, sizeof b.w), 0) << hwy::TargetName(target);
      }
      hwy::SetSupportedTargetsForTest(0);
      for (int i = 0; i < kBatch; ++i) {
        const double w = 1 - std::pow(1 - std::min(double(first.opacity[i]), 1.0), exponent);
        EXPECT_NEAR(first.w[i], w, 1e-4) << "exponent " << exponent << " sample " << i;
      }
    }
  }
}

// The bordered 8-bit codes give the bits the 16-bit ones give, on the samples of whole vectors of
// transparent samples too (their gradients are skipped alike).
TEST(SampleKernel, EightBitCodesGiveTheSixteenBitCodesBits) {
  Fixture f(256);
  int transparent = 0, total = 0;
  for (int round = 0; round < 4; ++round) {
    SampleBatch wide{}, narrow{};
    positions(wide, round);
    positions(narrow, round);
    f.source.padded = f.padded.data(), f.source.padded8 = nullptr;
    classifySamples(f.source, kBatch, wide);
    f.source.padded = nullptr, f.source.padded8 = f.padded8.data();
    classifySamples(f.source, kBatch, narrow);
    for (int i = 0; i < kBatch; ++i) {
      ++total;
      transparent += !(wide.opacity[i] > 0);
      EXPECT_EQ(std::memcmp(&wide.opacity[i], &narrow.opacity[i], 4), 0) << i;
      EXPECT_EQ(std::memcmp(&wide.r[i], &narrow.r[i], 4), 0) << i;
      EXPECT_EQ(std::memcmp(&wide.g[i], &narrow.g[i], 4), 0) << i;
      EXPECT_EQ(std::memcmp(&wide.b[i], &narrow.b[i], 4), 0) << i;
    }
  }
  // Both kinds of sample are there.
  EXPECT_GT(transparent, 0);
  EXPECT_LT(transparent, total);
  // A batch wholly transparent (one transparent sample's position in every lane): no gradient is
  // taken, and the colours are zero on every target.
  SampleBatch probe{};
  positions(probe, 0);
  classifySamples(f.source, kBatch, probe);
  int at = 0;
  while (at < kBatch && probe.opacity[at] > 0) ++at;
  ASSERT_LT(at, kBatch);
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    SampleBatch b{};
    for (int i = 0; i < kBatch; ++i) b.x[i] = probe.x[at], b.y[i] = probe.y[at], b.z[i] = probe.z[at];
    for (int i = 0; i < kBatch; ++i) b.r[i] = b.g[i] = b.b[i] = -1;
    classifySamples(f.source, kBatch, b);
    for (int i = 0; i < kBatch; ++i) {
      EXPECT_EQ(b.opacity[i], 0.0f) << hwy::TargetName(target);
      EXPECT_EQ(b.r[i], 0.0f) << hwy::TargetName(target);
      EXPECT_EQ(b.g[i], 0.0f) << hwy::TargetName(target);
      EXPECT_EQ(b.b[i], 0.0f) << hwy::TargetName(target);
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

}  // namespace
}  // namespace sv::volume
