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

extern template PassStats render_pass_for<PathIntegrator, StratifiedSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<DirectIntegrator, StratifiedSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<PathIntegrator, MultijitterSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<DirectIntegrator, MultijitterSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<PathIntegrator, LdSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<DirectIntegrator, LdSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<PathIntegrator, SobolSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<DirectIntegrator, SobolSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<PathIntegrator, ZSobolSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<DirectIntegrator, ZSobolSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<PathIntegrator, OrthogonalSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);
extern template PassStats render_pass_for<DirectIntegrator, OrthogonalSampler>(const Scene&, Film&, uint32_t, int, int,
                                                         const std::atomic<bool>*);

template <class S>
struct SamplerTag {
    using type = S;
};

template <class Integrator>
PassStats render_sampled_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                              const std::atomic<bool>* cancel) {
    auto pass = [&](auto tag) {
        using S = typename decltype(tag)::type;
        return render_pass_for<Integrator, S>(scene, film, first_sample, spp, n_threads, cancel);
    };
    switch (scene.settings.sampler.type) {
        case SamplerType::Stratified: return pass(SamplerTag<StratifiedSampler>{});
        case SamplerType::Multijitter: return pass(SamplerTag<MultijitterSampler>{});
        case SamplerType::LdSampler: return pass(SamplerTag<LdSampler>{});
        case SamplerType::Sobol: return pass(SamplerTag<SobolSampler>{});
        case SamplerType::ZSobol: return pass(SamplerTag<ZSobolSampler>{});
        case SamplerType::Orthogonal: return pass(SamplerTag<OrthogonalSampler>{});
        case SamplerType::Independent: break;
    }
    return pass(SamplerTag<IndependentSampler>{});
}

}  // namespace candela
