// The direct pass with the orthogonal sampler, in its own translation unit (integrator/sampled_pass.h).
#include "integrator/sampled_pass.h"

namespace candela {

template PassStats render_pass_for<DirectIntegrator, OrthogonalSampler>(const Scene&, Film&, uint32_t, int, int, const std::atomic<bool>*);

}  // namespace candela
