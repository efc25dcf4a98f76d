#pragma once
#include <array>
#include <cstdint>

namespace candela {

namespace detail {
// PCG32::advance's multiplier and increment factor after k of its doublings: kMult^(2^k) and
// prod_{j<k} (kMult^(2^j) + 1), both mod 2^64.
struct PcgDoubling {
    uint64_t mult, plus;
};
constexpr std::array<PcgDoubling, 64> pcg_doublings(uint64_t mult) {
    std::array<PcgDoubling, 64> d{};
    uint64_t plus = 1u;
    for (auto& e : d) {
        e = {mult, plus};
        plus *= mult + 1u;
        mult *= mult;
    }
    return d;
}
}  // namespace detail

// PCG32 (O'Neill 2014, "PCG: A family of simple fast space-efficient statistically good algorithms
// for random number generation"): 64-bit LCG state, XSH-RR output. Each `seq` selects an
// independent stream; advance() jumps ahead in O(log n), which lets a sampler place sample i of a
// pixel at a fixed offset in the pixel's stream, independent of which thread draws it.
class PCG32 {
public:
    static constexpr uint64_t kDefaultState = 0x853c49e6748fea9bULL;
    static constexpr uint64_t kDefaultStream = 0xda3e39cb94b95bdbULL;
    static constexpr uint64_t kMult = 0x5851f42d4c957f2dULL;

    PCG32() = default;
    PCG32(uint64_t seq, uint64_t seed) { set_sequence(seq, seed); }

    void set_sequence(uint64_t seq, uint64_t seed) {
        state_ = 0u;
        inc_ = (seq << 1u) | 1u;
        next_u32();
        state_ += seed;
        next_u32();
    }

    uint32_t next_u32() {
        uint64_t old = state_;
        state_ = old * kMult + inc_;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }

    // Uniform in [0, 1): 24 random mantissa bits, so 1 is never returned.
    float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }

    // Jump ahead by delta steps (Brown 1994, "Random number generation with arbitrary strides").
    // The doublings for delta's trailing zero bits come from a table: the samplers advance by
    // multiples of 2^16. Integer arithmetic mod 2^64, so the state is the same as doubling each time.
    void advance(uint64_t delta) {
        if (delta == 0) return;
        static constexpr std::array<detail::PcgDoubling, 64> kDoublings = detail::pcg_doublings(kMult);
        const int k = __builtin_ctzll(delta);
        delta >>= k;
        uint64_t cur_mult = kDoublings[size_t(k)].mult, cur_plus = kDoublings[size_t(k)].plus * inc_;
        uint64_t acc_mult = 1u, acc_plus = 0u;
        while (delta > 0) {
            if (delta & 1) {
                acc_mult *= cur_mult;
                acc_plus = acc_plus * cur_mult + cur_plus;
            }
            cur_plus = (cur_mult + 1) * cur_plus;
            cur_mult *= cur_mult;
            delta >>= 1;
        }
        state_ = acc_mult * state_ + acc_plus;
    }

    uint64_t state() const { return state_; }
    uint64_t inc() const { return inc_; }
    void restore(uint64_t state, uint64_t inc) { state_ = state; inc_ = inc; }

private:
    uint64_t state_ = kDefaultState;
    uint64_t inc_ = kDefaultStream;
};

}  // namespace candela
