// The path pass (per-path and staged loops) with the sobol sampler, in its own translation unit (integrator/sampled_pass.h).
#include "integrator/path/wavefront.h"
#include "integrator/sampled_pass.h"

namespace candela {

template PassStats render_pass_for<PathIntegrator, SobolSampler>(const Scene&, Film&, uint32_t, int, int, const std::atomic<bool>*);
template PassStats render_staged_for<SobolSampler>(const Scene&, Film&, uint32_t, int, int, const std::atomic<bool>*);

}  // namespace candela
