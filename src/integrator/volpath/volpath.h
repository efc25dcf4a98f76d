#pragma once
// Mitsuba 3's `volpath` in RGB (src/integrators/volpath.cpp): the path tracer with participating
// media (medium/medium.h). docs/media.md has the semantics; the differences from Mitsuba's are
// listed there.
//
// Estimator. A path picks one colour channel c uniformly (the first random number of the pixel
// sample after the camera's) and samples free-flight distances with that channel's density
// sigma_c exp(-sigma_c t); the throughput of every channel is weighted by its own transmittance
// over the chosen channel's density (Mitsuba's tr / tr_pdf):
//   a scattering event at t:  beta *= sigma_s exp(-sigma_t t) / (sigma_c exp(-sigma_c t))
//   a surface reached at s:   beta *= exp(-sigma_t s) / exp(-sigma_c s)
// (for a grey medium: albedo, and 1). At a scattering event: next-event estimation with the
// phase function, then a phase-sampled direction (weight 1). At a surface: the path tracer's
// step (shading.h: the BSDF; light sampling; BSDF sampling), MIS by the power heuristic between
// the light's and the phase function's or the BSDF's solid-angle densities, as Mitsuba (the
// transmittance is in neither). Shadow rays cross null (and masked) surfaces, changing medium
// there, with the exact transmittance exp(-sigma_t d) of each segment (Mitsuba tracks the free
// flight there: the same expectation, more variance). Russian roulette at the start of each
// segment once more than rr_depth scattering events were made, with survival
// min(max(beta) eta^2, 0.95); max_depth counts scattering events (surface and medium) as Mitsuba's.
// Null surfaces (and masks, with probability 1 - opacity) are crossed without a scattering event.
//
// Spectral MIS (Mitsuba's volpathmis; IntegratorDesc::spectral_mis). The same path, but its
// contribution is weighted by the balance heuristic over the three channels that could have
// sampled its distances: f / ((p_0 + p_1 + p_2) / 3), p_i the path's density had channel i been
// chosen (the product of its distance densities), instead of f / p_c. The loop keeps beta = f / p_c
// as above and ratio = p / p_c (per channel), both divided by max(ratio) at each step (a common
// factor, so that neither overflows); the throughput is beta / mean(ratio). A grey medium, a
// heterogeneous one (grey extinction) or no medium leave ratio at 1: the same image as volpath.
// Light sampling and its MIS with the phase function and the BSDF are volpath's (Mitsuba's
// volpathmis weighs them by one balance heuristic over techniques and channels: the same expectation).
#include "integrator/integrator.h"
#include "integrator/path.h"

namespace candela {

class VolpathIntegrator {
public:
    explicit VolpathIntegrator(const Scene& scene);

    // Radiance arriving along the camera ray (towards -ray.d), starting in the camera's medium.
    template <class S, bool DiffuseOnly = false>
    vec3 Li(Ray ray, S& sampler, PathStats& stats) const;

    // Transmittance from `o` along `shadow` (from spawn_ray_to or spawn_ray, which set tmax)
    // starting in `medium`: the product over segments of exp(-sigma_t length) and over crossed
    // surfaces of 1 - opacity (0 at any surface that is not null or masked). `surface_T` gets the
    // product of the surfaces' factors alone (the MIS weight's, as the path tracer's). In a
    // heterogeneous medium a segment's factor is ratio tracking's estimate (random numbers from
    // `sampler`; a homogeneous one draws none).
    template <class S>
    vec3 shadow_transmittance(Ray shadow, int32_t medium, float& surface_T, S& sampler, uint64_t& rays) const;

private:
    const Scene& scene_;
    const std::vector<Medium>& media_;
};

class VolpathPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

inline VolpathIntegrator::VolpathIntegrator(const Scene& scene) : scene_(scene), media_(scene.media) {}

// The medium a ray enters leaving the surface at `si` (world geometric normal of the shape, not
// turned towards the ray) in direction w: Mitsuba's target_medium. Unchanged where the shape names
// no media.
inline int32_t medium_after(const Shape& s, vec3 ng, vec3 w, int32_t current) {
    if (!s.medium_transition()) return current;
    return glm::dot(w, ng) > 0.f ? s.exterior : s.interior;
}

template <class S>
vec3 VolpathIntegrator::shadow_transmittance(Ray shadow, int32_t medium, float& surface_T, S& sampler,
                                             uint64_t& rays) const {
    const Scene& sc = scene_;
    const bool to_point = std::isfinite(shadow.tmax);
    const vec3 target = shadow.o + shadow.d;
    vec3 T(1.f);
    surface_T = 1.f;
    for (int i = 0; i < 256; ++i) {
        Hit h;
        const bool found = sc.accel->intersect(shadow, h);  // shrinks tmax to the hit
        if (medium >= 0) {
            const float dl = glm::length(shadow.d);
            const float len = std::isfinite(shadow.tmax) ? shadow.tmax * dl : kInfinity;
            const Medium& m = media_[size_t(medium)];
            if (m.heterogeneous()) {
                Ray unit = shadow;
                unit.d = shadow.d / dl;
                T *= ratio_track(m, unit, len, sampler);
            } else {
                T *= transmittance(m, len);
            }
            if (is_black(T)) return vec3(0.f);
        }
        if (!found) return T;
        const SurfaceInteraction s = sc.interaction(h);
        const Shape& shape = sc.shapes[s.shape];
        const Material& m = sc.materials[shape.material];
        if (!m.masked) return vec3(0.f);
        const float pass = 1.f - m.opacity_at(sc.texture_query(s, h));
        surface_T *= pass;
        T *= pass;
        if (!(pass > 0.f)) return vec3(0.f);
        medium = medium_after(shape, s.ng, shadow.d, medium);
        shadow.o = offset_ray_origin(s.p, s.p_error, s.ng, shadow.d);
        shadow.tmin = 0.f;
        if (to_point) {
            shadow.d = target - shadow.o;
            shadow.tmax = 1.f - kShadowEpsilon;
        } else {
            shadow.tmax = kInfinity;
        }
        ++rays;
    }
    return vec3(0.f);  // deeper than any scene needs: opaque
}

template <class S, bool DiffuseOnly>
vec3 VolpathIntegrator::Li(Ray ray, S& sampler, PathStats& stats) const {
    const Scene& sc = scene_;
    const RenderSettings& st = sc.settings;
    const SamplingMode mode = st.sampling;
    const bool have_lights = !sc.lights.empty();
    const bool hide = st.integrator.hide_emitters;
    // The channel whose density samples distances (Mitsuba: min(3 u, 2)).
    const int channel = std::min(int(sampler.next_1d() * 3.f), 2);
    int32_t medium = sc.geometry->camera_medium;
    const bool spectral_mis = st.integrator.spectral_mis;
    vec3 L(0.f), beta(1.f);
    vec3 ratio(1.f);            // spectral MIS: the channels' path densities over the chosen one's
    // The throughput each contribution is weighted by (the balance heuristic under spectral MIS).
    auto throughput = [&]() { return spectral_mis ? beta * (3.f / (ratio.x + ratio.y + ratio.z)) : beta; };
    float eta = 1.f;            // product of the sampled BSDFs' eta (Russian roulette uses eta^2)
    int depth = 0;              // scattering events so far (surface and medium; not null crossings)
    bool after_delta = true;    // emission counts fully: camera rays, delta bounces
    float prev_pdf = 0.f;       // solid-angle pdf of the last scattering's sampled direction
    vec3 prev_p(0.f);
    bool valid = false;         // the film's alpha: some scattering event or surface was reached
    ShadingT<DiffuseOnly> sh;
    ray.d = glm::normalize(ray.d);  // distances in the media are t along a unit direction

    for (int iter = 0; iter < 4096; ++iter) {
        // Russian roulette, then the depth limit (Mitsuba's loop head).
        if (is_black(beta)) break;
        if (depth > st.rr_depth) {
            const float q = std::min(max_component(throughput()) * eta * eta, 0.95f);
            if (sampler.next_1d() >= q) break;
            beta /= q;
        }
        if (st.max_depth >= 0 && depth > st.max_depth) break;

        Hit hit;
        ++stats.rays;
        const bool found = sc.accel->intersect(ray, hit);
        if (medium >= 0) {
            const Medium& m = media_[size_t(medium)];
            const float t_surface = found ? hit.t : kInfinity;
            // A scattering event before the surface, and its weight (the estimator in the header).
            float t = kInfinity;
            bool scatter;
            if (m.heterogeneous()) {
                // Delta tracking (grey extinction): a real collision's weight is the albedo there.
                scatter = delta_track(m, ray, t_surface, sampler, t);
                if (scatter) beta *= albedo_at(m, ray.o + t * ray.d);
            } else {
                t = sample_distance(m, channel, sampler.next_1d());
                scatter = t < t_surface;
                const vec3 tr = transmittance(m, scatter ? t : t_surface);
                if (scatter) {
                    beta *= m.sigma_s() * tr / (m.sigma_t[channel] * tr[channel]);
                    if (spectral_mis) ratio *= m.sigma_t * tr / (m.sigma_t[channel] * tr[channel]);
                } else {
                    if (!(tr[channel] > 0.f)) break;
                    beta *= tr / tr[channel];
                    if (spectral_mis) ratio *= tr / tr[channel];
                }
                if (spectral_mis) {
                    // The chosen channel's entry is unchanged by the step, so the maximum is > 0.
                    const float s = max_component(ratio);
                    if (!(s > 0.f && s < kInfinity)) break;  // a density that underflowed: no path
                    ratio /= s;
                    beta /= s;
                }
            }
            if (scatter) {
                ++depth;
                valid = true;
                if (st.max_depth >= 0 && depth > st.max_depth) break;
                const vec3 p = ray.o + t * ray.d;
                if (mode != SamplingMode::Bsdf && have_lights) {
                    const float ul = sampler.next_1d();
                    const vec2 up = sampler.next_2d();
                    LightSample ls;
                    if (sc.lights.sample_li(p, ul, up, ls) && ls.pdf > 0.f) {
                        const float ph = hg_phase(m.g, glm::dot(ray.d, ls.wi));
                        Ray shadow;
                        shadow.o = p;
                        if (ls.infinite) {
                            shadow.d = ls.wi;
                        } else {
                            shadow.d = offset_ray_origin(ls.p, ls.p_error, ls.n, p - ls.p) - p;
                            shadow.tmax = 1.f - kShadowEpsilon;
                        }
                        ++stats.rays;
                        float surface_T = 1.f;
                        const vec3 T = shadow_transmittance(shadow, medium, surface_T, sampler, stats.rays);
                        if (!is_black(T)) {
                            const float w =
                                mode == SamplingMode::Mis && !ls.delta ? power_heuristic(ls.pdf, ph * surface_T) : 1.f;
                            L += throughput() * ls.Le * T * (ph * w / ls.pdf);
                        }
                    }
                }
                const vec3 wo = sample_phase(m.g, ray.d, sampler.next_2d());
                prev_pdf = hg_phase(m.g, glm::dot(ray.d, wo));
                prev_p = p;
                after_delta = false;
                ray = Ray();
                ray.o = p;
                ray.d = glm::normalize(wo);
                continue;
            }
        }

        if (!found) {
            // Escaped: the infinite lights (hidden from the camera by hide_emitters).
            if (sc.lights.has_infinite() && !(depth == 0 && hide))
                add_infinite(sc.lights, ray.d, throughput(), after_delta || depth == 0, mode, prev_pdf, L);
            break;
        }
        SurfaceInteraction si = sc.interaction(hit);
        const Shape& shape = sc.shapes[si.shape];
        const vec3 ng = si.ng;  // the shape's side, before shade() turns it
        const vec3 wo_world = -ray.d;
        if (!(depth == 0 && hide)) add_emission(sc, hit, si, wo_world, throughput(), after_delta || depth == 0, mode, prev_p, prev_pdf, L);

        const Material& mat = sc.materials[shape.material];
        if (mat.masked) {
            // A null surface (an index-matched boundary) or a mask: crossed with probability
            // 1 - opacity, no scattering event; the medium changes as the shape says.
            const float a = mat.opacity_at(sc.texture_query(si, hit));
            if (a < 1.f && (a <= 0.f || sampler.next_1d() >= a)) {
                if (a > 0.f) prev_pdf *= 1.f - a;
                medium = medium_after(shape, ng, ray.d, medium);
                ray = spawn_ray(si, ray.d);
                continue;
            }
        }
        valid = true;
        // No scattering event may follow the last one allowed: nothing more to add.
        if (st.max_depth >= 0 && depth >= st.max_depth) break;

        shade<DiffuseOnly>(sc, hit, si, wo_world, sh);
        if (mode != SamplingMode::Bsdf && have_lights && sh.has_smooth_component()) {
            const float ul = sampler.next_1d();
            const vec2 up = sampler.next_2d();
            LightSample ls;
            if (sc.lights.sample_li(si.p, ul, up, ls) && ls.pdf > 0.f) {
                const BsdfEval e = sh.eval_pdf(sh.frame.to_local(ls.wi));
                if (!is_black(e.f)) {
                    ++stats.rays;
                    float surface_T = 1.f;
                    const vec3 T = shadow_transmittance(shadow_ray(si, ls), medium_after(shape, ng, ls.wi, medium),
                                                        surface_T, sampler, stats.rays);
                    if (!is_black(T)) {
                        const float w = mode == SamplingMode::Mis && !ls.delta ? power_heuristic(ls.pdf, e.pdf * surface_T) : 1.f;
                        L += throughput() * e.f * ls.Le * T * (w / ls.pdf);
                    }
                }
            }
        }
        const float u1 = sampler.next_1d();
        const vec2 u2 = sampler.next_2d();
        std::optional<BsdfSample> bs = sh.sample(u1, u2);
        if (!bs || !(bs->pdf > 0.f)) break;
        beta *= bs->weight();
        eta *= bs->eta;
        ++depth;
        after_delta = bs->delta;
        prev_pdf = bs->pdf;
        prev_p = si.p;
        const vec3 wi_world = glm::normalize(sh.frame.to_world(bs->wi));
        medium = medium_after(shape, ng, wi_world, medium);
        ray = spawn_ray(si, wi_world);
    }
    if (valid) ++stats.camera_hits;
    return L;
}

}  // namespace candela
