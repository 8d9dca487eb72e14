// Sub-pixel coverage masks from tables (SPEC §5, seed 000), read by the tile kernel when
// anti-aliasing; tests/raster/coverage_masks_test.cpp pins down the properties it relies on.
//
// A pixel carries N sample positions (a documented pattern per N). For one edge a mask of samples
// is read from a table indexed by the edge's slope and its distance to the pixel centre — the
// normalized a and c of SPEC §3.3 — and the signs of A and B; a polygon's mask is the AND of its
// edges' masks.
//
// Symbols. An edge is e(x, y) = a·x + b·y + c in pixel units with (x, y) relative to the pixel
// centre; inside is e ≥ 0. Normalized by |a| + |b| (SPEC §3.3): the slope t = |a| / (|a| + |b|)
// ∈ [0, 1] and the distance d = c / (|a| + |b|). A sample s = (sx, sy) ∈ (−½, ½)² lies at
// v = ±t·sx ± (1 − t)·sy + d from the edge, so |d| ≥ ½ decides the whole pixel and the table covers
// d ∈ (−½, ½) in kDistanceSteps cells and t ∈ [0, 1] in kSlopeSteps cells, per sign quadrant.
//
// Area masks (Schilling 1991; RASTER-NOTES "4×4 masks whose popcount is the exact area"). An
// entry holds k = round(N·A) samples, A being the area of the pixel inside the edge at the cell's
// centre — the k samples farthest inside it (largest v). So a pixel crossed by one edge is covered
// by its area to within 1/(2N) plus the table's error, where plain point samples are off by up to
// c·N^(−3/4) (the half-plane discrepancy: 0.31 for 4 samples, 0.07 for 64). Measured against
// ground truth this halves 16 samples' edge error (docs/quality.md). Where k differs from the
// number of samples truly inside, the extra (or missing) ones are those nearest the edge.
//
// Precision. Within a cell d moves by 1/(2·kDistanceSteps) and, through t, v by less than
// 1/(2·kSlopeSteps) (|∂v/∂t| = |sx ∓ sy| < 1); the area moves by at most twice that (the chord is
// at most √2 long, and the L1-normalized normal at least 1/√2 long): kAreaError.
//
// Complementarity (RASTER-NOTES pitfall 4). Only the cells with d > 0 are computed; the reversed
// edge's entry — opposite quadrant, mirrored distance cell — is set to the complement. Hence
// mask(e) AND mask(−e) = 0 and mask(e) OR mask(−e) = all samples, for every entry: shared edges of
// a mesh sum to full coverage, no seams. (At a vertex, several edges' masks meet and their AND is
// an approximation: a sample may end in no triangle or in two — tests/raster/antialias_test.cpp
// bounds it — and may even be claimed just beyond the triangle's tip, which the kernel's bounding
// box cuts off.)
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sv::raster {

// Sample offsets from the pixel centre, in pixels, each coordinate in (−½, ½) and a multiple of
// 1/256 (exact in binary, which the complementarity argument needs).
struct SamplePattern {
  int count = 0;
  std::vector<std::array<double, 2>> offsets;
};

// The patterns: 1 (the centre), 4 (rotated grid), 8 and 16 (the standard Direct3D multisample
// positions; 16 is n-rooks — one sample per row and column of its 16×16 grid — shifted by 1/32 px
// so that no sample lies on the pixel's border), 64 (an 8×8 grid jittered within its cells by a
// fixed seeded sequence, positions on a 1/256 grid). Returns nullptr for other counts.
const SamplePattern* samplePattern(int count);

class EdgeMaskTable {
 public:
  // 32 × 128 cells: 67 KB of 32-bit masks per table. 64 × 256 cut 64 samples' edge error by 4 %
  // more at no gain in speed (docs/quality.md, docs/performance.md).
  static constexpr int kSlopeSteps = 32;
  static constexpr int kDistanceSteps = 128;
  static constexpr double kAreaError = 2 * (0.5 / kSlopeSteps + 0.5 / kDistanceSteps);
  // A row holds one (quadrant, slope): [0] = no sample (d ≤ −½), [1 + j] = distance cell j,
  // [kRowEntries − 1] = every sample (d ≥ ½) — so the kernel indexes it without range checks.
  static constexpr int kRowEntries = kDistanceSteps + 2;
  static constexpr int kRows = 4 * kSlopeSteps + 1;  // the last row: constant edges, below

  explicit EdgeMaskTable(const SamplePattern& pattern);

  int sampleCount() const { return count_; }
  uint64_t allSamples() const { return all_; }

  // The mask for the edge a·x + b·y + c ≥ 0 (pixel units, relative to the pixel centre).
  // (a, b) = (0, 0) is a constant edge: every sample when c > 0, none otherwise (the tie rule of a
  // zero normal gives the boundary to neither side).
  uint64_t mask(double a, double b, double c) const;

  // The table itself: entry(quadrant, slope, distance cell); quadrant bit 0 = a negative, bit 1 =
  // b negative (a zero coefficient counts with the sign of the other one, so that reversing an
  // edge flips both bits).
  uint64_t entry(int quadrant, int slope, int distance) const {
    return table_[size_t(rowIndex(quadrant, slope)) * kRowEntries + 1 + size_t(distance)];
  }
  static int rowIndex(int quadrant, int slope) { return quadrant * kSlopeSteps + slope; }
  // The row for (0, 0): entries up to the d = 0 cell (index kRowEntries/2 − 1) are empty, the rest
  // full, so an integer edge value E gives every sample iff E > 0 (tests/raster shows the index).
  static constexpr int kConstantRow = kRows - 1;
  // Row r's kRowEntries masks, for the kernel.
  const uint64_t* row(int r) const { return table_.data() + size_t(r) * kRowEntries; }

 private:
  int count_;
  uint64_t all_;
  std::vector<uint64_t> table_;
};

// The tables the tile kernel gathers from, per sample count: the EdgeMaskTable's rows as 32-bit
// words (word w holds samples 32·w … 32·w + 31; one word up to 32 samples, two for 64).
struct CoverageTables {
  int samples = 0;
  int words = 0;
  const SamplePattern* pattern = nullptr;
  int32_t offsetX[64] = {}, offsetY[64] = {};  // the pattern's offsets in 1/256 pixel
  // Shade a partly covered pixel at the centroid of its covered samples rather than at its centre
  // (shadeBlockSamples, samplesPassing in raster/*-inl.h): with 16 and 64 samples, where it cuts the edge error of small Gouraud
  // triangles by 4 %; with 4 and 8 it changes it by under 1 % and costs more than it gives
  // (docs/quality.md, docs/performance.md "Anti-aliasing").
  bool centroid = false;
  EdgeMaskTable table;
  std::vector<uint32_t> word[2];  // kRows × kRowEntries each

  // Built once per count on first use (thread-safe); nullptr for a count without a pattern.
  static const CoverageTables* forCount(int samples);

 private:
  explicit CoverageTables(const SamplePattern& p);
};

}  // namespace sv::raster
