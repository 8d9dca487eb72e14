#include "render/passes.h"

#include "render/freeforms.h"
#include "render/terrains.h"

namespace sv::render {

lights::LightInput lightInput(const scene::Scene& scene, const FrameCamera& camera) {
  lights::LightInput in;
  in.appearances = scene.lightAppearances;
  in.points = scene.lightPoints;
  in.groups = scene.lightGroups;
  in.settings = scene.lightSettings;
  in.stars = scene.stars.stars.empty() ? nullptr : &scene.stars;
  in.time = scene.time;
  in.view = camera.view;
  in.projection = camera.projection;
  in.fogBeta = scene.fog.enabled ? scene.fog.beta : 0.0f;
  in.subset = camera.lightSubset;
  in.laws = camera.lightLaws;
  return in;
}

std::vector<raster::TilePass*> FramePasses::compose(const scene::Scene& scene,
                                                    const RenderOptions& o,
                                                    const FrameCamera& camera,
                                                    const ShadingTables& shading) {
  std::vector<raster::TilePass*> passes;
  if (o.debugView != RenderOptions::DebugView::none) return passes;
  if (!scene.freeForms.empty()) {
    freeForms_.setForms(
        makeShadedForms(scene, camera.view, camera.projection, shading), &shading.environment,
        freeform::CastSettings{.masking = true, .adaptiveSamples = !o.freeFormEverySample},
        o.freeFormMethod == RenderOptions::FreeFormMethod::march ? o.marchSteps : 0);
    passes.push_back(&freeForms_);
  }
  if (!scene.terrains.empty()) {
    const EyeRays rays = eyeRays(camera);
    terrains_.setTerrains(terrainDraws(scene, rays, shading, o), rays, shading.environment);
    passes.push_back(&terrains_);
  }
  if (!scene.lines.empty()) {
    lines_.setLines(lines::LineInput{scene.lines, scene.lineSettings, camera.view,
                                     camera.projection, scene.fog.enabled, scene.fog.color,
                                     scene.fog.beta});
    passes.push_back(&lines_);
  }
  if (!scene.volumes.empty()) {
    volume::VolumeInput in;
    in.volumes = &scene.volumes;
    in.settings = scene.volumeSettings;
    if (o.volumeWindowTolerance >= 0) in.settings.windowTolerance = o.volumeWindowTolerance;
    in.rays = eyeRays(camera);
    in.viewProjection = camera.projection * camera.view;
    in.lightOn = scene.light.enabled;
    in.toLight = normalize(scene.light.direction * -1.0f);
    in.lightColor = scene.light.color;
    in.ambient = scene.light.ambient;
    if (scene.fog.enabled) in.fogBeta = scene.fog.beta, in.fogColor = scene.fog.color;
    volumes_.setVolumes(in);
    passes.push_back(&volumes_);
  }
  // A view given a subset of no light (a sub-frustum cell no light reaches) has no light pass:
  // no visibility kept a tile, no wavefront.
  const bool noLight = camera.lightSubset && camera.lightSubset->empty();
  if ((!scene.lightPoints.empty() || !scene.stars.stars.empty()) && !noLight) {
    lights_.setLights(lightInput(scene, camera));
    passes.push_back(&lights_);
  }
  return passes;
}

}  // namespace sv::render
