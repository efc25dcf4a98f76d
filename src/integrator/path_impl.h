#pragma once
// The path tracer's inner loop (included by path.h; kept apart for readability).

namespace candela {

inline float power_heuristic(float a, float b) {
    float a2 = a * a, b2 = b * b;
    if (std::isinf(a2)) return 1.f;
    return a2 + b2 > 0.f ? a2 / (a2 + b2) : 0.f;
}

// Mitsuba 3's hide_emitters: a camera ray that hits an area emitter goes on through it, and through
// every further emitter, to the first surface that does not emit (Integrator::skip_area_emitters).
// `ray` and `hit` become that continuation. Returns false when it hits nothing.
inline bool skip_area_emitters(const Scene& sc, Ray& ray, Hit& hit, PathStats& stats) {
    for (int i = 0; i < 1024 && sc.lights.emitter_of(hit) >= 0; ++i) {
        const SurfaceInteraction si = sc.interaction(hit);
        ray = spawn_ray(si, ray.d);  // unbounded, as Mitsuba's si.spawn_ray: the far clip is not kept
        hit = Hit();
        ++stats.rays;
        if (!sc.accel->intersect(ray, hit)) return false;
    }
    return true;
}

// The shadow ray of a light sample: to the point on the light, or unbounded towards an infinite
// light.
inline Ray shadow_ray(const SurfaceInteraction& si, const LightSample& ls) {
    if (__builtin_expect(ls.infinite, 0)) return spawn_ray(si, ls.wi);
    return spawn_ray_to(si, ls.p, ls.p_error, ls.n);
}

// What an escaping ray of direction w brings from the infinite lights, weighted as the emission
// an area light gives a BSDF-sampled ray: fully after a delta bounce or in BSDF mode, by the power
// heuristic against that light's sampling density in MIS mode, not at all in light mode (light
// sampling counted it).
inline void add_infinite(const LightSet& lights, vec3 w, vec3 beta, bool after_delta, SamplingMode mode, float prev_pdf,
                         vec3& L) {
    if (!after_delta && mode == SamplingMode::Light) return;
    lights.for_each_infinite(w, [&](vec3 Le, float light_pdf) {
        if (after_delta || mode == SamplingMode::Bsdf) L += beta * Le;
        else L += beta * Le * power_heuristic(prev_pdf, light_pdf);
    });
}

// The emission a ray reaches at `hit` (seen from wo_world), weighted as light sampling requires:
// fully after a delta bounce or in BSDF mode, by the power heuristic against the light's sampling
// density in MIS mode, not at all in light mode (light sampling counted it). Shared by Li and the
// staged loop (path/wavefront.h), which must add the same bits.
inline void add_emission(const Scene& sc, const Hit& hit, const SurfaceInteraction& si, vec3 wo_world, vec3 beta,
                         bool after_delta, SamplingMode mode, vec3 prev_p, float prev_pdf, vec3& L) {
    if (sc.lights.emitter_of(hit) < 0) return;
    const vec3 Le = sc.lights.emitted(si, wo_world);
    if (is_black(Le)) return;
    if (after_delta || mode == SamplingMode::Bsdf) {
        L += beta * Le;
    } else if (mode == SamplingMode::Mis) {
        const float light_pdf = sc.lights.pdf_li(prev_p, si);
        L += beta * Le * power_heuristic(prev_pdf, light_pdf);
    }
}

template <class S, bool DiffuseOnly>
vec3 PathIntegrator::Li(Ray ray, S& sampler, PathStats& stats) const {
    const Scene& sc = scene_;
    const RenderSettings& st = sc.settings;
    const SamplingMode mode = st.sampling;
    const bool have_lights = !sc.lights.empty();
    vec3 L(0.f), beta(1.f);
    bool after_delta = true;     // camera rays and delta bounces: emission always counts fully
    float prev_pdf = 0.f;        // solid-angle pdf of the BSDF sample that led here (times the
                                 // probabilities of the mask pass-throughs since)
    vec3 prev_p(0.f);
    float eta_scale = 1.f;       // product of eta^2 over refractions: undoes their radiance scaling
    ShadingT<DiffuseOnly> sh;
    int passes = 0;              // mask pass-throughs (bounded, as skip_area_emitters)

    for (int depth = 0;; ++depth) {
        Hit hit;
        ++stats.rays;
        if (!sc.accel->intersect(ray, hit)) {
            // The ray leaves the scene: the infinite lights it sees (hidden from camera rays by
            // hide_emitters, as Mitsuba). MIS as for area lights, with each light's own pdf.
            if (sc.lights.has_infinite() && !(depth == 0 && st.integrator.hide_emitters))
                add_infinite(sc.lights, glm::normalize(ray.d), beta, after_delta, mode, prev_pdf, L);
            break;
        }
        // A camera ray that goes on through hidden area emitters and leaves sees no infinite light
        // either (it is still at depth 0).
        if (depth == 0 && st.integrator.hide_emitters && !skip_area_emitters(sc, ray, hit, stats)) break;
        if (depth == 0 && passes == 0) ++stats.camera_hits;
        SurfaceInteraction si = sc.interaction(hit);
        vec3 wo_world = -glm::normalize(ray.d);

        // Emission reached by this ray.
        add_emission(sc, hit, si, wo_world, beta, after_delta, mode, prev_p, prev_pdf, L);
        if constexpr (!DiffuseOnly) {
            if (masks_) {  // pass straight through with probability 1 - opacity (not a vertex)
                const Material& m = sc.materials[sc.shapes[si.shape].material];
                const float a = m.opacity_at(m.masked ? sc.texture_query(si, hit) : TextureQuery{});
                if (a < 1.f && sampler.next_1d() >= a) {
                    if (++passes > 1024) break;
                    prev_pdf *= 1.f - a;
                    ray = spawn_ray(si, ray.d);
                    --depth;
                    continue;
                }
            }
        }
        if (st.max_depth >= 0 && depth >= st.max_depth) break;

        shade<DiffuseOnly>(sc, hit, si, wo_world, sh);

        // Next-event estimation.
        if (mode != SamplingMode::Bsdf && have_lights && sh.has_smooth_component()) {
            float ul = sampler.next_1d();
            vec2 up = sampler.next_2d();
            LightSample ls;
            if (sc.lights.sample_li(si.p, ul, up, ls)) {
                vec3 wi = sh.frame.to_local(ls.wi);
                const BsdfEval e = sh.eval_pdf(wi);  // f, and the pdf for MIS, from one evaluation
                const vec3 f = e.f;
                if (!is_black(f)) {
                    Ray shadow = shadow_ray(si, ls);
                    ++stats.rays;
                    const float T = shadow_transmittance(sc, shadow, !DiffuseOnly && masks_, stats.rays);
                    if (T > 0.f) {
                        // A delta light cannot be reached by BSDF sampling: no MIS.
                        float w = mode == SamplingMode::Mis && !ls.delta ? power_heuristic(ls.pdf, e.pdf * T) : 1.f;
                        L += beta * f * ls.Le * (T * w / ls.pdf);
                    }
                }
            }
        } else if (mode != SamplingMode::Bsdf) {
            // Keep the sample dimensions aligned whatever the material (helps MLT and QMC later).
            sampler.next_1d();
            sampler.next_2d();
        }

        // Continue the path by sampling the BSDF.
        float u1 = sampler.next_1d();
        vec2 u2 = sampler.next_2d();
        std::optional<BsdfSample> bs = sh.sample(u1, u2);
        if (!bs || !(bs->pdf > 0.f)) break;
        beta *= bs->weight();
        if (is_black(beta)) break;
        eta_scale *= sqr(bs->eta);
        after_delta = bs->delta;
        prev_pdf = bs->pdf;
        prev_p = si.p;
        vec3 wi_world = sh.frame.to_world(bs->wi);
        ray = spawn_ray(si, wi_world);

        if (depth + 1 >= st.rr_depth) {
            // Survival by the throughput without the 1/eta^2 of refractions, which only reflects the
            // change of solid angle: a path inside glass is not less important (pbrt-v4 etaScale).
            float q = std::min(max_component(beta) * eta_scale, 0.95f);
            if (sampler.next_1d() >= q) break;
            beta /= q;
        }
    }
    return L;
}

}  // namespace candela
