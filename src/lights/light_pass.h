// Light points in the frame (SPEC §13): the last pass of a tile (raster/tile_pass.h, stage
// `lights`), after the translucent polygons. Each light becomes an anti-aliased splat added in
// linear light to the samples of the pixels it reaches, its energy conserved whatever its size
// and sub-pixel position; hidden where the frame's surface at its centre is nearer.
//
// Per frame (prepare, in parallel over chunks of lights): every light projected, culled (behind
// the eye, off screen, off, dark, beyond the far plane), its blink, lobe, fog, energy, size and
// weight sum worked out (lights/light_laws.h), then listed for every tile its splat reaches, in
// light order. Per tile, once its depth is final (seeTile): the visibility of every light whose
// centre pixel lies inside its one-pixel border, from the depth around that pixel — all in the
// tile — and the border's depth kept. Per tile, once every tile around it has been seen
// (drawTile): the visibility of its lights centred on a border, from the kept borders, then every
// light's weights, times its visibility, added into its colour samples. Depth is left as it was.
// A splat reaches at most 33 px from its centre pixel, so what a tile's lights read lies in the
// eight tiles around it (FrameRenderer draws the frame as a wavefront: docs/lights.md).
#pragma once

#include <span>
#include <vector>

#include "lights/light_laws.h"
#include "lights/splat_sizes.h"
#include "raster/tile_lists.h"
#include "raster/tile_pass.h"
#include "synthvis/light_points.h"

namespace sv::lights {

class LightLaws;

// The eye of a view (world → eye, rigid) in the world, as the pass finds it: −Rᵀ t, in double (so
// that channels turned from one camera find the same eye).
Vec3 viewEye(const Mat4& view);

// What the pass needs of the scene and the frame's camera (render fills it; the spans and the
// star field must outlive the frame).
struct LightInput {
  std::span<const scene::LightAppearance> appearances;
  std::span<const scene::LightPoint> points;
  std::span<const scene::LightGroup> groups;
  scene::LightSettings settings;
  const scene::StarField* stars = nullptr;
  double time = 0;    // seconds
  Mat4 view;          // world → eye
  Mat4 projection;    // eye → clip (OpenGL conventions: depth row −m22 + m32 / s)
  float fogBeta = 0;  // the scene's fog β, 0 without fog
  // Only these lights, when the caller has culled them for the view (indices into the points,
  // then the stars, ascending; it must outlive the frame): a sub-frustum cell's (render/warped.h).
  // Nothing: every light. The frame is the same as with every light as long as the subset holds
  // every light whose splat reaches the view.
  const std::vector<uint32_t>* subset = nullptr;
  // The points' laws for this frame, when the caller worked them out once for several views of
  // one eye (LightLaws; it must outlive the frame): their eye is used, not the view's. Nothing:
  // worked out here, at the view's eye.
  const LightLaws* laws = nullptr;
};

// What a frame's light points are, whatever the view, for one eye (issue 60: worked out once for
// every display channel that shares it, per channel only the projection): per point, off (its
// group off, blinked out, at the eye) or its on-screen energy and colour — the lobes, the PAPI
// split, the fog by range. The same bits as the pass works out for a view whose eye it is.
class LightLaws {
 public:
  struct Point {
    float energy = -1;  // < 0: off
    float r = 0, g = 0, b = 0;
  };
  // `in`'s points (every one: the subset is not read) at viewEye(in.view), in parallel on `pool`.
  void compute(const LightInput& in, core::ThreadPool& pool);
  Vec3 eye() const { return eye_; }
  const Point& point(size_t i) const { return points_[i]; }

 private:
  Vec3 eye_;
  std::vector<Point> points_;
};

// The eye-frame positions of `in`'s lights under in.view, in the pass's order (the points, then
// the stars): (x, y, z, 1) for a point, (x, y, z, 0) — a direction, at infinity — for a star. For a
// caller culling lights for many views at once (LightInput::subset).
void lightEyePositions(const LightInput& in, std::vector<Vec4>& out);

// One light as the frame draws it.
struct Splat {
  float x = 0, y = 0;    // raster position, pixels (pixel centres at i + ½)
  float eyeDepth = 0;    // the light's depth along the view axis, clip w (s > 0); 0 for a star
  float radius = 1;      // the kernel's, pixels (light_laws.h: splatRadius)
  float rgb[3] = {};     // Φ · colour · 65535 / Σw: a weight-1 pixel's 16-bit addition
  float frontDepth = 1;  // the window depth depthBias in front of the light (a star: 1)
  // The kernel's pixel centres: columns firstX … firstX + spanX − 1, rows likewise. A splat of at
  // most kKeptSpan a side keeps its axis weights (worked out once, for the weight sum, and read
  // again by every tile it reaches); a larger one's are worked out again where it is drawn.
  static constexpr int kKeptSpan = 4;
  int firstX = 0, firstY = 0;
  int spanX = 0, spanY = 0;
  float kx[kKeptSpan] = {}, ky[kKeptSpan] = {};
  uint32_t light = 0;  // its place among the frame's candidates (points, then stars, or subset)
};

class LightPass final : public raster::TilePass {
 public:
  void setLights(const LightInput& input);

  raster::PassStage stage() const override { return raster::PassStage::lights; }
  void prepare(const raster::PassFrame& frame) override;
  // In a shared frame (PassFrame::share): the depths every splat's visibility reads — its centre
  // pixel's samples and the first sample of the eight around it — from the parts that drew them;
  // then every splat's visibility (seeTile does nothing).
  Status exchange() override;
  void seeTile(const raster::TileTarget& tile) override;
  void drawTile(const raster::TileTarget& tile) override;
  void addStats(FrameStats& stats) const override;

  // The frame's splats in light order (after prepare), a copy: for tests and the gl reference.
  std::vector<Splat> splats() const;

 private:
  // Lights [begin, end) of the input (stars after the points), or of its subset, into `out`.
  void projectRange(size_t begin, size_t end, std::vector<Splat>& out) const;
  // A light's raster position, eye depth, on-screen energy and colour into lane `i` of `batch`
  // (sized and weighed 16 at a time: lights/splat_sizes.h); false where it is culled first
  // (off, blinked out, behind the eye, beyond the far plane, below the star field's limit).
  bool projectPoint(size_t index, SizeBatch& batch, int i) const;
  bool projectStar(const scene::Star& star, SizeBatch& batch, int i) const;
  // Calls f(tile index) for every tile the splat's kernel square reaches.
  template <class F>
  void forTiles(const Splat& s, F&& f) const;
  // The fraction of the centre pixel's samples that do not hide splat `s`, from depthAt(x, y,
  // sample) (in the frame: 0 ≤ x < width, 0 ≤ y < height; the centre pixel and the eight around).
  template <class DepthAt>
  float visibilityFrom(const Splat& s, DepthAt&& depthAt) const;
  // The same from a shared frame's exchanged probes.
  float visibilityFromProbes(const Splat& s) const;
  // The same, for a splat centred on its tile's outermost pixels, from the borders seeTile kept.
  float visibilityFromBorders(const Splat& s) const;
  // A shared frame's probes per splat: the centre pixel's n samples, then these (the eight
  // neighbours' first samples).
  static constexpr int kNeighbourProbes = 8;
  float eyeDepthOf(float windowDepth) const;

  LightInput in_;
  raster::PassFrame frame_;
  float m22_ = 0, m32_ = 1, zfar_ = 1;  // the projection's depth row, its far plane
  SizeLaws sizeLaws_;                   // the frame's, for sizeSplats
  Vec3 eye_;
  Vec3 starAxes_[3];                        // equatorial x, y, z in world at this frame's time
  std::vector<LobeTangents> lobeTangents_;  // per appearance, this frame
  std::vector<std::vector<Splat>> chunks_;  // the drawn splats, chunk by chunk, in light order
  int tilesX_ = 0;
  size_t tiles_ = 0;
  raster::TileLists<Splat> tileSplats_;  // every tile's splats, in light order
  // Visibilities (seeTile), for drawTile: per list entry, a splat's whose centre tile is the list's
  // own and centre pixel inside its border, read in list order — or −1: then the splat's in
  // visible_ (per candidate; written only for splats that reach beyond their centre tile, so the
  // workers seldom share its lines), or, centred on a border, worked out from borders_.
  std::vector<float> entryVisible_;
  std::vector<float> visible_;
  // Per tile (seeTile): the depth of its outermost pixels, every sample, then of the ring inside
  // them, the first sample — what a border-centred light's visibility reads (light_pass.cpp).
  std::vector<float> borders_;
  std::vector<double> workerMs_;
  double prepareMs_ = 0, exchangeMs_ = 0;
  uint64_t candidates_ = 0;
  // A shared frame's probes (exchange): per drawn splat, in light order, its centre pixel's
  // samples then its neighbours' first samples; where each candidate's start (slot × stride).
  std::vector<float> probes_;
  std::vector<uint32_t> probeAt_;
};

}  // namespace sv::lights
