#pragma once
#include "core/math.h"
#include "sampling/pcg32.h"

namespace candela {

// The only source of randomness in rendering. Before each camera sample the renderer calls
// start_pixel_sample(pixel, index); the numbers drawn after it depend only on (pixel, index, seed),
// never on the thread or the order in which pixels are visited, so an image is reproducible bit for
// bit at any thread count. Metropolis samplers replace this with one that replays and mutates
// primary-sample-space vectors; integrators only see next_1d / next_2d.
class Sampler {
public:
    virtual ~Sampler() = default;
    virtual void start_pixel_sample(ivec2 pixel, uint32_t sample_index) = 0;
    virtual float next_1d() = 0;
    virtual vec2 next_2d() = 0;
};

// Independent uniform samples: each pixel owns the PCG32 stream hash(pixel, seed); sample i starts
// 2^16 draws into it (pbrt-v4 IndependentSampler does the same), so a path may use up to 65536
// numbers before it overlaps the next sample's numbers (it never does: paths are cut far earlier).
class IndependentSampler final : public Sampler {
public:
    explicit IndependentSampler(uint64_t seed = 0) : seed_(seed) {}
    void start_pixel_sample(ivec2 pixel, uint32_t sample_index) override {
        uint64_t px = (uint64_t(uint32_t(pixel.x)) << 32) | uint32_t(pixel.y);
        rng_.set_sequence(hash_combine(px, seed_), mix_bits(seed_ ^ 0x5bd1e995ULL));
        rng_.advance(uint64_t(sample_index) << 16);
    }
    // Forced inline: the full build's path loop otherwise calls next_2d out of line (GCC's
    // inlining budget is shared with every other instantiation), the diffuse-only build does not.
    __attribute__((always_inline)) float next_1d() override { return rng_.next_float(); }
    __attribute__((always_inline)) vec2 next_2d() override {
        float a = rng_.next_float();
        return vec2(a, rng_.next_float());
    }
    uint64_t seed() const { return seed_; }

private:
    uint64_t seed_;
    PCG32 rng_;
};

}  // namespace candela
