#include "integrator/direct/direct.h"
#include "integrator/tiles.h"

namespace candela {

namespace {

template <bool DiffuseOnly>
PassStats run(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
              const std::atomic<bool>* cancel) {
    DirectIntegrator integrator(scene);
    return render_tiles(scene, film, first_sample, spp, threads, cancel,
                        [&](IndependentSampler& sampler, Ray ray, PathStats& ps) {
                            return integrator.template Li<IndependentSampler, DiffuseOnly>(ray, sampler, ps);
                        });
}

}  // namespace

PassStats DirectPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                  const std::atomic<bool>* cancel) const {
    if (scene_is_diffuse_only(scene)) return run<true>(scene, film, first_sample, spp, threads, cancel);
    return run<false>(scene, film, first_sample, spp, threads, cancel);
}

}  // namespace candela
