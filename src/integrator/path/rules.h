#pragma once
// The numeric rules of a path's bounce that both the per-path bounce (path/bounce.h) and the SIMD
// lane step (path/diffuse_step.cpp) apply, written once over a value type V and its operations.
// Ops provides set(float), mul, add, div, lt, gt, is_inf and select(mask, a, b) for V: a float with
// ScalarOps below, a Highway vector in diffuse_step.cpp. Each rule is a fixed sequence of IEEE
// operations, so a lane computes what the per-path bounce computes, bit for bit (the staged loop's
// images are compared with the per-path loop's: tests/test_staged.cpp).
#include <cmath>

namespace candela {

// The operations on one float.
struct ScalarOps {
    static float set(float x) { return x; }
    static float mul(float a, float b) { return a * b; }
    static float add(float a, float b) { return a + b; }
    static float div(float a, float b) { return a / b; }
    static bool lt(float a, float b) { return a < b; }
    static bool gt(float a, float b) { return a > b; }
    static bool is_inf(float a) { return std::isinf(a); }
    static float select(bool m, float a, float b) { return m ? a : b; }
};

namespace path_rules {

// Veach's power heuristic (beta = 2): the weight of a sample of density a against another strategy
// of density b at the same point, both in the same measure. 1 when a^2 overflows (a delta-like
// peak), 0 when both densities are 0.
template <class Ops, class V>
inline V power_heuristic(const Ops& o, V a, V b) {
    const V a2 = o.mul(a, a), b2 = o.mul(b, b);
    const V sum = o.add(a2, b2);
    return o.select(o.is_inf(a2), o.set(1.f), o.select(o.gt(sum, o.set(0.f)), o.div(a2, sum), o.set(0.f)));
}

// The MIS weight of a light sample of solid-angle density light_pdf against BSDF sampling of the
// same direction (bsdf_pdf, solid angle), whose ray crosses masks with transmittance T: the BSDF
// strategy reaches the light through the same masks with probability T.
template <class Ops, class V>
inline V light_mis_weight(const Ops& o, V light_pdf, V bsdf_pdf, V T) {
    return power_heuristic(o, light_pdf, o.mul(bsdf_pdf, T));
}

// What multiplies beta f Le in a light sample's contribution: T w / light_pdf (the estimator of
// the direct light divides by the light sample's solid-angle density).
template <class Ops, class V>
inline V light_scale(const Ops& o, V T, V w, V light_pdf) {
    return o.div(o.mul(T, w), light_pdf);
}

// Russian roulette's survival probability: min(max(beta) x eta_scale, 0.95), written as std::max
// and std::min are (a < b ? b : a, b < a ? b : a). eta_scale is the product of eta^2 over the
// refractions: it undoes their 1 / eta^2, a change of solid-angle measure and not a loss of
// importance (pbrt-v4's etaScale). The path survives when its number u < q, and beta is divided by q.
template <class Ops, class V>
inline V roulette_survival(const Ops& o, V b0, V b1, V b2, V eta_scale) {
    const V m12 = o.select(o.lt(b1, b2), b2, b1);
    const V m = o.select(o.lt(b0, m12), m12, b0);
    const V q = o.mul(m, eta_scale);
    const V c95 = o.set(0.95f);
    return o.select(o.lt(c95, q), c95, q);
}

}  // namespace path_rules
}  // namespace candela
