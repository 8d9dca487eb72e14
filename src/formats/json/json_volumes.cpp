// The JSON scene format's "volumes" section (docs/scene-format.md, "Volumes"): settings, and
// volume objects from files or generated, with their transfer functions and shells.
#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "core/quadric.h"
#include "formats/json/json_reader.h"

namespace sv::formats::json {

void SceneReader::readVolumes(const Json& v, const std::string& where) {
  expectKeys(v, where,
             {"step", "termination", "skipEmpty", "precomputedNormals", "windowTolerance",
              "closedForm", "objects"});
  VolumeSettings& settings = scene_.volumeSettings;
  if (const Json* x = find(v, "step")) settings.step = inRange(*x, member(where, "step"), 0.05f, 8);
  if (const Json* x = find(v, "termination"))
    settings.termination = inRange(*x, member(where, "termination"), 0, 0.5f);
  if (const Json* x = find(v, "skipEmpty"))
    settings.skipEmpty = boolean(*x, member(where, "skipEmpty"));
  if (const Json* x = find(v, "precomputedNormals"))
    settings.precomputedNormals = boolean(*x, member(where, "precomputedNormals"));
  if (const Json* x = find(v, "closedForm"))
    settings.closedForm = boolean(*x, member(where, "closedForm"));
  if (const Json* x = find(v, "windowTolerance"))
    settings.windowTolerance = inRange(*x, member(where, "windowTolerance"), 0, 1);
  const Json* objects = find(v, "objects");
  if (!objects) return;
  const std::string w = member(where, "objects");
  array(*objects, w);
  if (objects->size() > 64) fail(w, fmt::format("{} volumes (at most 64)", objects->size()));
  for (size_t i = 0; i < objects->size(); ++i) {
    const Json& o = (*objects)[i];
    const std::string wo = element(w, i);
    expectKeys(
        o, wo,
        {"name", "file", "generate", "transform", "transfer", "opacityUnit", "shaded", "shell"});
    VolumeObject vo;
    if (const Json* x = find(o, "name")) vo.name = string(*x, member(wo, "name"));
    const Json* file = find(o, "file");
    const Json* generate = find(o, "generate");
    if (bool(file) == bool(generate)) fail(wo, "needs one of 'file' and 'generate'");
    if (file) {
      const std::string ref = string(*file, member(wo, "file"));
      if (!context_.options.followReferences)
        fail(member(wo, "file"), fmt::format("'{}' is not opened here", ref));
      Result<VolumeGrid> grid = loadVolume(resolvePath(directoryOf(path_), ref));
      if (!grid) fail(member(wo, "file"), grid.error().str());
      vo.grid = std::make_shared<VolumeGrid>(std::move(grid.value()));
      if (vo.name.empty()) vo.name = ref;
    } else {
      const std::string wg = member(wo, "generate");
      expectKeys(*generate, wg, {"kind", "size", "bits", "seed", "cover"});
      const Json* kind = find(*generate, "kind");
      if (!kind) fail(wg, "missing key 'kind'");
      const std::string k = string(*kind, member(wg, "kind"));
      const Json* size = find(*generate, "size");
      if (k == "marschner-lobb") {
        const int n = size ? int(integer(*size, member(wg, "size"), 2, 512)) : 41;
        int bits = 8;
        if (const Json* b = find(*generate, "bits")) {
          bits = int(integer(*b, member(wg, "bits"), 8, 16));
          if (bits != 8 && bits != 16) fail(member(wg, "bits"), "must be 8 or 16");
        }
        vo.grid = std::make_shared<VolumeGrid>(marschnerLobbGrid(n, bits));
      } else if (k == "cloud") {
        const int n = size ? int(integer(*size, member(wg, "size"), 8, 512)) : 128;
        const uint64_t seed = find(*generate, "seed")
                                  ? uint64_t(integer(*find(*generate, "seed"), member(wg, "seed"),
                                                     0, int64_t(1) << 53))
                                  : 1;
        const float cover = find(*generate, "cover")
                                ? inRange(*find(*generate, "cover"), member(wg, "cover"), 0, 0.95f)
                                : 0.55f;
        vo.grid = std::make_shared<VolumeGrid>(cloudGrid(n, seed, cover));
      } else {
        fail(member(wg, "kind"),
             fmt::format("unknown volume generator '{}' (marschner-lobb or cloud)", k));
      }
      if (vo.name.empty()) vo.name = k;
    }
    if (const Json* x = find(o, "transform"))
      vo.transform = readTransform(*x, member(wo, "transform"));
    const Json* transfer = find(o, "transfer");
    if (!transfer) fail(wo, "missing key 'transfer'");
    const std::string wt = member(wo, "transfer");
    array(*transfer, wt);
    if (transfer->empty() || transfer->size() > 256)
      fail(wt, fmt::format("{} points (1 … 256)", transfer->size()));
    for (size_t k = 0; k < transfer->size(); ++k) {
      const Json& t = (*transfer)[k];
      const std::string wk = element(wt, k);
      expectKeys(t, wk, {"value", "color", "opacity"});
      TransferPoint point;
      const Json* value = find(t, "value");
      if (!value) fail(wk, "missing key 'value'");
      point.value = number(*value, member(wk, "value"));
      if (k > 0 && !(point.value > vo.transfer.back().value))
        fail(member(wk, "value"), "values must increase from point to point");
      if (const Json* x = find(t, "color")) {
        const Vec4 c = color(*x, member(wk, "color"), false);
        point.color = {c.x, c.y, c.z};
      }
      if (const Json* x = find(t, "opacity"))
        point.opacity = inRange(*x, member(wk, "opacity"), 0, 1);
      vo.transfer.push_back(point);
    }
    if (const Json* x = find(o, "opacityUnit"))
      vo.opacityUnit = inRange(*x, member(wo, "opacityUnit"), 0, 1e30f);
    if (const Json* x = find(o, "shaded")) vo.shaded = boolean(*x, member(wo, "shaded"));
    if (const Json* x = find(o, "shell")) {
      // A free form in the volume's own space: a quadric with clips bounds the rays (the box's
      // samples outside it promised transparent); a perturbed one clips the volume exactly.
      int quadrics = 0;
      FreeFormNode shell = readFreeForm(*x, member(wo, "shell"), 0, quadrics, true);
      if (!shell.perturbations.empty()) {
        vo.freeFormShell = std::move(shell);
      } else {
        if (shell.clips.size() > 15) fail(member(wo, "shell"), "at most 15 clips");
        vo.shell.push_back(shell.quadric);
        vo.shell.insert(vo.shell.end(), shell.clips.begin(), shell.clips.end());
      }
    }
    scene_.volumes.push_back(std::move(vo));
  }
}

}  // namespace sv::formats::json
