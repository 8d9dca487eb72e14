// `synthvis bench`: BENCH.md scenes timed on synthvis and, in the same run, on the OpenGL
// reference (Mesa llvmpipe), frames interleaved A/B; medians, ratios, throughput, PSNR between the
// two images; JSON rows as BENCH.md names them, and an HTML page with plots.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "synthvis/generators.h"
#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::reference {

// A scene to time: a generator with its parameters, or a scene file.
struct BenchCase {
  std::string name;  // e.g. "tris-100k-a10", or the file's path
  generators::Generator generator = generators::Generator::none;  // none: `file`
  generators::TrisParams tris;
  generators::LayersParams layers;
  generators::GrazingParams grazing;
  generators::FreeFormParams freeform;
  generators::TerrainParams terrain;
  generators::LightsParams lights;
  generators::CityParams city;
  generators::VolumeParams volume;
  std::string file;
};

// The cases of a named suite: "quick" (≤ 5 min on 2 cores with the reference) or "full".
Result<std::vector<BenchCase>> suiteCases(const std::string& suite);

// The case's scene, its parameters as JSON, and what the generator realized.
struct CaseScene {
  scene::Scene scene;
  nlohmann::json params;
  double meanArea = 0, depthComplexity = 0;  // 0 for files
};
Result<CaseScene> makeScene(const BenchCase& c, const RenderOptions& options);

// One renderer's timing of one case.
struct RendererRun {
  std::string renderer;     // "synthvis" or "gl"
  std::string description;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::vector<double> frameMs;
  double medianMs = 0, minMs = 0, maxMs = 0;
  FrameStats stats;                      // synthvis only (with channels: the first channel's)
  Image image;                           // the last frame (with channels: their mosaic, SPEC §9)
  std::vector<FrameStats> channelStats;  // synthvis with channels: each channel's, last frame
};

struct CaseResult {
  std::string name;
  nlohmann::json params;
  uint64_t triangles = 0;
  double meanArea = 0, depthComplexity = 0;
  std::vector<RendererRun> runs;  // synthvis first if it ran, then the reference if it ran
  double psnrDb = 0;              // between the two images; +∞ if identical; 0 if one renderer
};

struct BenchSettings {
  RenderOptions options;
  int frames = 10, warmup = 2;
  // The gl reference's multisampling (0 = none, 2…16; llvmpipe takes at most 4). synthvis's own
  // samples per pixel are options.samples.
  int referenceMsaa = 0;
  bool synthvis = true;   // time synthvis
  bool reference = true;  // time the gl reference (after startReference)
  // Time, on scenes with volumes (and nothing else), VTK's CPU volume ray caster
  // (reference/vtk_volume.h), renderer name "vtk"; other scenes take the gl reference if started.
  bool vtk = false;
  // Time, instead of the gl reference, synthvis with free forms marched in fixed steps (options.
  // marchSteps; RenderOptions::FreeFormMethod::march) — issue 7's sphere-tracing baseline, renderer
  // name "sphere-trace".
  bool sphereTrace = false;
  // Time, instead, synthvis on the scene with its free forms tessellated (tessellatedScene) — the
  // polygon baseline, renderer name "tessellated". (The gl reference always draws that scene.)
  bool tessellated = false;
  // Time, instead, synthvis with the traversal's savings off — every instance transformed at full
  // detail (RenderOptions cullInstances and lod false) — the baseline of issue 32's city, renderer
  // name "full-detail".
  bool fullDetail = false;
  // Count the gl reference's read-back (glReadPixels into an 8-bit image in memory) in its frame
  // time: synthvis's frame always ends with the image in memory.
  bool referenceReadback = false;
  // BENCH.md --shade textured: generated scenes get the bench texture (options.textureFilter
  // samples it; the reference uses GL's nearest equivalent).
  bool textured = false;
  // BENCH.md --fog: generated scenes get the bench fog (generators::addBenchFog), in both renderers.
  bool fog = false;
  // BENCH.md --channels N (SPEC §9): a scene without channels of its own gets N abutting ones in
  // an arc of `arcDegrees` around its camera, each options.width × options.height; one frame is
  // all channels (Renderer::renderChannels). 0: the classic single view. synthvis only.
  int channels = 0;
  float arcDegrees = 150;
  // Issue 34's benchmark: instead of a reference renderer, the scene's view on the centre
  // projector (options.width × options.height) of the demo's curved-screen display
  // (render::cylinderDisplay) — pre-distorted through sub-frusta (method (a), renderer name
  // "subfrusta", the plan made once as for a fixed eye) and by a flat view with margin resampled
  // bilinear (method (b), "resampled"), each frame beside the unwarped view ("synthvis"). synthvis
  // only.
  bool display = false;
  // Issue 35's benchmark: instead of a reference renderer, the segment pipeline
  // (RenderOptions::Pipeline::segments, renderer name "segments") beside the tile pipeline under
  // priority masking ("synthvis") — the same visibility — frame by frame; the case's params give
  // the segment pipeline's segments and runs a frame and its segments per second. synthvis only.
  bool pipelines = false;
};

// Renders, per case, warm-up frames then timed frames, alternating synthvis and the reference
// frame by frame so that drift of the machine hits both alike. `progress` gets one line per case.
// If the reference cannot start, the error says why (the caller decides whether that is fatal).
class BenchRunner {
 public:
  explicit BenchRunner(const BenchSettings& settings);
  ~BenchRunner();
  // Starts the reference; call before run() when settings.reference is set.
  Status startReference();
  const std::string& referenceDescription() const;
  Result<CaseResult> run(const BenchCase& c);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The SIMD target synthvis's kernels run on here (Highway's dispatch: the best of those built that
// this CPU supports), e.g. "AVX2" or "AVX3_ZEN4": the same scene's figures differ by target.
std::string simdTarget();

// Peak signal-to-noise ratio of two same-sized 8-bit images, dB (+∞ when equal).
double psnr(const Image& a, const Image& b);

// BENCH.md's JSON rows for one case: one per renderer, `psnr_db` against the other.
nlohmann::json jsonRows(const CaseResult& r, const BenchSettings& s);

// One line per renderer and case, as the CLI prints them.
std::string summaryLine(const CaseResult& r);

// After several measurements of one case (bench --repeat): each renderer's median frame time over
// them (the median of their medians) with its range, and the ratio's median and range. `middle`
// is set to the measurement whose ratio (or, for one renderer, whose time) is the median — the
// lower middle one for an even count. `repeats` is not empty.
std::string repeatSummaryLine(const std::vector<CaseResult>& repeats, size_t& middle);

// Writes DIR/index.html (table, plots, the two images of every case side by side), the plots
// DIR/ratio.svg and DIR/time-{triangles,area,depth}.svg, and the images
// DIR/<case>-<renderer>.png (the case name reduced to letters, digits, '_' and '-').
Status writeHtml(const std::string& dir, const std::vector<CaseResult>& results,
                 const BenchSettings& s, const std::string& referenceDescription);

}  // namespace sv::reference
