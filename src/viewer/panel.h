#pragma once
// The scene editors of the viewer's panel (Dear ImGui widgets). Each returns true when the user
// changed a value, so that the caller restarts the render exactly when the image changes.
#include "bsdf/bsdf.h"
#include "light/area.h"
#include "medium/medium.h"

namespace candela {

// The BSDF's model name ("diffuse", ...) as shown in the panel.
const char* bsdf_type_name(const Bsdf& b);

// Widgets for the parameters of the material's BSDF and its two-sided flag. std::visit dispatches
// to edit_bsdf(T&): a generic template that shows exactly the parameters type T has (found by their
// names: albedo, diffuse_reflectance, specular_reflectance, eta, k, int_ior, alpha, ...), so a new
// BSDF with conventional parameter names needs no viewer code; one with unusual parameters gets a
// non-template overload, which overload resolution prefers. Derived data (tables) is left to
// the render worker, which prepares the materials of every scene it builds.
bool edit_material(Material& m);

// Radiance of an area light (RGB, may exceed 1).
bool edit_emitter(AreaEmitter& e);
bool edit_light(Light& l);  // a top-level emitter's intensity, irradiance or radiance

// A participating medium's sigma_t before scale (homogeneous), albedo (unless a grid gives
// it), scale and phase g, kept within the values the loader accepts (medium_error); sigma_t and the
// majorant are derived again (refresh_medium) when one changes.
bool edit_medium(Medium& m);

}  // namespace candela
