// The path tracer as a pass object: `path`, and `volpath` in a scene without media.
#include "integrator/path/path_pass.h"
#include <cstdlib>
#include "integrator/path.h"
#include "integrator/path/wavefront.h"
#include "integrator/sampled_pass.h"

namespace candela {

PassStats PathPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                const std::atomic<bool>* cancel) const {
    // The staged loop (integrator/path/wavefront.h) where it applies: the same image, bit for bit,
    // with hit reconstruction, light samples and the diffuse step in SIMD lanes.
    // CANDELA_STAGED=0 keeps the per-path loop (for A/B measurements).
    static const bool staged = [] {
        const char* v = std::getenv("CANDELA_STAGED");
        return !(v && v[0] == '0');
    }();
    if (staged && scene.settings.sampler.type == SamplerType::Independent && staged_pass_applies(scene, film))
        return render_tiles_staged(scene, film, first_sample, spp, threads, cancel,
                                   make_sampler<IndependentSampler>(sampler_setup(scene, film)));
    return render_sampled_pass<PathIntegrator>(scene, film, first_sample, spp, threads, cancel);
}

}  // namespace candela
