// Based on: SPEC §11 (height tables); issue 29 (terrain from DEM files: mosaics of tiles). What the
// height readers share (their placement's checks, the frames geographic tables are placed in) and
// the mosaic; the readers are heights_gdal.cpp (GDAL rasters) and heights_png.cpp (16-bit PNGs).
#include "formats/heights.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "synthvis/files.h"

namespace sv::formats {

GeoFrame ownFrame(const HeightField::Geographic& g, int width, int height) {
  const double degrees = g.radiansPerUnit * 180 / M_PI;
  return GeoFrame(GeoPoint{(g.lat0 - 0.5 * (height - 1) * g.dLat) * degrees,
                           (g.lon0 + 0.5 * (width - 1) * g.dLon) * degrees, 0});
}

void placeGeographic(const HeightField::Geographic& g, const GeoFrame& frame, HeightField& f) {
  const double degrees = g.radiansPerUnit * 180 / M_PI;
  f.originU = frame.east(g.lon0 * degrees);
  f.originV = frame.north(g.lat0 * degrees);
  f.spacingU = g.dLon * degrees * frame.metresPerDegreeEast();
  f.spacingV = g.dLat * degrees * frame.metresPerDegreeNorth();
}

namespace detail {

// Map positions and extents beyond this are not a ground (the Earth's circumference is 4·10⁷ m):
// they come from a broken file, and would lose the precision of the positions they are added to.
constexpr double kMaxExtent = 1e8;  // metres

bool finite(std::initializer_list<double> values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// The origin and spacing `f` has, against kMaxExtent; `source` names it.
std::optional<Error> checkPlacement(const HeightField& f, const std::string& source) {
  if (!finite({f.originU, f.originV, f.spacingU, f.spacingV}) || !(f.spacingU > 0) ||
      !(f.spacingV > 0))
    return Error{source, "",
                 fmt::format("sample spacing {} × {} m at origin ({}, {}) is not a positive, "
                             "finite placement",
                             f.spacingU, f.spacingV, f.originU, f.originV)};
  const double extent = std::max(
      {std::fabs(f.originU), std::fabs(f.eastU()), std::fabs(f.originV), std::fabs(f.southV())});
  if (!(extent < kMaxExtent))
    return Error{source, "",
                 fmt::format("map extent u {} … {}, v {} … {} m reaches beyond ±{:g} m", f.originU,
                             f.eastU(), f.southV(), f.originV, kMaxExtent)};
  return std::nullopt;
}

}  // namespace detail

Result<HeightField> loadHeights(const std::string& path, const PngPlacement& pngPlacement) {
  return core::lowerExtension(path) == ".png" ? loadPng16(path, pngPlacement) : loadGdal(path);
}

namespace {

// Geographic tiles converted to metres at one latitude, the union's centre (each loaded alone was
// converted at its own, which gives tiles in different rows different east–west spacings).
Result<std::vector<HeightField>> onOneLatitude(const std::vector<HeightField>& tiles) {
  double top = -1e300, bottom = 1e300;
  for (const HeightField& t : tiles) {
    if (t.geographic.on != tiles.front().geographic.on)
      return Error{t.source, "",
                   fmt::format("is {} but {} is not: a mosaic's tiles share one kind of grid",
                               t.geographic.on ? "geographic" : "projected", tiles.front().source)};
    top = std::max(top, t.geographic.lat0 * t.geographic.radiansPerUnit);
    bottom = std::min(bottom, (t.geographic.lat0 - (t.height - 1) * t.geographic.dLat) *
                                  t.geographic.radiansPerUnit);
  }
  const HeightField::Geographic& g = tiles.front().geographic;
  const double degrees = 180 / M_PI;
  const GeoFrame frame(
      GeoPoint{0.5 * (top + bottom) * degrees, g.lon0 * g.radiansPerUnit * degrees, 0});
  std::vector<HeightField> out = tiles;
  for (HeightField& t : out) placeGeographic(t.geographic, frame, t);
  return out;
}

}  // namespace

Result<HeightField> mosaic(const std::vector<HeightField>& given) {
  if (given.empty()) return Error{"", "", "a mosaic needs at least one tile"};
  std::vector<HeightField> replaced;
  if (std::any_of(given.begin(), given.end(),
                  [](const HeightField& t) { return t.geographic.on; })) {
    Result<std::vector<HeightField>> r = onOneLatitude(given);
    if (!r) return r.error();
    replaced = std::move(r.value());
  }
  const std::vector<HeightField>& tiles = replaced.empty() ? given : replaced;
  for (const HeightField& t : tiles) {
    if (t.width < 1 || t.height < 1 || t.q.size() != size_t(t.width) * size_t(t.height))
      return Error{t.source, "", "the tile's table does not match its size"};
    if (std::optional<Error> e = detail::checkPlacement(t, t.source)) return *e;
  }
  // Step 1: one grid, the first tile's: each tile's spacing the same (to 1e-9 relative), its
  // origin on the grid (to 1/1000 of a step); (ci, cj) is its sample (0, 0) in grid steps from
  // the first tile's, columns east and rows south.
  const HeightField& first = tiles.front();
  const double su = first.spacingU, sv = first.spacingV;
  std::vector<int64_t> ci(tiles.size()), cj(tiles.size());
  int64_t minI = 0, minJ = 0, maxI = 0, maxJ = 0;
  for (size_t t = 0; t < tiles.size(); ++t) {
    const HeightField& tile = tiles[t];
    if (std::fabs(tile.spacingU - su) > 1e-9 * su || std::fabs(tile.spacingV - sv) > 1e-9 * sv)
      return Error{tile.source, "",
                   fmt::format("spacing {} × {} m differs from {}'s {} × {} m: mosaic tiles must "
                               "share one grid",
                               tile.spacingU, tile.spacingV, first.source, su, sv)};
    // Bounded by checkPlacement's extents, but not the spacing: a step count beyond the largest
    // mosaic cannot be placed in one anyway.
    const double fi = (tile.originU - first.originU) / su, fj = (first.originV - tile.originV) / sv;
    if (!(std::fabs(fi) < 1e9 && std::fabs(fj) < 1e9) || std::fabs(fi - std::round(fi)) > 1e-3 ||
        std::fabs(fj - std::round(fj)) > 1e-3)
      return Error{tile.source, "",
                   fmt::format("origin ({}, {}) is {} × {} steps from {}'s, not on its grid",
                               tile.originU, tile.originV, fi, fj, first.source)};
    ci[t] = int64_t(std::llround(fi));
    cj[t] = int64_t(std::llround(fj));
    minI = std::min(minI, ci[t]);
    minJ = std::min(minJ, cj[t]);
    maxI = std::max(maxI, ci[t] + tile.width - 1);
    maxJ = std::max(maxJ, cj[t] + tile.height - 1);
  }
  const int64_t width = maxI - minI + 1, height = maxJ - minJ + 1;
  const std::string source = fmt::format("mosaic of {} tiles from {}", tiles.size(), first.source);
  if (width > kMaxHeightSide || height > kMaxHeightSide || width * height > kMaxHeightSamples)
    return Error{source, "",
                 fmt::format("the tiles span {} × {} samples, beyond the limit of {} a side", width,
                             height, kMaxHeightSide)};

  // Step 2: every tile's heights into the union (NaN where none lands), each shared sample
  // checked against the tile that wrote it first. Each tile's heights are within half its step
  // of the truth, so two tiles holding the same sample differ by at most the sum of their half
  // steps ≤ the coarser step; 1e-9 of the height is for the rounding of offset + scale·q.
  std::vector<double> values(size_t(width) * size_t(height),
                             std::numeric_limits<double>::quiet_NaN());
  std::vector<int32_t> writer(values.size(), -1);
  for (size_t t = 0; t < tiles.size(); ++t) {
    const HeightField& tile = tiles[t];
    for (int j = 0; j < tile.height; ++j) {
      const size_t row = size_t(cj[t] - minJ + j) * size_t(width) + size_t(ci[t] - minI);
      for (int i = 0; i < tile.width; ++i) {
        const double h = tile.at(i, j);
        const size_t k = row + size_t(i);
        if (writer[k] < 0) {
          values[k] = h;
          writer[k] = int32_t(t);
          continue;
        }
        const HeightField& other = tiles[size_t(writer[k])];
        const double tolerance = std::max(tile.scale, other.scale) + 1e-9 * std::fabs(h);
        if (std::fabs(h - values[k]) > tolerance)
          return Error{tile.source, "",
                       fmt::format("height {} m at map ({}, {}) disagrees with {}'s {} m where "
                                   "the tiles overlap",
                                   h, tile.originU + i * su, tile.originV - j * sv, other.source,
                                   values[k])};
      }
    }
  }

  // Step 3: requantized over the union's range, placed at the union's north-west sample.
  Result<HeightField> f = quantize(values, int(width), int(height), source);
  if (!f.ok()) return f;
  f->originU = first.originU + double(minI) * su;
  f->originV = first.originV - double(minJ) * sv;
  f->spacingU = su;
  f->spacingV = sv;
  if (first.geographic.on) {
    f->geographic = first.geographic;
    f->geographic.lon0 += double(minI) * first.geographic.dLon;
    f->geographic.lat0 -= double(minJ) * first.geographic.dLat;
  }
  return f;
}

}  // namespace sv::formats
