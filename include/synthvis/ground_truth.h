// Ground truth for image quality (issue 4, SPEC §5 "quality is measured, not asserted"): an
// independent brute-force renderer and image metrics.
//
// The renderer shares nothing with synthvis's rasterizer: per triangle the 2D homogeneous edge
// functions in double (Olano & Greer 1997), per sample an exact point-in-triangle test with the
// near and far planes, a depth test "less" per sample, perspective-correct Gouraud colour; samples
// stratified on an n×n grid inside each pixel, each jittered within its cell (n² per pixel, 256 by
// default), box-filtered in linear light, then sRGB. Only the vertex stage (clip-space positions
// and lit vertex colours) is synthvis's own, so both see the same triangles and colours.
#pragma once

#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::reference {

struct GroundTruthOptions {
  RenderOptions options;    // size, camera, culling; threads for the bands
  int samplesPerSide = 16;  // n: n² samples per pixel, 1…32
};

// Renders `scene`; the image is 8-bit sRGB like synthvis's. Slow by design: every sample of every
// pixel a triangle's box covers is tested against it. With `edges`, also writes the edge mask:
// white where the pixel's samples do not all show the same triangle (or all the background) —
// the pixels an edge crosses, where anti-aliasing matters.
Result<Image> renderGroundTruth(const scene::Scene& scene, const GroundTruthOptions& options,
                                Image* edges = nullptr);

// Differences between two same-sized sRGB images, measured in linear light (each channel decoded
// to [0, 1]). "Edge pixels" are the non-black pixels of `edgeMask` (from renderGroundTruth) when
// one is given; otherwise those whose 3×3 neighbourhood in `reference` is not uniform (a
// neighbour's channel differs by more than one 8-bit level), which also counts steep shading.
struct ImageDifference {
  double rmse = 0, psnrDb = 0;          // over all pixels and channels
  double edgeRmse = 0, edgePsnrDb = 0;  // over edge pixels only
  size_t pixels = 0, edgePixels = 0;
};
Result<ImageDifference> compareImages(const Image& image, const Image& reference,
                                      const Image* edgeMask = nullptr);

}  // namespace sv::reference
