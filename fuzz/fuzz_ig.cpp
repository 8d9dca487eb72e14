// Fuzz target: the image generator's two text inputs — its configuration (parseIgConfig) and the
// scripted host's script (parseHostScript) — on arbitrary text, the first byte choosing which.
// Beyond "no crash, no sanitizer report": a read configuration has a rate and sizes in range, a
// read script has paths whose times increase; a failure carries a message.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "synthvis/ig.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1) {
    const auto r = sv::ig::parseHostScript(text, "fuzz-host.json");
    if (!r.ok()) {
      if (r.error().message.empty()) std::abort();
      return 0;
    }
    if (!(r->rate >= 1 && r->rate <= 240) || r->frames == 0) std::abort();
    for (const sv::ig::ScriptEntity& e : r->entities)
      for (size_t k = 1; k < e.path.size(); ++k)
        if (!(e.path[k].t > e.path[k - 1].t)) std::abort();
    return 0;
  }
  const auto c = sv::ig::parseIgConfig(text, "fuzz-ig.json");
  if (!c.ok()) {
    if (c.error().message.empty()) std::abort();
    return 0;
  }
  if (!(c->rate >= 1 && c->rate <= 240) || c->channels.size() > sv::scene::kMaxChannels ||
      c->render.samples < 1 || c->render.samples > 64 || c->scene.empty())
    std::abort();
  return 0;
}
