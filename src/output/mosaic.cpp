// The channels of a frame as one image (SPEC §9: "written as separate images or one mosaic").
#include <algorithm>
#include <cstring>

#include "synthvis/image.h"

namespace sv {

Image mosaic(const std::vector<Image>& images) {
  Image out;
  for (const Image& im : images) {
    out.width += im.width;
    out.height = std::max(out.height, im.height);
  }
  out.rgb.assign(size_t(out.width) * size_t(out.height) * 3, 0);  // black where nothing lands
  int x0 = 0;
  for (const Image& im : images) {
    for (int y = 0; y < im.height && im.width > 0; ++y)
      std::memcpy(out.pixel(x0, y), im.pixel(0, y), size_t(im.width) * 3);
    x0 += im.width;
  }
  return out;
}

}  // namespace sv
