// The frame's passes besides the polygons (raster/tile_pass.h), composed in tile order:
// ray-cast surfaces (free forms, then terrain), lines, volumes, light points (and stars).
#pragma once

#include <vector>

#include "freeform/freeform_pass.h"
#include "lights/light_pass.h"
#include "lines/line_pass.h"
#include "render/camera.h"
#include "render/shading_tables.h"
#include "terrain/terrain_pass.h"
#include "volume/volume_pass.h"

namespace sv::render {

// What the light pass needs of `scene` as `camera` sees it (the scene must outlive the frame).
lights::LightInput lightInput(const scene::Scene& scene, const FrameCamera& camera);

class FramePasses {
 public:
  // The passes `scene` needs under `options`, in the order they run (FrameSettings::passes): the
  // free forms when it has any, except in the debug views, which show the polygon pipeline. The
  // passes are this object's, valid until the next call.
  std::vector<raster::TilePass*> compose(const scene::Scene& scene, const RenderOptions& options,
                                         const FrameCamera& camera, const ShadingTables& shading);

 private:
  freeform::FreeFormPass freeForms_;
  terrain::TerrainPass terrains_;
  lines::LinePass lines_;
  volume::VolumePass volumes_;
  lights::LightPass lights_;
};

}  // namespace sv::render
