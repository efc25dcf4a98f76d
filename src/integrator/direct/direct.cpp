#include "integrator/direct/direct.h"
#include "integrator/tiles.h"

namespace candela {

PassStats DirectPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                  const std::atomic<bool>* cancel) const {
    return render_integrator_pass<DirectIntegrator>(scene, film, first_sample, spp, threads, cancel);
}

}  // namespace candela
