// Seeded, deterministic benchmark scenes exactly as shared BENCH.md defines them (src/generators,
// beside the bench harness that runs them).
#pragma once

#include <cstdint>
#include <string>

#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::generators {

using scene::Scene;

// BENCH.md's generators, one per kind of benchmark scene. `none`: a scene from a file.
enum class Generator : uint8_t {
  none,
  tris,
  layers,
  grazing,
  freeform,
  freeformOne,
  terrain,
  volume,
  lights,
  city,
};
// By name, as BENCH.md and the CLI write them: "tris", "layers", "grazing", "freeform",
// "freeform-one", "terrain", "volume", "lights", "city"; an error lists them.
Result<Generator> parseGenerator(const std::string& name);
const char* generatorName(Generator generator);  // "" for none

enum class SubmitOrder { random, frontToBack, backToFront };

// Parses "random", "f2b", "b2f".
Result<SubmitOrder> parseSubmitOrder(const std::string& text);
const char* submitOrderName(SubmitOrder order);

// BENCH.md `tris`: random triangles for raw rasterization and fill.
struct TrisParams {
  int count = 10000;
  double area = 100;  // mean projected area in pixels
  double depth =
      0;  // 0: centroids over the whole screen; else a centred region of area count·area/depth
  SubmitOrder order = SubmitOrder::random;
  uint64_t seed = 1;
  int width = 1920;  // the raster the areas refer to
  int height = 1080;
  // BENCH.md --shade textured: the material samples a 1024×1024 noise texture (texture 0). The
  // UVs, 0.5–4 texels per pixel (log-uniform per triangle), are generated either way.
  bool textured = false;
  bool fog = false;  // BENCH.md --fog: addBenchFog
};

// What the generator realized (BENCH.md asks for both).
struct TrisStats {
  double meanArea = 0;         // mean projected area of the triangles, pixels
  double depthComplexity = 0;  // total on-screen area / region area
};

// One camera (60° vertical field of view, looking down −Z, near 0.1), one unlit double-sided mesh
// of unshared vertices with random colours; triangles in the requested order.
Scene generateTris(const TrisParams& params, TrisStats* stats = nullptr);

// BENCH.md `layers`: `layers` parallel screen-filling grids of ≈ 200 px triangles at distances
// 2 … 20, so every pixel is covered `layers` times; same camera and material as `tris`. UVs give
// each layer its own offset and density (0.5–4 texels per pixel, log-uniform) on the bench texture.
struct LayersParams {
  int layers = 4;
  SubmitOrder order = SubmitOrder::random;
  uint64_t seed = 1;
  int width = 1920;
  int height = 1080;
  bool textured = false;  // as TrisParams
  bool fog = false;
};
Scene generateLayers(const LayersParams& params, TrisStats* stats = nullptr);

// BENCH.md `grazing`: a 1 km ground plane with seed 001's random texture seen from 2 m toward the
// horizon, and five cubes (thirty faces) with a squares texture, lit, Phong on the cubes — the
// scene of scenes/grazing.json without its glTF crate. `fog`: haze in the background colour.
struct GrazingParams {
  uint64_t seed = 1;  // the textures' noise
  bool fog = false;
};
Scene generateGrazing(const GrazingParams& params);

// BENCH.md `freeform`: `count` perturbed quadrics — spheres, ellipsoids, capped cylinders and
// capped paraboloids with 1–5 perturbations each (bumps and dents), randomly turned — spread over
// the view 5 … 25 m away with partial overlaps, eight Phong materials, a directional light, fog.
// No triangles: every object is a Scene::freeForms entry, ray cast (SPEC §12).
struct FreeFormParams {
  int count = 100;
  uint64_t seed = 1;
  int width = 1920;  // the aspect the objects are spread over
  int height = 1080;
};
Scene generateFreeForms(const FreeFormParams& params);
// BENCH.md `freeform-one`: a unit sphere with six R = w·Q³ perturbations on its surface,
// alternately bumps and dents (spheres and ellipsoids), Phong-lit, seen in perspective (render it
// at 1024 × 1024).
Scene generateFreeFormOne();

// BENCH.md `terrain`: a seeded fractal height field of `size` × `size` samples over a fixed
// 40.96 km square (so a larger table is finer ground, the same view: the cost of more heights
// alone), 1 200 m of relief, draped with a 2048² image coloured by height and seed 001's noise,
// lit by a low sun, with haze (half the colour every 12 km); the camera 300 m above the ground at
// the map's centre looking toward the horizon (8° down, 60° vertical field of view, near 1 m,
// far 60 km). `bicubic`: Catmull–Rom below the finest level (else bilinear).
struct TerrainParams {
  int size = 4096;
  uint64_t seed = 1;
  bool bicubic = false;
};
Result<Scene> generateTerrain(const TerrainParams& params);

// BENCH.md `lights`: `count` light points over the `layers` D = 1 scene (its screen-filling grid at
// view distance 2, its camera: 60°, looking down −Z): the Bright Star Catalogue when `starCatalog`
// names it (behind the grid: every star projected and tested, none seen), then runway-like
// strings (a quarter: pairs of edge rows and a centreline running away from the eye, directional,
// some blinking in sequence) and a city grid (the rest: omnidirectional, warm), all in front of
// the grid at view distances 0.15 … 1.9, sized 1.5 … 4 px. Lights are in scene units: intensity
// and exposure are set for that scale.
struct LightsParams {
  int count = 100000;
  uint64_t seed = 1;
  int width = 1920;
  int height = 1080;
  std::string starCatalog;  // xplanet's BSC; empty: no stars
};
Result<Scene> generateLights(const LightsParams& params);

// BENCH.md `city` (issue 32): a town of `buildings` blocks 40 m apart in a square, one building each
// (eight kinds, 4–25 storeys, walls of separate window quads: 1 000–4 000 triangles; a 10-triangle
// box beyond 250 m) turned by multiples of 90°, and `trees` trees scattered between them (three
// kinds, scaled 0.8–1.3, turned: 420 triangles to 100 m, 72 to 400 m, 8 to 1.5 km, none beyond),
// every level switch dissolving; on a ground quad, lit by the sun, with haze; the camera 150 m up
// at the south-west corner looking across (60°, near 1 m, far 8 km). Instanced: one mesh per kind
// and level; the instance tree built.
struct CityParams {
  int buildings = 10000;
  int trees = 100000;
  uint64_t seed = 1;
};
Scene generateCity(const CityParams& params);

// BENCH.md's `volume`: a size³ 8-bit grid over [−1, 1]³ of the Marschner–Lobb signal inside a
// sphere and seeded blobs, classified so that the emptiest 70 % of its samples are transparent —
// translucent and shaded, or `opaque` (iso-surface-like: fully opaque above the threshold) — in a
// free-form shell: the smallest sphere about its centre holding every cell that is not
// transparent (unless !shell); the camera 3.4 units from its centre (45°), lit from the upper
// left.
struct VolumeParams {
  int size = 256;  // 8 … 512
  bool opaque = false;
  bool precomputedNormals = false;  // VolumeSettings::precomputedNormals
  bool shell = true;
  uint64_t seed = 1;
};
Scene generateVolume(const VolumeParams& params);

// The frame every generated scene shares: one instance of mesh 0 with material 0 (unlit,
// double-sided, named `name`), the BENCH.md camera, no light, black background. No meshes yet.
Scene benchCameraScene(const std::string& name);
// BENCH.md's texture for --shade textured: a 1024 × 1024 noise texture as texture 0, used by every
// material of `s`.
void addBenchTexture(Scene& s);
// BENCH.md's fog for --fog: grey-blue haze with β = 0.1 per unit, so that the generated scenes'
// nearest surfaces (distance 2) keep 87 % of their colour and the farthest (20) a quarter.
void addBenchFog(Scene& s);

}  // namespace sv::generators
