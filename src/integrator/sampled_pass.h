#pragma once
// The pass of a per-ray integrator with the scene's sampler: a dispatch once per pass to the
// instantiation of the tile loop for that sampler type (integrator/tiles.h render_pass_for). The
// independent sampler's is instantiated where this is called (the integrator's translation unit,
// where it always was); the others are compiled once each in integrator/samplers/<integrator>_<sampler>.cpp, so
// their inlining does not change the independent loop's (measured: docs/samplers.md).
#include "integrator/direct/direct.h"
#include "integrator/path.h"
#include "integrator/tiles.h"

namespace candela {

#define CANDELA_PASS_EXTERN(S)                                                                                   \
    extern template PassStats render_pass_for<PathIntegrator, S>(const Scene&, Film&, uint32_t, int, int,             \
                                                                 const std::atomic<bool>*);                           \
    extern template PassStats render_pass_for<DirectIntegrator, S>(const Scene&, Film&, uint32_t, int, int,           \
                                                                   const std::atomic<bool>*);
CANDELA_FOR_EACH_SAMPLER_COMPILED_APART(CANDELA_PASS_EXTERN)
#undef CANDELA_PASS_EXTERN

template <class Integrator>
PassStats render_sampled_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                              const std::atomic<bool>* cancel) {
    return visit_sampler_type(scene.settings.sampler.type, [&](auto tag) {
        using S = typename decltype(tag)::type;
        return render_pass_for<Integrator, S>(scene, film, first_sample, spp, n_threads, cancel);
    });
}

}  // namespace candela
