// Images draped over a ground (issue 29 item 4): an ortho image read by GDAL — an RGB GeoTIFF, or
// three bands of a multispectral one (Landsat's 3, 2, 1 give natural colour) — with the map
// bounds its georeferencing gives, as a texture's level 0.
#pragma once

#include <array>
#include <string>

#include "formats/heights.h"
#include "synthvis/result.h"
#include "texture/texture.h"

namespace sv::formats {

struct OrthoImage {
  texture::Level level;            // linear light, opaque
  std::array<double, 4> bounds{};  // map metres: west, south, east, north (the pixels' outer edges)
  bool georeferenced = false;      // false: the file had no geotransform (bounds are pixels)
  HeightField::Geographic geographic;  // a geographic raster's own grid (heights.h)
};

// A geographic image's bounds in `frame`'s map metres (heights.h, placeGeographic); a projected
// image's are left as they are.
void placeGeographic(OrthoImage& image, const GeoFrame& frame);

// Bands `bands` (1-based; one band is grey) of the raster at `path`. Each band is stretched
// linearly from its 2nd to its 98th percentile to [0, 1] — satellite bands span a fraction of
// their type's range — and read as sRGB-encoded (as displays show such images) into linear light.
// Geographic rasters' bounds are in map metres of the frame at their own centre, as height tables'
// are (heights.h).
// Sides above texture::kMaxTextureSide, or more texels than texture::kMaxTextureTexels, are
// refused before reading.
Result<OrthoImage> loadOrthoImage(const std::string& path, const std::array<int, 3>& bands);

}  // namespace sv::formats
