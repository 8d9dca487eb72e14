// The frame's settings for setup and the tiles (render::FrameSettings), from the options.
#pragma once

#include "render/frame_renderer.h"

namespace sv::render {

// The raster (k times larger when supersampling by k), clear colour, what a covered pixel does
// (the debug views, pixel shading when `pixelShading`, else Gouraud), samples, masking, and with
// anti-aliasing the batch size that keeps the sample buffer within memory for `triangles` — an
// error when even that needs over 4 GB. No tile sink and no passes yet.
Result<FrameSettings> makeFrameSettings(const RenderOptions& options, Vec3 background,
                                        const shade::Environment& environment, bool pixelShading,
                                        size_t triangles);

}  // namespace sv::render
