#pragma once
// The BSDF of a wrapped material (blendbsdf, bumpmap, normalmap) at one surface point.
//
// Design: a material with wrappers is a flat tree (bsdf.h, Material::blend) that is resolved at each
// hit into a WrappedBsdf: up to kMaxBlendLeaves leaf BSDFs with their mixture weights (the products
// of the blend weights from the root down), and optionally a perturbed shading frame. Plain
// materials never build one: the integrators call the leaf BSDF directly (integrator/shading.h).
//
// Contract (as bsdf.h): wo, wi are unit vectors in the integrator's local shading frame (the
// unperturbed one, n = +z); eval_w = f |cos theta_i| with the cosine the leaves take in their own
// (possibly perturbed) frame, pdf_w in solid angle, sample_w's weight = f |cos| / pdf:
//   blend:    eval = sum_k w_k eval_k,  pdf = sum_k w_k pdf_k (solid angle). sample picks leaf k with
//             probability w_k (u1 rescaled into the leaf), samples it, and for a non-delta direction
//             returns the whole mixture's eval and pdf at that direction (so sample, pdf and eval
//             agree, which MIS needs); for a delta lobe f and pdf are the leaf's times w_k.
//   perturbed (Mitsuba 3.9 perturbed_bsdf.h): the leaves see wo and wi in the perturbed frame P
//             (given in local coordinates); a direction on different sides of the two frames'
//             tangent planes has eval = pdf = 0 (no light leaks through the geometric side), and
//             eval and the sample weight are multiplied by the shadow-terminator factor
//             G(n_P, wi) = 2 / (1 + sqrt(1 + a2 tan^2 theta_i)), a2 = min(tan^2 theta_{n_P} / 8, 1)
//             (Estevez et al. 2019), tan theta_i in the unperturbed frame. pdf is not multiplied.
#include <array>
#include "core/frame.h"
#include "bsdf/bsdf.h"

namespace candela {

constexpr int kMaxBlendLeaves = 8;

struct WrappedBsdf {
    int n = 0;                                   // number of leaves with weight > 0
    std::array<const Bsdf*, kMaxBlendLeaves> leaf;  // the first n are set
    std::array<float, kMaxBlendLeaves> w;        // mixture weights of the first n, sum 1
    bool perturbed = false;
    Frame frame;                                 // the perturbed frame, local coordinates
    bool terminator = false;

    // ---- the mixture, in the leaves' frame -----------------------------------------------------
    vec3 mix_eval(vec3 wo, vec3 wi, TransportMode mode) const {
        vec3 f(0.f);
        for (int k = 0; k < n; ++k) f += w[k] * eval(*leaf[k], wo, wi, mode);
        return f;
    }
    float mix_pdf(vec3 wo, vec3 wi, TransportMode mode) const {
        float p = 0.f;
        for (int k = 0; k < n; ++k) p += w[k] * pdf(*leaf[k], wo, wi, mode);
        return p;
    }
    BsdfEval mix_eval_pdf(vec3 wo, vec3 wi, TransportMode mode) const {
        BsdfEval e;
        for (int k = 0; k < n; ++k) {
            const BsdfEval l = eval_pdf(*leaf[k], wo, wi, mode);
            e.f += w[k] * l.f;
            e.pdf += w[k] * l.pdf;
        }
        return e;
    }
    std::optional<BsdfSample> mix_sample(vec3 wo, float u1, vec2 u2, TransportMode mode) const {
        if (n == 1) return sample(*leaf[0], wo, u1, u2, mode);
        int k = 0;
        float c = 0.f;
        while (k < n - 1 && u1 >= c + w[k]) c += w[k++];
        const float u = std::min((u1 - c) / w[k], 0x1.fffffep-1f);
        std::optional<BsdfSample> bs = sample(*leaf[k], wo, std::max(u, 0.f), u2, mode);
        if (!bs) return bs;
        if (bs->delta) {
            bs->f *= w[k];
            bs->pdf *= w[k];
        } else {
            bs->f = mix_eval(wo, bs->wi, mode);
            bs->pdf = mix_pdf(wo, bs->wi, mode);
        }
        return bs;
    }

    // ---- the wrapped BSDF, in the integrator's frame -------------------------------------------
    static float terminator_factor(vec3 n_p, vec3 wi) {
        auto tan2 = [](vec3 v) { return std::max(0.f, 1.f - v.z * v.z) / std::max(v.z * v.z, 1e-30f); };
        const float a2 = std::min(0.125f * tan2(n_p), 1.f);
        return 2.f / (1.f + std::sqrt(1.f + a2 * tan2(wi)));
    }
    vec3 eval_w(vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) const {
        if (!perturbed) return mix_eval(wo, wi, mode);
        const vec3 wip = frame.to_local(wi);
        if (!(wi.z * wip.z > 0.f)) return vec3(0.f);
        vec3 f = mix_eval(frame.to_local(wo), wip, mode);
        return terminator ? f * terminator_factor(frame.n, wi) : f;
    }
    float pdf_w(vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) const {
        if (!perturbed) return mix_pdf(wo, wi, mode);
        const vec3 wip = frame.to_local(wi);
        if (!(wi.z * wip.z > 0.f)) return 0.f;
        return mix_pdf(frame.to_local(wo), wip, mode);
    }
    BsdfEval eval_pdf_w(vec3 wo, vec3 wi, TransportMode mode = TransportMode::Radiance) const {
        if (!perturbed) return mix_eval_pdf(wo, wi, mode);
        const vec3 wip = frame.to_local(wi);
        if (!(wi.z * wip.z > 0.f)) return {};
        BsdfEval e = mix_eval_pdf(frame.to_local(wo), wip, mode);
        if (terminator) e.f = e.f * terminator_factor(frame.n, wi);
        return e;
    }
    std::optional<BsdfSample> sample_w(vec3 wo, float u1, vec2 u2, TransportMode mode = TransportMode::Radiance) const {
        if (!perturbed) return mix_sample(wo, u1, u2, mode);
        std::optional<BsdfSample> bs = mix_sample(frame.to_local(wo), u1, u2, mode);
        if (!bs) return bs;
        const vec3 wi = frame.to_world(bs->wi);
        if (!(wi.z * bs->wi.z > 0.f)) return std::nullopt;
        bs->wi = wi;
        if (terminator) bs->f *= terminator_factor(frame.n, wi);
        return bs;
    }
    bool has_smooth_w() const {
        for (int k = 0; k < n; ++k)
            if (has_smooth_component(*leaf[k])) return true;
        return false;
    }
};

// The perturbed normal of Mitsuba 3.9's bumpmap and normalmap, in local coordinates of the
// unperturbed shading frame `base` (whose normal is +z), made a frame as perturbed_bsdf.h does:
// flipped (x, y mirrored) when it lies on the other side of wo than the shading normal
// (flip_invalid_normals, after Schuessler et al. 2017), and (0, 0, 1) when it has no length.
inline Frame perturbed_frame(vec3 n_local, vec3 wo_local, bool flip_invalid) {
    if (flip_invalid && wo_local.z * glm::dot(wo_local, n_local) <= 0.f) n_local = vec3(-n_local.x, -n_local.y, n_local.z);
    const float len2 = glm::dot(n_local, n_local);
    const vec3 n = len2 > 0.f && std::isfinite(len2) ? n_local / std::sqrt(len2) : vec3(0.f, 0.f, 1.f);
    return Frame(n);
}

// bumpmap: the height h(u, v) = scale * texture moves the point along the shading normal n; the
// perturbed tangents are dp/du' = dp/du + n (dh/du - n.dp/du) (and v alike), the normal their cross
// product, turned to the geometric normal's side (Mitsuba's bumpmap). World space in, world out.
inline vec3 bump_normal(vec3 ns, vec3 ng, vec3 dpdu, vec3 dpdv, vec2 grad) {
    const vec3 du = dpdu + ns * (grad.x - glm::dot(ns, dpdu));
    const vec3 dv = dpdv + ns * (grad.y - glm::dot(ns, dpdv));
    vec3 n = glm::cross(du, dv);
    if (glm::dot(n, ng) < 0.f) n = -n;
    return n;
}

// normalmap: the texture's RGB in [0, 1]^3 is a tangent-space normal 2 rgb - 1 in Mitsuba's shading
// frame: s = dp/du made orthogonal to n, t = n x s, n = the shading normal. World space out.
inline vec3 normalmap_normal(vec3 ns, vec3 dpdu, vec3 rgb) {
    vec3 s = dpdu - ns * glm::dot(ns, dpdu);
    const float l2 = glm::dot(s, s);
    s = l2 > 0.f ? s / std::sqrt(l2) : Frame(ns).s;
    const vec3 t = glm::cross(ns, s);
    const vec3 m = 2.f * rgb - 1.f;
    return m.x * s + m.y * t + m.z * ns;
}

}  // namespace candela
