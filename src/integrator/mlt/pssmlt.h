#pragma once
// Primary-sample-space Metropolis light transport over the path tracer (Kelemen et al. 2002;
// docs/mlt.md). A state is a PssSampler vector; its first two coordinates pick the film position
// (pixel and jitter), the rest are the path tracer's, drawn in its fixed order (path_impl.h). The
// scalar contribution I = luminance of the path's radiance.
//
// Bootstrap: `bootstrap_samples` independent states (iteration 0 of PssSampler(seed, i)) give
// b = mean I (the image's mean luminance) and the chains' start states, drawn in proportion to I.
// Each mutation proposes y from x, accepts with a = min(1, I(y)/I(x)), and splats both states by
// Veach's expected values: y with a b / I(y), x with (1 - a) b / I(x). The film's splat
// normalisation (pixels / mutations) then makes a pixel its share of b's image.
//
// Passes: sample index s of the render is one mutation per pixel in total, shared out over the
// chains (chain c makes floor((c+1) N / C) - floor(c N / C) of them); each chain's splats go to its
// own SplatTile, merged in chain order (splat_pass_units). The chains' states persist between
// passes (a process-wide cache keyed by the scene and film), so the image of samples [0, n) is the
// same bit for bit however the passes split it and whatever the thread count. A pass that does not
// continue the cached chains (another scene, a restart at sample 0, a resumed checkpoint) rebuilds
// them and replays the mutations up to its first sample without splatting.
#include <cstdint>
#include "integrator/integrator.h"

namespace candela {

class PssmltPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

// Multiplexed MLT over BDPT (Hachisuka et al. 2014): the same chains, each at a path length (depth)
// drawn with its start state from the bootstrap (state i has depth i mod (max depth + 1)), its
// states of three streams (camera path, light path, connection) evaluated by one BDPT strategy
// (s, t) of that depth chosen by the connection stream, weighted by MIS over the depth's strategies
// (Bdpt::sample_strategy). An unbounded max depth is capped at 12 scattering events.
class MmltPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

// The chains' statistics after the last pssmlt or mmlt pass (for the viewer's panel and the tests).
struct MltStats {
    double b = 0;          // the bootstrap's normalisation: mean luminance over the image
    double b_std_error = 0;  // its standard error (sample standard deviation / sqrt(bootstrap_samples))
    uint64_t small_proposed = 0, small_accepted = 0;
    uint64_t large_proposed = 0, large_accepted = 0;
    uint64_t mutations = 0;
    bool valid = false;
};
MltStats pssmlt_stats();

// The bootstrap alone (tests): b and its standard error for the scene (pssmlt or mmlt, by its
// integrator type) at this film size.
MltStats pssmlt_bootstrap(const Scene& scene, int width, int height, int threads);

}  // namespace candela
