#pragma once
// One bounce of the path tracer, the one definition that both loops run: PathIntegrator::Li
// (path_impl.h, one path at a time, its shadow rays traced at once) and the staged loop's per-path
// branch (path/wavefront.h, whose shadow rays are traced together at the end of a round). The SIMD
// lane step of the staged loop (path/diffuse_step.cpp) is this bounce specialised to a plain
// diffuse material and emissive-triangle lights; the numeric rules it shares with this one are in
// path/rules.h. A change to shading (a medium, a guided direction) is made here.
#include "integrator/path/rules.h"
#include "integrator/shading.h"

namespace candela {

struct PathStats {
    uint64_t rays = 0;  // closest-hit and shadow rays traced
    uint64_t camera_hits = 0;  // camera rays that hit a surface (the film's alpha: hdrfilm rgba)
};

inline float power_heuristic(float a, float b) { return path_rules::power_heuristic(ScalarOps{}, a, b); }

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
// density in MIS mode, not at all in light mode (light sampling counted it). The bounce below and
// the staged loop's lanes (path/wavefront.h) add it.
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

// What a path carries from one vertex to the next.
struct PathState {
    Ray ray;                 // towards the next vertex (world space; any length)
    vec3 L{0.f};             // the radiance gathered so far (the sample's value when the path ends)
    vec3 beta{1.f};          // throughput: prod of f |cos theta_i| / pdf over the bounces, / q per roulette
    vec3 prev_p{0.f};        // the last scattering vertex (MIS of the emission the ray reaches)
    float prev_pdf = 0.f;    // solid-angle pdf of the BSDF sample that left prev_p, times the
                             // probabilities of the mask pass-throughs since
    float eta_scale = 1.f;   // product of eta^2 over refractions: undoes their radiance scaling
    bool after_delta = true; // camera rays and delta bounces: emission counts fully
    int passes = 0;          // mask pass-throughs so far (bounded, as skip_area_emitters)
};

// A light sample's shadow ray and what it adds when the light is reached with transmittance T
// (1 unoccluded, 0 blocked, prod (1 - opacity) through masks).
struct ShadowRequest {
    Ray ray;              // from the surface to the light (spawn_ray_to: tmax 1 - eps), or unbounded
    vec3 beta_f_Le{0.f};  // beta f Le: the throughput, f |cos theta_i| at the light's direction, Le
    float light_pdf = 0.f;// the light sample's solid-angle density (its choice's pmf included)
    float bsdf_pdf = 0.f; // the BSDF's solid-angle density of the same direction
    bool mis = false;     // weighted against BSDF sampling (Mis mode and not a delta light)

    // beta f Le T w / light_pdf, w = the power heuristic against BSDF sampling through T.
    __attribute__((always_inline)) vec3 contribution(float T) const {
        const float w = mis ? path_rules::light_mis_weight(ScalarOps{}, light_pdf, bsdf_pdf, T) : 1.f;
        return beta_f_Le * path_rules::light_scale(ScalarOps{}, T, w, light_pdf);
    }
};

// The light sample at a shaded vertex with the numbers (ul chooses the light, up the point):
// false when there is none or the BSDF is black there; else its request.
template <bool DiffuseOnly>
__attribute__((always_inline)) inline bool light_sample(const Scene& sc, const SurfaceInteraction& si,
                                                        const ShadingT<DiffuseOnly>& sh, vec3 beta, float ul, vec2 up,
                                                        ShadowRequest& r) {
    LightSample ls;
    if (!sc.lights.sample_li(si.p, ul, up, ls)) return false;
    const BsdfEval e = sh.eval_pdf(sh.frame.to_local(ls.wi));  // f, and the pdf for MIS, from one evaluation
    if (is_black(e.f)) return false;
    r.ray = shadow_ray(si, ls);
    r.beta_f_Le = beta * e.f * ls.Le;
    r.light_pdf = ls.pdf;
    r.bsdf_pdf = e.pdf;
    // A delta light cannot be reached by BSDF sampling: no MIS.
    r.mis = sc.settings.sampling == SamplingMode::Mis && !ls.delta;
    return true;
}

// The escape of p.ray from the scene at `depth` (scattering events so far): the infinite lights it
// sees, MIS as for area lights with each light's own pdf; hidden from camera rays by hide_emitters
// (as Mitsuba).
__attribute__((always_inline)) inline void path_escaped(const Scene& sc, PathState& p, int depth) {
    if (sc.lights.has_infinite() && !(depth == 0 && sc.settings.integrator.hide_emitters))
        add_infinite(sc.lights, glm::normalize(p.ray.d), p.beta, p.after_delta, sc.settings.sampling, p.prev_pdf, p.L);
}

enum class BounceResult { Continue, PassThrough, End };

// What every bounce of a path loop reads from the scene, read once per loop (measured: read per
// bounce from the scene, it cost Li 0.4% more instructions per sample).
struct BounceSettings {
    SamplingMode mode;
    bool have_lights;  // the scene has lights: light samples are made
    bool masks;        // opacity tests at hits (some material is masked)
    int max_depth, rr_depth;
    BounceSettings(const Scene& sc, bool masks_)
        : mode(sc.settings.sampling), have_lights(!sc.lights.empty()), masks(masks_),
          max_depth(sc.settings.max_depth), rr_depth(sc.settings.rr_depth) {}
};

// One bounce at `hit`, the closest hit of p.ray, reached after `depth` scattering events (the
// conventions of PathIntegrator in path.h):
//   1. the emission there, MIS-weighted against the light sample that could have found it;
//   2. with cfg.masks, the opacity test: a pass-through (probability 1 - a) continues p.ray beyond
//      the surface and returns PassThrough (not a vertex: depth does not advance, prev_pdf *= 1 - a);
//   3. at depth >= max_depth: End;
//   4. the light sample (next-event estimation): its ShadowRequest goes to shadow(request), which
//      traces it now (Li) or later (the staged loop) and adds request.contribution(T);
//   5. the BSDF sample: beta *= f |cos theta_i| / pdf (solid angle; a delta lobe's f over its
//      discrete probability), p.ray becomes the next ray, prev_pdf the sample's pdf;
//   6. Russian roulette from depth + 1 >= rr_depth: survival q (path_rules::roulette_survival),
//      beta /= q.
// Frame: si in world space; the BSDF in sh.frame (shading.h), wo towards the previous vertex.
// Sampler draws, in this order: opacity (1D, masked surfaces only), light (1D then 2D, whenever
// the mode is not Bsdf, even when no light sample is made, so that dimensions stay aligned), BSDF
// (1D then 2D), roulette (1D, when it applies). The staged loop's lanes draw the same (wavefront.h).
// `sh` is scratch kept by the caller (one per path loop). Returns Continue when the path goes on
// along p.ray, End when it ends; PassThrough continues p.ray at the same depth. Inlined into each
// loop, as the loop body it was (measured: called, it cost the per-path loop 3-4% more
// instructions per sample).
template <bool DiffuseOnly, class S, class Shadow>
__attribute__((always_inline)) inline BounceResult path_bounce(const Scene& sc, const BounceSettings& cfg, const Hit& hit,
                                                               SurfaceInteraction& si, int depth, PathState& p,
                                                               S& sampler, ShadingT<DiffuseOnly>& sh, PathStats& stats,
                                                               Shadow&& shadow) {
    const SamplingMode mode = cfg.mode;
    const vec3 wo_world = -glm::normalize(p.ray.d);
    add_emission(sc, hit, si, wo_world, p.beta, p.after_delta, mode, p.prev_p, p.prev_pdf, p.L);
    if constexpr (!DiffuseOnly) {
        if (cfg.masks) {  // pass straight through with probability 1 - opacity (not a vertex)
            const Material& m = sc.materials[sc.shapes[si.shape].material];
            const float a = m.opacity_at(m.masked ? sc.texture_query(si, hit) : TextureQuery{});
            if (a < 1.f && sampler.next_1d() >= a) {
                if (++p.passes > 1024) return BounceResult::End;
                p.prev_pdf *= 1.f - a;
                p.ray = spawn_ray(si, p.ray.d);
                return BounceResult::PassThrough;
            }
        }
    }
    if (cfg.max_depth >= 0 && depth >= cfg.max_depth) return BounceResult::End;

    shade<DiffuseOnly>(sc, hit, si, wo_world, sh);

    // Next-event estimation.
    if (mode != SamplingMode::Bsdf && cfg.have_lights && sh.has_smooth_component()) {
        const float ul = sampler.next_1d();
        const vec2 up = sampler.next_2d();
        ShadowRequest r;
        if (light_sample(sc, si, sh, p.beta, ul, up, r)) {
            ++stats.rays;
            shadow(r);
        }
    } else if (mode != SamplingMode::Bsdf) {
        // Keep the sample dimensions aligned whatever the material (helps MLT and QMC later).
        sampler.next_1d();
        sampler.next_2d();
    }

    // Continue the path by sampling the BSDF.
    const float u1 = sampler.next_1d();
    const vec2 u2 = sampler.next_2d();
    const std::optional<BsdfSample> bs = sh.sample(u1, u2);
    if (!bs || !(bs->pdf > 0.f)) return BounceResult::End;
    p.beta *= bs->weight();
    if (is_black(p.beta)) return BounceResult::End;
    p.eta_scale *= sqr(bs->eta);
    p.after_delta = bs->delta;
    p.prev_pdf = bs->pdf;
    p.prev_p = si.p;
    p.ray = spawn_ray(si, sh.frame.to_world(bs->wi));

    if (depth + 1 >= cfg.rr_depth) {
        // Survival by the throughput without the 1/eta^2 of refractions, which only reflects the
        // change of solid angle: a path inside glass is not less important (pbrt-v4 etaScale).
        const float q = path_rules::roulette_survival(ScalarOps{}, p.beta.x, p.beta.y, p.beta.z, p.eta_scale);
        if (sampler.next_1d() >= q) return BounceResult::End;
        p.beta /= q;
    }
    return BounceResult::Continue;
}

}  // namespace candela
