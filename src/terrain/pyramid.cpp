// Based on: SPEC §11 (max-LOD maps: level n − 1 the maximum of each 2×2 group, level 0 the whole
// map's; here with the minimum beside, and over the interpolated surface).
#include "terrain/pyramid.h"

#include <algorithm>
#include <cmath>

namespace sv::terrain {
namespace {

// The fraction of a cell's sample range the Catmull–Rom surface may overshoot it by (pyramid.h).
constexpr double kBicubicOvershoot = 9.0 / 32.0;

}  // namespace

Pyramid::Pyramid(const HeightField& field, Interpolation interp) : field_(&field), interp_(interp) {
  cellsX_ = field.width - 1;
  cellsY_ = field.height - 1;
  n_ = 1;
  while ((1 << n_) < cellsX_ || (1 << n_) < cellsY_) ++n_;
  sideX_.resize(size_t(n_) + 1);
  sideY_.resize(size_t(n_) + 1);
  for (int k = 0; k <= n_; ++k) {
    sideX_[size_t(k)] = (cellsX_ + nodeCells(k) - 1) / nodeCells(k);
    sideY_[size_t(k)] = (cellsY_ + nodeCells(k) - 1) / nodeCells(k);
  }
  // Level n − 1 from the table: node (I, J) covers cells 2I, 2I + 1 × 2J, 2J + 1, whose surface
  // reads samples 2I … 2I + 2 (bilinear) or 2I − 1 … 2I + 3 (bicubic), clamped to the table.
  const int a = interp == Interpolation::bicubic ? 1 : 0;
  const double e = interp == Interpolation::bicubic ? kBicubicOvershoot : 0.0;
  const int nx = sideX_[size_t(n_ - 1)], ny = sideY_[size_t(n_ - 1)];
  std::vector<double> lo(size_t(nx) * size_t(ny)), hi(lo.size());
  std::vector<uint16_t> rowMin(static_cast<size_t>(nx)), rowMax(static_cast<size_t>(nx));
  for (int J = 0; J < ny; ++J) {
    std::fill(rowMin.begin(), rowMin.end(), uint16_t(65535));
    std::fill(rowMax.begin(), rowMax.end(), uint16_t(0));
    const int j0 = std::max(2 * J - a, 0), j1 = std::min(2 * J + 2 + a, field.height - 1);
    for (int j = j0; j <= j1; ++j) {
      const uint16_t* row = field.q.data() + size_t(j) * size_t(field.width);
      for (int I = 0; I < nx; ++I) {
        const int i0 = std::max(2 * I - a, 0), i1 = std::min(2 * I + 2 + a, field.width - 1);
        uint16_t mn = rowMin[size_t(I)], mx = rowMax[size_t(I)];
        for (int i = i0; i <= i1; ++i) mn = std::min(mn, row[i]), mx = std::max(mx, row[i]);
        rowMin[size_t(I)] = mn;
        rowMax[size_t(I)] = mx;
      }
    }
    for (int I = 0; I < nx; ++I) {
      const double r = double(rowMax[size_t(I)]) - rowMin[size_t(I)];
      lo[size_t(J) * size_t(nx) + size_t(I)] = rowMin[size_t(I)] - e * r;
      hi[size_t(J) * size_t(nx) + size_t(I)] = rowMax[size_t(I)] + e * r;
    }
  }
  // The bounds' own 16-bit scale over their whole range (codes of the table, widened by the
  // overshoot), rounded outward so that a stored bound never cuts into the surface.
  const double codeLo = *std::min_element(lo.begin(), lo.end());
  const double codeHi = *std::max_element(hi.begin(), hi.end());
  const double span = std::max(codeHi - codeLo, 1.0);
  boundOffset_ = field.offset + field.scale * codeLo;
  boundScale_ = field.scale * span / 65535.0;
  const double toBound = 65535.0 / span;
  levels_.resize(size_t(n_));
  std::vector<Bound>& finest = levels_[size_t(n_ - 1)];
  finest.resize(lo.size());
  for (size_t k = 0; k < lo.size(); ++k)
    finest[k] = {uint16_t(std::clamp(std::floor((lo[k] - codeLo) * toBound), 0.0, 65535.0)),
                 uint16_t(std::clamp(std::ceil((hi[k] - codeLo) * toBound), 0.0, 65535.0))};
  // Coarser levels: min of minima, max of maxima of each 2×2 (nodes beyond the footprint absent).
  for (int k = n_ - 2; k >= 0; --k) {
    const std::vector<Bound>& fine = levels_[size_t(k) + 1];
    const int fx = sideX_[size_t(k) + 1], fy = sideY_[size_t(k) + 1];
    const int cx = sideX_[size_t(k)], cy = sideY_[size_t(k)];
    std::vector<Bound>& coarse = levels_[size_t(k)];
    coarse.assign(size_t(cx) * size_t(cy), Bound{65535, 0});
    for (int J = 0; J < cy; ++J)
      for (int I = 0; I < cx; ++I) {
        Bound b{65535, 0};
        for (int j = 2 * J; j < std::min(2 * J + 2, fy); ++j)
          for (int i = 2 * I; i < std::min(2 * I + 2, fx); ++i) {
            const Bound& f = fine[size_t(j) * size_t(fx) + size_t(i)];
            b.lo = std::min(b.lo, f.lo);
            b.hi = std::max(b.hi, f.hi);
          }
        coarse[size_t(J) * size_t(cx) + size_t(I)] = b;
      }
  }
  // The mean levels, each from the one above it: [1 2 1]/4 along x, then along y, rounded.
  means_.resize(size_t(n_));
  meanW_.resize(size_t(n_));
  meanH_.resize(size_t(n_));
  for (int k = n_ - 1; k >= 0; --k) {
    const MeanLevel fine = mean(k + 1);
    const int w = (fine.width - 1 + 1) / 2 + 1, h = (fine.height - 1 + 1) / 2 + 1;
    std::vector<uint32_t> rows(size_t(w) * size_t(fine.height));
    for (int j = 0; j < fine.height; ++j)
      for (int i = 0; i < w; ++i) {
        const int c = std::min(2 * i, fine.width - 1);
        rows[size_t(j) * size_t(w) + size_t(i)] = uint32_t(fine.code(std::max(c - 1, 0), j)) +
                                                  2u * fine.code(c, j) +
                                                  fine.code(std::min(c + 1, fine.width - 1), j);
      }
    std::vector<uint16_t>& out = means_[size_t(k)];
    out.resize(size_t(w) * size_t(h));
    for (int j = 0; j < h; ++j) {
      const int c = std::min(2 * j, fine.height - 1);
      const uint32_t* up = rows.data() + size_t(std::max(c - 1, 0)) * size_t(w);
      const uint32_t* mid = rows.data() + size_t(c) * size_t(w);
      const uint32_t* down = rows.data() + size_t(std::min(c + 1, fine.height - 1)) * size_t(w);
      for (int i = 0; i < w; ++i)
        out[size_t(j) * size_t(w) + size_t(i)] = uint16_t((up[i] + 2 * mid[i] + down[i] + 8) / 16);
    }
    meanW_[size_t(k)] = w;
    meanH_[size_t(k)] = h;
  }
  buildTops();
}

void Pyramid::buildTops() {
  if (interp_ == Interpolation::bicubic) {
    const HeightField& f = *field_;
    cellTops_.assign(size_t(cellsX_) * size_t(cellsY_) + 1, kNoTop);
    double h[4][4];
    for (int j = 0; j < cellsY_; ++j)
      for (int i = 0; i < cellsX_; ++i) {
        cellSamples(f, i, j, h);
        const double top = std::ceil(bezierTop(h));
        cellTops_[size_t(j) * size_t(cellsX_) + size_t(i)] =
            top < kNoTop ? uint16_t(std::max(top, 0.0)) : kNoTop;
      }
  }
  tops_.resize(size_t(n_) + 1);
  topW_.resize(size_t(n_) + 1);
  topH_.resize(size_t(n_) + 1);
  for (int k = 0; k <= n_; ++k) {
    const MeanLevel m = mean(k);
    const int w = (m.width - 1 + kTopCells - 1) / kTopCells;
    const int h = (m.height - 1 + kTopCells - 1) / kTopCells;
    topW_[size_t(k)] = w;
    topH_[size_t(k)] = h;
    std::vector<uint16_t>& top = tops_[size_t(k)];
    top.assign(size_t(w) * size_t(h) + 1, 0);
    if (k == n_ && !cellTops_.empty()) {  // the bicubic table: its cells' tops
      for (int j = 0; j < cellsY_; ++j)
        for (int i = 0; i < cellsX_; ++i) {
          uint16_t& t = top[size_t(j / kTopCells) * size_t(w) + size_t(i / kTopCells)];
          t = std::max(t, cellTops_[size_t(j) * size_t(cellsX_) + size_t(i)]);
        }
      continue;
    }
    // Per node column the highest sample of each row it reads, then per node over its rows.
    std::vector<uint16_t> rows(size_t(w) * size_t(m.height));
    for (int j = 0; j < m.height; ++j) {
      const uint16_t* row = m.q + size_t(j) * size_t(m.width);
      for (int I = 0; I < w; ++I) {
        uint16_t mx = 0;
        for (int i = I * kTopCells; i <= std::min((I + 1) * kTopCells, m.width - 1); ++i)
          mx = std::max(mx, row[i]);
        rows[size_t(j) * size_t(w) + size_t(I)] = mx;
      }
    }
    for (int J = 0; J < h; ++J)
      for (int j = J * kTopCells; j <= std::min((J + 1) * kTopCells, m.height - 1); ++j)
        for (int I = 0; I < w; ++I) {
          uint16_t& t = top[size_t(J) * size_t(w) + size_t(I)];
          t = std::max(t, rows[size_t(j) * size_t(w) + size_t(I)]);
        }
  }
}

Pyramid::TopLevel Pyramid::tops(int level) const {
  const size_t k = size_t(std::clamp(level, 0, n_));
  return {topW_[k], topH_[k], tops_[k].data()};
}

Pyramid::Range Pyramid::cell(int i, int j) const {
  const HeightField& f = *field_;
  const int a = interp_ == Interpolation::bicubic ? 1 : 0;
  double mn = 65535, mx = 0;
  for (int y = std::max(j - a, 0); y <= std::min(j + 1 + a, f.height - 1); ++y)
    for (int x = std::max(i - a, 0); x <= std::min(i + 1 + a, f.width - 1); ++x)
      mn = std::min<double>(mn, f.code(x, y)), mx = std::max<double>(mx, f.code(x, y));
  const double e = interp_ == Interpolation::bicubic ? kBicubicOvershoot * (mx - mn) : 0.0;
  return {f.offset + f.scale * (mn - e), f.offset + f.scale * (mx + e)};
}

Pyramid::Range Pyramid::node(int level, int i, int j) const {
  if (level >= n_) {
    if (i < 0 || j < 0 || i >= cellsX_ || j >= cellsY_) return {1, 0};
    return cell(i, j);
  }
  return range(level, i, i, j, j);
}

Pyramid::Range Pyramid::range(int level, int i0, int i1, int j0, int j1) const {
  const int sx = sideX_[size_t(level)], sy = sideY_[size_t(level)];
  i0 = std::max(i0, 0), j0 = std::max(j0, 0);
  i1 = std::min(i1, sx - 1), j1 = std::min(j1, sy - 1);
  if (i0 > i1 || j0 > j1) return {1, 0};
  const std::vector<Bound>& nodes = levels_[size_t(level)];
  uint16_t lo = 65535, hi = 0;
  for (int j = j0; j <= j1; ++j) {
    const Bound* row = nodes.data() + size_t(j) * size_t(sx);
    for (int i = i0; i <= i1; ++i) lo = std::min(lo, row[i].lo), hi = std::max(hi, row[i].hi);
  }
  return {boundOffset_ + boundScale_ * lo, boundOffset_ + boundScale_ * hi};
}

size_t Pyramid::bytes() const {
  size_t b = 0;
  for (const auto& l : levels_) b += l.size() * sizeof(Bound);
  for (const auto& l : means_) b += l.size() * sizeof(uint16_t);
  for (const auto& l : tops_) b += l.size() * sizeof(uint16_t);
  b += cellTops_.size() * sizeof(uint16_t);
  return b;
}

}  // namespace sv::terrain
