// The scene's free forms for the frame (SPEC §11–§12): the wiring between scene::FreeFormObject
// and the free-form pass (freeform/freeform_pass.h). tessellatedScene, the polygon baseline, is
// declared in synthvis/render.h and defined beside these.
#pragma once

#include <vector>

#include "freeform/freeform_pass.h"
#include "render/shading_tables.h"

namespace sv::render {

// The frame's free forms for the pass: each carried into the cube by projection · view · model
// (SPEC §12), lit per pixel with its material's colour and specular term (Phong whenever the scene
// has lights and the material is lit: the normal is exact at every pixel), both sides lit. A
// texture is projected along the object's y axis (freeform/freeform_pass.h). Free forms are always
// opaque. A form with a singular placement shows nothing and is left out.
std::vector<freeform::ShadedForm> makeShadedForms(const scene::Scene& scene, const Mat4& view,
                                                  const Mat4& projection,
                                                  const ShadingTables& shading);

}  // namespace sv::render
