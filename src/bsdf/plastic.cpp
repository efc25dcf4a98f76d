#include "bsdf/plastic.h"
#include <map>
#include <mutex>
#include <tuple>
#include "sampling/warp.h"

namespace candela {

// ---- Fresnel helpers (declared in fresnel.h) ---------------------------------------------------

float fresnel_diffuse_reflectance(float eta) {
    // 2 * integral_0^1 F(mu) mu dmu by composite Simpson's rule on a fine grid; F has a kink at the
    // critical angle (eta < 1), so the grid is fine rather than clever.
    const int n = 4096;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
        double mu = double(i) / n;
        double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * fresnel_dielectric(float(mu), eta).F * mu;
    }
    return float(2.0 * sum / (3.0 * n));
}

std::optional<float> ior_from_name(const std::string& name) {
    // The table Mitsuba 3 documents for its dielectric plugins (standard physical values).
    static const std::map<std::string, float> table = {
        {"vacuum", 1.0f},        {"helium", 1.000036f},        {"hydrogen", 1.000132f},
        {"air", 1.000277f},      {"carbon dioxide", 1.00045f}, {"water", 1.3330f},
        {"acetone", 1.36f},      {"ethanol", 1.361f},          {"carbon tetrachloride", 1.461f},
        {"glycerol", 1.4729f},   {"benzene", 1.501f},          {"silicone oil", 1.52045f},
        {"bromine", 1.661f},     {"water ice", 1.31f},         {"fused quartz", 1.458f},
        {"pyrex", 1.470f},       {"acrylic glass", 1.49f},     {"polypropylene", 1.49f},
        {"bk7", 1.5046f},        {"sodium chloride", 1.544f},  {"amber", 1.55f},
        {"pet", 1.5750f},        {"diamond", 2.419f},
    };
    auto it = table.find(name);
    if (it == table.end()) return std::nullopt;
    return it->second;
}

// ---- coat tables -----------------------------------------------------------------------------

float CoatTables::transmittance_at(float cos_theta) const {
    float x = std::clamp(cos_theta, 0.f, 1.f) * float(kRes - 1);
    int i = std::min(int(x), kRes - 2);
    float t = x - float(i);
    return (1.f - t) * transmittance[size_t(i)] + t * transmittance[size_t(i + 1)];
}

namespace {

// Directional albedo of the rough interface for a direction w (w.z > 0) on the side where the
// relative IOR across is eta: the part reflected (transmitted = false) or transmitted, counting
// single scattering only. With visible-normal sampling of h the estimator of one lobe is
// F G1(reflected) or (1 - F) G1(refracted), integrated over the unit square by the midpoint rule.
double rough_interface_albedo(const Microfacet& ggx, vec3 w, float eta, bool transmitted) {
    const int n = 64;
    double sum = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            vec2 u((float(i) + 0.5f) / n, (float(j) + 0.5f) / n);
            vec3 m = ggx.sample_visible(w, u);
            FresnelDielectric fr = fresnel_dielectric(glm::dot(w, m), eta);
            if (transmitted) {
                vec3 t = refract(w, m, fr.cos_t, fr.eta_ti);
                if (t.z < 0.f) sum += (1.0 - fr.F) * ggx.G1(t, m);
            } else {
                vec3 r = reflect(w, m);
                if (r.z > 0.f) sum += fr.F * ggx.G1(r, m);
            }
        }
    return sum / (double(n) * n);
}

std::shared_ptr<const CoatTables> compute_tables(float alpha, float eta, MicrofacetType dist) {
    auto t = std::make_shared<CoatTables>();
    t->alpha = alpha;
    t->eta = eta;
    t->distribution = dist;
    const int R = CoatTables::kRes;
    if (alpha == 0.f) {
        for (int i = 0; i < R; ++i) t->transmittance[size_t(i)] = 1.f - fresnel_dielectric(float(i) / (R - 1), eta).F;
        t->internal_reflectance = fresnel_diffuse_reflectance(1.f / eta);
        return t;
    }
    const Microfacet ggx(dist, alpha);
    double internal = 0.0;
    for (int i = 0; i < R; ++i) {
        // Mitsuba's grid: mu = i / (R - 1), kept off exactly grazing.
        float mu = std::max(1e-6f, float(i) / float(R - 1));
        vec3 w(std::sqrt(1.f - mu * mu), 0.f, mu);
        t->transmittance[size_t(i)] = float(rough_interface_albedo(ggx, w, eta, true));
        internal += rough_interface_albedo(ggx, w, 1.f / eta, false) * mu;
    }
    // The cosine-weighted hemispherical average as Mitsuba 3 defines it: 2 * mean over the grid.
    t->internal_reflectance = float(2.0 * internal / R);
    return t;
}

}  // namespace

namespace {

// Scenes often share one coat among many objects, and the viewer's scenes share it between the
// versions an edit makes: tables are shared by (alpha, eta, distribution; smooth coats by eta). The cache holds them weakly, so a
// table lives as long as some material uses it; a roughness slider dragged through a thousand
// values leaves only the tables still in use (expired entries are dropped on every insertion).
std::mutex coat_cache_mutex;
std::map<std::tuple<float, float, MicrofacetType>, std::weak_ptr<const CoatTables>> coat_cache;

}  // namespace

size_t coat_table_cache_size() {
    std::lock_guard<std::mutex> lock(coat_cache_mutex);
    return coat_cache.size();
}

void PlasticBsdf::prepare() {
    if (prepared()) return;
    const float a = smooth() ? 0.f : alpha;
    // A smooth coat does not depend on the distribution: one key for it.
    const MicrofacetType d = smooth() ? MicrofacetType::Beckmann : distribution;
    std::lock_guard<std::mutex> lock(coat_cache_mutex);
    std::weak_ptr<const CoatTables>& slot = coat_cache[{a, eta(), d}];
    std::shared_ptr<const CoatTables> t = slot.lock();
    if (!t) {
        // Computed under the lock: two threads preparing the same coat compute it once.
        t = compute_tables(a, eta(), d);
        slot = t;
        for (auto it = coat_cache.begin(); it != coat_cache.end();)
            it = it->second.expired() ? coat_cache.erase(it) : std::next(it);
    }
    tables = std::move(t);
}

// ---- evaluation --------------------------------------------------------------------------------

float PlasticBsdf::specular_probability(float cos_o) const {
    const float s = (specular_reflectance.x + specular_reflectance.y + specular_reflectance.z) / 3.f;
    const float d = (diffuse_reflectance.x + diffuse_reflectance.y + diffuse_reflectance.z) / 3.f;
    const float w = s + d > 0.f ? s / (s + d) : 0.5f;
    const float t = smooth() ? 1.f - fresnel_dielectric(cos_o, eta()).F : tables->transmittance_at(cos_o);
    const float ps = (1.f - t) * w, pd = t * (1.f - w);
    return ps + pd > 0.f ? ps / (ps + pd) : 0.f;
}

vec3 PlasticBsdf::diffuse_value(vec3 wo, vec3 wi) const {
    const float e = eta();
    float to, ti;
    if (smooth()) {
        to = 1.f - fresnel_dielectric(wo.z, e).F;
        ti = 1.f - fresnel_dielectric(wi.z, e).F;
    } else {
        to = tables->transmittance_at(wo.z);
        ti = tables->transmittance_at(wi.z);
    }
    const float ri = tables->internal_reflectance;
    const vec3 rho = diffuse_reflectance;
    const vec3 base = nonlinear ? rho / (vec3(1.f) - rho * ri) : rho / (1.f - ri);
    return base * (to * ti * wi.z * kInvPi / (e * e));
}

PlasticBsdf::Lobe PlasticBsdf::coat(vec3 wo, vec3 wi, vec3 m) const {
    const Microfacet ggx(distribution, alpha);
    const float g1o = ggx.G1(wo, m), g1i = ggx.G1(wi, m);
    if (g1o == 0.f || g1i == 0.f) return {};
    // pdf = D_wo(m) / (4 wo.m) = G1(wo, m) D(m) / (4 cos theta_o): the Jacobian of reflection,
    // 1 / (4 wi.m), written with wo.m (equal for a half vector) so that f / pdf is
    // R F G1(wi, m) <= R even where rounding makes m an inexact half vector of wo and wi.
    const float pdf = g1o * ggx.D(m) / (4.f * wo.z);
    const float F = fresnel_dielectric(glm::dot(wo, m), eta()).F;
    return {specular_reflectance * (F * g1i * pdf), pdf};
}

vec3 PlasticBsdf::eval(vec3 wo, vec3 wi, TransportMode) const {
    if (wo.z <= 0.f || wi.z <= 0.f || !prepared()) return vec3(0.f);
    vec3 f = diffuse_value(wo, wi);
    if (!smooth()) f += coat(wo, wi, glm::normalize(wo + wi)).f;
    return f;
}

float PlasticBsdf::pdf(vec3 wo, vec3 wi, TransportMode) const {
    if (wo.z <= 0.f || wi.z <= 0.f || !prepared()) return 0.f;
    const float ps = specular_probability(wo.z);
    float p = (1.f - ps) * square_to_cosine_hemisphere_pdf(wi);
    if (!smooth()) p += ps * coat(wo, wi, glm::normalize(wo + wi)).pdf;
    return p;
}

BsdfEval PlasticBsdf::eval_pdf(vec3 wo, vec3 wi, TransportMode) const {
    if (wo.z <= 0.f || wi.z <= 0.f || !prepared()) return {};
    BsdfEval e{diffuse_value(wo, wi), 0.f};
    const float ps = specular_probability(wo.z);
    e.pdf = (1.f - ps) * square_to_cosine_hemisphere_pdf(wi);
    if (!smooth()) {
        const Lobe c = coat(wo, wi, glm::normalize(wo + wi));
        e.f += c.f;
        e.pdf += ps * c.pdf;
    }
    return e;
}

std::optional<BsdfSample> PlasticBsdf::sample(vec3 wo, float u1, vec2 u2, TransportMode mode) const {
    if (wo.z <= 0.f || !prepared()) return std::nullopt;
    const float ps = specular_probability(wo.z);
    BsdfSample s;
    if (smooth() && u1 < ps) {
        s.wi = reflect_z(wo);
        s.pdf = ps;
        s.delta = true;
        s.f = specular_reflectance * fresnel_dielectric(wo.z, eta()).F;
        return s;
    }
    if (u1 < ps) {
        // The coat's part from the sampled normal m itself: near grazing, the half vector that
        // eval() rebuilds from wo + wi (nearly cancelling) can be far from m.
        const vec3 m = Microfacet(distribution, alpha).sample_visible(wo, u2);
        s.wi = reflect(wo, m);
        if (s.wi.z <= 0.f) return std::nullopt;
        const Lobe c = coat(wo, s.wi, m);
        s.f = c.f + diffuse_value(wo, s.wi);
        s.pdf = ps * c.pdf + (1.f - ps) * square_to_cosine_hemisphere_pdf(s.wi);
    } else {
        s.wi = square_to_cosine_hemisphere(u2);
        if (s.wi.z <= 0.f) return std::nullopt;
        s.f = eval(wo, s.wi, mode);
        s.pdf = pdf(wo, s.wi, mode);
    }
    if (!(s.pdf > 0.f) || !std::isfinite(s.pdf) || !all_finite(s.f)) return std::nullopt;
    return s;
}

}  // namespace candela
