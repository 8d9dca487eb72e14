// Based on: SPEC §5 (seed 000: masks from a table indexed by distance and slope); Schilling 1991
// (A new simple and efficient antialiasing with subpixel masks: masks chosen by area); Microsoft,
// D3D11 standard multisample patterns (D3D11_STANDARD_MULTISAMPLE_PATTERN) for 8 and 16 samples.
#include "raster/coverage_masks.h"

#include <algorithm>
#include <cmath>

#include "geometry/setup.h"

namespace sv::raster {
namespace {

SamplePattern fromSixteenths(std::initializer_list<std::array<int, 2>> points, double shift) {
  SamplePattern p;
  for (const auto& q : points) p.offsets.push_back({q[0] / 16.0 + shift, q[1] / 16.0 + shift});
  p.count = int(p.offsets.size());
  return p;
}

SamplePattern jittered8x8() {
  SamplePattern p;
  uint32_t state = 0x9E3779B9u;  // fixed: the pattern is part of the format
  auto next = [&] {
    state = state * 1664525u + 1013904223u;  // Numerical Recipes LCG
    return (state >> 8) % 30;
  };
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const uint32_t u = 1 + next(), v = 1 + next();  // 1…30 of 32 steps inside the cell
      p.offsets.push_back({(32.0 * i + u) / 256.0 - 0.5, (32.0 * j + v) / 256.0 - 0.5});
    }
  p.count = 64;
  return p;
}

// The area of the pixel (−½, ½)² where nx·x + ny·y + d ≥ 0: the square clipped by the line
// (Sutherland–Hodgman), then the shoelace formula.
double halfPlaneArea(double nx, double ny, double d) {
  const double square[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
  double poly[8][2];
  int n = 0;
  for (int i = 0; i < 4; ++i) {
    const double* p = square[i];
    const double* q = square[(i + 1) % 4];
    const double ep = nx * p[0] + ny * p[1] + d, eq = nx * q[0] + ny * q[1] + d;
    if (ep >= 0) {
      poly[n][0] = p[0];
      poly[n++][1] = p[1];
    }
    if ((ep >= 0) != (eq >= 0)) {
      const double u = ep / (ep - eq);
      poly[n][0] = p[0] + u * (q[0] - p[0]);
      poly[n++][1] = p[1] + u * (q[1] - p[1]);
    }
  }
  double area = 0;
  for (int i = 0; i < n; ++i)
    area += poly[i][0] * poly[(i + 1) % n][1] - poly[(i + 1) % n][0] * poly[i][1];
  return std::fabs(area) / 2;
}

}  // namespace

const SamplePattern* samplePattern(int count) {
  static const SamplePattern one{1, {{0.0, 0.0}}};
  static const SamplePattern four =
      fromSixteenths({{-2, -6}, {6, -2}, {-6, 2}, {2, 6}}, 0.0);  // rotated grid
  static const SamplePattern eight =
      fromSixteenths({{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, -7}, {7, 7}}, 0.0);
  static const SamplePattern sixteen = fromSixteenths({{1, 1},
                                                       {-1, -3},
                                                       {-3, 2},
                                                       {4, -1},
                                                       {-5, -2},
                                                       {2, 5},
                                                       {5, 3},
                                                       {3, -5},
                                                       {-2, 6},
                                                       {0, -7},
                                                       {-4, -6},
                                                       {-6, 4},
                                                       {-8, 0},
                                                       {7, -4},
                                                       {6, 7},
                                                       {-7, -8}},
                                                      1.0 / 32);
  static const SamplePattern sixtyFour = jittered8x8();
  switch (count) {
    case 1:
      return &one;
    case 4:
      return &four;
    case 8:
      return &eight;
    case 16:
      return &sixteen;
    case 64:
      return &sixtyFour;
    default:
      return nullptr;
  }
}

EdgeMaskTable::EdgeMaskTable(const SamplePattern& pattern)
    : count_(pattern.count),
      all_(pattern.count >= 64 ? ~uint64_t(0) : (uint64_t(1) << pattern.count) - 1),
      table_(size_t(kRows) * kRowEntries) {
  for (int q = 0; q < 4; ++q)
    for (int i = 0; i < kSlopeSteps; ++i) {
      uint64_t* row = table_.data() + size_t(rowIndex(q, i)) * kRowEntries;
      uint64_t* mirror = table_.data() + size_t(rowIndex(q ^ 3, i)) * kRowEntries;
      row[0] = 0;
      row[kRowEntries - 1] = all_;
      // The cells with d > 0; each one's reversed edge, (q ^ 3, i, mirrored cell), gets the
      // complement — exact complements by construction.
      for (int j = kDistanceSteps / 2; j < kDistanceSteps; ++j) {
        const double t = (i + 0.5) / kSlopeSteps;
        const double nx = (q & 1) ? -t : t, ny = (q & 2) ? -(1 - t) : (1 - t);
        const double d = (j + 0.5) / kDistanceSteps - 0.5;
        // The k = round(N·A) samples farthest inside (largest v; ties by sample index).
        std::vector<std::pair<double, int>> v(static_cast<size_t>(count_));
        for (int s = 0; s < count_; ++s)
          v[size_t(s)] = {
              nx * pattern.offsets[size_t(s)][0] + ny * pattern.offsets[size_t(s)][1] + d, s};
        const int k = int(std::lround(halfPlaneArea(nx, ny, d) * count_));
        std::stable_sort(v.begin(), v.end(),
                         [](const auto& a, const auto& b) { return a.first > b.first; });
        uint64_t m = 0;
        for (int s = 0; s < k; ++s) m |= uint64_t(1) << v[size_t(s)].second;
        row[1 + j] = m;
        mirror[1 + (kDistanceSteps - 1 - j)] = ~m & all_;
      }
    }
  uint64_t* constant = table_.data() + size_t(kConstantRow) * kRowEntries;
  for (int j = 0; j < kRowEntries; ++j) constant[j] = j < kRowEntries / 2 ? 0 : all_;
}

uint64_t EdgeMaskTable::mask(double a, double b, double c) const {
  const double norm = std::fabs(a) + std::fabs(b);
  if (norm == 0) return c > 0 ? all_ : 0;
  const double d = c / norm;
  if (d >= 0.5) return all_;  // every sample is within ½ (L1) of the centre
  if (d <= -0.5) return 0;
  const int quadrant = int(a < 0 || (a == 0 && b < 0)) | int(b < 0 || (b == 0 && a < 0)) << 1;
  const int slope = std::min(kSlopeSteps - 1, int(std::fabs(a) / norm * kSlopeSteps));
  // Distance cells mirror around 0 so that −d finds the mirrored cell; d = 0 (an edge through the
  // centre) goes by the fill rule, antisymmetric in the normal.
  int distance;
  if (d > 0 || (d == 0 && geometry::ownsBoundary(a, b)))
    distance = std::min(kDistanceSteps - 1, kDistanceSteps / 2 + int(d * kDistanceSteps));
  else
    distance = std::max(0, kDistanceSteps / 2 - 1 - int(-d * kDistanceSteps));
  return entry(quadrant, slope, distance);
}

CoverageTables::CoverageTables(const SamplePattern& p)
    : samples(p.count),
      words(p.count > 32 ? 2 : 1),
      pattern(&p),
      centroid(p.count >= 16),
      table(p) {
  for (int s = 0; s < p.count; ++s) {
    offsetX[s] = int32_t(std::lround(p.offsets[size_t(s)][0] * 256));  // exact: 1/256 grid
    offsetY[s] = int32_t(std::lround(p.offsets[size_t(s)][1] * 256));
  }
  for (int w = 0; w < words; ++w) {
    word[w].resize(size_t(EdgeMaskTable::kRows) * EdgeMaskTable::kRowEntries);
    for (int r = 0; r < EdgeMaskTable::kRows; ++r)
      for (int j = 0; j < EdgeMaskTable::kRowEntries; ++j)
        word[w][size_t(r) * EdgeMaskTable::kRowEntries + size_t(j)] =
            uint32_t(table.row(r)[j] >> (32 * w));
  }
}

const CoverageTables* CoverageTables::forCount(int samples) {
  static const CoverageTables four(*samplePattern(4)), eight(*samplePattern(8)),
      sixteen(*samplePattern(16)), sixtyFour(*samplePattern(64));
  switch (samples) {
    case 4:
      return &four;
    case 8:
      return &eight;
    case 16:
      return &sixteen;
    case 64:
      return &sixtyFour;
    default:
      return nullptr;
  }
}

}  // namespace sv::raster
