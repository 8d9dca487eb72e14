// The OpenGL reference renderer: the same scene, camera and shading model drawn through OpenGL
// on Mesa's llvmpipe, offscreen (EGL surfaceless), for `synthvis bench --renderer gl` and the
// side-by-side suites (BENCH.md). Not part of the synthvis pipeline; a yardstick for it.
//
// What "the same" means here: the view-projection of sv::viewProjection, per-vertex lighting of
// geometry/vertex_stage.cpp (material × vertex colour × (ambient + diffuse·n·l)) in the vertex
// shader, perspective-correct colour, depth test "less" with depth cleared to 1, back faces culled
// as RenderOptions and the materials say, an sRGB colour buffer (linear colour in, 8-bit sRGB
// stored: the conversion synthvis's resolve does). Textured materials: synthvis's own MIP pyramid
// uploaded level by level as SRGB8_ALPHA8 (so both renderers sample the same levels), the
// texture's wrap modes, --texture-filter mapped to the GL min/mag filters (aniso: 16×
// GL_TEXTURE_MAX_ANISOTROPY), UVs scaled by the material's uvScale, modulating the lit colour.
// The geometry is uploaded once to static buffers; a frame is clear, one draw per instance,
// the light points as one draw of blended, depth-tested point sprites, glFinish.
#pragma once

#include <memory>
#include <string>

#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::reference {

// Whether this build has the OpenGL reference (Mesa EGL and GL headers found at configure time).
bool glBuilt();

class GlRenderer {
 public:
  // Starts llvmpipe with `options.threads` rasterizer threads (LP_NUM_THREADS; the first renderer
  // of a process decides, as Mesa reads it once) and a width × height target with `msaa` samples
  // per pixel (0 = none). Errors name what is missing: the build option, EGL, the driver.
  static Result<std::unique_ptr<GlRenderer>> create(const RenderOptions& options, int msaa);
  ~GlRenderer();
  GlRenderer(const GlRenderer&) = delete;
  GlRenderer& operator=(const GlRenderer&) = delete;

  // Uploads the scene's meshes to static buffers and keeps the per-instance uniforms.
  Status load(const scene::Scene& scene);
  // Draws the loaded scene and waits for it (glFinish).
  Status render();
  // Reads back the last frame (top row first, sRGB) — not part of a timed frame.
  Status readImage(Image& image);

  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& description() const;

 private:
  GlRenderer();
  Status loadLights(const scene::Scene& scene);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sv::reference
