#pragma once
// The closed set of BSDFs, dispatched through std::variant (no virtual calls per scattering event).
//
// Contract shared by every BSDF (all vectors in the local shading frame, n = +z, unit length):
//   wo      direction towards the previous vertex (the camera side, in Radiance mode)
//   wi      direction towards the next vertex (the light side, in Radiance mode)
//   eval    f(wo, wi) * |cos theta_i|            [1/sr], zero for delta lobes
//   pdf     density of sample() choosing wi       [1/sr, solid angle], zero for delta lobes
//   sample  wi with weight = f * |cos theta_i| / pdf; for a delta lobe pdf is the discrete
//           probability of that lobe and f carries the Dirac's weight, so only f / pdf matters.
// TransportMode says which quantity flows along the path: Radiance (camera paths) or Importance
// (light paths, for bidirectional methods), for the non-symmetric scaling of refraction.
#include <optional>
#include <variant>
#include "bsdf/diffuse.h"

namespace candela {

using Bsdf = std::variant<DiffuseBsdf>;

inline vec3 eval(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return std::visit([&](const auto& x) { return x.eval(wo, wi, mode); }, b);
}
inline float pdf(const Bsdf& b, vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) {
    return std::visit([&](const auto& x) { return x.pdf(wo, wi, mode); }, b);
}
inline std::optional<BsdfSample> sample(const Bsdf& b, vec3 wo, float u1, vec2 u2,
                                        TransportMode mode = TransportMode::Radiance) {
    return std::visit([&](const auto& x) { return x.sample(wo, u1, u2, mode); }, b);
}
// True when the BSDF has a non-delta component, so that light sampling can contribute.
inline bool has_smooth_component(const Bsdf& b) {
    return std::visit([](const auto& x) { return x.has_smooth_component(); }, b);
}

// A material as scenes name it: a BSDF plus whether both sides of the surface scatter.
// Mitsuba's BSDFs are one-sided (black from the back) unless wrapped in `twosided`; plain OBJ+MTL
// scenes are two-sided, as users of those files expect.
struct Material {
    std::string name;
    Bsdf bsdf;
    bool two_sided = false;
};

}  // namespace candela
