#pragma once
#include <array>
#include <memory>
#include <optional>
#include "bsdf/common.h"
#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"

namespace candela {

// What a plastic coat needs beyond its parameters; computed by prepare() (plastic.cpp) for one
// (alpha, eta, distribution).
struct CoatTables {
    static constexpr int kRes = 64;
    float alpha = -1.f, eta = 0.f;  // what the tables were computed for
    MicrofacetType distribution = MicrofacetType::Beckmann;
    // Transmittance of the coat for light arriving from outside, against cos theta on a uniform
    // grid over [0, 1] (smooth coat: 1 - F; rough: integral of the rough dielectric transmission).
    std::array<float, kRes> transmittance{};
    // Fraction of the base's diffuse light that the coat reflects back down.
    float internal_reflectance = 0.f;

    float transmittance_at(float cos_theta) const;  // linear interpolation in the table
};

// Coats whose tables are alive in the shared cache (PlasticBsdf::prepare), for tests.
size_t coat_table_cache_size();

// A dielectric coat over a Lambertian base (Mitsuba 3 `plastic` and `roughplastic`, nonlinear =
// false by default). eta = int_ior / ext_ior. With T(mu) the coat's transmittance, Ri its internal
// reflectance and rho = diffuse_reflectance:
//   specular  alpha == 0: a delta mirror lobe with weight R_s F(cos theta_o), eval/pdf exclude it.
//             alpha > 0:  microfacet (Beckmann or GGX) reflection R_s F(wo.h) D G / (4 cos theta_o) (as the rough conductor),
//                         h sampled from the visible normals: lobe weight R_s F(wo.h) G1(wi, h) <= 1
//   diffuse   f cos theta_i = rho / (1 - Ri) * T(cos theta_o) T(cos theta_i) cos theta_i / (pi eta^2)
//             (nonlinear: rho / (1 - rho Ri), the colour shift of repeated internal bounces)
// T and Ri are Mitsuba's: smooth T = 1 - F, Ri = the hemispherical average of F from inside; rough
// T from the GGX interface, Ri = twice the mean of r(mu) mu over the 64 grid points. The specular
// lobe is chosen with probability proportional to (1 - T(cos theta_o)) * s / (s + d), where s and d
// are the mean specular and diffuse reflectances; the sample's pdf is the mixture of both lobes'.
// One-sided; reflection only (symmetric, mode-independent). Call prepare() after editing alpha or
// the IORs; until then eval and sample return nothing.
struct PlasticBsdf {
    vec3 diffuse_reflectance{0.5f};
    vec3 specular_reflectance{1.f};
    float int_ior = 1.49f;      // polypropylene
    float ext_ior = 1.000277f;  // air
    float alpha = 0.f;          // roughness of the coat (isotropic, as Mitsuba); 0 = smooth
    MicrofacetType distribution = MicrofacetType::Beckmann;  // Mitsuba's default
    bool nonlinear = false;
    std::shared_ptr<const CoatTables> tables;  // derived data, see prepare()

    float eta() const { return int_ior / ext_ior; }
    bool smooth() const { return !(alpha > 0.f); }
    bool prepared() const {
        return tables && tables->alpha == (smooth() ? 0.f : alpha) && tables->eta == eta() &&
               (smooth() || tables->distribution == distribution);
    }
    // (Re)computes the tables when alpha or the IORs changed since the last call.
    void prepare();

    vec3 eval(vec3 wo, vec3 wi, TransportMode) const;
    float pdf(vec3 wo, vec3 wi, TransportMode) const;
    BsdfEval eval_pdf(vec3 wo, vec3 wi, TransportMode) const;  // the coat evaluated once
    std::optional<BsdfSample> sample(vec3 wo, float u1, vec2 u2, TransportMode) const;
    bool has_smooth_component() const { return true; }

private:
    struct Lobe {
        vec3 f{0.f};      // f |cos theta_i|
        float pdf = 0.f;  // the lobe's own density (before the lobe choice)
    };
    // The rough coat's GGX reflection from wo to wi through the microfacet normal m (their half
    // vector); the lobe samples m from the normals visible from wo (Heitz 2018).
    Lobe coat(vec3 wo, vec3 wi, vec3 m) const;
    float specular_probability(float cos_o) const;
    vec3 diffuse_value(vec3 wo, vec3 wi) const;
};

}  // namespace candela
