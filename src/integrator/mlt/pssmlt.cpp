// PSSMLT and MMLT: the bootstrap, the chains and their passes (pssmlt.h).
#include "integrator/mlt/pssmlt.h"
#include <omp.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <type_traits>
#include <vector>
#include "integrator/bdpt/bdpt.h"
#include "integrator/path.h"
#include "integrator/splat_pass.h"
#include "sampling/pss_sampler.h"

namespace candela {

namespace {

constexpr uint64_t kChainStream = 0x6a09e667f3bcc909ULL;  // the acceptance decisions' streams

struct Chain {
    PssSampler sampler;
    PCG32 rng;  // acceptance decisions
    vec3 L{0.f};
    vec2 pos{0.f};
    float I = 0.f;
    int depth = 0;  // MMLT: the path length (scattering events) the chain's paths have
    int rank = 0;   // its place among its depth's chains
    uint64_t small_proposed = 0, small_accepted = 0, large_proposed = 0, large_accepted = 0;
    // This sample index's large steps: added to the depth's estimate after the index, in chain order.
    double large_sum = 0, large_sum2 = 0;
    uint64_t large_n = 0;
};

// One depth's estimate of b_d: its bootstrap states and, as the render goes, its chains' large
// steps (independent uniform states too), pooled.
struct DepthEstimate {
    double sum = 0, sum2 = 0;
    uint64_t n = 0;
    int first_chain = 0, chains = 0;  // chains [first_chain, first_chain + chains) have this depth
    uint64_t mutations = 0;           // the depth's mutations per sample index
    double mean() const { return n ? sum / double(n) : 0.0; }
    double variance_of_mean() const {
        if (n < 2) return 0.0;
        const double m = mean();
        return std::max(0.0, (sum2 - sum * m) / double(n - 1)) / double(n);
    }
};

struct ChainKey {
    const Scene* scene = nullptr;
    int type = 0;
    int w = 0, h = 0;
    uint64_t seed = 0;
    int max_depth = 0, rr_depth = 0, sampling = 0;
    bool hide_emitters = false;
    int bootstrap = 0, chains = 0;
    float sigma = 0, large = 0;
    bool operator==(const ChainKey& o) const {
        return scene == o.scene && type == o.type && w == o.w && h == o.h && seed == o.seed && max_depth == o.max_depth &&
               rr_depth == o.rr_depth && sampling == o.sampling && hide_emitters == o.hide_emitters &&
               bootstrap == o.bootstrap && chains == o.chains && sigma == o.sigma && large == o.large;
    }
};

ChainKey key_of(const Scene& scene, int w, int h) {
    const RenderSettings& st = scene.settings;
    const MltParams& m = st.integrator.mlt;
    return {&scene, int(st.integrator.type), w, h, st.seed, st.max_depth, st.rr_depth, int(st.sampling), st.integrator.hide_emitters,
            m.bootstrap_samples, m.chains, m.sigma, m.large_step_probability};
}

struct ChainSet {
    ChainKey key;
    uint32_t next_index = 0;  // the render's sample index the chains have reached
    double b = 0, b_std_error = 0;                      // current: bootstrap and large steps pooled
    double b_bootstrap = 0, b_bootstrap_std_error = 0;  // the bootstrap's alone
    uint64_t bootstrap_paths = 0, large_steps = 0;
    double bootstrap_seconds = 0, replay_seconds = 0;
    std::vector<DepthEstimate> depths;
    std::vector<float> weight;  // per depth: the next index's splat weight b_d M / M_d
    uint64_t mutations_per_index = 0;  // M (the pixels)
    double b_used_sum = 0;  // sum over the indices rendered of the b their splats carry
    std::vector<Chain> chains;
};

// b, its standard error and the next index's splat weights from the depths' estimates.
void refresh(ChainSet& set) {
    double b = 0, var = 0;
    for (const DepthEstimate& d : set.depths) {
        b += d.mean();
        var += d.variance_of_mean();
    }
    set.b = b;
    set.b_std_error = std::sqrt(var);
    set.weight.assign(set.depths.size(), 0.f);
    if (!(b > 0)) return;
    for (size_t i = 0; i < set.depths.size(); ++i) {
        const DepthEstimate& d = set.depths[i];
        if (d.mutations > 0)
            set.weight[i] = float(d.mean() * double(set.mutations_per_index) / double(d.mutations));
    }
}

// After a sample index: the chains' large steps go into their depths' estimates in chain order
// (a fixed order of additions: the same sums at any thread count), then b and the weights are
// recomputed for the next index.
void end_index(ChainSet& set) {
    double carried = 0;  // the luminance the index's splats carry per mutation: sum of live depths' b_d
    for (const DepthEstimate& d : set.depths)
        if (d.mutations > 0) carried += d.mean();
    set.b_used_sum += carried;
    for (Chain& ch : set.chains) {
        DepthEstimate& d = set.depths[size_t(ch.depth)];
        d.sum += ch.large_sum;
        d.sum2 += ch.large_sum2;
        d.n += ch.large_n;
        set.large_steps += ch.large_n;
        ch.large_sum = ch.large_sum2 = 0;
        ch.large_n = 0;
    }
    refresh(set);
}

std::mutex g_chains_mutex;  // held for a whole pass: one pssmlt render at a time
std::unique_ptr<ChainSet> g_chains;
std::mutex g_stats_mutex;
MltStats g_stats;

// The path tracer on one state: the first two coordinates pick the film position.
class PathEvaluator {
public:
    PathEvaluator(const Scene& scene, int w, int h) : scene_(scene), integrator_(scene), w_(w), h_(h) {
        camera_ = scene.camera;
        camera_.set_film_size(w, h);
        diffuse_only_ = scene_is_diffuse_only(scene);
    }
    // The radiance of the state's path, its film position, and the scalar contribution I (0 for a
    // non-finite radiance, which is then zeroed: no NaN reaches the film).
    static constexpr int kStreams = 1;
    int depths() const { return 1; }
    float eval(PssSampler& s, int, vec3& L, vec2& pos, PathStats& ps) const {
        s.start_pixel_sample(ivec2(0), 0);
        const vec2 u = s.next_2d();
        pos = u * vec2(float(w_), float(h_));
        const ivec2 px(std::min(int(pos.x), w_ - 1), std::min(int(pos.y), h_ - 1));
        const vec2 jitter = glm::clamp(pos - vec2(px), vec2(0.f), vec2(0x1.fffffep-1f));
        const vec2 lens = camera_.needs_lens_sample() ? s.next_2d() : vec2(0.5f);
        const Ray ray = camera_.generate_ray(px, jitter, lens);
        L = diffuse_only_ ? integrator_.Li<PssSampler, true>(ray, s, ps) : integrator_.Li<PssSampler, false>(ray, s, ps);
        if (!all_finite(L)) L = vec3(0.f);
        return std::max(luminance(L), 0.f);
    }
    int width() const { return w_; }
    int height() const { return h_; }

private:
    const Scene& scene_;
    PathIntegrator integrator_;
    Camera camera_;
    int w_, h_;
    bool diffuse_only_ = false;
};

// MMLT: BDPT's strategies on one state of three streams (Bdpt::sample_strategy), at the chain's
// depth, for the depths mmlt_depths gives.
class MmltEvaluator {
public:
    MmltEvaluator(const Scene& scene, int w, int h, int threads) : w_(w), h_(h) {
        camera_ = scene.camera;
        camera_.set_film_size(w, h);
        bdpt_ = std::make_unique<Bdpt>(scene, camera_, w, h);
        depths_ = mmlt_depths(scene.settings.max_depth);
        spaces_.resize(size_t(std::max(1, threads)));
        for (auto& s : spaces_) s = std::make_unique<Bdpt::Workspace>();
    }
    static constexpr int kStreams = 3;
    int depths() const { return depths_; }
    float eval(PssSampler& s, int depth, vec3& L, vec2& pos, PathStats& ps) const {
        L = bdpt_->sample_strategy(s, depth, *spaces_[size_t(omp_get_thread_num())], ps, pos);
        if (!all_finite(L)) L = vec3(0.f);
        return std::max(luminance(L), 0.f);
    }
    int width() const { return w_; }
    int height() const { return h_; }

private:
    Camera camera_;
    std::unique_ptr<Bdpt> bdpt_;
    std::vector<std::unique_ptr<Bdpt::Workspace>> spaces_;
    int w_, h_, depths_ = 1;
};

// The bootstrap's contributions I_i, i < bootstrap_samples x depths (state i: PssSampler(seed, i)
// at its iteration 0, at depth i mod depths), and each depth's estimate of b_d from its states.
template <class Evaluator>
std::vector<float> bootstrap(const Evaluator& ev, const RenderSettings& st, int threads, std::vector<DepthEstimate>& est,
                             uint64_t& rays) {
    const MltParams& m = st.integrator.mlt;
    const uint64_t depths = uint64_t(ev.depths());
    const uint64_t n = uint64_t(std::max(1, m.bootstrap_samples)) * depths;
    std::vector<float> I(static_cast<size_t>(n));
    std::atomic<uint64_t> total_rays{0};
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
    for (int64_t i = 0; i < int64_t(n); ++i) {
        PssSampler s(st.seed, uint64_t(i), m.sigma, m.large_step_probability, Evaluator::kStreams);
        PathStats ps;
        vec3 L;
        vec2 pos;
        I[size_t(i)] = ev.eval(s, int(uint64_t(i) % depths), L, pos, ps);
        total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
    }
    est.assign(size_t(depths), DepthEstimate{});
    for (uint64_t i = 0; i < n; ++i) {
        DepthEstimate& d = est[size_t(i % depths)];
        const double v = double(I[size_t(i)]);
        d.sum += v;
        d.sum2 += v * v;
        ++d.n;
    }
    rays = total_rays.load();
    return I;
}

template <class Evaluator>
std::unique_ptr<ChainSet> make_chains(const Evaluator& ev, const Scene& scene, int threads, uint64_t& rays) {
    const auto t0 = std::chrono::steady_clock::now();
    const RenderSettings& st = scene.settings;
    const MltParams& m = st.integrator.mlt;
    auto set = std::make_unique<ChainSet>();
    set->key = key_of(scene, ev.width(), ev.height());
    set->mutations_per_index = uint64_t(ev.width()) * uint64_t(ev.height());
    const std::vector<float> I = bootstrap(ev, st, threads, set->depths, rays);
    set->bootstrap_paths = I.size();
    refresh(*set);
    set->b_bootstrap = set->b;
    set->b_bootstrap_std_error = set->b_std_error;
    // Chains to the depths in proportion to b_d, a depth's mutations in proportion to its chains.
    const size_t depths = set->depths.size();
    std::vector<double> bd(depths), cd(depths);
    for (size_t d = 0; d < depths; ++d) bd[d] = set->depths[d].mean();
    const std::vector<uint64_t> chains = mlt_allocate(bd, uint64_t(std::max(1, m.chains)));
    for (size_t d = 0; d < depths; ++d) cd[d] = double(chains[d]);
    const std::vector<uint64_t> muts = mlt_allocate(cd, set->mutations_per_index);
    int first = 0;
    for (size_t d = 0; d < depths; ++d) {
        set->depths[d].first_chain = first;
        set->depths[d].chains = int(chains[d]);
        set->depths[d].mutations = muts[d];
        first += int(chains[d]);
    }
    refresh(*set);
    if (first == 0) {  // a black image: one chain, never evaluated, counts the mutations
        set->depths[0].chains = 1;
        set->depths[0].mutations = set->mutations_per_index;
        set->chains.resize(1);
        return set;
    }
    set->chains.resize(size_t(first));
    // Within a depth, each chain's start state is one of the depth's bootstrap states drawn in
    // proportion to I: per depth, the CDF over its states (state i = k x depths + d).
    const size_t per_depth = I.size() / depths;
    std::vector<double> cdf(I.size());
    for (size_t d = 0; d < depths; ++d) {
        double acc = 0;
        for (size_t k = 0; k < per_depth; ++k) cdf[d * per_depth + k] = acc += double(I[k * depths + d]);
    }
    std::atomic<uint64_t> total_rays{0};
    const int n_chains = first;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int c = 0; c < n_chains; ++c) {
        Chain& ch = set->chains[size_t(c)];
        size_t d = 0;
        while (c >= set->depths[d].first_chain + set->depths[d].chains) ++d;
        ch.depth = int(d);
        ch.rank = c - set->depths[d].first_chain;
        ch.rng = PCG32(hash_combine(uint64_t(c), st.seed ^ kChainStream), mix_bits(st.seed + uint64_t(c)));
        // The start state in proportion to I among the depth's states, rebuilt from its index.
        const double* begin = &cdf[d * per_depth];
        const double u = (double(ch.rng.next_u32()) + 0.5) * 0x1p-32 * begin[per_depth - 1];
        const size_t k = std::min(size_t(std::upper_bound(begin, begin + per_depth, u) - begin), per_depth - 1);
        const size_t i = k * depths + d;
        ch.sampler = PssSampler(st.seed, uint64_t(i), m.sigma, m.large_step_probability, Evaluator::kStreams);
        PathStats ps;
        ch.I = ev.eval(ch.sampler, ch.depth, ch.L, ch.pos, ps);
        ch.sampler.reseed(st.seed, uint64_t(c));
        total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
    }
    rays += total_rays.load();
    set->bootstrap_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return set;
}

// A chain's mutations at sample index s: its depth's M_d shared out over the depth's C_d chains,
// slot j of C_d getting floor((j+1) M_d / C_d) - floor(j M_d / C_d); the chain of rank r takes slot
// (r + s) mod C_d, so that when M_d is not a multiple of C_d the shorter shares rotate.
uint64_t chain_share(const Chain& ch, const DepthEstimate& d, uint32_t s) {
    const uint64_t C = uint64_t(d.chains), M = d.mutations;
    const uint64_t j = (uint64_t(ch.rank) + uint64_t(s) % C) % C;
    return ((j + 1) * M) / C - (j * M) / C;
}

// `n` mutations of a chain; with `st`, their expected-value splats times the depth's weight. Its
// large steps' I are summed for b.
template <class Evaluator>
void mutate(const Evaluator& ev, Chain& ch, uint64_t n, float weight, SplatTile* st, PathStats& ps) {
    const int w = ev.width(), h = ev.height();
    for (uint64_t k = 0; k < n; ++k) {
        ch.sampler.start_iteration();
        const bool large = ch.sampler.large_step();
        vec3 Ly;
        vec2 pos;
        const float Iy = ev.eval(ch.sampler, ch.depth, Ly, pos, ps);
        const float a = ch.I > 0.f ? std::min(1.f, Iy / ch.I) : 1.f;
        if (large) {
            ch.large_sum += double(Iy);
            ch.large_sum2 += double(Iy) * double(Iy);
            ++ch.large_n;
        }
        if (st) {
            if (a > 0.f && Iy > 0.f) st->add(w, h, pos, Ly * float(double(a) * double(weight) / double(Iy)));
            if (a < 1.f && ch.I > 0.f) st->add(w, h, ch.pos, ch.L * float(double(1.f - a) * double(weight) / double(ch.I)));
            ++st->paths;
        }
        (large ? ch.large_proposed : ch.small_proposed) += 1;
        if (ch.rng.next_float() < a) {
            ch.sampler.accept();
            ch.L = Ly;
            ch.pos = pos;
            ch.I = Iy;
            (large ? ch.large_accepted : ch.small_accepted) += 1;
        } else {
            ch.sampler.reject();
        }
    }
}

MltStats stats_of(const ChainSet& set) {
    MltStats s;
    s.b = set.b;
    s.b_std_error = set.b_std_error;
    s.b_bootstrap = set.b_bootstrap;
    s.b_bootstrap_std_error = set.b_bootstrap_std_error;
    for (const DepthEstimate& d : set.depths) {
        s.b_depth.push_back(d.mean());
        s.b_depth_std_error.push_back(std::sqrt(d.variance_of_mean()));
        s.chains_per_depth.push_back(d.chains);
    }
    s.bootstrap_paths = set.bootstrap_paths;
    s.large_steps = set.large_steps;
    s.bootstrap_seconds = set.bootstrap_seconds;
    s.replay_seconds = set.replay_seconds;
    for (const DepthEstimate& d : set.depths)
        if (d.mutations > 0) s.b_rendered += d.mean();
    s.b_image = set.next_index > 0 ? set.b_used_sum / double(set.next_index) : 0.0;
    s.valid = true;
    return s;
}

void publish(const ChainSet& set, uint64_t pixels) {
    MltStats s = stats_of(set);
    for (const Chain& ch : set.chains) {
        s.small_proposed += ch.small_proposed;
        s.small_accepted += ch.small_accepted;
        s.large_proposed += ch.large_proposed;
        s.large_accepted += ch.large_accepted;
    }
    s.mutations = uint64_t(set.next_index) * pixels;
    s.valid = true;
    std::lock_guard<std::mutex> lock(g_stats_mutex);
    g_stats = s;
}

}  // namespace

int mmlt_depths(int max_depth) {
    return (max_depth < 0 ? kMmltUnboundedDepth : std::min(max_depth, kBdptMaxVertices - 2)) + 1;
}

std::string mmlt_depth_note(int max_depth) {
    const int d = mmlt_depths(max_depth) - 1;
    const std::string bound = std::to_string(d) + " scattering events (Mitsuba max_depth " + std::to_string(d + 1) + ")";
    if (max_depth < 0)
        return "mmlt renders an unbounded max depth up to " + bound +
               ": its chains are per path length; set max_depth to choose";
    if (max_depth > d) return "mmlt renders up to " + bound + ", BDPT's bound on subpath vertices";
    return {};
}

std::vector<uint64_t> mlt_allocate(const std::vector<double>& weights, uint64_t total) {
    const size_t n = weights.size();
    std::vector<uint64_t> out(n, 0);
    double sum = 0;
    size_t positive = 0;
    for (double w : weights)
        if (w > 0) {
            sum += w;
            ++positive;
        }
    if (positive == 0 || total == 0) return out;
    const bool floor_one = total >= positive;
    uint64_t given = 0;
    std::vector<double> rest(n, -1.0);  // the remainders, -1 for zero weights
    for (size_t i = 0; i < n; ++i) {
        if (!(weights[i] > 0)) continue;
        const double q = weights[i] / sum * double(total);
        out[i] = std::min(total, uint64_t(q));
        rest[i] = q - double(out[i]);
        given += out[i];
    }
    // Floating-point rounding may overshoot by a unit: take it back from the largest.
    while (given > total) {
        const size_t i = size_t(std::max_element(out.begin(), out.end()) - out.begin());
        --out[i];
        --given;
    }
    // Largest remainders first (ties to the lower index).
    std::vector<size_t> order;
    for (size_t i = 0; i < n; ++i)
        if (rest[i] >= 0) order.push_back(i);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rest[a] > rest[b]; });
    for (size_t k = 0; given < total; k = (k + 1) % order.size()) {
        ++out[order[k]];
        ++given;
    }
    // Every positive weight at least one unit, taken from the one with most (ties: lower index).
    if (floor_one)
        for (size_t i = 0; i < n; ++i)
            if (weights[i] > 0 && out[i] == 0) {
                const size_t j = size_t(std::max_element(out.begin(), out.end()) - out.begin());
                --out[j];
                ++out[i];
            }
    return out;
}

void mlt_output(const Film& film, const MltStats& s, Film& out) {
    out.resize(film.width(), film.height());
    out.set_layout(film.weighted(), film.aov_channels());
    if (film.has_alpha()) out.enable_alpha();
    out.add(film);
    if (!s.valid || s.mutations != film.splat_paths() || !(s.b_image > 0) || film.splat_sums().empty()) return;
    std::vector<dvec3> sums = film.splat_sums();
    const double k = s.b_rendered / s.b_image;
    for (dvec3& v : sums) v *= k;
    out.restore_splats(std::move(sums), film.splat_paths());
}

MltStats pssmlt_stats() {
    std::lock_guard<std::mutex> lock(g_stats_mutex);
    return g_stats;
}

MltStats pssmlt_bootstrap(const Scene& scene, int width, int height, int threads) {
    ChainSet set;
    uint64_t rays = 0;
    threads = std::max(1, threads);
    if (scene.settings.integrator.type == IntegratorType::Mmlt)
        set.bootstrap_paths = bootstrap(MmltEvaluator(scene, width, height, threads), scene.settings, threads, set.depths, rays).size();
    else
        set.bootstrap_paths = bootstrap(PathEvaluator(scene, width, height), scene.settings, threads, set.depths, rays).size();
    refresh(set);
    set.b_bootstrap = set.b;
    set.b_bootstrap_std_error = set.b_std_error;
    return stats_of(set);
}

namespace {

template <class Evaluator>
PassStats mlt_pass(const Evaluator& ev, const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                   const std::atomic<bool>* cancel) {
    std::lock_guard<std::mutex> lock(g_chains_mutex);
    const int w = film.width(), h = film.height();
    const uint64_t pixels = uint64_t(w) * uint64_t(h);
    uint64_t rays = 0;
    if (pixels == 0) return PassStats{};
    // Continue the cached chains when this pass follows on from them; otherwise start afresh.
    if (!g_chains || first_sample == 0 || !(g_chains->key == key_of(scene, w, h)) || g_chains->next_index > first_sample) {
        g_chains.reset();
        g_chains = make_chains(ev, scene, threads, rays);
    }
    ChainSet& set = *g_chains;
    const int n_chains = int(set.chains.size());
    const bool live = set.b > 0;
    std::atomic<uint64_t> replay_rays{0};
    if (set.next_index < first_sample && live) {
        // Replay without splats up to this pass (a resumed render), index by index: the large
        // steps' sums are rebuilt in the order the render made them.
        const auto t0 = std::chrono::steady_clock::now();
        for (uint32_t s = set.next_index; s < first_sample; ++s) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
            for (int c = 0; c < n_chains; ++c) {
                PathStats ps;
                Chain& ch = set.chains[size_t(c)];
                mutate(ev, ch, chain_share(ch, set.depths[size_t(ch.depth)], s), 0.f, nullptr, ps);
                replay_rays.fetch_add(ps.rays, std::memory_order_relaxed);
            }
            end_index(set);
        }
        set.replay_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    set.next_index = first_sample;
    auto work = [&](uint32_t s, int c, Film&, SplatTile& st, PathStats& ps) {
        Chain& ch = set.chains[size_t(c)];
        const uint64_t n = chain_share(ch, set.depths[size_t(ch.depth)], s);
        if (live) mutate(ev, ch, n, set.weight[size_t(ch.depth)], &st, ps);
        else st.paths += n;  // a black image: the mutations are counted, none splats
    };
    auto merge = [&](int c, Film& layer) {
        if (c == 0)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) layer.count_sample(ivec2(x, y));
        if (c == n_chains - 1) end_index(set);  // the index is whole: refine b for the next
    };
    PassStats out = splat_pass_units(film, scene.settings.filter, first_sample, spp, threads, cancel, n_chains, work, merge);
    out.rays += rays + replay_rays.load();
    if (!out.completed) {
        // The film holds the indices completed before the cut (each adds N mutations): the stats
        // describe them, then the chains, left part-way through an index, are dropped.
        set.next_index = first_sample + uint32_t(out.samples / pixels);
        publish(set, pixels);
        g_chains.reset();
        return out;
    }
    set.next_index = first_sample + uint32_t(spp);
    publish(set, pixels);
    return out;
}

}  // namespace

PassStats PssmltPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                  const std::atomic<bool>* cancel) const {
    return mlt_pass(PathEvaluator(scene, film.width(), film.height()), scene, film, first_sample, spp, threads, cancel);
}

PassStats MmltPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                const std::atomic<bool>* cancel) const {
    return mlt_pass(MmltEvaluator(scene, film.width(), film.height(), threads), scene, film, first_sample, spp, threads,
                    cancel);
}

}  // namespace candela
