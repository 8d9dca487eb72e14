// The frame's camera (SPEC §1 stage 2): the scene's, or one that frames a scene without cameras.
#pragma once

#include <cstdint>
#include <vector>

#include "core/eye_rays.h"
#include "synthvis/render.h"

namespace sv::lights {
class LightLaws;
}

namespace sv::render {

struct FrameCamera {
  scene::Camera camera;  // the scene's camera in the world (a channel's view is turned from it)
  Mat4 view;             // world → eye (the camera at the origin looking down −z)
  Mat4 projection;       // eye → clip: the view window below onto the raster
  // The view window at unit eye depth: the ray through raster point (px, py) of a W × H raster is
  // (tanLeft + (tanRight − tanLeft)·px/W, tanTop − (tanTop − tanBottom)·py/H, −1) in eye space.
  // Symmetric for the classic view; a channel's may be asymmetric (SPEC §9). Whatever needs rays
  // or pixel sizes (terrain, free-form tessellation) reads these, never the camera's yfov.
  double tanLeft = -1, tanRight = 1, tanBottom = -1, tanTop = 1;
  // The projection is not a window but a sub-frustum's projective map (SPEC §12, distortion
  // correction: render/warped.h): rays come from its inverse (eyeRays), and the window above is
  // the display channel's whole, for what is chosen per frame rather than per pixel (levels of
  // detail), so that every cell of a display chooses alike.
  bool projective = false;
  // The lights this view can show, when its caller culled them for it (lights::LightInput::subset:
  // a sub-frustum cell's, culled for every cell at once); nothing: every light.
  const std::vector<uint32_t>* lightSubset = nullptr;
  // The light points' laws, when the caller worked them out once for several views sharing this
  // view's eye (lights::LightInput::laws); nothing: the view works them out.
  const lights::LightLaws* lightLaws = nullptr;
};

// The camera's rays through its raster (the terrain and volume passes').
EyeRays eyeRays(const FrameCamera& camera);

// The camera `options.camera` of the scene (an error names one that does not exist), or for a
// scene without cameras one that frames its bounds; its window is yfov high, aspect
// options.width / options.height.
Result<FrameCamera> chooseCamera(const scene::Scene& scene, const RenderOptions& options);

// Display channel `channel` (SPEC §9) of the camera chooseCamera picks: its view is the camera's
// turned by the channel's yaw, pitch and roll and moved by its offset (scene.h, Channel); its
// projection is the channel's frustum (Mat4::frustum), or without one the camera's yfov at the
// channel's aspect. A channel with no turn, no offset and no frustum at the options' size is the
// classic view exactly (the same matrices, bit for bit).
Result<FrameCamera> channelCamera(const scene::Scene& scene, const RenderOptions& options,
                                  const scene::Channel& channel);

}  // namespace sv::render
