// openflight_sweep: our OpenFlight reading against OpenSceneGraph's over a set of models of other
// formats (scripts/openflight-peer; the table in docs/scene-format.md). For each MODEL argument,
// osgconv exports it as OpenFlight; then synthvis and OSG each read that .flt, and one line
// compares their triangle counts, bounds and distinct vertices:
//   model <TAB> same|differs|osg-export-failed|error <TAB> details
// Exit status 1 when any export OSG made reads differently here.
#include <cstdio>
#include <filesystem>
#include <string>

#include "formats/osg_peer.h"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using namespace sv::formats::testing;
  if (argc < 3) {
    std::fprintf(stderr, "usage: openflight_sweep WORKDIR MODEL...\n");
    return 2;
  }
  const fs::path work = argv[1];
  fs::create_directories(work);
  int differs = 0;
  for (int i = 2; i < argc; ++i) {
    const std::string model = argv[i];
    const std::string flt = (work / "model.flt").string(), obj = (work / "model-osg.obj").string();
    fs::remove(flt);
    if (!osgconv(model, flt) || !fs::exists(flt)) {
      std::printf("%s\tosg-export-failed\t\n", model.c_str());
      continue;
    }
    const PeerComparison c = compareWithOsg(flt, obj);
    if (!c.error.empty()) {
      std::printf("%s\terror\t%s\n", model.c_str(), c.error.c_str());
      ++differs;
    } else {
      std::printf(
          "%s\t%s\ttriangles %zu/%zu, bounds %.3g, vertices only ours %zu, only OSG's %zu\n",
          model.c_str(), c.same() ? "same" : "differs", c.ours, c.theirs, c.boundsDifference,
          c.verticesOnlyOurs, c.verticesOnlyTheirs);
      differs += c.same() ? 0 : 1;
    }
    std::fflush(stdout);
  }
  return differs ? 1 : 0;
}
