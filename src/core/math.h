// Basic math: GLM vectors plus the few float helpers the renderer needs everywhere.
#pragma once
#include <glm/glm.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace candela {

using glm::vec2;
using glm::vec3;
using glm::ivec2;
using glm::uvec3;
using glm::dvec3;
using glm::dvec4;
using glm::mat4;

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInv2Pi = 0.15915494309189533577f;
constexpr float kInv4Pi = 0.07957747154594766788f;
constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Half an ulp of 1: the unit roundoff used in pbrt-style error bounds.
constexpr float kMachineEpsilon = std::numeric_limits<float>::epsilon() * 0.5f;

// gamma(n) bounds the relative error of n chained float operations (Higham).
constexpr float gamma_bound(int n) { return (n * kMachineEpsilon) / (1 - n * kMachineEpsilon); }

inline float max_component(vec3 v) { return std::max(v.x, std::max(v.y, v.z)); }
inline float min_component(vec3 v) { return std::min(v.x, std::min(v.y, v.z)); }
// The axis of the largest component: (x > y) ? (x > z ? 0 : 2) : (y > z ? 1 : 2), without branches
// (a ray's main axis is a coin toss from one ray to the next).
inline int max_dimension(vec3 v) {
    const bool xy = v.x > v.y;
    const float m = xy ? v.x : v.y;
    const int i = 1 - int(xy);
    return 2 - int(m > v.z) * (2 - i);
}
// |v| per component with the sign bit cleared (andps). glm::abs is x >= 0 ? x : -x, which GCC
// compiles to a branch per component, taken at random for directions and normals; the two
// differ only in the sign of a zero (glm keeps -0), which no comparison sees.
inline vec3 abs3(vec3 v) { return vec3(std::abs(v.x), std::abs(v.y), std::abs(v.z)); }
inline float luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
inline bool is_black(vec3 c) { return c.x == 0.f && c.y == 0.f && c.z == 0.f; }
inline bool all_finite(vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline float safe_sqrt(float x) { return std::sqrt(std::max(x, 0.f)); }
inline float sqr(float x) { return x * x; }

inline uint32_t float_to_bits(float f) { uint32_t u; std::memcpy(&u, &f, 4); return u; }
inline float bits_to_float(uint32_t u) { float f; std::memcpy(&f, &u, 4); return f; }

// The next representable float above / below v (pbrt-v4 NextFloatUp / NextFloatDown).
inline float next_float_up(float v) {
    if (std::isinf(v) && v > 0.f) return v;
    if (v == -0.f) v = 0.f;
    uint32_t ui = float_to_bits(v);
    ui = (v >= 0) ? ui + 1 : ui - 1;
    return bits_to_float(ui);
}
inline float next_float_down(float v) {
    if (std::isinf(v) && v < 0.f) return v;
    if (v == 0.f) v = -0.f;
    uint32_t ui = float_to_bits(v);
    ui = (v > 0) ? ui - 1 : ui + 1;
    return bits_to_float(ui);
}

// c ? a : b without a branch, bit for bit the ternary's result. For choices made by random numbers
// (which of two warps' halves, which side of a split), where a predictor guesses wrong half the time.
inline float choose(bool c, float a, float b) {
    const uint32_t m = 0u - uint32_t(c);
    return bits_to_float((float_to_bits(a) & m) | (float_to_bits(b) & ~m));
}

// 64-bit mixing (the MurmurHash3 finaliser): turns structured integers into seeds.
inline uint64_t mix_bits(uint64_t v) {
    v ^= (v >> 31);
    v *= 0x7fb5d329728ea185ULL;
    v ^= (v >> 27);
    v *= 0x81dadef4bc2dd44dULL;
    v ^= (v >> 33);
    return v;
}
inline uint64_t hash_combine(uint64_t a, uint64_t b) { return mix_bits(a ^ (mix_bits(b) + 0x9e3779b97f4a7c15ULL + (a << 6) + (a >> 2))); }

}  // namespace candela
