// Edge blending (issue 34 item 4): a region's alpha and beta maps taken to its pixels, and applied
// to a frame in linear light — before the gamma table (output/resolve.h), where light from
// overlapping projectors adds.
#pragma once

#include <cstdint>
#include <vector>

#include "display/geometry.h"
#include "display/mpcdi.h"

namespace sv::display {

// A blend map's value at region pixel (px, py) (continuous, centres at +0.5) of a W × H region,
// as code / (2^bitDepth − 1): bilinear between the map's samples, which sit as a warp's do
// (mpcdi.h: sample (i, j) at ((i + 0.5)·W/w, (j + 0.5)·H/h)), the edge's value beyond them.
double sampleBlend(const BlendMap& map, int regionWidth, int regionHeight, double px, double py);

// Per region pixel, rows top first: alpha in linear light ((map value)^gammaEmbedded; 1 without an
// alpha map) and beta (the map value; 0 without a beta map).
struct BlendWeights {
  int width = 0, height = 0;
  std::vector<float> alpha, beta;
};
BlendWeights blendWeights(const MpcdiRegion& region);

// Blends a frame of linear 16-bit RGB (3 values a pixel, rows top first, the size of `weights`):
// each value becomes round(value·alpha + beta·65535), within 0 … 65535. Beta lifts the black level
// of a pixel (to match the overlaps', where two projectors' black adds).
void applyBlend(const BlendWeights& weights, uint16_t* rgb);
// The same over the rectangle [x0, x1) × [y0, y1) of the frame alone (a sub-frustum cell's, while
// it is in cache).
void applyBlend(const BlendWeights& weights, uint16_t* rgb, int x0, int y0, int x1, int y1);

// The demo's alpha maps for threeProjectorCylinder (geometry.h): projector i's weight falls with
// the screen point's azimuth across each overlap with a neighbour along a smoothstep, so that the
// two weights of a point in an overlap sum to one; 1 elsewhere, 0 where a pixel misses the screen.
// 16-bit maps of mapWidth × mapHeight samples (sample centres as above).
std::vector<BlendMap> cylinderAlphaMaps(const CylinderRig& rig, double overlapDegrees, int mapWidth,
                                        int mapHeight);

}  // namespace sv::display
