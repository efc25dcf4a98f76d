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
    // with the diffuse hits' reconstruction, shading, light samples and BSDF samples in SIMD lanes.
    // CANDELA_STAGED=0 keeps the per-path loop (for A/B measurements).
    static const bool staged = [] {
        const char* v = std::getenv("CANDELA_STAGED");
        return !(v && v[0] == '0');
    }();
    if (staged && staged_pass_applies(scene, film))
        return render_staged_sampled_pass(scene, film, first_sample, spp, threads, cancel);
    return render_sampled_pass<PathIntegrator>(scene, film, first_sample, spp, threads, cancel);
}

}  // namespace candela
