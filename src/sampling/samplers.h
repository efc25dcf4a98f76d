#pragma once
// The samplers other than the independent one (sampling/sampler.h), and the choice among them.
// Each is a concrete class with inline next_1d / next_2d: the tile loop (integrator/tiles.h) is a
// template on the sampler, instantiated once per sampler type and chosen once per pass
// (visit_sampler), so no sample pays for a dispatch and the independent sampler's loop is the one
// it always was.
//
// Contract shared by all: after start_pixel_sample(pixel, i) the numbers drawn depend only on
// (pixel, i, seed, the scene's sample_count n, the film's size for zsobol), never on the thread,
// the pass split or the order pixels are visited. The k-th call (next_1d or next_2d alike) after it
// is "dimension k"; the integrators draw their dimensions in a fixed order per bounce
// (integrator/path_impl.h) so that dimension k means the same thing in every sample of a pixel.
// Every returned number is uniform on [0, 1) (each a randomised point set or sequence), so every
// estimator stays unbiased; what differs is how the n samples of a pixel spread jointly.
//
// Stratified sets over n samples (stratified, multijitter, ldsampler): sample i of a pixel is
// member i mod n' of set i / n' (n' = sampler_sample_count(n)); each set has its own random
// permutations. So 4 passes of 4 spp and 1 pass of 16 spp are the same samples, bit for bit, and
// the stratification is complete for every whole multiple of n' samples.
//
// Dimension budget. sobol: the first kSobolDimensions (32) dimensions of a pixel are Sobol
// dimensions 0..31 (a next_2d takes two consecutive ones); from the first draw that does not fit on
// it falls back to independent PCG32 numbers (the pixel's independent stream). The others pad: each
// dimension is its own randomised 1D or 2D point set, with no budget.
#include <algorithm>
#include <cstdint>
#include <utility>
#include "core/math.h"
#include "sampling/pcg32.h"
#include "sampling/sampler.h"
#include "sampling/sampler_desc.h"
#include "sampling/sobol.h"

namespace candela {

// What a sampler needs besides the pixel and the sample index.
struct SamplerSetup {
    SamplerDesc desc;
    uint64_t seed = 0;
    uint32_t sample_count = 1;  // the scene's sample_count (RenderSettings::spp)
    ivec2 resolution{1, 1};     // sampler pixels lie in [0, resolution): zsobol's Morton index
};

namespace sampler_detail {

inline uint32_t ceil_log2(uint32_t n) {
    uint32_t k = 0;
    while ((uint64_t(1) << k) < n) ++k;
    return k;
}

// A pseudo-random permutation of [0, n) chosen by `seed`: a bijection of [0, 2^b) (2^b >= n: XOR
// with a key, multiply by an odd constant, xorshift right, each invertible mod 2^b) iterated until
// it lands below n ("cycle walking": the cycle through i returns below n, so this terminates and
// stays a bijection of [0, n)). Fewer than 2 rounds on average.
inline uint32_t permute(uint32_t i, uint32_t n, uint32_t seed) {
    if (n <= 1) return 0;
    const uint32_t b = ceil_log2(n), w = (b >= 32) ? ~0u : (1u << b) - 1u;
    const uint32_t sh = std::max(1u, b / 2);
    do {
        i = (i ^ seed) & w;
        i = (i * 0x9e3779b1u) & w;
        i ^= i >> sh;
        i = (i + (seed >> 11)) & w;
        i = (i * 0x85ebca6bu) & w;
        i ^= i >> (sh + 1 < b ? sh + 1 : 1);
        i = (i ^ (seed >> 21)) & w;
        i = (i * 0xc2b2ae35u) & w;
        i ^= i >> sh;
    } while (i >= n);
    return i;
}

inline float below_one(float x) { return std::min(x, 0x1.fffffep-1f); }

inline uint64_t pixel_key(ivec2 p) { return (uint64_t(uint32_t(p.x)) << 32) | uint32_t(p.y); }

// Morton code of a pixel (16 bits per axis): x in the even bits.
inline uint64_t morton2(ivec2 p) {
    auto spread = [](uint64_t v) {
        v &= 0xffff;
        v = (v | (v << 8)) & 0x00ff00ffULL;
        v = (v | (v << 4)) & 0x0f0f0f0fULL;
        v = (v | (v << 2)) & 0x33333333ULL;
        v = (v | (v << 1)) & 0x55555555ULL;
        return v;
    };
    return spread(uint64_t(uint32_t(p.x))) | (spread(uint64_t(uint32_t(p.y))) << 1);
}

}  // namespace sampler_detail

// Common state: the pixel's hash, the sample index, the dimension counter and the pixel's PCG32
// stream at sample i (the independent sampler's, for jitter and fallbacks).
class PixelSampleBase {
protected:
    explicit PixelSampleBase(uint64_t seed) : seed_(seed) {}
    void start(ivec2 pixel, uint32_t sample_index) {
        key_ = hash_combine(sampler_detail::pixel_key(pixel), seed_);
        index_ = sample_index;
        dim_ = 0;
        rng_ready_ = false;
    }
    // The pixel's independent stream at this sample, set up on first use (the Sobol samplers
    // rarely need it).
    PCG32& rng() {
        if (!rng_ready_) {
            rng_.set_sequence(key_, mix_bits(seed_ ^ 0x5bd1e995ULL));
            rng_.advance(uint64_t(index_) << 16);
            rng_ready_ = true;
        }
        return rng_;
    }
    // A seed for dimension dim_ of set `set` of this pixel, then the next dimension.
    uint32_t next_dim_seed(uint32_t set) {
        return uint32_t(mix_bits(key_ ^ (((uint64_t(set) << 32) | dim_++) * 0x9e3779b97f4a7c15ULL)) >> 16);
    }
    uint64_t seed_;
    uint64_t key_ = 0;
    uint32_t index_ = 0, dim_ = 0;
    bool rng_ready_ = false;
    PCG32 rng_;
};

// The samplers that draw a pixel's samples in sets of n' (Mitsuba's stratified, multijitter,
// ldsampler, orthogonal): sample i is member i mod n' of set i / n'; every set is a fresh
// randomisation. jitter: uniform inside a stratum, else its centre.
class SetSampleBase : public PixelSampleBase {
protected:
    SetSampleBase(uint64_t seed, uint32_t set_size, bool jitter)
        : PixelSampleBase(seed), n_(set_size), jitter_(jitter) {}
    void start_set(ivec2 pixel, uint32_t i) {
        start(pixel, i);
        set_ = i / n_;
        member_ = i % n_;
    }
    // The next dimension's seed in this set.
    uint32_t next_seed() { return next_dim_seed(set_); }
    float jit() { return jitter_ ? rng().next_float() : 0.5f; }
    uint32_t n_, set_ = 0, member_ = 0;
    bool jitter_;
};

// Mitsuba's `stratified`: n' = r^2 strata. 1D: the sample's stratum of n' is a per-dimension
// random permutation of its index in the set; 2D: the same on an r x r grid. jitter: uniform in
// the stratum, else its centre (not unbiased for an integrand that varies within a stratum: as
// Mitsuba, for comparisons only).
class StratifiedSampler final : public SetSampleBase {
public:
    explicit StratifiedSampler(const SamplerSetup& s)
        : SetSampleBase(s.seed, sampler_sample_count(SamplerType::Stratified, s.sample_count), s.desc.jitter) {
        res_ = 1;
        while (res_ * res_ < n_) ++res_;
    }
    void start_pixel_sample(ivec2 pixel, uint32_t i) { start_set(pixel, i); }
    float next_1d() {
        const uint32_t p = sampler_detail::permute(member_, n_, next_seed());
        return sampler_detail::below_one((float(p) + jit()) / float(n_));
    }
    vec2 next_2d() {
        const uint32_t p = sampler_detail::permute(member_, n_, next_seed());
        const float jx = jit(), jy = jit();
        return vec2(sampler_detail::below_one((float(p % res_) + jx) / float(res_)),
                    sampler_detail::below_one((float(p / res_) + jy) / float(res_)));
    }

private:
    uint32_t res_ = 1;
};

// Mitsuba's `multijitter`: correlated multi-jittered sampling (Kensler 2013), n' = a x b with
// a = floor(sqrt(n)), b = ceil(n / a). 2D: the sample's cell (x, y) of the a x b grid is a random
// permutation of its index; inside the cell it takes sub-column sy(y) of b and sub-row sx(x) of a,
// with sx, sy random permutations shared by all cells of a column / row, so that both 1D
// projections fall one point per stratum of n' as well. 1D: as stratified.
class MultijitterSampler final : public SetSampleBase {
public:
    explicit MultijitterSampler(const SamplerSetup& s)
        : SetSampleBase(s.seed, sampler_sample_count(SamplerType::Multijitter, s.sample_count), s.desc.jitter) {
        a_ = 1;
        while ((a_ + 1) * (a_ + 1) <= n_) ++a_;
        b_ = n_ / a_;
    }
    void start_pixel_sample(ivec2 pixel, uint32_t i) { start_set(pixel, i); }
    float next_1d() {
        const uint32_t p = sampler_detail::permute(member_, n_, next_seed());
        return sampler_detail::below_one((float(p) + jit()) / float(n_));
    }
    vec2 next_2d() {
        const uint32_t seed = next_seed();
        const uint32_t p = sampler_detail::permute(member_, n_, seed);
        const uint32_t x = p % a_, y = p / a_;
        const uint32_t sx = sampler_detail::permute(x, a_, seed * 0x2c1b3c6du + 1u);
        const uint32_t sy = sampler_detail::permute(y, b_, seed * 0x297a2d39u + 2u);
        const float jx = jit(), jy = jit();
        return vec2(sampler_detail::below_one((float(x) + (float(sy) + jx) / float(b_)) / float(a_)),
                    sampler_detail::below_one((float(y) + (float(sx) + jy) / float(a_)) / float(b_)));
    }

private:
    uint32_t a_ = 1, b_ = 1;
};

// Mitsuba's `ldsampler` (Kollig and Keller 2002): n' = 2^m. Each dimension (pair) takes point p of
// the (0, 2)-sequence of Sobol dimensions 0 and 1, p a random permutation of the sample's index in
// its set, XOR-shifted by a random 32-bit vector (a digital shift keeps the first 2^m points a
// (0, m, 2)-net, one point in every elementary interval of area 2^-m, and makes each point uniform).
class LdSampler final : public SetSampleBase {
public:
    explicit LdSampler(const SamplerSetup& s)
        : SetSampleBase(s.seed, sampler_sample_count(SamplerType::LdSampler, s.sample_count), false) {}
    void start_pixel_sample(ivec2 pixel, uint32_t i) { start_set(pixel, i); }
    float next_1d() {
        const uint32_t seed = next_seed();
        const uint32_t p = sampler_detail::permute(member_, n_, seed);
        return bits_to_unit(sobol_bits(p, 0) ^ uint32_t(mix_bits(seed)));
    }
    vec2 next_2d() {
        const uint32_t seed = next_seed();
        const uint32_t p = sampler_detail::permute(member_, n_, seed);
        const uint64_t shift = mix_bits(seed);
        return vec2(bits_to_unit(sobol_bits(p, 0) ^ uint32_t(shift)), bits_to_unit(sobol_bits(p, 1) ^ uint32_t(shift >> 32)));
    }
};

// candela's `sobol`: each pixel has its own Owen-scrambled Sobol sequence (Burley 2020's
// per-pixel randomisation: the scramble seed of dimension k is hash(pixel, k, seed)); sample i of a
// pixel is point i, so every prefix of 2^m samples is a (t, m, s)-net in the first s dimensions, at
// any pass split and without knowing the sample count. Dimensions 0 and 1 (the pixel jitter) are a
// (0, 2)-sequence. Budget: 32 dimensions, then independent numbers.
class SobolSampler final : public PixelSampleBase {
public:
    explicit SobolSampler(const SamplerSetup& s) : PixelSampleBase(s.seed) {}
    void start_pixel_sample(ivec2 pixel, uint32_t i) { start(pixel, i); }
    float next_1d() {
        if (dim_ >= uint32_t(kSobolDimensions)) return rng().next_float();
        const int d = int(dim_);
        return bits_to_unit(owen_scramble_reversed(sobol_bits_reversed(index_, d), next_dim_seed(0)));
    }
    vec2 next_2d() {
        if (dim_ + 2 > uint32_t(kSobolDimensions)) {
            dim_ = uint32_t(kSobolDimensions);  // the budget is spent: no later draw goes back to Sobol
            const float a = rng().next_float();
            return vec2(a, rng().next_float());
        }
        const int d = int(dim_);
        const float x = bits_to_unit(owen_scramble_reversed(sobol_bits_reversed(index_, d), next_dim_seed(0)));
        return vec2(x, bits_to_unit(owen_scramble_reversed(sobol_bits_reversed(index_, d + 1), next_dim_seed(0))));
    }
};

// candela's `zsobol` (after pbrt-v4's ZSobolSampler, Ahmed and Wonka 2020, "Screen-space blue
// noise from a base-4 scrambled Sobol sequence"): one Sobol sequence for the whole image. Sample i
// of pixel p is point (morton(p) << m) | (i mod 2^m) with 2^m = the sample count rounded up to a
// power of two (further sets of 2^m above all pixels), so each aligned quad of 2^(2l) pixels owns
// an aligned block of 2^(2l + m) consecutive points: together they form a net, and neighbouring
// pixels' errors cancel (blue noise). Per dimension, the base-4 digits of that index are permuted
// at random (each digit by a permutation of {0..3} chosen by a hash of the digits above it and the
// dimension), which keeps the blocks and decorrelates dimensions; each dimension then uses Sobol
// dimensions 0 (1D) or 0 and 1 (2D), Owen-scrambled by hash(dimension, seed). No dimension budget.
// Pixels are correlated on purpose: statistics over pixels must use blocks of aligned quads
// (tests/test_samplers.cpp).
class ZSobolSampler final : public PixelSampleBase {
public:
    explicit ZSobolSampler(const SamplerSetup& s) : PixelSampleBase(s.seed) {
        log2_spp_ = sampler_detail::ceil_log2(std::max(1u, s.sample_count));
        const uint32_t levels = sampler_detail::ceil_log2(uint32_t(std::max({1, s.resolution.x, s.resolution.y})));
        bits_ = 2 * levels + log2_spp_;
        digits_ = (bits_ + 1) / 2;
        salt_ = mix_bits(s.seed ^ 0x2545f4914f6cdd1dULL);
    }
    void start_pixel_sample(ivec2 pixel, uint32_t i) {
        start(pixel, i);
        const uint64_t low = uint64_t(i) & ((uint64_t(1) << log2_spp_) - 1);
        const uint64_t set = uint64_t(i) >> log2_spp_;
        base_ = (set << bits_) | (sampler_detail::morton2(pixel) << log2_spp_) | low;
    }
    float next_1d() {
        const uint64_t h = mix_bits(salt_ ^ (uint64_t(dim_) * 0x9e3779b97f4a7c15ULL));
        const uint64_t idx = permuted(h);
        ++dim_;
        return bits_to_unit(owen_scramble(sobol_bits(idx, 0), uint32_t(h)));
    }
    vec2 next_2d() {
        const uint64_t h = mix_bits(salt_ ^ (uint64_t(dim_) * 0x9e3779b97f4a7c15ULL));
        const uint64_t idx = permuted(h);
        ++dim_;
        uint32_t x, y;
        sobol_bits_01(idx, x, y);
        return vec2(bits_to_unit(owen_scramble(x, uint32_t(h))), bits_to_unit(owen_scramble(y, uint32_t(h >> 32))));
    }

private:
    // The index with its low bits_ bits permuted digit by digit (base 4; the lowest digit is one
    // bit when bits_ is odd), each by the digits above it (unpermuted) and the dimension's hash.
    uint64_t permuted(uint64_t h) const {
        static constexpr uint8_t kPerm[24][4] = {
            {0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 1, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {0, 3, 2, 1},
            {1, 0, 2, 3}, {1, 0, 3, 2}, {1, 2, 0, 3}, {1, 2, 3, 0}, {1, 3, 0, 2}, {1, 3, 2, 0},
            {2, 0, 1, 3}, {2, 0, 3, 1}, {2, 1, 0, 3}, {2, 1, 3, 0}, {2, 3, 0, 1}, {2, 3, 1, 0},
            {3, 0, 1, 2}, {3, 0, 2, 1}, {3, 1, 0, 2}, {3, 1, 2, 0}, {3, 2, 0, 1}, {3, 2, 1, 0}};
        uint64_t out = base_ >> bits_ << bits_;
        const bool odd = bits_ & 1u;
        for (int d = int(digits_) - 1; d >= 0; --d) {
            const int width = (odd && d == 0) ? 1 : 2;
            const int shift = odd ? std::max(0, 2 * d - 1) : 2 * d;
            const uint64_t above = base_ >> (shift + width);
            uint64_t r = (above ^ h) * 0xd6e8feb86659fd93ULL;  // one round of a multiply-xorshift hash:
            r ^= r >> 32;                                     // enough to pick 1 of 24 permutations
            r *= 0xd6e8feb86659fd93ULL;
            uint64_t digit = (base_ >> shift) & ((uint64_t(1) << width) - 1);
            digit = width == 2 ? kPerm[(r >> 32) % 24][digit] : digit ^ ((r >> 32) & 1u);
            out |= digit << shift;
        }
        return out;
    }
    uint32_t log2_spp_ = 0, bits_ = 0, digits_ = 0;
    uint64_t salt_ = 0, base_ = 0;
};

// Mitsuba's `orthogonal` (Jarosz et al. 2019, "Orthogonal array sampling for Monte Carlo
// rendering"), strength 2: n' = p^2, p the smallest prime with p^2 >= n. Row r of the sample (a
// random permutation of its index in the set) is the pair (a0, a1) = (r / p, r % p); the Bose array
// gives it p + 1 columns, a1 and a0 + l a1 mod p for l = 0..p-1, any two of which take every pair
// of values once over the n' rows (p prime). Dimension k of a group is column k: its stratum of p is
// a random permutation of that column's value and its sub-stratum of p one of another column's
// (correlated multi-jitter: a 2D draw's x and y take each other's), so every dimension is a Latin
// hypercube in n' strata and every pair of dimensions of a group is stratified on the p x p grid.
// The array has p + 1 columns only; a draw that does not fit starts the next group, a fresh array
// (own row permutation; a 2D draw never straddles two). Mitsuba instead wraps l mod p, so that its
// dimensions repeat past p + 1. jitter as for stratified.
class OrthogonalSampler final : public SetSampleBase {
public:
    explicit OrthogonalSampler(const SamplerSetup& s)
        : SetSampleBase(s.seed, sampler_sample_count(SamplerType::Orthogonal, s.sample_count), s.desc.jitter) {
        p_ = 2;
        while (p_ * p_ < n_) ++p_;
    }
    void start_pixel_sample(ivec2 pixel, uint32_t i) {
        start_set(pixel, i);
        group_ = ~0u;  // no group yet: the first draw starts group 0
        col_ = p_ + 1;
    }
    float next_1d() {
        if (col_ + 1 > p_ + 1) new_group();
        const uint32_t c = col_++;
        return coordinate(c, c == 0 ? 1 : c - 1);
    }
    vec2 next_2d() {
        if (col_ + 2 > p_ + 1) new_group();
        const uint32_t c = col_;
        col_ += 2;
        const float x = coordinate(c, c + 1);
        return vec2(x, coordinate(c + 1, c));
    }

private:
    void new_group() {
        ++group_;
        const uint32_t gseed = uint32_t(mix_bits(key_ ^ (((uint64_t(set_) << 32) | group_) * 0xbf58476d1ce4e5b9ULL)) >> 16);
        const uint32_t r = sampler_detail::permute(member_, n_, gseed);
        a0_ = r / p_;
        a1_ = r % p_;
        col_ = 0;
    }
    // Column c of the row: c = 1 is a1, else a0 + l a1 with l = 0 (c = 0) or c - 1.
    uint32_t column(uint32_t c) const { return c == 1 ? a1_ : (a0_ + (c == 0 ? 0 : c - 1) * a1_) % p_; }
    float coordinate(uint32_t c, uint32_t sub) {
        const uint32_t seed = next_seed();
        const uint32_t stratum = sampler_detail::permute(column(c), p_, seed * 0x51633e2du + 1u);
        const uint32_t substratum = sampler_detail::permute(column(sub), p_, seed * 0x68bc21ebu + 2u);
        const float j = jit();
        return sampler_detail::below_one((float(stratum) + (float(substratum) + j) / float(p_)) / float(p_));
    }
    uint32_t p_ = 2, group_ = 0, col_ = 0, a0_ = 0, a1_ = 0;
};

// The sampler of type S for a setup.
template <class S>
S make_sampler(const SamplerSetup& s) {
    return S(s);
}
template <>
inline IndependentSampler make_sampler<IndependentSampler>(const SamplerSetup& s) {
    return IndependentSampler(s.seed);
}

// A sampler type as a value: SamplerTag<S>::type is S.
template <class S>
struct SamplerTag {
    using type = S;
};

// The one dispatch on the sampler type: calls f(SamplerTag<S>{}) for the class S of `type`, so
// that f is instantiated once per sampler class and chosen once per pass (every pass, per-path or
// staged, path or direct or BDPT, goes through here).
template <class F>
decltype(auto) visit_sampler_type(SamplerType type, F&& f) {
    switch (type) {
        case SamplerType::Stratified: return f(SamplerTag<StratifiedSampler>{});
        case SamplerType::Multijitter: return f(SamplerTag<MultijitterSampler>{});
        case SamplerType::LdSampler: return f(SamplerTag<LdSampler>{});
        case SamplerType::Sobol: return f(SamplerTag<SobolSampler>{});
        case SamplerType::ZSobol: return f(SamplerTag<ZSobolSampler>{});
        case SamplerType::Orthogonal: return f(SamplerTag<OrthogonalSampler>{});
        case SamplerType::Independent: break;
    }
    return f(SamplerTag<IndependentSampler>{});
}

// X(S) for each sampler class but the independent one: the instantiations compiled apart, each in
// its own translation unit (integrator/samplers/), declared extern where the passes are dispatched.
#define CANDELA_FOR_EACH_SAMPLER_COMPILED_APART(X) \
    X(StratifiedSampler)                           \
    X(MultijitterSampler)                          \
    X(LdSampler)                                   \
    X(SobolSampler)                                \
    X(ZSobolSampler)                               \
    X(OrthogonalSampler)

// Calls f(sampler) with the sampler the setup names, constructed: one instantiation of f per type.
template <class F>
decltype(auto) visit_sampler(const SamplerSetup& s, F&& f) {
    return visit_sampler_type(s.desc.type, [&](auto tag) -> decltype(auto) {
        return f(make_sampler<typename decltype(tag)::type>(s));
    });
}

}  // namespace candela
