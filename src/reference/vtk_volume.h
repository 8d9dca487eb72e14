// VTK's CPU volume ray caster (vtkFixedPointVolumeRayCastMapper, Debian's python3-vtk9) as the
// baseline of the volume scenes (BENCH.md `volume`, issue 33): bench/vtk_volume.py, run under Xvfb
// in a child process, draws the scene's volumes as synthvis does — the same 16-bit codes, transfer
// function (at the codes' positions), opacity unit, sample distance, light, camera and image size —
// and is driven a frame at a time, so that its frames alternate with synthvis's in one run.
#pragma once

#include <memory>
#include <string>

#include "synthvis/image.h"
#include "synthvis/render.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::reference {

// What `scene` holds beside its volumes that VTK does not draw (e.g. "38 triangles"), or "".
std::string besideVolumes(const scene::Scene& scene);
// What of `scene` VTK draws: its volumes with their settings, the background, cameras, channels
// and light, without the polygons, free forms, terrain, light points and lines around them (the
// bench times both renderers on this when it compares a volume scene with VTK, and says so).
scene::Scene volumesAlone(const scene::Scene& scene);

class VtkVolumeRenderer {
 public:
  // Writes the scene's volumes and view for the script and starts it. The scene must hold
  // volumes and nothing else VTK would have to draw (polygons, free forms, terrain, light
  // points, fog, channels): the error names what is there. The script is bench/vtk_volume.py
  // of the source tree (or $SV_VTK_SCRIPT), run by /usr/bin/python3 (or $SV_VTK_PYTHON) under
  // xvfb-run when no $DISPLAY is set; a missing piece is named.
  static Result<std::unique_ptr<VtkVolumeRenderer>> create(const scene::Scene& scene,
                                                           const RenderOptions& options);
  ~VtkVolumeRenderer();
  VtkVolumeRenderer(const VtkVolumeRenderer&) = delete;
  VtkVolumeRenderer& operator=(const VtkVolumeRenderer&) = delete;

  // One frame; its time as VTK's render call took it (the pipe's round trip is not counted).
  Result<double> render();
  // The last frame (top row first, sRGB-encoded as synthvis's) — not part of a timed frame.
  Status readImage(Image& image);
  // e.g. "VTK 9.1.0 vtkFixedPointVolumeRayCastMapper".
  const std::string& description() const;

 private:
  VtkVolumeRenderer();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sv::reference
