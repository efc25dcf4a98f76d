#pragma once
// Mitsuba 3's `direct` integrator (src/integrators/direct.cpp): emission seen by the camera ray,
// plus direct lighting at the first surface by `emitter_samples` light samples and `bsdf_samples`
// BSDF samples, combined by the power heuristic with the sample counts in it:
//   light sample:  f |cos| Le / p_light * w_l / n_l,   w_l = h(n_l p_light, n_b p_bsdf)
//   BSDF sample:   f |cos| / p_bsdf * Le * w_b / n_b,   w_b = h(n_b p_bsdf, n_l p_light)
// with h(a, b) = a^2 / (a^2 + b^2) (0 when not finite), pdfs in solid angle at the shading point,
// and n_l, n_b the two counts, so that the weights of one direction sum to one over the n_l + n_b
// samples (Veach's balance of sample counts). Delta lobes: a BSDF-sampled delta direction has no
// light-sampling density (w_b = 1); light samples are taken only when the BSDF has a smooth part.
// hide_emitters: the camera ray passes through area emitters (as in the path tracer) and does not
// see the infinite lights. Delta lights (point, spot, directional) are reached by light samples
// only, with w_l = 1 / n_l (Mitsuba's 1 counts them n_l times); BSDF samples that leave the scene
// see the infinite lights, weighted as above with each light's own density.
// Sample order per pixel sample: for each light sample next_1d (which emitter triangle), next_2d
// (the point); then for each BSDF sample next_1d, next_2d.
#include "integrator/integrator.h"
#include "integrator/path.h"

namespace candela {

class DirectIntegrator {
public:
    explicit DirectIntegrator(const Scene& scene);

    // Radiance arriving along the camera ray (towards -ray.d). DiffuseOnly as in PathIntegrator.
    template <class S, bool DiffuseOnly = false>
    vec3 Li(Ray ray, S& sampler, PathStats& stats) const;

private:
    // h(a, b) as Mitsuba's mis_weight: a^2 / (a^2 + b^2), 0 when that is not finite.
    static float mis_weight(float a, float b) {
        a *= a;
        b *= b;
        float w = a / (a + b);
        return std::isfinite(w) ? w : 0.f;
    }
    const Scene& scene_;
    int n_light_, n_bsdf_;
    float frac_light_, frac_bsdf_;      // n_l / (n_l + n_b), n_b / (n_l + n_b)
    float weight_light_, weight_bsdf_;  // 1 / n_l, 1 / n_b
    bool masks_;                        // some material is masked (shading.h)
};

class DirectPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

inline DirectIntegrator::DirectIntegrator(const Scene& scene) : scene_(scene), masks_(scene_has_masks(scene)) {
    const IntegratorDesc& d = scene.settings.integrator;
    n_light_ = d.emitter_samples;
    n_bsdf_ = d.bsdf_samples;
    const float sum = float(n_light_ + n_bsdf_);
    frac_light_ = float(n_light_) / sum;
    frac_bsdf_ = float(n_bsdf_) / sum;
    weight_light_ = n_light_ > 0 ? 1.f / float(n_light_) : 0.f;
    weight_bsdf_ = n_bsdf_ > 0 ? 1.f / float(n_bsdf_) : 0.f;
}

template <class S, bool DiffuseOnly>
vec3 DirectIntegrator::Li(Ray ray, S& sampler, PathStats& stats) const {
    const Scene& sc = scene_;
    Hit hit;
    ++stats.rays;
    const bool hide = sc.settings.integrator.hide_emitters;
    if (!sc.accel->intersect(ray, hit)) {
        vec3 Le(0.f);  // the infinite lights seen directly, unless hidden (Mitsuba's semantics)
        if (!hide) sc.lights.for_each_infinite(glm::normalize(ray.d), [&](vec3 e, float) { Le += e; });
        return Le;
    }
    if (hide && !skip_area_emitters(sc, ray, hit, stats)) return vec3(0.f);
    SurfaceInteraction si = sc.interaction(hit);
    if constexpr (!DiffuseOnly) {
        // The camera ray passes masked surfaces with probability 1 - opacity (as in the path tracer).
        for (int k = 0; masks_ && k < 1024; ++k) {
            const Material& m = sc.materials[sc.shapes[si.shape].material];
            if (!m.masked || sampler.next_1d() < m.opacity_at(sc.texture_query(si, hit))) break;
            ray = spawn_ray(si, ray.d);
            hit = Hit();
            ++stats.rays;
            if (!sc.accel->intersect(ray, hit)) return vec3(0.f);
            if (hide && !skip_area_emitters(sc, ray, hit, stats)) return vec3(0.f);
            si = sc.interaction(hit);
        }
    }
    ++stats.camera_hits;  // the film's alpha
    const vec3 wo_world = -glm::normalize(ray.d);
    vec3 L(0.f);
    if (!hide && sc.lights.emitter_of(hit) >= 0) L += sc.lights.emitted(si, wo_world);
    if (sc.lights.empty()) return L;

    ShadingT<DiffuseOnly> sh;
    shade<DiffuseOnly>(sc, hit, si, wo_world, sh);
    const Frame& frame = sh.frame;
    const bool masks = !DiffuseOnly && masks_;

    if (sh.has_smooth_component()) {
        for (int i = 0; i < n_light_; ++i) {
            float ul = sampler.next_1d();
            vec2 up = sampler.next_2d();
            LightSample ls;
            if (!sc.lights.sample_li(si.p, ul, up, ls) || !(ls.pdf > 0.f)) continue;
            const vec3 wi = frame.to_local(ls.wi);
            const BsdfEval e = sh.eval_pdf(wi);
            const vec3 f = e.f;
            if (is_black(f)) continue;
            Ray shadow = shadow_ray(si, ls);
            ++stats.rays;
            const float T = shadow_transmittance(sc, shadow, masks, stats.rays);
            if (!(T > 0.f)) continue;
            // A delta light: no MIS (no BSDF sample can reach it), but still one of n_l samples, so
            // 1 / n_l. Mitsuba 3.9's direct.cpp weights it 1 and so counts it n_l times: a bias of
            // its own, not matched (docs/lights.md).
            const float w = ls.delta ? weight_light_ : mis_weight(ls.pdf * frac_light_, e.pdf * frac_bsdf_) * weight_light_;
            L += f * ls.Le * (T * w / ls.pdf);
        }
    } else {
        for (int i = 0; i < n_light_; ++i) {  // keep the sample dimensions aligned
            sampler.next_1d();
            sampler.next_2d();
        }
    }

    for (int i = 0; i < n_bsdf_; ++i) {
        float u1 = sampler.next_1d();
        vec2 u2 = sampler.next_2d();
        std::optional<BsdfSample> bs = sh.sample(u1, u2);
        if (!bs || !(bs->pdf > 0.f)) continue;
        vec3 beta = bs->weight();
        if (is_black(beta)) continue;
        Ray r = spawn_ray(si, frame.to_world(bs->wi));
        Hit h;
        ++stats.rays;
        // The BSDF ray crosses masked surfaces with their transmittance (deterministically, like the
        // shadow rays: both strategies then have the densities p_bsdf and p_light in the MIS weights).
        bool found = sc.accel->intersect(r, h);
        for (int k = 0; masks && found && k < 256; ++k) {
            const SurfaceInteraction sm = sc.interaction(h);
            const Material& m = sc.materials[sc.shapes[sm.shape].material];
            if (!m.masked || sc.lights.emitter_of(h) >= 0) break;
            beta *= 1.f - m.opacity_at(sc.texture_query(sm, h));
            if (is_black(beta)) break;
            r = spawn_ray(sm, r.d);
            h = Hit();
            ++stats.rays;
            found = sc.accel->intersect(r, h);
        }
        if (is_black(beta)) continue;
        if (!found) {
            // Escaped: the infinite lights, each weighted against its own sampling density.
            sc.lights.for_each_infinite(glm::normalize(r.d), [&](vec3 Le, float light_pdf) {
                if (bs->delta) light_pdf = 0.f;
                L += beta * Le * (mis_weight(bs->pdf * frac_bsdf_, light_pdf * frac_light_) * weight_bsdf_);
            });
            continue;
        }
        if (sc.lights.emitter_of(h) < 0) continue;
        const SurfaceInteraction se = sc.interaction(h);
        const vec3 Le = sc.lights.emitted(se, -glm::normalize(r.d));
        if (is_black(Le)) continue;
        const float light_pdf = bs->delta ? 0.f : sc.lights.pdf_li(si.p, se);
        const float w = mis_weight(bs->pdf * frac_bsdf_, light_pdf * frac_light_) * weight_bsdf_;
        L += beta * Le * w;
    }
    return L;
}

}  // namespace candela
