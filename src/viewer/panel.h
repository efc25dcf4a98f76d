#pragma once
// The scene editors of the viewer's panel (Dear ImGui widgets). Each returns true when the user
// changed a value, so that the caller restarts the render exactly when the image changes.
#include "bsdf/bsdf.h"
#include "light/area.h"

namespace candela {

// The BSDF's model name ("diffuse", ...) as shown in the panel.
const char* bsdf_type_name(const Bsdf& b);

// Widgets for the parameters of the material's BSDF (dispatched by std::visit: one overload per
// BSDF type, so a new BSDF needs one new function) and its two-sided flag.
bool edit_material(Material& m);

// Radiance of an area light (RGB, may exceed 1).
bool edit_emitter(AreaEmitter& e);

}  // namespace candela
