#include "integrator/volpath/volpath.h"
#include "integrator/sampled_pass.h"

namespace candela {

PassStats VolpathPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                   const std::atomic<bool>* cancel) const {
    return render_sampled_pass<VolpathIntegrator>(scene, film, first_sample, spp, threads, cancel);
}

}  // namespace candela
