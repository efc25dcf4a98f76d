#pragma once
#include "scene/scene.h"
#include "sampling/sampler.h"
#include "integrator/path/bounce.h"
#include "integrator/shading.h"

namespace candela {

// Unidirectional path tracing with next-event estimation, combined with BSDF sampling by the
// power heuristic (Veach 1997) in Mis mode. Light mode counts emission only through light
// sampling (and after delta bounces); Bsdf mode only through BSDF-sampled rays. All three estimate
// the same radiance.
//
// Depth: `max_depth` counts scattering events (0: emitters seen directly, 1: direct lighting).
// At a vertex reached after k scattering events, emission is added (a path of k events) and, when
// k < max_depth, a light sample (a path of k + 1 events) and a BSDF sample for the next vertex.
// Russian roulette starts once k >= rr_depth, with survival probability
// min(max(beta) x prod(eta^2), 0.95): the eta^2 of refractions is undone so that paths inside glass
// are not cut for a change of solid-angle measure (pbrt-v4 etaScale; Mitsuba does the same).
//
// Masks (mask, null; docs/materials.md): at a masked surface of opacity a the path passes straight
// through with probability 1 - a (weight (1 - a) / (1 - a) = 1) and scatters off the nested BSDF
// otherwise. A pass-through is not a vertex: it does not count as a scattering event for max_depth,
// and the MIS bookkeeping (previous point and pdf) stays that of the last real vertex, with the
// pass-through probabilities T multiplied into the BSDF pdf. Light sampling weighs the same path
// the same way: its shadow ray crosses masks with transmittance T = prod (1 - a), contribution
// f Le T / p_light, MIS weights h(p_light, p_bsdf T) and h(p_bsdf T, p_light), which sum to one.
class PathIntegrator {
public:
    explicit PathIntegrator(const Scene& scene) : scene_(scene), masks_(scene_has_masks(scene)) {}

    // Radiance arriving along the camera ray (towards -ray.d). Template on the sampler so that the
    // independent sampler's calls are inlined; MLT instantiates it with its own sampler.
    // DiffuseOnly: the caller has checked that every material is diffuse (scene_is_diffuse_only);
    // BSDF calls then skip the variant dispatch and the code of the other lobes (issue 6: a feature a
    // scene does not use costs it nothing).
    template <class S, bool DiffuseOnly = false>
    vec3 Li(Ray ray, S& sampler, PathStats& stats) const;

private:
    const Scene& scene_;
    bool masks_;  // some material is masked: opacity tests at hits, shadow rays through masks
};

// True when every material of the scene is the diffuse BSDF without wrappers, so that
// PathIntegrator::Li can be instantiated with DiffuseOnly = true.
inline bool scene_is_diffuse_only(const Scene& scene) {
    for (const Material& m : scene.materials)
        if (!m.plain() || !std::holds_alternative<DiffuseBsdf>(m.bsdf)) return false;
    return true;
}

}  // namespace candela

#include "integrator/path_impl.h"
