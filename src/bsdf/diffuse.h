#pragma once
#include <optional>
#include "bsdf/common.h"
#include "sampling/warp.h"

namespace candela {

// Ideal diffuse (Lambertian) reflection: f = albedo / pi on the upper hemisphere. One-sided like
// Mitsuba 3's `diffuse`: zero unless both wo and wi are above the surface. Sampled with the cosine-
// weighted hemisphere, so the weight f cos / pdf is exactly the albedo.
struct DiffuseBsdf {
    vec3 albedo{0.5f};

    vec3 eval(vec3 wo, vec3 wi, TransportMode) const {
        if (wo.z <= 0.f || wi.z <= 0.f) return vec3(0.f);
        return albedo * (kInvPi * wi.z);
    }
    float pdf(vec3 wo, vec3 wi, TransportMode) const {
        if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
        return square_to_cosine_hemisphere_pdf(wi);
    }
    BsdfEval eval_pdf(vec3 wo, vec3 wi, TransportMode) const {
        if (wo.z <= 0.f || wi.z <= 0.f) return {};
        return {albedo * (kInvPi * wi.z), square_to_cosine_hemisphere_pdf(wi)};
    }
    std::optional<BsdfSample> sample(vec3 wo, float, vec2 u, TransportMode) const {
        if (wo.z <= 0.f) return std::nullopt;
        BsdfSample s;
        s.wi = square_to_cosine_hemisphere(u);
        if (s.wi.z <= 0.f) return std::nullopt;  // u on the disk's rim: a zero-measure set
        s.pdf = square_to_cosine_hemisphere_pdf(s.wi);
        s.f = albedo * (kInvPi * s.wi.z);
        return s;
    }
    bool has_smooth_component() const { return true; }
};

}  // namespace candela
