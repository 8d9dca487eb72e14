// Fuzz target: free forms from JSON scene text, rendered (SPEC §11–§12). The loader's checks
// (fuzz_check.h), then the scene's free forms alone, cast into a 24×16 raster at 1 and 4 samples:
// no crash, no hang (each ray's work is bounded), and the same bytes on 1 and 2 threads.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_check.h"
#include "synthvis/formats.h"
#include "synthvis/render.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sv;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Result<scene::Scene> r = formats::parseJsonScene(
      text, "/nonexistent-synthvis-fuzz/scene.json", formats::fuzz::fuzzOptions());
  formats::fuzz::checkResult(r);
  if (!r.ok() || r.value().freeForms.empty()) return 0;
  scene::Scene s = r.value();
  s.meshes.clear();
  s.instances.clear();
  for (int samples : {1, 4}) {
    RenderOptions o;
    o.width = 24;
    o.height = 16;
    o.samples = samples;
    o.threads = 1;
    Image one, two;
    const Status a = Renderer(o).render(s, one);
    o.threads = 2;
    const Status b = Renderer(o).render(s, two);
    if (a.ok() != b.ok() || (a.ok() && one.rgb != two.rgb)) {
      std::fprintf(stderr, "free forms rendered differently on 1 and 2 threads\n");
      std::abort();
    }
  }
  return 0;
}
