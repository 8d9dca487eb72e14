// Edge blending in linear light. Based on: the MPCDI standard's alpha map (an attenuation per
// projector pixel, with the gamma it was stored with: gammaEmbedded) and beta map (black-level
// offset); Raskar et al. 1998, "The office of the future" (intensity ramps across projector
// overlaps that sum to one).
#include "display/blend.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sv::display {

double sampleBlend(const BlendMap& map, int regionWidth, int regionHeight, double px, double py) {
  // As sampleWarp (mpcdi.cpp): grid coordinate px·w/W − 0.5, clamped to the outer centres.
  const double gx = std::clamp(px * map.width / regionWidth - 0.5, 0.0, double(map.width - 1));
  const double gy = std::clamp(py * map.height / regionHeight - 0.5, 0.0, double(map.height - 1));
  const int x0 = std::min(int(gx), map.width - 1), y0 = std::min(int(gy), map.height - 1);
  const int x1 = std::min(x0 + 1, map.width - 1), y1 = std::min(y0 + 1, map.height - 1);
  const double fx = gx - x0, fy = gy - y0;
  auto code = [&](int x, int y) { return double(map.codes[size_t(y) * size_t(map.width) + size_t(x)]); };
  const double top = code(x0, y0) * (1 - fx) + code(x1, y0) * fx;
  const double bottom = code(x0, y1) * (1 - fx) + code(x1, y1) * fx;
  return (top * (1 - fy) + bottom * fy) / double((1u << map.bitDepth) - 1);
}

BlendWeights blendWeights(const MpcdiRegion& r) {
  BlendWeights w;
  w.width = r.xResolution;
  w.height = r.yResolution;
  const size_t n = size_t(w.width) * size_t(w.height);
  w.alpha.assign(n, 1.0f);
  w.beta.assign(n, 0.0f);
  for (int y = 0; y < w.height; ++y)
    for (int x = 0; x < w.width; ++x) {
      const size_t i = size_t(y) * size_t(w.width) + size_t(x);
      if (r.alpha)
        w.alpha[i] = float(std::pow(sampleBlend(*r.alpha, w.width, w.height, x + 0.5, y + 0.5),
                                    r.alphaGammaEmbedded));
      if (r.beta) w.beta[i] = float(sampleBlend(*r.beta, w.width, w.height, x + 0.5, y + 0.5));
    }
  return w;
}

void applyBlend(const BlendWeights& w, uint16_t* rgb) {
  applyBlend(w, rgb, 0, 0, w.width, w.height);
}

void applyBlend(const BlendWeights& w, uint16_t* rgb, int x0, int y0, int x1, int y1) {
  for (int y = y0; y < y1; ++y)
    for (size_t i = size_t(y) * size_t(w.width) + size_t(x0),
                end = size_t(y) * size_t(w.width) + size_t(x1);
         i < end; ++i) {
      const float a = w.alpha[i], b = w.beta[i] * 65535.0f;
      for (int c = 0; c < 3; ++c) {
        const float v = float(rgb[i * 3 + size_t(c)]) * a + b;
        rgb[i * 3 + size_t(c)] = uint16_t(std::clamp(std::nearbyint(v), 0.0f, 65535.0f));
      }
    }
}

namespace {
// The smoothstep 3t² − 2t³ of t clamped to [0, 1]: s(t) + s(1 − t) = 1, so the two ramps of an
// overlap sum to one, and its slope vanishes at both ends, so that the maps' bilinear
// interpolation does not round the ramp's corners off (a linear ramp's kinks cost up to 1%).
double smoothRamp(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3 - 2 * t);
}
}  // namespace

std::vector<BlendMap> cylinderAlphaMaps(const CylinderRig& rig, double overlap, int mapWidth,
                                        int mapHeight) {
  std::vector<BlendMap> maps;
  const int count = int(rig.projectors.size());
  for (int i = 0; i < count; ++i) {
    const DisplayGeometry g = rig.geometry(i);
    // Projector i covers azimuths [lo, hi] (threeProjectorCylinder's layout).
    const double lo = -90 + 60 * i - overlap / 2, hi = -30 + 60 * i + overlap / 2;
    BlendMap m;
    m.width = mapWidth;
    m.height = mapHeight;
    m.bitDepth = 16;
    m.codes.assign(size_t(mapWidth) * size_t(mapHeight), 0);
    for (int y = 0; y < mapHeight; ++y)
      for (int x = 0; x < mapWidth; ++x) {
        const double px = (x + 0.5) * g.projector.width / mapWidth;
        const double py = (y + 0.5) * g.projector.height / mapHeight;
        const PixelView v = viewOfPixel(g, px, py);
        if (!v.valid) continue;
        const Vec3 p = v.screenPoint - rig.screen.centre;
        const double azimuth = std::atan2(double(p.x), -double(p.z)) * 180 / std::numbers::pi;
        double weight = 1;
        if (i > 0) weight *= smoothRamp((azimuth - lo) / overlap);
        if (i < count - 1) weight *= smoothRamp((hi - azimuth) / overlap);
        m.codes[size_t(y) * size_t(mapWidth) + size_t(x)] = uint16_t(std::lround(weight * 65535));
      }
    maps.push_back(std::move(m));
  }
  return maps;
}

}  // namespace sv::display
