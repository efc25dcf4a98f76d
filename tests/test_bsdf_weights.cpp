// Sample weights of the rough dielectric and the rough plastic coat stay bounded at every roughness
// (1e-4 to 1) and incident angle (cos theta_o from 1 down to 1e-7), both sides and both transport
// modes: large weights are fireflies even when the estimator is unbiased.
//
// The bound, from visible-normal sampling (Heitz 2018) of a microfacet normal m:
//   dielectric  reflection  f |cos i| / pdf = R_s F D G1(wo) G1(wi) / (4 |cos o|)
//                                             / (F G1(wo) |wo.m| D / |cos o| / (4 |wo.m|)) = R_s G1(wi, m)
//               refraction  f |cos i| / pdf = T_s G1(wi, m) s, with s = 1 / eta_r^2 (Radiance) or 1
//   so weight * (Radiance ? eta_r^2 : 1) <= max(R_s, T_s) = 1: the G2 / G1 of the separable Smith
//   term, times the Fresnel choice cancelled by its probability.
//   plastic     the coat alone (black base, so the coat is always chosen): R_s F(wo.m) G1(wi, m) <= 1.
//               With a base, the sample is drawn from the mixture ps coat + (1 - ps) cosine and
//               weighed by the sum of both lobes over the mixture pdf, which is at most the larger
//               of the lobes' own weights over their probabilities: R_s / ps and
//               rho / (1 - Ri) T(cos o) T(cos i) / (eta^2 (1 - ps)).
// Before the sampled normal m was used directly (the half vector was rebuilt from wo + wi, which
// nearly cancels for grazing reflection), these weights reached ~1e5 at alpha 1e-4.
#include <gtest/gtest.h>
#include <cstdio>
#include <string>
#include "bsdf/bsdf.h"
#include "sampling/pcg32.h"
#include "support/stats.h"

using namespace candela;
using namespace candela::stats;

namespace {

const float kRoughness[] = {1e-4f, 1e-3f, 1e-2f, 0.1f, 0.3f, 1.f};
const float kCosines[] = {1.f, 0.7f, 0.3f, 0.1f, 1e-2f, 1e-3f, 1e-4f, 1e-5f, 1e-7f};
constexpr int kSamplesPerCase = 4000;
constexpr float kRounding = 1e-4f;  // float rounding of f / pdf

vec3 dir_with_cos(float c, float phi) {
    float s = std::sqrt(std::max(0.f, 1.f - c * c));
    return vec3(s * std::cos(phi), s * std::sin(phi), c);
}

// The lobe choice of PlasticBsdf::sample (plastic.h): proportional to (1 - T(cos o)) s / (s + d).
float plastic_specular_probability(const PlasticBsdf& p, float cos_o) {
    const float s = (p.specular_reflectance.x + p.specular_reflectance.y + p.specular_reflectance.z) / 3.f;
    const float d = (p.diffuse_reflectance.x + p.diffuse_reflectance.y + p.diffuse_reflectance.z) / 3.f;
    const float w = s / (s + d);
    const float t = p.tables->transmittance_at(cos_o);
    const float ps = (1.f - t) * w, pd = t * (1.f - w);
    return ps / (ps + pd);
}

}  // namespace

TEST(BsdfWeights, RoughDielectricWeightIsAtMostOne) {
    PCG32 rng(41, 5);
    float worst = 0.f;
    std::string worst_case;
    for (float ior : {1.0001f, 1.5f, 2.42f, 4.f})
        for (float a : kRoughness) {
            DielectricBsdf d;
            d.int_ior = ior;
            d.ext_ior = 1.f;
            d.distribution = MicrofacetType::GGX;
            d.alpha_u = d.alpha_v = a;
            const Bsdf b = d;
            float row_max = 0.f;
            for (float side : {1.f, -1.f})
                for (float c : kCosines) {
                    RunningStats albedo;  // importance mode: no eta^2 scaling
                    for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance})
                        for (int i = 0; i < kSamplesPerCase; ++i) {
                            const vec3 wo = side * dir_with_cos(c, 6.2831853f * rng.next_float());
                            const float u1 = rng.next_float(), ux = rng.next_float();
                            auto bs = sample(b, wo, u1, vec2(ux, rng.next_float()), mode);
                            if (mode == TransportMode::Importance) albedo.add(bs ? double(bs->weight().x) : 0.0);
                            if (!bs) continue;
                            ASSERT_FALSE(bs->delta);
                            // Undo the Radiance scaling of refraction: what remains is R or T times G1.
                            const float unscale = mode == TransportMode::Radiance ? bs->eta * bs->eta : 1.f;
                            const float w = max_component(bs->weight()) * unscale;
                            ASSERT_TRUE(std::isfinite(w));
                            row_max = std::max(row_max, w);
                            if (w > worst) {
                                worst = w;
                                char buf[96];
                                std::snprintf(buf, sizeof buf, "ior %g alpha %g cos theta_o %g", ior, a, side * c);
                                worst_case = buf;
                            }
                        }
                    // A nearly smooth interface (alpha <= 0.01 and alpha tan theta_o <= 0.1, so G1 >
                    // 0.99 for wo and the scattered wi) keeps nearly all the energy, as the smooth
                    // one does: bounded weights must not come from dropping samples.
                    const float tan_o = std::sqrt(std::max(0.f, 1.f - c * c)) / c;
                    if (a <= 0.01f && a * tan_o <= 0.1f) {
                        EXPECT_GT(albedo.mean(), 0.98) << "ior " << ior << " alpha " << a << " cos " << side * c;
                    }
                }
            std::printf("  dielectric ior %-6g alpha %-6g max weight (eta_r^2 undone) %.6f\n", ior, a, row_max);
        }
    std::printf("  worst: %.6f at %s\n", worst, worst_case.c_str());
    EXPECT_LE(worst, 1.f + kRounding) << worst_case;
}

TEST(BsdfWeights, RoughPlasticWeightIsBounded) {
    PCG32 rng(43, 5);
    for (float ior : {1.0001f, 1.49f, 4.f})
        for (float a : kRoughness)
            for (float rho : {0.f, 0.5f}) {
                PlasticBsdf p;
                p.int_ior = ior;
                p.ext_ior = 1.f;
                p.alpha = a;
                p.diffuse_reflectance = vec3(rho);
                p.prepare();
                const Bsdf b = p;
                const float e = p.eta();
                const float base = rho / (1.f - p.tables->internal_reflectance);
                float t_max = 0.f;
                for (float t : p.tables->transmittance) t_max = std::max(t_max, t);
                float row_max = 0.f, row_ratio = 0.f, worst_cos = 0.f;
                for (float c : kCosines) {
                    // The lobe bound of the header comment; with a black base only the coat's R_s.
                    const float ps = plastic_specular_probability(p, c);
                    float bound = 1.f;
                    if (rho > 0.f) {
                        bound = std::max(ps > 0.f ? 1.f / ps : 0.f,
                                         ps < 1.f ? base * p.tables->transmittance_at(c) * t_max / (e * e * (1.f - ps)) : 0.f);
                    }
                    for (int i = 0; i < kSamplesPerCase; ++i) {
                        const vec3 wo = dir_with_cos(c, 6.2831853f * rng.next_float());
                        const float u1 = rng.next_float(), ux = rng.next_float();
                        auto bs = sample(b, wo, u1, vec2(ux, rng.next_float()), TransportMode::Radiance);
                        if (!bs) continue;
                        const float w = max_component(bs->weight());
                        ASSERT_TRUE(std::isfinite(w));
                        row_max = std::max(row_max, w);
                        if (w / bound > row_ratio) {
                            row_ratio = w / bound;
                            worst_cos = c;
                        }
                    }
                }
                EXPECT_LE(row_ratio, 1.f + kRounding)
                    << "ior " << ior << " alpha " << a << " rho " << rho << " cos theta_o " << worst_cos;
                std::printf("  plastic ior %-6g alpha %-6g rho %.1f max weight %.6f (%.3f of the bound)\n", ior, a,
                            rho, row_max, row_ratio);
            }
}
