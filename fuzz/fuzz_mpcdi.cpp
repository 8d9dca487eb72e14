// Fuzz target: the MPCDI reader (display/mpcdi.h). The first byte chooses what the rest is:
// 0 — a whole .mpcdi archive; 1 — mpcdi.xml alone, zipped here beside fixed, valid warp and blend
// files (so that mutations reach the XML rather than stopping at the zip's CRC); 2 — a PFM file.
// Beyond "no crash, no sanitizer report": a read file keeps the reader's promises (limits, warp
// samples valid or the invalid marker, a frustum per 3d region), a failure carries a message,
// and what the writer writes of a read file reads back and writes again to the same bytes.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "display/mpcdi.h"
#include "display/zip_memory.h"

namespace {

using namespace sv::display;

// Small enough that the largest accepted input runs in milliseconds.
MpcdiLimits fuzzLimits() {
  MpcdiLimits l;
  l.maxArchiveBytes = l.maxEntryBytes = uint64_t(1) << 20;
  l.maxXmlBytes = uint64_t(1) << 18;
  l.maxEntries = 64;
  l.maxRegions = 16;
  l.maxSide = 1024;
  l.maxSamples = uint64_t(1) << 16;
  return l;
}

[[noreturn]] void broken(const char* what) {
  std::fprintf(stderr, "broken promise: %s\n", what);
  std::abort();
}

void checkMap(const FloatMap& m, const MpcdiLimits& l) {
  if (m.width < 1 || m.height < 1 || m.width > l.maxSide || m.height > l.maxSide ||
      uint64_t(m.width) * uint64_t(m.height) > l.maxSamples || (m.channels != 1 && m.channels != 3) ||
      m.values.size() != size_t(m.width) * size_t(m.height) * size_t(m.channels))
    broken("map size");
}

void checkBlend(const BlendMap& b, const MpcdiLimits& l) {
  if (b.width < 1 || b.height < 1 || b.width > l.maxSide || b.height > l.maxSide ||
      b.codes.size() != size_t(b.width) * size_t(b.height) || (b.bitDepth != 8 && b.bitDepth != 16))
    broken("blend map size");
  for (uint16_t c : b.codes)
    if (c >= (1u << b.bitDepth)) broken("blend code beyond its bit depth");
}

void check(const sv::Result<Mpcdi>& r, const MpcdiLimits& l) {
  if (!r.ok()) {
    if (r.error().message.empty()) broken("error without a message");
    return;
  }
  const Mpcdi& m = r.value();
  size_t regions = 0;
  for (const MpcdiBuffer& b : m.buffers)
    for (const MpcdiRegion& g : b.regions) {
      ++regions;
      if (g.xResolution < 1 || g.yResolution < 1 || g.xResolution > l.maxSide ||
          g.yResolution > l.maxSide)
        broken("region resolution");
      if (m.profile == MpcdiProfile::simulation3d && !g.frustum) broken("3d region without frustum");
      checkMap(g.warp, l);
      if (g.warp.channels != 3) broken("warp channels");
      for (size_t i = 0; i < g.warp.values.size(); i += 3) {
        const float* s = &g.warp.values[i];
        const bool marker = std::isnan(s[0]) && std::isnan(s[1]);
        if (!marker && !(std::isfinite(s[0]) && std::isfinite(s[1]) && std::isfinite(s[2])))
          broken("warp sample neither finite nor the invalid marker");
      }
      if (g.alpha) checkBlend(*g.alpha, l);
      if (g.beta) checkBlend(*g.beta, l);
      if (g.distortion) checkMap(*g.distortion, l);
      // The mappings, on regions small enough to stay fast.
      if (g.xResolution * g.yResolution <= 4096) {
        const ContentMap c = contentMap(g);
        for (size_t i = 0; i < c.uv.size(); ++i)
          if (c.valid[i] && !(std::isfinite(c.uv[i].x) && std::isfinite(c.uv[i].y)))
            broken("valid content coordinate not finite");
        if (g.frustum && !directionMap(g).ok()) broken("direction map of a region with a frustum");
      }
    }
  if (regions > size_t(l.maxRegions)) broken("region count");
  // What the writer makes of it reads back, and writes again to the same bytes.
  sv::Result<std::string> once = encodeMpcdi(m, "fuzz.mpcdi");
  if (!once.ok()) return;  // e.g. two regions naming one warp file: the writer will not
  sv::Result<Mpcdi> back = parseMpcdi(once->data(), once->size(), "fuzz.mpcdi", l);
  if (!back.ok()) {
    std::fprintf(stderr, "%s\n", back.error().str().c_str());
    broken("the writer's archive does not read back");
  }
  sv::Result<std::string> twice = encodeMpcdi(back.value(), "fuzz.mpcdi");
  if (!twice.ok() || twice.value() != once.value()) broken("writing is not a fixed point");
}

// The files mpcdi.xml inputs (kind 1) find beside them.
std::vector<std::pair<std::string, std::string>> fixedEntries() {
  static const std::vector<std::pair<std::string, std::string>> entries = [] {
    FloatMap warp;
    warp.width = 3;
    warp.height = 2;
    warp.values = {0, 0, 0, 0.5f, 0, 0, 1, 0, 0, 0, 1, 0, 0.5f, 1, 0, NAN, NAN, NAN};
    FloatMap distortion;
    distortion.width = 2;
    distortion.height = 1;
    distortion.channels = 1;
    distortion.values = {0.25f, 4};
    Mpcdi m;
    MpcdiBuffer b;
    b.id = "fixed";
    MpcdiRegion r;
    r.id = "fixed";
    r.xResolution = 6;
    r.yResolution = 4;
    r.frustum = MpcdiFrustum{};
    r.warp = warp;
    r.alpha = BlendMap{2, 2, 8, {255, 128, 64, 0}};
    r.beta = BlendMap{1, 1, 16, {1000}};
    r.distortion = distortion;
    r.warpPath = "r/warp.pfm";
    r.alphaPath = "r/alpha.png";
    r.betaPath = "r/beta.png";
    r.distortionPath = "r/dist.pfm";
    b.regions.push_back(r);
    m.buffers.push_back(b);
    // Take the writer's entries back out of its archive: the files, without its mpcdi.xml.
    const std::string zip = encodeMpcdi(m, "fixed").value();
    sv::display::detail::ZipReader reader(zip, 16);
    std::vector<std::pair<std::string, std::string>> out;
    for (const char* name : {"r/warp.pfm", "r/alpha.png", "r/beta.png", "r/dist.pfm"})
      out.emplace_back(name, reader.read(name, 1 << 20));
    return out;
  }();
  return entries;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const MpcdiLimits limits = fuzzLimits();
  const std::string rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 3) {
    case 0:
      check(parseMpcdi(rest.data(), rest.size(), "/nonexistent/fuzz.mpcdi", limits), limits);
      break;
    case 1: {
      std::vector<std::pair<std::string, std::string>> entries = fixedEntries();
      entries.insert(entries.begin(), {"mpcdi.xml", rest});
      const std::string zip = sv::display::detail::writeZip(entries);
      check(parseMpcdi(zip.data(), zip.size(), "/nonexistent/fuzz.mpcdi", limits), limits);
      break;
    }
    default: {
      const sv::Result<FloatMap> m = parsePfm(rest, "/nonexistent/fuzz.pfm", limits);
      if (m.ok()) checkMap(m.value(), limits);
      else if (m.error().message.empty()) broken("error without a message");
    }
  }
  return 0;
}
