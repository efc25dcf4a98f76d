// The path tracer as a pass object: `path`, and `volpath` in a scene without media.
#include "integrator/path/path_pass.h"
#include "integrator/path.h"
#include "integrator/tiles.h"

namespace candela {

namespace {

template <bool DiffuseOnly>
PassStats run(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
              const std::atomic<bool>* cancel) {
    PathIntegrator integrator(scene);
    return render_tiles(scene, film, first_sample, spp, threads, cancel,
                        [&](IndependentSampler& sampler, Ray ray, PathStats& ps) {
                            return integrator.template Li<IndependentSampler, DiffuseOnly>(ray, sampler, ps);
                        });
}

}  // namespace

PassStats PathPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                const std::atomic<bool>* cancel) const {
    // Chosen per pass, so that a material edited in the viewer (which restarts the accumulation)
    // switches the instantiation too. Both give the same image: the specialisation only drops code.
    if (scene_is_diffuse_only(scene)) return run<true>(scene, film, first_sample, spp, threads, cancel);
    return run<false>(scene, film, first_sample, spp, threads, cancel);
}

}  // namespace candela
