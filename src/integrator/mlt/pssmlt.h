#pragma once
// Primary-sample-space Metropolis light transport over the path tracer (Kelemen et al. 2002;
// docs/mlt.md). A state is a PssSampler vector; its first two coordinates pick the film position
// (pixel and jitter), the rest are the path tracer's, drawn in its fixed order (path_impl.h). The
// scalar contribution I = luminance of the path's radiance.
//
// Bootstrap: `bootstrap_samples` independent states per depth (iteration 0 of PssSampler(seed, i);
// pssmlt has one depth) give b_d = mean I over the depth's states, b = sum of b_d (the image's mean
// luminance), and the chains' start states, drawn in proportion to I within their depth. Each
// mutation proposes y from x, accepts with a = min(1, I(y)/I(x)), and splats both states by Veach's
// expected values: y with a / I(y), x with (1 - a) / I(x), times the depth's weight b_d M / M_d
// (M_d of the index's M mutations are the depth's). b_d is refined after each sample index by
// pooling the chains' large steps (independent uniform states, so their I has mean b_d: Kelemen's
// estimator) with the bootstrap, and the next index splats with the refined value; at output,
// mlt_output rescales the splats so that the image's mean is the last b (the film's mean is the
// average of the b each index used): the image's brightness converges as the render runs.
//
// Passes: sample index s of the render is one mutation per pixel in total, shared out over the
// depths in proportion to their chains and over a depth's chains (rotating by index the chains
// that get one mutation fewer); each chain's splats go to its own SplatTile, merged in chain order
// (splat_pass_units). The chains' states persist between passes (a process-wide cache keyed by the
// scene and film), so the image of samples [0, n) is the same bit for bit however the passes split
// it and whatever the thread count. A pass that does not continue the cached chains (another
// scene, a restart at sample 0, a resumed checkpoint) rebuilds them and replays the mutations up
// to its first sample without splatting (the large steps' sums are rebuilt with them).
#include <cstdint>
#include <string>
#include <vector>
#include "integrator/integrator.h"

namespace candela {

class PssmltPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

// Multiplexed MLT over BDPT (Hachisuka et al. 2014): the same chains, each at a path length (depth,
// scattering events): bootstrap state i has depth i mod (max depth + 1), and the chains are
// allocated to the depths in proportion to b_d (mlt_allocate). A state has three streams (camera
// path, light path, connection), evaluated by one BDPT strategy (s, t) of its depth chosen by the
// connection stream, weighted by MIS over the depth's strategies (Bdpt::sample_strategy). The max
// depth is honoured up to BDPT's own bound (kBdptMaxVertices - 2); an unbounded one is bounded at
// kMmltUnboundedDepth (mmlt_depth_note says so).
class MmltPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

constexpr int kMmltUnboundedDepth = 12;  // scattering events, for an unbounded max depth
// The depths mmlt renders for these settings (max depth + 1), and a one-line note when the scene's
// max depth is not honoured as given (unbounded, or past BDPT's bound); empty otherwise.
int mmlt_depths(int max_depth);
std::string mmlt_depth_note(int max_depth);

// Stratified allocation: `total` units shared out in proportion to `weights` (largest remainders,
// ties to the lower index), each positive weight getting at least one unit when total is at least
// the number of positive weights; zero weights get none. Deterministic. MMLT shares its chains
// over the depths by b_d with it, and each sample index's mutations over the depths by their chains.
std::vector<uint64_t> mlt_allocate(const std::vector<double>& weights, uint64_t total);

// The chains' statistics after the last pssmlt or mmlt pass (for the viewer's panel, the summary
// line and the tests).
struct MltStats {
    double b = 0;            // the image's mean luminance: the bootstrap pooled with the large steps so far
    double b_std_error = 0;  // its standard error (from the pooled samples' variance per depth)
    double b_bootstrap = 0, b_bootstrap_std_error = 0;  // the bootstrap's alone
    double b_rendered = 0;  // b of the depths that have chains (all but those with b_d = 0, unless
                            // there are fewer chains or pixels than depths)
    double b_image = 0;     // the film's mean luminance: the mean over its indices of the b they used
    std::vector<double> b_depth, b_depth_std_error;  // per depth (mmlt; pssmlt: one), pooled
    std::vector<int> chains_per_depth;
    uint64_t bootstrap_paths = 0;  // bootstrap_samples x depths
    uint64_t large_steps = 0;      // large steps pooled into b
    double bootstrap_seconds = 0;  // the bootstrap and the chains' start (last rebuild)
    double replay_seconds = 0;     // mutations replayed without splats (a resumed render)
    uint64_t small_proposed = 0, small_accepted = 0;
    uint64_t large_proposed = 0, large_accepted = 0;
    uint64_t mutations = 0;
    bool valid = false;
};
MltStats pssmlt_stats();

// The image to show or write of a film an MLT render made (its stats `s`): `out` becomes a copy
// whose splats are scaled by b_rendered / b_image, so that its mean luminance is the latest b. The
// film itself stays the sum of its per-index layers (checkpoints, determinism); a film the stats
// do not describe (other mutations) is copied as it is.
void mlt_output(const Film& film, const MltStats& s, Film& out);

// The bootstrap alone (tests): b, b_depth and their standard errors for the scene (pssmlt or mmlt,
// by its integrator type) at this film size.
MltStats pssmlt_bootstrap(const Scene& scene, int width, int height, int threads);

}  // namespace candela
