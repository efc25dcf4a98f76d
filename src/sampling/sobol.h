#pragma once
// Sobol points in base 2 and hash-based Owen scrambling: the building blocks of the QMC samplers
// (sampling/samplers.h).
//
// Generator matrices. Dimension j of the Sobol sequence is x_j(i) = C_j * bits(i) over GF(2), the
// columns of C_j being the direction numbers v_{j,k} (k = 0, 1, ...), kept left-aligned in 32 bits
// (bit 31 is 1/2). Dimension 0 is the identity (van der Corput). Dimension j >= 1 comes from a
// primitive polynomial x^s + a_1 x^{s-1} + ... + a_{s-1} x + 1 over GF(2) and s initial odd
// integers m_1..m_s (m_k < 2^k), v_k = m_k / 2^k; past them the recurrence
//   v_k = a_1 v_{k-1} ^ a_2 v_{k-2} ^ ... ^ a_{s-1} v_{k-s+1} ^ v_{k-s} ^ (v_{k-s} >> s)
// (Bratley and Fox 1988). The polynomials and initial numbers of dimensions 1..31 are Joe and
// Kuo's (2008) new-joe-kuo-6.21201 set, the public data of their paper (its lines d = 2..32), chosen
// so that the two-dimensional projections have small t-values. Truncating the direction numbers to
// 32 bits commutes with the recurrence (right shifts and XORs only), so columns past 32 (the Z-order
// sampler's 64-bit indices) are the exact leading bits too.
//
// Owen scrambling (Owen 1995): every digit of a point is flipped by a random function of the digits
// above it. Burley 2020 ("Practical Hash-based Owen Scrambling", JCGT 9(4)) does that with a hash
// that, applied to the bit-reversed value, changes bit k only as a function of the bits below k:
// x + c, and x ^ (x * e) for even e, both have that property. A nested scramble maps elementary
// intervals onto elementary intervals of the same shape, so a (t, m, s)-net stays one and each
// scrambled point is uniform on [0, 1): unbiased, with the net's stratification.
#include <array>
#include <cstddef>
#include <cstdint>

namespace candela {

constexpr int kSobolDimensions = 32;  // generator matrices tabulated (dimensions 0..31)
constexpr int kSobolColumns = 64;     // index bits (the per-pixel sampler uses 32, Z order up to 64)

namespace sobol_detail {

struct Poly {
    int s;         // degree
    uint32_t a;    // the inner coefficients a_1..a_{s-1}, a_1 the most significant bit
    uint32_t m[8]; // m_1..m_s
};

// Joe and Kuo, new-joe-kuo-6.21201, lines d = 2..32 (dimensions 1..31 here).
constexpr Poly kPolys[kSobolDimensions - 1] = {
    {1, 0, {1}},
    {2, 1, {1, 3}},
    {3, 1, {1, 3, 1}},
    {3, 2, {1, 1, 1}},
    {4, 1, {1, 1, 3, 3}},
    {4, 4, {1, 3, 5, 13}},
    {5, 2, {1, 1, 5, 5, 17}},
    {5, 4, {1, 1, 5, 5, 5}},
    {5, 7, {1, 1, 7, 11, 19}},
    {5, 11, {1, 1, 5, 1, 1}},
    {5, 13, {1, 1, 1, 3, 11}},
    {5, 14, {1, 3, 5, 5, 31}},
    {6, 1, {1, 3, 3, 9, 7, 49}},
    {6, 13, {1, 1, 1, 15, 21, 21}},
    {6, 16, {1, 3, 1, 13, 27, 49}},
    {6, 19, {1, 1, 1, 15, 7, 5}},
    {6, 22, {1, 3, 1, 15, 13, 25}},
    {6, 25, {1, 1, 5, 5, 19, 61}},
    {7, 1, {1, 3, 7, 11, 23, 15, 103}},
    {7, 4, {1, 3, 7, 13, 13, 15, 69}},
    {7, 7, {1, 1, 3, 13, 7, 35, 63}},
    {7, 8, {1, 3, 5, 9, 1, 25, 53}},
    {7, 14, {1, 3, 1, 13, 9, 35, 107}},
    {7, 19, {1, 3, 1, 5, 27, 61, 31}},
    {7, 21, {1, 1, 5, 11, 19, 41, 61}},
    {7, 28, {1, 3, 5, 3, 3, 13, 69}},
    {7, 31, {1, 1, 7, 13, 1, 19, 1}},
    {7, 32, {1, 3, 7, 5, 13, 19, 59}},
    {7, 37, {1, 1, 3, 9, 25, 29, 41}},
    {7, 41, {1, 3, 5, 13, 23, 1, 55}},
    {7, 42, {1, 3, 7, 3, 13, 59, 17}},
};

using Matrices = std::array<std::array<uint32_t, kSobolColumns>, kSobolDimensions>;

constexpr Matrices make_matrices() {
    Matrices c{};
    for (int k = 0; k < kSobolColumns; ++k) c[0][size_t(k)] = k < 32 ? 1u << (31 - k) : 0u;
    for (int j = 1; j < kSobolDimensions; ++j) {
        const Poly& p = kPolys[j - 1];
        auto& v = c[size_t(j)];
        for (int k = 0; k < kSobolColumns; ++k) {
            if (k < p.s) {
                v[size_t(k)] = p.m[k] << (31 - k);
                continue;
            }
            uint32_t x = v[size_t(k - p.s)] ^ (v[size_t(k - p.s)] >> p.s);
            for (int i = 1; i < p.s; ++i)
                if ((p.a >> (p.s - 1 - i)) & 1u) x ^= v[size_t(k - i)];
            v[size_t(k)] = x;
        }
    }
    return c;
}

inline constexpr Matrices kMatrices = make_matrices();

constexpr uint32_t reverse_bits32_constexpr(uint32_t x) {
    uint32_t r = 0;
    for (int i = 0; i < 32; ++i) r |= ((x >> i) & 1u) << (31 - i);
    return r;
}

// The same columns bit-reversed: the Owen scramble works on reversed values, so the samplers build
// the reversed point directly and save one reversal per dimension.
constexpr Matrices make_reversed() {
    Matrices c = make_matrices();
    for (auto& d : c)
        for (auto& v : d) v = reverse_bits32_constexpr(v);
    return c;
}

inline constexpr Matrices kReversedMatrices = make_reversed();

}  // namespace sobol_detail

namespace sobol_detail {
// All ones where the index's low bit is set: the matrix-vector product masks each column instead of
// branching on the bit. The bits of a hashed or permuted index (zsobol) are random, so a branch per
// bit mispredicts about half the time; that cost is invisible to instruction counts (callgrind)
// but was most of the Sobol samplers' wall-clock overhead (docs/samplers.md).
inline uint32_t low_bit_mask(uint64_t index) { return 0u - uint32_t(index & 1u); }

inline uint32_t multiply(const std::array<uint32_t, kSobolColumns>& c, uint64_t index) {
    uint32_t v = 0;
    for (size_t k = 0; index != 0; index >>= 1, ++k) v ^= c[k] & low_bit_mask(index);
    return v;
}
}  // namespace sobol_detail

// x_dim(index) as 32 fixed-point bits (unscrambled); dim < kSobolDimensions.
inline uint32_t sobol_bits(uint64_t index, int dim) {
    return sobol_detail::multiply(sobol_detail::kMatrices[size_t(dim)], index);
}

// reverse_bits32(sobol_bits(index, dim)).
inline uint32_t sobol_bits_reversed(uint64_t index, int dim) {
    return sobol_detail::multiply(sobol_detail::kReversedMatrices[size_t(dim)], index);
}

// Dimensions 0 and 1 together (one pass over the index bits).
inline void sobol_bits_01(uint64_t index, uint32_t& x, uint32_t& y) {
    const auto& c0 = sobol_detail::kMatrices[0];
    const auto& c1 = sobol_detail::kMatrices[1];
    x = y = 0;
    for (size_t k = 0; index != 0; index >>= 1, ++k) {
        const uint32_t m = sobol_detail::low_bit_mask(index);
        x ^= c0[k] & m;
        y ^= c1[k] & m;
    }
}

inline uint32_t reverse_bits32(uint32_t x) {
    x = __builtin_bswap32(x);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

// Owen scrambling of the 32-bit fixed-point value `v` by the hash of `seed` (Burley 2020, with his
// constants): on the reversed bits, each step flips bit k by a function of bits 0..k-1 only.
// owen_scramble of the value whose bit reversal is `x` (sobol_bits_reversed).
inline uint32_t owen_scramble_reversed(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverse_bits32(x);
}
inline uint32_t owen_scramble(uint32_t v, uint32_t seed) { return owen_scramble_reversed(reverse_bits32(v), seed); }

// 32 fixed-point bits to [0, 1): the top 24 bits, exactly representable, so 1 is never returned.
inline float bits_to_unit(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

}  // namespace candela
