// PSSMLT and MMLT: the bootstrap, the chains and their passes (pssmlt.h).
#include "integrator/mlt/pssmlt.h"
#include <omp.h>
#include <algorithm>
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
    uint64_t small_proposed = 0, small_accepted = 0, large_proposed = 0, large_accepted = 0;
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
    double b = 0, b_std_error = 0;
    std::vector<Chain> chains;
};

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
// depth. An unbounded max depth is capped at kMmltMaxDepth (longer paths are dropped).
constexpr int kMmltMaxDepth = 12;
class MmltEvaluator {
public:
    MmltEvaluator(const Scene& scene, int w, int h, int threads) : w_(w), h_(h) {
        camera_ = scene.camera;
        camera_.set_film_size(w, h);
        bdpt_ = std::make_unique<Bdpt>(scene, camera_, w, h);
        const int md = scene.settings.max_depth;
        depths_ = (md < 0 ? kMmltMaxDepth : std::min(md, kMmltMaxDepth)) + 1;
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

// The bootstrap's contributions I_i, i < bootstrap_samples (state i: PssSampler(seed, i) at its
// iteration 0, at depth i mod depths for MMLT), and b with its standard error: b is the mean of I
// times the number of depths (each depth's image is estimated by its share of the samples).
template <class Evaluator>
std::vector<float> bootstrap(const Evaluator& ev, const RenderSettings& st, int threads, double& b, double& se,
                             uint64_t& rays) {
    const MltParams& m = st.integrator.mlt;
    const int n = std::max(1, m.bootstrap_samples);
    std::vector<float> I(static_cast<size_t>(n));
    std::atomic<uint64_t> total_rays{0};
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
    for (int i = 0; i < n; ++i) {
        PssSampler s(st.seed, uint64_t(i), m.sigma, m.large_step_probability, Evaluator::kStreams);
        PathStats ps;
        vec3 L;
        vec2 pos;
        I[size_t(i)] = ev.eval(s, i % ev.depths(), L, pos, ps);
        total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
    }
    double sum = 0, sum2 = 0;
    for (float v : I) {
        sum += double(v);
        sum2 += double(v) * double(v);
    }
    const double mean = sum / double(n);
    const double var = n > 1 ? std::max(0.0, (sum2 - sum * mean) / double(n - 1)) : 0.0;
    b = mean * double(ev.depths());
    se = std::sqrt(var / double(n)) * double(ev.depths());
    rays = total_rays.load();
    return I;
}

template <class Evaluator>
std::unique_ptr<ChainSet> make_chains(const Evaluator& ev, const Scene& scene, int threads, uint64_t& rays) {
    const RenderSettings& st = scene.settings;
    const MltParams& m = st.integrator.mlt;
    auto set = std::make_unique<ChainSet>();
    set->key = key_of(scene, ev.width(), ev.height());
    const std::vector<float> I = bootstrap(ev, st, threads, set->b, set->b_std_error, rays);
    std::vector<double> cdf(I.size());
    double acc = 0;
    for (size_t i = 0; i < I.size(); ++i) cdf[i] = acc += double(I[i]);
    set->chains.resize(size_t(m.chains));
    if (!(acc > 0)) return set;  // a black image: no chain can start
    std::atomic<uint64_t> total_rays{0};
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int c = 0; c < m.chains; ++c) {
        Chain& ch = set->chains[size_t(c)];
        ch.rng = PCG32(hash_combine(uint64_t(c), st.seed ^ kChainStream), mix_bits(st.seed + uint64_t(c)));
        // The start state in proportion to I: a bootstrap state, rebuilt from its index.
        const double u = (double(ch.rng.next_u32()) + 0.5) * 0x1p-32 * acc;
        const size_t i = std::min(size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()), cdf.size() - 1);
        ch.sampler = PssSampler(st.seed, uint64_t(i), m.sigma, m.large_step_probability, Evaluator::kStreams);
        ch.depth = int(i % size_t(ev.depths()));
        PathStats ps;
        ch.I = ev.eval(ch.sampler, ch.depth, ch.L, ch.pos, ps);
        ch.sampler.reseed(st.seed, uint64_t(c));
        total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
    }
    rays += total_rays.load();
    return set;
}

// Mutations per chain for one sample index: N pixels' worth shared out over C chains.
uint64_t chain_share(int c, int n_chains, uint64_t pixels) {
    return (uint64_t(c + 1) * pixels) / uint64_t(n_chains) - (uint64_t(c) * pixels) / uint64_t(n_chains);
}

// `n` mutations of a chain; with `st`, their expected-value splats scaled by b.
template <class Evaluator>
void mutate(const Evaluator& ev, Chain& ch, uint64_t n, double b, SplatTile* st, PathStats& ps) {
    const int w = ev.width(), h = ev.height();
    for (uint64_t k = 0; k < n; ++k) {
        ch.sampler.start_iteration();
        const bool large = ch.sampler.large_step();
        vec3 Ly;
        vec2 pos;
        const float Iy = ev.eval(ch.sampler, ch.depth, Ly, pos, ps);
        const float a = ch.I > 0.f ? std::min(1.f, Iy / ch.I) : 1.f;
        if (st) {
            if (a > 0.f && Iy > 0.f) st->add(w, h, pos, Ly * float(double(a) * b / double(Iy)));
            if (a < 1.f && ch.I > 0.f) st->add(w, h, ch.pos, ch.L * float(double(1.f - a) * b / double(ch.I)));
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

void publish(const ChainSet& set, uint64_t pixels) {
    MltStats s;
    s.b = set.b;
    s.b_std_error = set.b_std_error;
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

MltStats pssmlt_stats() {
    std::lock_guard<std::mutex> lock(g_stats_mutex);
    return g_stats;
}

MltStats pssmlt_bootstrap(const Scene& scene, int width, int height, int threads) {
    MltStats s;
    uint64_t rays = 0;
    threads = std::max(1, threads);
    if (scene.settings.integrator.type == IntegratorType::Mmlt)
        bootstrap(MmltEvaluator(scene, width, height, threads), scene.settings, threads, s.b, s.b_std_error, rays);
    else
        bootstrap(PathEvaluator(scene, width, height), scene.settings, threads, s.b, s.b_std_error, rays);
    s.valid = true;
    return s;
}

namespace {

template <class Evaluator>
PassStats mlt_pass(const Evaluator& ev, const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                   const std::atomic<bool>* cancel) {
    std::lock_guard<std::mutex> lock(g_chains_mutex);
    const int w = film.width(), h = film.height();
    const uint64_t pixels = uint64_t(w) * uint64_t(h);
    uint64_t rays = 0;
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
        // Replay without splats up to this pass (a resumed or distributed render).
        const uint64_t steps = first_sample - set.next_index;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (int c = 0; c < n_chains; ++c) {
            PathStats ps;
            mutate(ev, set.chains[size_t(c)], chain_share(c, n_chains, pixels) * steps, set.b, nullptr, ps);
            replay_rays.fetch_add(ps.rays, std::memory_order_relaxed);
        }
    }
    set.next_index = first_sample;
    auto work = [&](uint32_t, int c, Film&, SplatTile& st, PathStats& ps) {
        const uint64_t n = chain_share(c, n_chains, pixels);
        if (live) mutate(ev, set.chains[size_t(c)], n, set.b, &st, ps);
        else st.paths += n;  // a black image: the mutations are counted, none splats
    };
    auto merge = [&](int c, Film& layer) {
        if (c != 0) return;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) layer.count_sample(ivec2(x, y));
    };
    PassStats out = splat_pass_units(film, first_sample, spp, threads, cancel, n_chains, work, merge);
    out.rays += rays + replay_rays.load();
    if (!out.completed) {
        g_chains.reset();  // a sample index was cut part-way: the chains are between indices
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
