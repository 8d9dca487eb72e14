// The star catalogue (docs/lights.md#stars): the Yale Bright Star Catalogue as Debian's xplanet
// ships it (/usr/share/xplanet/stars/BSC) — one star a line, "Dec RA Mag", then a quoted name and
// numbers xplanet ignores; '#' starts a comment. An optional B−V colour index may follow the
// magnitude (xplanet's copy has none: its stars are white).
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <string_view>

#include "formats/reader.h"

namespace sv::formats {
namespace {

// Far more than any naked-eye catalogue (the BSC has 9 110 stars; Hipparcos 118 218).
constexpr size_t kMaxStars = size_t(1) << 20;
constexpr uint64_t kMaxCatalogBytes = uint64_t(1) << 26;

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The next number of `line` from `at`, skipping blanks; false at a non-number.
bool nextNumber(std::string_view line, size_t& at, double& out) {
  while (at < line.size() && isSpace(line[at])) ++at;
  if (at < line.size() && line[at] == '+') ++at;
  const char* begin = line.data() + at;
  const auto [end, ec] = std::from_chars(begin, line.data() + line.size(), out);
  if (ec != std::errc() || !std::isfinite(out)) return false;
  at += size_t(end - begin);
  return at == line.size() || isSpace(line[at]);
}

}  // namespace

// A star's colour from its B−V colour index: the black-body temperature by Ballesteros' formula,
// then the blackbody's linear sRGB chromaticity (a fit), scaled to a maximum component of 1.
Vec3 starColor(float bv) {
  bv = std::clamp(bv, -0.4f, 2.0f);
  const float temp = 4600 * (1 / (0.92f * bv + 1.7f) + 1 / (0.92f * bv + 0.62f));
  // Tanner Helland's fit of the Planckian locus (display values), decoded to linear.
  const float t = temp / 100;
  float r, g, b;
  if (t <= 66) {
    r = 255;
    g = 99.4708025861f * std::log(t) - 161.1195681661f;
    b = t <= 19 ? 0 : 138.5177312231f * std::log(t - 10) - 305.0447927307f;
  } else {
    r = 329.698727446f * std::pow(t - 60, -0.1332047592f);
    g = 288.1221695283f * std::pow(t - 60, -0.0755148492f);
    b = 255;
  }
  auto lin = [](float v) {
    const float c = std::clamp(v / 255, 0.0f, 1.0f);
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  };
  const Vec3 c{lin(r), lin(g), lin(b)};
  const float m = std::max({c.x, c.y, c.z, 1e-6f});
  return c * (1 / m);
}

Result<std::vector<Star>> parseStarCatalog(std::string_view text, const std::string& path) {
  std::vector<Star> stars;
  size_t lineNo = 0;
  for (size_t pos = 0; pos < text.size();) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++lineNo;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    size_t at = 0;
    while (at < line.size() && isSpace(line[at])) ++at;
    if (at == line.size()) continue;
    auto bad = [&](std::string what) {
      return Error{path, fmt::format("line {}", lineNo), std::move(what)};
    };
    double dec, ra, mag;
    if (!nextNumber(line, at, dec) || !nextNumber(line, at, ra) || !nextNumber(line, at, mag))
      return bad("expected 'declination right-ascension magnitude' (degrees, hours, magnitude)");
    if (!(dec >= -90 && dec <= 90)) return bad(fmt::format("declination {} is not in −90…90", dec));
    if (!(ra >= 0 && ra <= 24)) return bad(fmt::format("right ascension {} is not in 0…24 h", ra));
    if (!(mag >= -30 && mag <= 30)) return bad(fmt::format("magnitude {} is not in −30…30", mag));
    Star s;
    s.magnitude = float(mag);
    // An optional colour index before the name.
    size_t look = at;
    double bv;
    if (nextNumber(line, look, bv)) {
      if (!(bv >= -1 && bv <= 5)) return bad(fmt::format("colour index {} is not in −1…5", bv));
      s.color = starColor(float(bv));
    }
    const double d = dec * std::numbers::pi / 180, a = ra * std::numbers::pi / 12;
    s.direction = {float(std::cos(d) * std::cos(a)), float(std::cos(d) * std::sin(a)),
                   float(std::sin(d))};
    if (stars.size() == kMaxStars)
      return Error{path, "", fmt::format("more than {} stars", kMaxStars)};
    stars.push_back(s);
  }
  if (stars.empty()) return Error{path, "", "no stars in the catalogue"};
  return stars;
}

Result<std::vector<Star>> loadStarCatalog(const std::string& path) {
  Result<std::string> text = detail::readFile(path);
  if (!text.ok()) return text.error();
  if (text.value().size() > kMaxCatalogBytes)
    return Error{path, "",
                 fmt::format("{} bytes is larger than a star catalogue may be ({})",
                             text.value().size(), kMaxCatalogBytes)};
  return parseStarCatalog(text.value(), path);
}

}  // namespace sv::formats
