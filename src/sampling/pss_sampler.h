#pragma once
// The primary-sample-space sampler of Metropolis light transport (Kelemen et al. 2002; the
// structure of pbrt-v3's MLTSampler). A state is a vector X in [0,1)^inf, extended lazily: the
// integrator draws X_0, X_1, ... through next_1d / next_2d as with any sampler, and a coordinate
// is only made (or mutated) when it is first drawn in an iteration. An iteration is a proposal:
//   start_iteration(); run the integrator (it draws what it needs); accept() or reject().
// A proposal is a large step (every coordinate fresh uniform) with probability
// large_step_probability, otherwise a small step: X_i += N(0, sigma^2) wrapped to [0,1). Both are
// symmetric proposals, so the Metropolis ratio is I(y) / I(x). reject() restores the backups of
// the coordinates this iteration touched.
//
// Laziness: a coordinate not drawn for k iterations is brought up to date when next drawn. If a
// large step was accepted since, it is first made fresh uniform (what the large step would have
// made it), then moved by the small steps since: k normal steps of sigma sum to one of
// sigma sqrt(k).
//
// Streams (for MMLT: camera path, light path, connection): coordinate j of stream s is X[j n + s]
// with n streams, so each stream extends independently. PSSMLT uses one stream.
//
// The rng is seeded per state (seed, index): a bootstrap sample and the chain started from it
// replay the same numbers, so a chain's start state is rebuilt from its bootstrap index.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>
#include "core/math.h"
#include "sampling/pcg32.h"
#include "sampling/sampler.h"

namespace candela {

class PssSampler final : public Sampler {
public:
    PssSampler() = default;
    PssSampler(uint64_t seed, uint64_t index, float sigma, float large_step_probability, int streams = 1)
        : rng_(hash_combine(index, seed), mix_bits(seed ^ 0x9e3779b97f4a7c15ULL)), sigma_(sigma),
          large_step_probability_(large_step_probability), streams_(streams) {}

    // The sampler seam: the pixel and index are meaningless here (the state picks the pixel);
    // a camera sample starts drawing stream 0 from its first coordinate.
    void start_pixel_sample(ivec2, uint32_t) override { start_stream(0); }
    void start_stream(int s) {
        stream_ = s;
        next_ = 0;
    }
    float next_1d() override { return value(index(next_++)); }
    vec2 next_2d() override {
        const float a = next_1d();
        return vec2(a, next_1d());
    }

    // A new random stream for the mutations from here on (the state is kept): chains started from
    // the same bootstrap sample then move apart.
    void reseed(uint64_t seed, uint64_t chain) {
        rng_.set_sequence(hash_combine(chain, seed ^ 0x2545f4914f6cdd1dULL), mix_bits(seed + chain));
    }
    void start_iteration() {
        ++iteration_;
        large_step_ = rng_.next_float() < large_step_probability_;
    }
    void accept() {
        if (large_step_) last_large_step_ = iteration_;
    }
    void reject() {
        for (Coord& c : x_)
            if (c.modified == iteration_) {
                c.value = c.backup;
                c.modified = c.backup_modified;
            }
        --iteration_;
    }
    bool large_step() const { return large_step_; }
    size_t dimensions() const { return x_.size(); }

private:
    struct Coord {
        float value = 0.f, backup = 0.f;
        uint64_t modified = 0, backup_modified = 0;  // the iteration that last set value
        bool made = false;
    };
    size_t index(int j) const { return size_t(j) * size_t(streams_) + size_t(stream_); }

    float value(size_t i) {
        if (i >= x_.size()) x_.resize(i + 1);
        Coord& c = x_[i];
        // A coordinate never drawn, or not since an accepted large step (or the start state, made as
        // one): it is what that step made it, a fresh uniform.
        if (!c.made || c.modified < last_large_step_) {
            c.made = true;
            c.value = rng_.next_float();
            c.modified = last_large_step_;
        }
        c.backup = c.value;
        c.backup_modified = c.modified;
        if (large_step_) {
            c.value = rng_.next_float();
        } else {
            const double steps = double(iteration_ - c.modified);
            double v = double(c.value) + normal() * double(sigma_) * std::sqrt(steps);
            v -= std::floor(v);
            c.value = std::min(float(v), 0x1.fffffep-1f);  // v < 1 may round up to 1 in float
        }
        c.modified = iteration_;
        return c.value;
    }
    // A standard normal by Box-Muller (one of the pair: the other would need state across calls).
    double normal() {
        const double u1 = 1.0 - double(rng_.next_float());  // (0, 1]
        const double u2 = double(rng_.next_float());
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
    }

    PCG32 rng_;
    float sigma_ = 0.01f, large_step_probability_ = 0.3f;
    int streams_ = 1, stream_ = 0, next_ = 0;
    // Iteration 0 is the start state, made as a large step (fresh uniform coordinates): what a
    // bootstrap sample evaluates.
    uint64_t iteration_ = 0, last_large_step_ = 0;
    bool large_step_ = true;
    std::vector<Coord> x_;
};

}  // namespace candela
