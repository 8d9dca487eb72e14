// Rendering a scene to an image: the public entry point of the library.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "synthvis/display.h"
#include "synthvis/frame_stats.h"
#include "synthvis/image.h"
#include "synthvis/result.h"
#include "synthvis/sample_counts.h"
#include "synthvis/scene.h"
#include "synthvis/tile_share.h"

namespace sv {

inline constexpr int kMaxRasterSize = 8192;  // width and height, each
inline constexpr int kMaxThreads = 256;

// Everything that configures a frame (STYLE.md habit 10). Built by the CLI, passed by reference.
struct RenderOptions {
  int width = 1280;
  int height = 720;
  int threads = 0;            // worker threads in all; 0 = one per hardware thread
  bool cullBackFaces = true;  // for materials that are not double-sided
  // Instances whose bounding box lies wholly beyond one plane of the view volume (or behind the
  // eye) are dropped before the vertex stage: setup would cull each of their triangles anyway, so
  // the image is the same (FrameStats::culledInstances). False: every instance is transformed.
  bool cullInstances = true;
  // Levels of detail (Scene::lodGroups): chosen by range, with dissolves across each switch, and
  // nothing drawn beyond the last level. False: every instance at full detail (level 0) at every
  // range. `lodScale` (> 0) multiplies every range: 2 switches to coarser levels at half the
  // distance (the overload governor's lever on geometry).
  bool lod = true;
  float lodScale = 1;
  // Hierarchical levels of detail (InstanceTree::Cell): where every member of a merged cell draws
  // the same far level alone, the cell's one mesh is drawn instead of its members — the same
  // triangles placed once at load time, so the image differs from drawing each member only in the
  // rounding of the vertices' placement. Only with `lod`, under the Z-buffer (masking draws
  // objects nearest first, which a merged cell is not). False: every member drawn on its own.
  bool mergeCells = true;
  int camera = 0;  // index into Scene::cameras (a default camera if there is none)
  // False-colour diagnostics instead of the image (one sample per pixel): how many triangles
  // covered each pixel (no depth test); where the visible triangle's subdivision stopped (the
  // window size it was filled at, or a 4×4 leaf tested pixel by pixel); which windows masking
  // found occupied (the largest full window holding the pixel; --hsr priority or hybrid).
  enum class DebugView { none, overdraw, levels, occupancy } debugView = DebugView::none;
  // Output transfer function (SPEC §8): 0 = sRGB (IEC 61966-2-1); otherwise a display gamma G,
  // encoded value = linear^(1/G), G in [0.5, 5].
  double gamma = 0;
  // Plain supersampling, k = 1, 2, 4, 8 or 16: the frame is rendered at k·width × k·height and each
  // pixel is the average of its k×k samples in linear light (the 1×1 box filter). The baseline
  // synthvis's own anti-aliasing (issue 4) is measured against.
  int supersample = 1;
  // Anti-aliasing (SPEC §5): samples per pixel, one of kSampleCounts (synthvis/sample_counts.h):
  // 1 (point sampling at pixel centres) or 4, 8, 16, 64 — sub-pixel masks from tables (patterns in docs/quality.md), depth per sample, colour shaded
  // once per pixel. Frame-buffer memory per pixel: samples × 10 bytes (whole frame only in frames
  // of more than 2^18 triangles; otherwise per 64×64 tile and thread).
  int samples = 1;
  // The resolve filter (SPEC §5): the 1×1 box (each pixel the mean of its own samples), or the
  // 3×3 triangle filter of seed 002 over the box-resolved frame, in linear light.
  enum class Filter { box, tent3 } filter = Filter::box;
  // How texture maps are sampled (SPEC §7), for materials that do not choose (`inherit`).
  scene::TextureFilter textureFilter = scene::TextureFilter::trilinear;
  // Hidden-surface removal (SPEC §4): the Z-buffer alone; multi-level priority masking, which
  // takes the scene's opaque triangles in submission order as their priority, nearest first
  // (exact for scenes given in a true front-to-back order without interpenetration, as the seeds'
  // databases were; docs/hidden-surfaces.md), the depth test kept for translucent triangles; or
  // hybrid — masking combined with depth bounds per window, the Z-buffer's image for any order,
  // fastest when the order is roughly front to back.
  enum class Hsr { zbuffer, priority, hybrid } hsr = Hsr::zbuffer;
  // The rasterization pipeline: the tiles (recursive 2×2 subdivision, masks, masking and the
  // passes), or seed 002's segment pipeline (SPEC §10) — each scan line's segments in priority
  // order, sorted by overwrite into RUN codes, each run shaded along it. The segment pipeline's
  // visibility is priority (the scene's triangles in the order Hsr::priority draws them, whatever
  // `hsr` says); it draws polygons with vertex colours, and fog (issue 35): a scene or options
  // needing more are refused. Its anti-aliasing is its own (SegmentChannel::donor, `filter` tent3).
  enum class Pipeline { tiles, segments } pipeline = Pipeline::tiles;
  // The segment pipeline's video channel (SPEC §10, §5, §9), for Pipeline::segments only.
  struct SegmentChannel {
    // The recipient–donor 1×1 filter: a pixel an edge of its visible triangle crosses is that
    // triangle's colour times the area it covers plus a neighbour's across the edge for the rest.
    bool donor = false;
    // Two fields a frame (the even lines, then the odd), each through the channel on its own clock.
    bool interlaced = false;
    // Overload protection on a model clock counted in segment words (docs/ARCHITECTURE.md): the
    // geometry stage's rate in words per line period (0: unlimited, no line is ever repeated), the
    // lines that must be buffered ahead of the display before a line is drawn, and the FIFO's
    // capacity in words (seed 002: 4096). A line that would come late is repeated instead.
    int64_t wordsPerLine = 0;
    int criticalLines = 2;
    int fifoWords = 4096;
  } segmentChannel = {};
  // How free forms (Scene::freeForms) are drawn: multi-level ray casting (SPEC §12), or — the
  // baseline it is measured against — every pixel marched front to back in `marchSteps` equal
  // steps of depth (in the cube the view volume is mapped onto), its first sign change bisected.
  enum class FreeFormMethod { raycast, march } freeFormMethod = FreeFormMethod::raycast;
  int marchSteps = 1024;
  // With anti-aliasing, free forms cast the pixel centres and every sample only where the centres
  // do not tell (silhouettes, intersections; docs/freeforms.md) — unless this is set: then every
  // sample is a ray, exact also for features thinner than a pixel, at up to `samples` times the
  // cost.
  bool freeFormEverySample = false;
  // Terrain (Scene::terrains) interpolation below the finest level: each terrain's own, or all
  // bilinear or all bicubic (SPEC §11; the CLI's --terrain-filter).
  enum class TerrainFilter { scene, bilinear, bicubic } terrainFilter = TerrainFilter::scene;
  // Terrain levels of detail (terrain/caster.h): where a pixel spans more than a grid step the
  // ground is drawn from the mean pyramid's level of its size, as a texture's MIP levels are;
  // false: the table's own surface everywhere (exact, and aliased in the distance).
  bool terrainLod = true;
  // With terrainLod: each step draws the ground one level of detail coarser than its pixels' size
  // asks (a pixel taken as 2^bias wide: a quarter of the rays' cells walked a step, blurrier in the
  // distance) — a quality level of the IG's governor (docs/ig.md).
  int terrainLodBias = 0;
  // The volumes' screen-window tolerance (VolumeSettings::windowTolerance; the CLI's
  // --volume-window-tolerance): negative, the scene's own; 0, every pixel's ray cast.
  float volumeWindowTolerance = -1;
  // How a curved-screen display's frames are pre-distorted (Renderer::renderDisplay; SPEC §12,
  // docs/display.md): the seeds' sub-frusta, each drawn through its own projective map with no
  // resampling; or a flat view with a margin, rendered and resampled bilinearly or bicubically
  // through the display mapping (the industry's way, for comparison).
  enum class Correction { subFrusta, bilinear, bicubic } correction = Correction::subFrusta;
};

// The scene with every free form replaced by triangles (issue 7's polygon baseline): marching
// tetrahedra on an interval octree in object space, cells small enough that a chord strays at most
// a quarter of a pixel from the surface at the object's nearest distance in this camera and raster
// (`options`: camera, height) — equal silhouette error with ray casting, within the resolution of
// the image. Errors name a form that is unbounded or needs over 4 million triangles. Every terrain
// becomes its full-resolution grid, two triangles a cell (issue 29's polygon baseline: the same
// heights at the same resolution, the surface linear across each triangle), with the
// interpolated surface's normals and the draped image's texture coordinates (or the colour ramp
// as vertex colours).
Result<scene::Scene> tessellatedScene(const scene::Scene& scene, const RenderOptions& options);

// By name, as the CLI's --pipeline writes them: "tiles", "segments".
Result<RenderOptions::Pipeline> parsePipeline(const std::string& text);
const char* pipelineName(RenderOptions::Pipeline pipeline);

// By name, as the CLI's --terrain-filter writes them: "scene", "bilinear", "bicubic".
Result<RenderOptions::TerrainFilter> parseTerrainFilter(const std::string& text);

// By name, as the CLI's --correction writes them: "subfrusta", "bilinear", "bicubic".
Result<RenderOptions::Correction> parseCorrection(const std::string& text);
const char* correctionName(RenderOptions::Correction correction);

// By name, as the CLI's --hsr writes them: "zbuffer", "priority", "hybrid".
Result<RenderOptions::Hsr> parseHsr(const std::string& text);
const char* hsrName(RenderOptions::Hsr hsr);

// Checks sizes and counts; the error names the option.
Status validate(const RenderOptions& options);

// The view-projection matrix a frame uses: the scene's camera `options.camera`, or for a scene
// without cameras one that frames its bounds; the aspect ratio is width / height.
Result<Mat4> viewProjection(const scene::Scene& scene, const RenderOptions& options);
// Its view matrix alone: world to eye space (the camera at the origin looking down −z), where
// lighting and fog ranges are computed.
Result<Mat4> viewMatrix(const scene::Scene& scene, const RenderOptions& options);

// One process's share of a display channel in a job of several (issue 36, docs/cluster.md): the
// channel (an index into scene.channels), and which of its tiles this process draws — all of them
// unless `tiles` is shared.
struct ChannelShare {
  int channel = 0;
  TileShare tiles;
};

// Renders scenes; keeps its threads and buffers from frame to frame.
class Renderer {
 public:
  explicit Renderer(const RenderOptions& options);  // options must pass validate()
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders `scene` into `image`. Identical bytes for any thread count.
  Status render(const scene::Scene& scene, Image& image, FrameStats* stats = nullptr);
  // Renders every display channel of `scene` (SPEC §9: one scene at one instant, N views): channel
  // i into images[i] at its own width × height, its statistics into (*stats)[i] — the options'
  // width and height are not used. The channels are drawn one after another, each frame's tiles
  // shared among all the renderer's threads. A scene without channels gives the one classic image.
  // Identical bytes for any thread count; a channel with no turn, offset or frustum of its own at
  // the options' size gives render()'s image.
  // With `only`, just those channels, ascending (the others' images are left as they are, their
  // statistics zero): one process's share of a cluster's channels. A channel shared by several
  // processes is drawn in part, and assembled in part 0's image (the other parts' images hold
  // their own tiles alone); every part renders its shared channels in the same order.
  Status renderChannels(const scene::Scene& scene, std::vector<Image>& images,
                        std::vector<FrameStats>* stats = nullptr,
                        const std::vector<ChannelShare>* only = nullptr);

  // Renders every projector of `display` (SPEC §9, §12; docs/display.md): the scene camera's
  // view from the display's eye, each projector's pixels in their own directions, pre-distorted
  // as options().correction says and edge-blended in linear light before the gamma table —
  // projector i into images[i] at its own size (the options' width and height are not used), its
  // statistics into (*stats)[i] and its correction's into (*correction)[i]. The projectors are
  // drawn one after another, each on all the renderer's threads; the frames in linear light are
  // kept for viewerImage. Identical bytes for any thread count. An error names the projector.
  // `view` moves the eye and chooses the projectors (DisplayView); a projector not drawn keeps
  // its image, statistics and correction's from the last call.
  Status renderDisplay(const scene::Scene& scene, const Display& display,
                       std::vector<Image>& images, std::vector<FrameStats>* stats = nullptr,
                       std::vector<DisplayStats>* correction = nullptr,
                       const DisplayView& view = {});
  // The simulated viewer's view of the screen (docs/display.md, "The viewer"): the frames of the
  // last renderDisplay of `display` projected onto its screen and seen from its eye, azimuth
  // −100…100°, elevation −25…25°, through the gamma table. An error for a display whose geometry
  // is not known (Display::hasGeometry) or that this renderer has not drawn.
  Result<Image> viewerImage(const Display& display) const;

  const RenderOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sv
