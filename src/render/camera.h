// The frame's camera (SPEC §1 stage 2): the scene's, or one that frames a scene without cameras.
#pragma once

#include "synthvis/render.h"

namespace sv::render {

struct FrameCamera {
  scene::Camera camera;  // as placed in the world
  Mat4 view;             // world → eye (the camera at the origin looking down −z)
  Mat4 projection;       // eye → clip, aspect width / height
};

// The camera `options.camera` of the scene (an error names one that does not exist), or for a
// scene without cameras one that frames its bounds.
Result<FrameCamera> chooseCamera(const scene::Scene& scene, const RenderOptions& options);

}  // namespace sv::render
