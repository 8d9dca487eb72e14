// synthvis — command-line front end.
//
//   synthvis render [SCENE] -o out.png [--width W] [--height H] [--threads T] [--camera I]
//                   [--channels N [--arc DEG]] [--mosaic FILE]
//                   [--no-cull] [--no-instance-cull] [--no-lod] [--no-merge] [--lod-scale S] [--debug-view overdraw|levels|occupancy] [--gamma G]
//                   [--supersample K] [--aa 1|4|8|16|64] [--filter box|tent3]
//                   [--texture-filter point|nearest|tri3|bilinear|trilinear3|trilinear|aniso]
//                   [--hsr zbuffer|priority|hybrid]
//   synthvis bench SCENE|--suite quick|full [--count N] [--area A] [--depth D] [--layers D]
//                  [--order random|f2b|b2f] [--shade gouraud|textured] [--fog]
//                  [--texture-filter F] [--hsr zbuffer|priority|hybrid] [--width W] [--height H]
//                  [--threads T] [--frames F] [--warmup W] [--seed S] [--aa S] [--gl-aa S]
//                  [--filter box|tent3] [--repeat N] [--channels N [--arc DEG]]
//                  [--renderer synthvis|gl|both] [--gl-readback] [--json FILE] [--html DIR]
//                  [--image FILE]
//   synthvis gen tris|layers|grazing -o scene.glb [--count N] [--area A] [--depth D] [--layers D]
//                [--order O] [--seed S] [--width W] [--height H] [--shade gouraud|textured]
//   synthvis truth [SCENE] -o truth.png [--samples 256] [--width W] [--height H] [--threads T]
//   synthvis truth … [--edges MASK.png]
//   synthvis compare IMAGE.png REFERENCE.png [--edges MASK.png]
//   synthvis ig CONFIG [--output null|png:DIR|y4m:PATH|window[:channels]] [--frames N]
//               [--record FILE.pcap] [--replay FILE.pcap] [--status FILE|-] [--overlay]
//               [--test-pattern grid|bars|wedges] [--as-fast-as-possible] [--no-governor]
//   synthvis host SCRIPT [--ig-port P] [--port P] [--frames N]
//   synthvis prep INPUT|city -o DB.svdb [--no-optimize] [--no-lods] [--lod-levels N]
//                [--reduction R] [--pixel-error P] [--buildings N] [--trees N]
//   (shared BENCH.md defines the scenes and the JSON fields)
//
// Errors print one line, "synthvis: <file>: <problem>", and exit with status 1 (2 for usage).
// Each command is a file of its own (<command>_command.cpp, cli.h); this one only dispatches.
#include <CLI/CLI.hpp>

#include "cli.h"

int main(int argc, char** argv) {
  CLI::App app{"synthvis — a real-time software image generator (recursive 2x2 subdivision)"};
  app.require_subcommand(1);
  sv::cli::Run run;
  sv::cli::addRenderCommand(app, run);
  sv::cli::addBenchCommand(app, run);
  sv::cli::addGenCommand(app, run);
  sv::cli::addTruthCommand(app, run);
  sv::cli::addCompareCommand(app, run);
  sv::cli::addTerrainCommand(app, run);
  sv::cli::addIgCommand(app, run);
  sv::cli::addPrepCommand(app, run);
  sv::cli::addHostCommand(app, run);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return run ? run() : 0;
}
