#pragma once
#include "core/math.h"

namespace candela {

enum class TransportMode { Radiance, Importance };

// eval() and pdf() of one direction pair, from one evaluation: f |cos theta_i| and the solid-angle
// density of sample(). Next-event estimation needs both (the pdf for MIS), and the microfacet
// lobes share their half vector, D and G1 between them, as Mitsuba 3's eval_pdf does.
struct BsdfEval {
    vec3 f{0.f};
    float pdf = 0.f;
};

struct BsdfSample {
    vec3 f{0.f};       // f * |cos theta_i| (see bsdf.h for delta lobes)
    vec3 wi{0.f};      // sampled direction, local frame
    float pdf = 0.f;   // solid-angle density, or the lobe's discrete probability for delta lobes
    bool delta = false;
    // Relative IOR crossed: n(wi side) / n(wo side); 1 for reflection. Radiance is scaled by
    // 1 / eta^2 through a refraction, which Russian roulette undoes so as not to kill paths in glass.
    float eta = 1.f;
    vec3 weight() const { return pdf > 0.f ? f / pdf : vec3(0.f); }
};

}  // namespace candela
