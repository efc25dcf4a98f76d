#pragma once
#include "integrator/integrator.h"

namespace candela {

// Passes of the path tracer (integrator/path.h: NEE + MIS, Russian roulette, hide_emitters).
class PathPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

}  // namespace candela
