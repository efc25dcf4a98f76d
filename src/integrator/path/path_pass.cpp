// The path tracer as a pass object: `path`, and `volpath` in a scene without media.
#include "integrator/path/path_pass.h"
#include "integrator/path.h"
#include "integrator/sampled_pass.h"

namespace candela {

PassStats PathPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                const std::atomic<bool>* cancel) const {
    return render_sampled_pass<PathIntegrator>(scene, film, first_sample, spp, threads, cancel);
}

}  // namespace candela
