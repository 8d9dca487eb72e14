// Fuzz target: texture images (decodeTextureImage: PNG through libpng, JPEG through TurboJPEG) on
// arbitrary bytes, a PNG's chunks' CRCs made to match (png_crc.h), and the MIP pyramid and
// samplers (trilinear, and each single-level filter) on what decodes. Beyond "no crash, no sanitizer report": a
// decoded level has its stated size, the pyramid ends at 1×1 with each level half the one above
// (rounded up), and samples stay within [0, 1]; a failure carries a message.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "png_crc.h"
#include "texture/texture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace tx = sv::texture;
  const std::vector<uint8_t> bytes = sv::fuzz::withPngCrcs(data, size);
  sv::Result<tx::Level> r = tx::decodeTextureImage(bytes.data(), bytes.size(), "fuzz.png");
  if (!r.ok()) {
    if (r.error().message.empty()) std::abort();
    return 0;
  }
  const tx::Level& l = r.value();
  if (l.width < 1 || l.height < 1 || l.width > tx::kMaxTextureSide ||
      l.height > tx::kMaxTextureSide || l.texels.size() != size_t(l.width) * size_t(l.height)) {
    std::fprintf(stderr, "bad level %dx%d with %zu texels\n", l.width, l.height, l.texels.size());
    std::abort();
  }
  if (l.texels.size() > (size_t(1) << 20)) return 0;  // keep each input fast
  const tx::Texture t(std::move(r).value(), tx::Wrap(size % 3), tx::Wrap((size / 3) % 3));
  for (int k = 1; k < t.levelCount(); ++k)
    if (t.level(k).width != (t.level(k - 1).width + 1) / 2 ||
        t.level(k).height != (t.level(k - 1).height + 1) / 2)
      std::abort();
  const tx::LevelView last = t.level(t.levelCount() - 1);
  if (last.width != 1 || last.height != 1) std::abort();
  for (float lod : {0.0f, 0.7f, 3.2f}) {
    const tx::Color4 c = t.trilinearThreePoint(lod, 1.3f, -2.6f);
    const tx::Color4 d = t.trilinear(lod, 7.9f, 0.4f);
    for (float v : {c.r, c.g, c.b, c.a, d.r, d.g, d.b, d.a})
      if (!(v >= 0 && v <= 1.0001f)) std::abort();
    for (tx::Filter f : {tx::Filter::nearest, tx::Filter::threePoint, tx::Filter::bilinear}) {
      const tx::Color4 e = t.sample(f, lod, -0.3f, 5.6f);
      for (float v : {e.r, e.g, e.b, e.a})
        if (!(v >= 0 && v <= 1.0001f)) std::abort();
    }
  }
  return 0;
}
