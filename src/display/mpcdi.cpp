// MPCDI files: zip + mpcdi.xml + PFM warps + PNG blend maps (display/mpcdi.h; docs/display.md).
// Based on: VESA MPCDI standard v1.0 (2013) and v2.0 (2015): the XML tree <MPCDI profile level
// version date> / <display> / <buffer id Xresolution Yresolution> / <region id Xresolution
// Yresolution x y xsize ysize> with <frustum> and <coordinateFrame>, and <files> / <fileset
// region> with <geometryWarpFile>, <alphaMap>, <betaMap>, <distortionMap>, each with its <path>;
// PFM after Debevec's Portable Float Map (rows bottom to top, the sign of the scale giving the
// byte order). Element and attribute names are matched without regard to case: writers differ
// (Xresolution, xResolution; fileset, fileSet).
#include "display/mpcdi.h"

#include <fmt/format.h>
#include <strings.h>
#include <tinyxml2.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <set>

#include "display/zip_memory.h"
#include "synthvis/files.h"
#include "texture/png.h"

namespace sv::display {
namespace {

using detail::Problem;
constexpr const char* kXml = "mpcdi.xml";

[[noreturn]] void fail(std::string position, std::string message) {
  throw Problem{std::move(position), std::move(message)};
}

// ---------------------------------------------------------------------------------------------
// PFM

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// The next whitespace-delimited token of the header at `at` (skipping whitespace before it), at
// most `longest` characters.
std::string_view token(const std::string& s, size_t& at, size_t longest, const std::string& name,
                       const char* what) {
  while (at < s.size() && isSpace(s[at])) ++at;
  const size_t begin = at;
  while (at < s.size() && !isSpace(s[at]) && at - begin <= longest) ++at;
  if (at == begin) fail(name, fmt::format("PFM header: missing the {}", what));
  if (at - begin > longest || at >= s.size())
    fail(name, fmt::format("PFM header: malformed {}", what));
  return std::string_view(s).substr(begin, at - begin);
}

FloatMap readPfm(const std::string& s, const std::string& name, const MpcdiLimits& limits) {
  if (s.size() < 3 || s[0] != 'P' || (s[1] != 'F' && s[1] != 'f') || !isSpace(s[2]))
    fail(name, "not a PFM file (it must begin with \"PF\" or \"Pf\")");
  FloatMap m;
  m.channels = s[1] == 'F' ? 3 : 1;
  size_t at = 2;
  auto integer = [&](const char* what) {
    const std::string_view t = token(s, at, 9, name, what);
    int v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size())
      fail(name, fmt::format("PFM header: the {} is not a whole number", what));
    return v;
  };
  m.width = integer("width");
  m.height = integer("height");
  const std::string_view scaleText = token(s, at, 32, name, "scale");
  double scale = 0;
  const auto r = std::from_chars(scaleText.data(), scaleText.data() + scaleText.size(), scale);
  if (r.ec != std::errc() || r.ptr != scaleText.data() + scaleText.size() || !std::isfinite(scale) ||
      scale == 0)
    fail(name, "PFM header: the scale must be a non-zero number");
  ++at;  // exactly one whitespace character ends the header
  if (m.width < 1 || m.height < 1 || m.width > limits.maxSide || m.height > limits.maxSide)
    fail(name, fmt::format("PFM of {} × {} samples: each side must be 1 … {}", m.width, m.height,
                           limits.maxSide));
  const uint64_t samples = uint64_t(m.width) * uint64_t(m.height);
  if (samples > limits.maxSamples)
    fail(name, fmt::format("PFM of {} × {} samples: more than {}", m.width, m.height,
                           limits.maxSamples));
  const uint64_t bytes = samples * uint64_t(m.channels) * 4;
  if (s.size() - at != bytes)
    fail(name, fmt::format("PFM of {} × {} × {} floats needs {} bytes of samples, the file has {}",
                           m.width, m.height, m.channels, bytes, s.size() - at));
  const bool swap = (scale > 0) != (std::endian::native == std::endian::big);
  m.values.resize(size_t(samples) * size_t(m.channels));
  const size_t row = size_t(m.width) * size_t(m.channels);
  for (int y = 0; y < m.height; ++y) {
    // The file's first row is the bottom one.
    float* dst = m.values.data() + size_t(m.height - 1 - y) * row;
    std::memcpy(dst, s.data() + at + size_t(y) * row * 4, row * 4);
    if (swap)
      for (size_t i = 0; i < row; ++i) dst[i] = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<uint32_t>(dst[i])));
  }
  return m;
}

std::string writePfm(const FloatMap& m) {
  std::string out = fmt::format("{}\n{} {}\n-1.0\n", m.channels == 3 ? "PF" : "Pf", m.width, m.height);
  const size_t row = size_t(m.width) * size_t(m.channels);
  const size_t header = out.size();
  out.resize(header + row * size_t(m.height) * 4);
  for (int y = 0; y < m.height; ++y) {
    const float* src = m.values.data() + size_t(m.height - 1 - y) * row;
    char* dst = out.data() + header + size_t(y) * row * 4;
    if constexpr (std::endian::native == std::endian::little) {
      std::memcpy(dst, src, row * 4);
    } else {
      for (size_t i = 0; i < row; ++i) {
        const uint32_t v = __builtin_bswap32(std::bit_cast<uint32_t>(src[i]));
        std::memcpy(dst + i * 4, &v, 4);
      }
    }
  }
  return out;
}

// A warp sample's state: finite x and y (valid), the invalid marker (x and y NaN), or neither.
enum class Sample { valid, invalid, bad };
Sample classify(const float* v) {
  const bool nx = std::isnan(v[0]), ny = std::isnan(v[1]);
  if (nx && ny) return Sample::invalid;
  if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) return Sample::valid;
  return Sample::bad;
}

void checkWarp(const FloatMap& m, const std::string& entry) {
  if (m.channels != 3)
    fail(entry, "a geometry warp must have three components per sample (\"PF\", not \"Pf\")");
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x)
      if (classify(m.at(x, y)) == Sample::bad)
        fail(entry, fmt::format("warp sample ({}, {}) is ({}, {}, {}): not finite, and not the "
                                "invalid marker (x and y both NaN)",
                                x, y, m.at(x, y)[0], m.at(x, y)[1], m.at(x, y)[2]));
}

void checkFinite(const FloatMap& m, const std::string& entry) {
  for (size_t i = 0; i < m.values.size(); ++i)
    if (!std::isfinite(m.values[i]))
      fail(entry, fmt::format("value {} of the map is not finite", i));
}

// ---------------------------------------------------------------------------------------------
// XML reading

std::string lineOf(const tinyxml2::XMLElement* e) { return fmt::format("{}:{}", kXml, e->GetLineNum()); }

bool same(const char* a, const char* b) { return strcasecmp(a, b) == 0; }

const tinyxml2::XMLElement* child(const tinyxml2::XMLElement* e, const char* name) {
  for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement())
    if (same(c->Name(), name)) return c;
  return nullptr;
}
const tinyxml2::XMLElement* required(const tinyxml2::XMLElement* e, const char* name) {
  const tinyxml2::XMLElement* c = child(e, name);
  if (!c) fail(lineOf(e), fmt::format("<{}> has no <{}>", e->Name(), name));
  return c;
}
const char* attribute(const tinyxml2::XMLElement* e, const char* name) {
  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
    if (same(a->Name(), name)) return a->Value();
  return nullptr;
}

std::string_view trimmed(const char* text) {
  std::string_view s = text ? text : "";
  while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  return s;
}

double number(const tinyxml2::XMLElement* at, std::string_view text, const std::string& what) {
  double v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() || !std::isfinite(v))
    fail(lineOf(at), fmt::format("{}: '{}' is not a finite number", what, text));
  return v;
}
int whole(const tinyxml2::XMLElement* at, std::string_view text, const std::string& what, int lo,
          int hi) {
  int v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() || v < lo || v > hi)
    fail(lineOf(at), fmt::format("{}: '{}' is not a whole number in {} … {}", what, text, lo, hi));
  return v;
}
double numberAttribute(const tinyxml2::XMLElement* e, const char* name) {
  const char* v = attribute(e, name);
  if (!v) fail(lineOf(e), fmt::format("<{}> has no {} attribute", e->Name(), name));
  return number(e, trimmed(v), name);
}
int resolutionAttribute(const tinyxml2::XMLElement* e, const char* name, const MpcdiLimits& l,
                        bool needed) {
  const char* v = attribute(e, name);
  if (!v) {
    if (needed) fail(lineOf(e), fmt::format("<{}> has no {} attribute", e->Name(), name));
    return 0;
  }
  return whole(e, trimmed(v), name, 1, l.maxSide);
}
double numberText(const tinyxml2::XMLElement* e, const char* name) {
  const tinyxml2::XMLElement* c = required(e, name);
  return number(c, trimmed(c->GetText()), name);
}
std::string text(const tinyxml2::XMLElement* e, const char* name, const std::string& fallback) {
  const tinyxml2::XMLElement* c = child(e, name);
  return c ? std::string(trimmed(c->GetText())) : fallback;
}

// What is wrong with a frustum, or nothing: the reader's and the writer's one rule.
std::string frustumProblem(const MpcdiFrustum& f) {
  const Orientation& o = f.orientation;
  const Window& w = f.window;
  for (double a : {o.yawDegrees, o.pitchDegrees, o.rollDegrees})
    if (!std::isfinite(a)) return "frustum: yaw, pitch and roll must be finite";
  for (double a : {w.leftDegrees, w.rightDegrees, w.downDegrees, w.upDegrees})
    if (!(a > -90 && a < 90)) return "frustum angles must be in (−90, 90) degrees";
  if (!(w.leftDegrees < w.rightDegrees) || !(w.downDegrees < w.upDegrees))
    return "frustum: leftAngle must be less than rightAngle, downAngle less than upAngle";
  return {};
}

// Whether a region's place lies within its buffer (to a millionth, for sizes written as decimals).
bool withinBuffer(const MpcdiRegion& r) {
  return r.x >= 0 && r.y >= 0 && r.xSize > 0 && r.ySize > 0 && r.x + r.xSize <= 1 + 1e-6 &&
         r.y + r.ySize <= 1 + 1e-6;
}
constexpr const char* kOutsideBuffer =
    "the region must lie within its buffer (x, y ≥ 0, sizes > 0, x + xsize and y + ysize ≤ 1)";

// The element's id attribute, which must be present, not empty, and not among `seen`.
std::string uniqueId(const tinyxml2::XMLElement* e, std::set<std::string>& seen) {
  const char* id = attribute(e, "id");
  if (!id || !*id) fail(lineOf(e), fmt::format("<{}> has no id", e->Name()));
  if (!seen.insert(id).second) fail(lineOf(e), fmt::format("duplicate {} id '{}'", e->Name(), id));
  return id;
}

MpcdiFrustum readFrustum(const tinyxml2::XMLElement* e) {
  MpcdiFrustum f;
  f.orientation.yawDegrees = numberText(e, "yaw");
  f.orientation.pitchDegrees = numberText(e, "pitch");
  f.orientation.rollDegrees = numberText(e, "roll");
  f.window.leftDegrees = numberText(e, "leftAngle");
  f.window.rightDegrees = numberText(e, "rightAngle");
  f.window.downDegrees = numberText(e, "downAngle");
  f.window.upDegrees = numberText(e, "upAngle");
  if (const std::string problem = frustumProblem(f); !problem.empty()) fail(lineOf(e), problem);
  return f;
}

MpcdiCoordinateFrame readFrame(const tinyxml2::XMLElement* e) {
  MpcdiCoordinateFrame f;
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    f.pos[i] = numberText(e, fmt::format("pos{}", axes[i]).c_str());
    f.yaw[i] = numberText(e, fmt::format("yaw{}", axes[i]).c_str());
    f.pitch[i] = numberText(e, fmt::format("pitch{}", axes[i]).c_str());
    f.roll[i] = numberText(e, fmt::format("roll{}", axes[i]).c_str());
  }
  return f;
}

std::string pathOf(const tinyxml2::XMLElement* e) {
  const std::string p(trimmed(required(e, "path")->GetText()));
  if (p.empty()) fail(lineOf(e), fmt::format("<{}>: empty <path>", e->Name()));
  return p;
}

BlendMap readBlend(detail::ZipReader& zip, const tinyxml2::XMLElement* e, const std::string& path,
                   const MpcdiLimits& limits) {
  if (const tinyxml2::XMLElement* c = child(e, "componentDepth"))
    if (whole(c, trimmed(c->GetText()), "componentDepth", 1, 4) != 1)
      fail(lineOf(c), "componentDepth: only greyscale (1) blend maps are supported");
  const std::string bytes = zip.read(path, limits.maxEntryBytes);
  texture::PngLimits pl;
  pl.maxSide = limits.maxSide;
  pl.maxPixels = int64_t(limits.maxSamples);
  Result<texture::PngGrey> png = texture::decodePngGrey(bytes.data(), bytes.size(), path, pl);
  if (!png.ok()) fail(path, png.error().message);
  if (const tinyxml2::XMLElement* c = child(e, "bitDepth")) {
    const int depth = whole(c, trimmed(c->GetText()), "bitDepth", 1, 16);
    if (depth != png->bitDepth)
      fail(lineOf(c), fmt::format("bitDepth {} but {} is a {}-bit PNG", depth, path, png->bitDepth));
  }
  BlendMap b;
  b.width = png->width;
  b.height = png->height;
  b.bitDepth = png->bitDepth;
  b.codes = std::move(png->samples);
  return b;
}

FloatMap readMap(detail::ZipReader& zip, const std::string& path, const MpcdiLimits& limits) {
  return readPfm(zip.read(path, limits.maxEntryBytes), path, limits);
}

void readFileset(detail::ZipReader& zip, const tinyxml2::XMLElement* e, MpcdiRegion& r,
                 const MpcdiLimits& limits) {
  const tinyxml2::XMLElement* warp = required(e, "geometryWarpFile");
  r.warpPath = pathOf(warp);
  r.geometricUnit = text(warp, "geometricUnit", r.geometricUnit);
  r.interpolation = text(warp, "interpolation", r.interpolation);
  r.originOf3DData = text(warp, "originOf3DData", r.originOf3DData);
  r.warp = readMap(zip, r.warpPath, limits);
  checkWarp(r.warp, r.warpPath);
  if (const tinyxml2::XMLElement* a = child(e, "alphaMap")) {
    r.alphaPath = pathOf(a);
    if (child(a, "gammaEmbedded")) {
      r.alphaGammaEmbedded = numberText(a, "gammaEmbedded");
      if (!(r.alphaGammaEmbedded > 0)) fail(lineOf(a), "gammaEmbedded must be positive");
    }
    r.alpha = readBlend(zip, a, r.alphaPath, limits);
  }
  if (const tinyxml2::XMLElement* b = child(e, "betaMap")) {
    r.betaPath = pathOf(b);
    r.beta = readBlend(zip, b, r.betaPath, limits);
  }
  if (const tinyxml2::XMLElement* d = child(e, "distortionMap")) {
    r.distortionPath = pathOf(d);
    r.distortion = readMap(zip, r.distortionPath, limits);
    checkFinite(*r.distortion, r.distortionPath);
  }
}

Mpcdi readArchive(const std::string& bytes, const MpcdiLimits& limits) {
  detail::ZipReader zip(bytes, limits.maxEntries);
  if (!zip.has(kXml)) fail("", "the archive has no mpcdi.xml");
  const std::string xml = zip.read(kXml, limits.maxXmlBytes);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS)
    fail(fmt::format("{}:{}", kXml, doc.ErrorLineNum()),
         fmt::format("malformed XML ({})", tinyxml2::XMLDocument::ErrorIDToName(doc.ErrorID())));
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (!root || !same(root->Name(), "MPCDI")) fail(kXml, "the root element is not <MPCDI>");

  Mpcdi m;
  const char* profile = attribute(root, "profile");
  if (!profile) fail(lineOf(root), "<MPCDI> has no profile attribute");
  const std::string_view p = trimmed(profile);
  if (p == "2d") m.profile = MpcdiProfile::media2d;
  else if (p == "3d") m.profile = MpcdiProfile::simulation3d;
  else if (p == "a3" || p == "sl")
    fail(lineOf(root), fmt::format("profile '{}' is not supported (only 2d and 3d)", p));
  else fail(lineOf(root), fmt::format("unknown profile '{}'", p));
  // MPCDI 1.0 has level; 2.0 splits it into geometry and color levels.
  const char* level = attribute(root, "level");
  if (!level) level = attribute(root, "geometry");
  if (!level) fail(lineOf(root), "<MPCDI> has no level (or geometry) attribute");
  m.level = whole(root, trimmed(level), "level", 1, 4);
  if (const char* v = attribute(root, "version")) m.version = v;
  if (const char* d = attribute(root, "date")) m.date = d;

  const tinyxml2::XMLElement* display = required(root, "display");
  std::set<std::string> bufferIds, regionIds;
  int regions = 0;
  for (const tinyxml2::XMLElement* b = display->FirstChildElement(); b; b = b->NextSiblingElement()) {
    if (!same(b->Name(), "buffer")) continue;
    MpcdiBuffer buffer;
    buffer.id = uniqueId(b, bufferIds);
    buffer.xResolution = resolutionAttribute(b, "Xresolution", limits, false);
    buffer.yResolution = resolutionAttribute(b, "Yresolution", limits, false);
    for (const tinyxml2::XMLElement* e = b->FirstChildElement(); e; e = e->NextSiblingElement()) {
      if (!same(e->Name(), "region")) continue;
      if (++regions > limits.maxRegions)
        fail(lineOf(e), fmt::format("more than {} regions", limits.maxRegions));
      MpcdiRegion r;
      r.id = uniqueId(e, regionIds);
      r.xResolution = resolutionAttribute(e, "Xresolution", limits, true);
      r.yResolution = resolutionAttribute(e, "Yresolution", limits, true);
      r.x = numberAttribute(e, "x");
      r.y = numberAttribute(e, "y");
      r.xSize = numberAttribute(e, "xsize");
      r.ySize = numberAttribute(e, "ysize");
      if (!withinBuffer(r)) fail(lineOf(e), kOutsideBuffer);
      if (const tinyxml2::XMLElement* f = child(e, "frustum")) r.frustum = readFrustum(f);
      else if (m.profile == MpcdiProfile::simulation3d)
        fail(lineOf(e), fmt::format("region '{}' has no <frustum> (the 3d profile needs one)", r.id));
      if (const tinyxml2::XMLElement* f = child(e, "coordinateFrame")) r.coordinateFrame = readFrame(f);
      buffer.regions.push_back(std::move(r));
    }
    m.buffers.push_back(std::move(buffer));
    if (m.buffers.size() > size_t(limits.maxRegions))
      fail(lineOf(b), fmt::format("more than {} buffers", limits.maxRegions));
  }

  // <files>: one <fileset> per region, keyed by the region's id.
  const tinyxml2::XMLElement* files = required(root, "files");
  std::set<std::string> done;
  for (const tinyxml2::XMLElement* f = files->FirstChildElement(); f; f = f->NextSiblingElement()) {
    if (!same(f->Name(), "fileset")) continue;
    const char* rid = attribute(f, "region");
    if (!rid) fail(lineOf(f), "<fileset> has no region attribute");
    MpcdiRegion* target = nullptr;
    for (MpcdiBuffer& b : m.buffers)
      for (MpcdiRegion& r : b.regions)
        if (r.id == rid) target = &r;
    if (!target) fail(lineOf(f), fmt::format("<fileset> for unknown region '{}'", rid));
    if (!done.insert(rid).second) fail(lineOf(f), fmt::format("second <fileset> for region '{}'", rid));
    readFileset(zip, f, *target, limits);
  }
  for (const MpcdiBuffer& b : m.buffers)
    for (const MpcdiRegion& r : b.regions)
      if (!done.count(r.id)) fail(lineOf(files), fmt::format("region '{}' has no <fileset>", r.id));
  return m;
}

// ---------------------------------------------------------------------------------------------
// Writing

// Shortest text that reads back as the same double.
std::string num(double v) { return fmt::format("{}", v); }

std::string escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string encodeBlend(const BlendMap& b, const std::string& path) {
  Result<std::vector<uint8_t>> png = [&]() -> Result<std::vector<uint8_t>> {
    if (b.bitDepth == 16) return texture::encodePngGrey16(path, b.width, b.height, b.codes.data());
    std::vector<uint8_t> eight(b.codes.size());
    for (size_t i = 0; i < eight.size(); ++i) eight[i] = uint8_t(b.codes[i]);
    return texture::encodePngGrey8(path, b.width, b.height, eight.data());
  }();
  if (!png.ok()) fail(path, png.error().message);
  return std::string(png->begin(), png->end());
}

void checkBlendForWriting(const BlendMap& b, const std::string& path) {
  const MpcdiLimits limits;
  if (b.bitDepth != 8 && b.bitDepth != 16) fail(path, "blend maps are 8- or 16-bit");
  if (b.width < 1 || b.height < 1 || b.width > limits.maxSide || b.height > limits.maxSide ||
      b.codes.size() != size_t(b.width) * size_t(b.height))
    fail(path, fmt::format("blend map of {} × {} with {} codes", b.width, b.height, b.codes.size()));
  const uint16_t most = uint16_t((1u << b.bitDepth) - 1);
  for (uint16_t c : b.codes)
    if (c > most) fail(path, fmt::format("code {} exceeds {} bits", c, b.bitDepth));
}

void checkMapForWriting(const FloatMap& m, const std::string& path) {
  const MpcdiLimits limits;
  if ((m.channels != 1 && m.channels != 3) || m.width < 1 || m.height < 1 ||
      m.width > limits.maxSide || m.height > limits.maxSide ||
      uint64_t(m.width) * uint64_t(m.height) > limits.maxSamples ||
      m.values.size() != size_t(m.width) * size_t(m.height) * size_t(m.channels))
    fail(path, fmt::format("map of {} × {} × {} with {} values", m.width, m.height, m.channels,
                           m.values.size()));
}

std::string writeArchive(const Mpcdi& m) {
  std::vector<std::pair<std::string, std::string>> entries;
  entries.emplace_back(kXml, "");
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += fmt::format("<MPCDI profile=\"{}\" level=\"{}\" version=\"{}\" date=\"{}\">\n",
                   m.profile == MpcdiProfile::media2d ? "2d" : "3d", m.level, escaped(m.version),
                   escaped(m.date));
  if (m.level < 1 || m.level > 4) fail(kXml, fmt::format("level {} is not 1 … 4", m.level));
  x += "  <display>\n";
  std::string files = "  <files>\n";
  std::set<std::string> ids, names;
  size_t regions = 0;
  for (const MpcdiBuffer& b : m.buffers) regions += b.regions.size();
  if (regions > size_t(MpcdiLimits{}.maxRegions))
    fail(kXml, fmt::format("{} regions, more than {}", regions, MpcdiLimits{}.maxRegions));
  std::set<std::string> bufferIds;
  for (const MpcdiBuffer& b : m.buffers) {
    if (b.id.empty() || !bufferIds.insert(b.id).second)
      fail(kXml, fmt::format("buffer id '{}' is empty or not unique", b.id));
    if (b.xResolution < 0 || b.yResolution < 0 || b.xResolution > MpcdiLimits{}.maxSide ||
        b.yResolution > MpcdiLimits{}.maxSide)
      fail(kXml, fmt::format("buffer '{}': resolution {} × {} out of range", b.id, b.xResolution,
                             b.yResolution));
    x += fmt::format("    <buffer id=\"{}\"", escaped(b.id));
    if (b.xResolution > 0) x += fmt::format(" Xresolution=\"{}\"", b.xResolution);
    if (b.yResolution > 0) x += fmt::format(" Yresolution=\"{}\"", b.yResolution);
    x += ">\n";
    for (const MpcdiRegion& r : b.regions) {
      if (r.id.empty() || !ids.insert(r.id).second)
        fail(kXml, fmt::format("region id '{}' is empty or not unique", r.id));
      if (m.profile == MpcdiProfile::simulation3d && !r.frustum)
        fail(kXml, fmt::format("region '{}' needs a frustum in the 3d profile", r.id));
      const MpcdiLimits limits;
      if (r.xResolution < 1 || r.yResolution < 1 || r.xResolution > limits.maxSide ||
          r.yResolution > limits.maxSide)
        fail(kXml, fmt::format("region '{}': {} × {} pixels, each side must be 1 … {}", r.id,
                               r.xResolution, r.yResolution, limits.maxSide));
      if (!withinBuffer(r)) fail(kXml, fmt::format("region '{}': {}", r.id, kOutsideBuffer));
      if (r.frustum)
        if (const std::string problem = frustumProblem(*r.frustum); !problem.empty())
          fail(kXml, fmt::format("region '{}': {}", r.id, problem));
      if (r.coordinateFrame)
        for (const double* v : {r.coordinateFrame->pos, r.coordinateFrame->yaw,
                                r.coordinateFrame->pitch, r.coordinateFrame->roll})
          if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
            fail(kXml, fmt::format("region '{}': coordinateFrame values must be finite", r.id));
      x += fmt::format(
          "      <region id=\"{}\" Xresolution=\"{}\" Yresolution=\"{}\" x=\"{}\" y=\"{}\" "
          "xsize=\"{}\" ysize=\"{}\">\n",
          escaped(r.id), r.xResolution, r.yResolution, num(r.x), num(r.y), num(r.xSize), num(r.ySize));
      if (r.frustum) {
        const MpcdiFrustum& f = *r.frustum;
        x += fmt::format(
            "        <frustum>\n          <yaw>{}</yaw>\n          <pitch>{}</pitch>\n"
            "          <roll>{}</roll>\n          <rightAngle>{}</rightAngle>\n"
            "          <leftAngle>{}</leftAngle>\n          <upAngle>{}</upAngle>\n"
            "          <downAngle>{}</downAngle>\n        </frustum>\n",
            num(f.orientation.yawDegrees), num(f.orientation.pitchDegrees),
            num(f.orientation.rollDegrees), num(f.window.rightDegrees), num(f.window.leftDegrees),
            num(f.window.upDegrees), num(f.window.downDegrees));
      }
      if (r.coordinateFrame) {
        const MpcdiCoordinateFrame& c = *r.coordinateFrame;
        x += "        <coordinateFrame>\n";
        const char* axes[3] = {"x", "y", "z"};
        for (const auto& [name, v] : {std::pair<const char*, const double*>{"pos", c.pos},
                                      {"yaw", c.yaw}, {"pitch", c.pitch}, {"roll", c.roll}})
          for (int i = 0; i < 3; ++i)
            x += fmt::format("          <{0}{1}>{2}</{0}{1}>\n", name, axes[i], num(v[i]));
        x += "        </coordinateFrame>\n";
      }
      x += "      </region>\n";

      // The region's files, under default names where none is given.
      const std::string stem = b.id + "/" + r.id;
      auto named = [&](const std::string& given, const char* suffix) {
        std::string n = given.empty() ? stem + suffix : given;
        if (n == kXml || !names.insert(n).second)
          fail(n, "two files of the archive would have this name");
        return n;
      };
      files += fmt::format("    <fileset region=\"{}\">\n", escaped(r.id));
      const std::string warp = named(r.warpPath, "_warp.pfm");
      checkMapForWriting(r.warp, warp);
      if (r.warp.channels != 3) fail(warp, "a geometry warp has three components per sample");
      checkWarp(r.warp, warp);
      entries.emplace_back(warp, writePfm(r.warp));
      files += fmt::format(
          "      <geometryWarpFile>\n        <path>{}</path>\n"
          "        <geometricUnit>{}</geometricUnit>\n        <interpolation>{}</interpolation>\n"
          "        <originOf3DData>{}</originOf3DData>\n      </geometryWarpFile>\n",
          escaped(warp), escaped(r.geometricUnit), escaped(r.interpolation), escaped(r.originOf3DData));
      if (r.alpha) {
        const std::string alpha = named(r.alphaPath, "_alpha.png");
        checkBlendForWriting(*r.alpha, alpha);
        if (!(std::isfinite(r.alphaGammaEmbedded) && r.alphaGammaEmbedded > 0))
          fail(alpha, "gammaEmbedded must be positive");
        entries.emplace_back(alpha, encodeBlend(*r.alpha, alpha));
        files += fmt::format(
            "      <alphaMap>\n        <path>{}</path>\n        <componentDepth>1</componentDepth>\n"
            "        <bitDepth>{}</bitDepth>\n        <gammaEmbedded>{}</gammaEmbedded>\n"
            "      </alphaMap>\n",
            escaped(alpha), r.alpha->bitDepth, num(r.alphaGammaEmbedded));
      }
      if (r.beta) {
        const std::string beta = named(r.betaPath, "_beta.png");
        checkBlendForWriting(*r.beta, beta);
        entries.emplace_back(beta, encodeBlend(*r.beta, beta));
        files += fmt::format(
            "      <betaMap>\n        <path>{}</path>\n        <componentDepth>1</componentDepth>\n"
            "        <bitDepth>{}</bitDepth>\n      </betaMap>\n",
            escaped(beta), r.beta->bitDepth);
      }
      if (r.distortion) {
        const std::string d = named(r.distortionPath, "_distortion.pfm");
        checkMapForWriting(*r.distortion, d);
        checkFinite(*r.distortion, d);
        entries.emplace_back(d, writePfm(*r.distortion));
        files += fmt::format("      <distortionMap>\n        <path>{}</path>\n      </distortionMap>\n",
                             escaped(d));
      }
      files += "    </fileset>\n";
    }
    x += "    </buffer>\n";
  }
  x += "  </display>\n" + files + "  </files>\n</MPCDI>\n";
  entries[0].second = std::move(x);
  return detail::writeZip(entries);
}

Error errorIn(const std::string& file, const Problem& p) { return Error{file, p.position, p.message}; }

}  // namespace

// -----------------------------------------------------------------------------------------------

Result<Mpcdi> parseMpcdi(const void* data, size_t size, const std::string& name,
                         const MpcdiLimits& limits) {
  if (size > limits.maxArchiveBytes)
    return Error{name, "", fmt::format("{} bytes: more than the limit of {}", size, limits.maxArchiveBytes)};
  const std::string bytes(static_cast<const char*>(data), size);
  try {
    return readArchive(bytes, limits);
  } catch (const Problem& p) {
    return errorIn(name, p);
  } catch (const std::bad_alloc&) {
    return Error{name, "", "out of memory"};
  }
}

Result<Mpcdi> readMpcdi(const std::string& path, const MpcdiLimits& limits) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return Error{path, "", "cannot open the file"};
  const std::streamoff size = in.tellg();
  if (size < 0) return Error{path, "", "cannot tell the file's size"};
  if (uint64_t(size) > limits.maxArchiveBytes)
    return Error{path, "", fmt::format("{} bytes: more than the limit of {}", size, limits.maxArchiveBytes)};
  std::string bytes(size_t(size), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), size)) return Error{path, "", "cannot read the file"};
  return parseMpcdi(bytes.data(), bytes.size(), path, limits);
}

Result<std::string> encodeMpcdi(const Mpcdi& m, const std::string& name) {
  try {
    return writeArchive(m);
  } catch (const Problem& p) {
    return errorIn(name, p);
  }
}

Status writeMpcdi(const std::string& path, const Mpcdi& m) {
  Result<std::string> bytes = encodeMpcdi(m, path);
  if (!bytes.ok()) return bytes.error();
  return core::writeFile(path, {bytes.value()});
}

std::string encodePfm(const FloatMap& map) { return writePfm(map); }

Result<FloatMap> parsePfm(const std::string& bytes, const std::string& name,
                          const MpcdiLimits& limits) {
  try {
    return readPfm(bytes, "", limits);
  } catch (const Problem& p) {
    return Error{name, "", p.message};
  }
}

// -----------------------------------------------------------------------------------------------
// Mappings

std::optional<Vec2> sampleWarp(const MpcdiRegion& r, double px, double py) {
  const FloatMap& w = r.warp;
  // Sample (i, j) sits at region pixel ((i + 0.5)·W/w, (j + 0.5)·H/h): the continuous grid
  // coordinate is px·w/W − 0.5. Inside the outermost sample centres the warp is bilinear; in the
  // half cell beyond them it is extrapolated linearly from the edge cell (a geometry warp is
  // smooth, and the edge's value held constant there would be off by up to half a cell).
  auto cell = [](double g, int n, int& i0, int& i1, double& f) {
    if (n == 1) {
      i0 = i1 = 0;
      f = 0;
      return;
    }
    i0 = std::clamp(int(std::floor(g)), 0, n - 2);
    i1 = i0 + 1;
    f = std::clamp(g, -0.5, n - 0.5) - i0;  // within [−0.5, 1.5]
  };
  int x0, x1, y0, y1;
  double fx, fy;
  cell(px * w.width / r.xResolution - 0.5, w.width, x0, x1, fx);
  cell(py * w.height / r.yResolution - 0.5, w.height, y0, y1, fy);
  double u = 0, v = 0;
  const struct {
    int x, y;
    double weight;
  } taps[4] = {{x0, y0, (1 - fx) * (1 - fy)}, {x1, y0, fx * (1 - fy)}, {x0, y1, (1 - fx) * fy},
               {x1, y1, fx * fy}};
  for (const auto& t : taps) {
    if (t.weight == 0) continue;
    const float* s = w.at(t.x, t.y);
    if (std::isnan(s[0])) return std::nullopt;  // the invalid marker weighs in
    u += t.weight * s[0];
    v += t.weight * s[1];
  }
  return Vec2{float(u), float(v)};
}

ContentMap contentMap(const MpcdiRegion& r) {
  ContentMap m;
  m.width = r.xResolution;
  m.height = r.yResolution;
  const size_t n = size_t(m.width) * size_t(m.height);
  m.uv.assign(n, Vec2{});
  m.valid.assign(n, 0);
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x)
      if (std::optional<Vec2> uv = sampleWarp(r, x + 0.5, y + 0.5)) {
        m.uv[size_t(y) * size_t(m.width) + size_t(x)] = *uv;
        m.valid[size_t(y) * size_t(m.width) + size_t(x)] = 1;
      }
  return m;
}

Result<DirectionMap> directionMap(const MpcdiRegion& r) {
  if (!r.frustum) return Error{"", "", fmt::format("region '{}' has no frustum", r.id)};
  const WindowTangents t = tangentsOf(r.frustum->window);
  const Rotation rot = rotationOf(r.frustum->orientation);
  const ContentMap content = contentMap(r);
  DirectionMap m;
  m.width = content.width;
  m.height = content.height;
  m.valid = content.valid;
  m.directions.assign(content.uv.size(), Vec3{});
  for (size_t i = 0; i < content.uv.size(); ++i) {
    if (!m.valid[i]) continue;
    const double dx = t.left + content.uv[i].x * (t.right - t.left);
    const double dy = t.up - content.uv[i].y * (t.up - t.down);
    const double len = std::sqrt(dx * dx + dy * dy + 1);
    m.directions[i] = rot.apply(dx / len, dy / len, -1 / len);
  }
  return m;
}

MpcdiRegion regionFromGeometry(const DisplayGeometry& g, const MpcdiFrustum& frustum, int warpWidth,
                               int warpHeight, const std::string& id) {
  MpcdiRegion r;
  r.id = id;
  r.xResolution = g.projector.width;
  r.yResolution = g.projector.height;
  r.frustum = frustum;
  r.warp.width = warpWidth;
  r.warp.height = warpHeight;
  r.warp.channels = 3;
  r.warp.values.assign(size_t(warpWidth) * size_t(warpHeight) * 3, std::nanf(""));
  const WindowTangents t = tangentsOf(frustum.window);
  const Rotation rot = rotationOf(frustum.orientation);
  for (int j = 0; j < warpHeight; ++j)
    for (int i = 0; i < warpWidth; ++i) {
      const double px = (i + 0.5) * r.xResolution / warpWidth;
      const double py = (j + 0.5) * r.yResolution / warpHeight;
      const PixelView v = viewOfPixel(g, px, py);
      if (!v.valid) continue;
      // Into the frustum's body frame: the transpose of its rotation.
      const Vec3 d = v.direction;
      const double bx = rot.m[0][0] * d.x + rot.m[1][0] * d.y + rot.m[2][0] * d.z;
      const double by = rot.m[0][1] * d.x + rot.m[1][1] * d.y + rot.m[2][1] * d.z;
      const double bz = rot.m[0][2] * d.x + rot.m[1][2] * d.y + rot.m[2][2] * d.z;
      if (!(bz < 0)) continue;  // behind the frustum's eye
      const double u = (bx / -bz - t.left) / (t.right - t.left);
      const double w = (t.up - by / -bz) / (t.up - t.down);
      if (!(std::fabs(u) < 1e6 && std::fabs(w) < 1e6)) continue;  // at the frustum's horizon
      float* s = r.warp.values.data() + (size_t(j) * size_t(warpWidth) + size_t(i)) * 3;
      s[0] = float(u);
      s[1] = float(w);
      s[2] = 0;
    }
  return r;
}

}  // namespace sv::display
