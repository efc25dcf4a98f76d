#pragma once
// A pure light tracer: Mitsuba 3's `ptracer` (src/integrators/ptracer.cpp), the t = 1 strategy of
// bidirectional path tracing on its own (issue 15).
//
// Each pixel sample traces one light path, seeded from (pixel, sample index, seed) like a camera
// sample, but its contributions land wherever they project: they are SPLATS (film/film.h), and the
// pixel that started a path is only its owner for seeding and ordering. Per light path:
//  1. Emitters seen directly (unless hide_emitters; Mitsuba's sample_visible_emitters): a point on
//     a light chosen as for emission, connected to the camera. Area lights: a point uniform by
//     area, estimate Le(y -> camera) cos_y Wi / (pdf_wi pdf_area), cos_y the geometric cosine
//     (light/emitter.h: the normals of emitters with vertex normals). Infinite lights (constant,
//     envmap): a direction sampled as for next-event estimation from the camera, estimate
//     Le We cos_cam lens_area / pdf_sa when the ray from the camera escapes (not for the
//     orthographic camera, whose single direction no sampled direction hits). Delta lights are
//     never seen directly: their choice contributes nothing here.
//  2. A ray from the lights (LightSet::sample_le), throughput beta = Le |cos| / (pdf_pos pdf_dir),
//     cos against EmissionSample::n (area lights: the geometric normal).
//     At every surface vertex x_k (k = scattering events, 1 at the first hit) with k <= max_depth:
//     the camera connection (Camera::sample_wi) splats
//         beta f(wo, wi_cam) |cos| C(wo, wi_cam) Wi / pdf_wi x visibility
//     at the raster point it reaches; then, while k < max_depth, the path goes on by sampling the
//     BSDF in Importance mode, beta *= f |cos| / pdf x C(wo, wi). wo points to the previous (light
//     side) vertex. C is the adjoint BSDF's shading-normal correction (Veach 1997, p. 155):
//         C = |wo.ns wi.ng| / |wo.ng wi.ns|, and 0 when wo or wi lies on different sides of the
//     geometric and the shading normal (no light leaks), as Mitsuba's ptracer.
// Depth as everywhere in candela: max_depth counts scattering events (0: only the emitters seen
// directly; -1 unbounded), Mitsuba's max_depth - 1. Russian roulette after the BSDF sample at a
// vertex with k >= rr_depth, survival min(max(beta) eta^2, 0.95) (Mitsuba's).
// Masks: as in the path tracer, a masked surface is passed with probability 1 - opacity (not a
// vertex), and camera connections cross masks with their transmittance.
// Sampler dimensions per light path: [emitters seen directly: 1 (light), 2 (point or direction),
// 2 (lens)], then 1 (light), 2 (position), 2 (direction), and per vertex 2 (lens), 1 + 2 (BSDF),
// [1 (roulette)]; masks add 1 per masked surface reached.
// The splats go through the film's filter (film/splat_filter.h): the image estimates the same
// filtered image as the path tracer's camera samples.
// Limits: perturbed normals (bump, normal maps) use the interpolated shading normal in C; no alpha, no AOVs.
#include "integrator/integrator.h"
#include "integrator/path.h"

namespace candela {

class LightTracer {
public:
    // `camera` is already set to the film's size (set_film_size).
    LightTracer(const Scene& scene, const Camera& camera, int width, int height)
        : scene_(scene), camera_(camera), width_(width), height_(height), masks_(scene_has_masks(scene)) {}

    // One light path (and the emitters seen directly): its splats are appended to `out`.
    template <class S, bool DiffuseOnly = false>
    void trace(S& sampler, SplatTile& out, PathStats& stats) const;

private:
    // C above; 0 when a direction crosses between the shading and the geometric hemispheres.
    static float shading_correction(vec3 wo, vec3 wi, vec3 ns, vec3 ng) {
        const float a = glm::dot(wo, ns), b = glm::dot(wo, ng), c = glm::dot(wi, ns), d = glm::dot(wi, ng);
        if (!(a * b > 0.f) || !(c * d > 0.f)) return 0.f;
        return std::abs(a * d) / std::abs(b * c);
    }
    template <class S>
    void visible_emitters(S& sampler, SplatTile& out, PathStats& stats, bool masks) const;

    const Scene& scene_;
    const Camera& camera_;
    int width_, height_;
    bool masks_;
};

class LightTracerPass final : public Integrator {
public:
    PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                          const std::atomic<bool>* cancel) const override;
};

template <class S>
void LightTracer::visible_emitters(S& sampler, SplatTile& out, PathStats& stats, bool masks) const {
    const Scene& sc = scene_;
    const float u_sel = sampler.next_1d();
    const vec2 u_pos = sampler.next_2d();
    const vec2 u_lens = sampler.next_2d();
    LightSet::PositionSample ps;
    if (!sc.lights.sample_position(u_sel, u_pos, ps) || !(ps.pdf > 0.f)) return;
    if (ps.light < 0) {
        CameraWiSample cs;
        if (!camera_.sample_wi(ps.si.p, u_lens, cs)) return;
        // One-sided: the front (the shading normal's side) only; the area measure's cosine is the
        // geometric one (light/emitter.h).
        if (!(glm::dot(cs.wi, ps.si.ns) > 0.f) || is_black(ps.Le)) return;
        const float cos_l = std::abs(glm::dot(cs.wi, ps.si.ng));
        ++stats.rays;
        const float T = shadow_transmittance(sc, spawn_ray_to(ps.si, cs.p, vec3(0.f), vec3(0.f)), masks, stats.rays);
        if (!(T > 0.f)) return;
        out.add(width_, height_, cs.raster, ps.Le * (cos_l * cs.Wi * T / (cs.pdf * ps.pdf)));
        return;
    }
    if (camera_.type == CameraType::Orthographic) return;
    LightSample ls;
    if (!candela::sample_li(sc.lights.light(size_t(ps.light)).model, sc.lights.scene_sphere(), camera_.origin(), u_pos, ls) ||
        !(ls.pdf > 0.f))
        return;
    Ray ray;
    ray.o = camera_.origin();
    if (camera_.needs_lens_sample()) {
        const vec2 a = camera_.aperture_radius * square_to_uniform_disk_concentric(u_lens);
        ray.o = vec3(camera_.to_world * glm::vec4(a, 0.f, 1.f));
    }
    ray.d = ls.wi;
    vec2 raster;
    const float we = camera_.We(ray, &raster);
    if (!(we > 0.f)) return;
    const float cos_c = glm::dot(ray.d, camera_.forward());
    Ray vis = ray;  // the camera ray starts on the near clip plane
    vis.o = ray.o + ray.d * (camera_.near_clip / cos_c);
    ++stats.rays;
    const float T = shadow_transmittance(sc, vis, masks, stats.rays);
    if (!(T > 0.f)) return;
    out.add(width_, height_, raster, ls.Le * (we * cos_c * camera_.lens_area() * T / (ls.pdf * ps.pdf)));
}

template <class S, bool DiffuseOnly>
void LightTracer::trace(S& sampler, SplatTile& out, PathStats& stats) const {
    const Scene& sc = scene_;
    const RenderSettings& st = sc.settings;
    const bool masks = !DiffuseOnly && masks_;
    if (sc.lights.empty()) return;
    if (!st.integrator.hide_emitters) visible_emitters(sampler, out, stats, masks);
    if (st.max_depth == 0) return;

    const float u_sel = sampler.next_1d();
    const vec2 u_pos = sampler.next_2d(), u_dir = sampler.next_2d();
    std::optional<EmissionSample> es = sc.lights.sample_le(u_sel, u_pos, u_dir);
    if (!es || !(es->pdf_pos > 0.f) || !(es->pdf_dir > 0.f)) return;
    const float cos0 = glm::dot(es->n, es->n) > 0.f ? std::abs(glm::dot(es->n, es->ray.d)) : 1.f;
    vec3 beta = es->Le * (cos0 / (es->pdf_pos * es->pdf_dir));
    if (is_black(beta)) return;
    Ray ray = es->ray;
    ShadingT<DiffuseOnly> sh;
    float eta_scale = 1.f;
    int passes = 0;
    for (int depth = 1;; ++depth) {
        Hit hit;
        ++stats.rays;
        if (!sc.accel->intersect(ray, hit)) break;
        SurfaceInteraction si = sc.interaction(hit);
        const vec3 wo_world = -glm::normalize(ray.d);
        if constexpr (!DiffuseOnly) {
            if (masks_) {  // pass straight through with probability 1 - opacity (not a vertex)
                const Material& m = sc.materials[sc.shapes[si.shape].material];
                const float a = m.opacity_at(m.masked ? sc.texture_query(si, hit) : TextureQuery{});
                if (a < 1.f && sampler.next_1d() >= a) {
                    if (++passes > 1024) break;
                    ray = spawn_ray(si, ray.d);
                    --depth;
                    continue;
                }
            }
        }
        if (st.max_depth >= 0 && depth > st.max_depth) break;
        shade<DiffuseOnly>(sc, hit, si, wo_world, sh);

        // t = 1: connect x_k to the camera.
        const vec2 u_lens = sampler.next_2d();
        CameraWiSample cs;
        if (sh.has_smooth_component() && camera_.sample_wi(si.p, u_lens, cs)) {
            const float C = shading_correction(wo_world, cs.wi, sh.frame.n, si.ng);
            const vec3 f = C > 0.f ? sh.eval(sh.frame.to_local(cs.wi), TransportMode::Importance) : vec3(0.f);
            if (!is_black(f)) {
                ++stats.rays;
                const float T = shadow_transmittance(sc, spawn_ray_to(si, cs.p, vec3(0.f), vec3(0.f)), masks, stats.rays);
                if (T > 0.f) out.add(width_, height_, cs.raster, beta * f * (C * cs.Wi * T / cs.pdf));
            }
        }
        if (st.max_depth >= 0 && depth >= st.max_depth) break;

        const float u1 = sampler.next_1d();
        const vec2 u2 = sampler.next_2d();
        std::optional<BsdfSample> bs = sh.sample(u1, u2, TransportMode::Importance);
        if (!bs || !(bs->pdf > 0.f)) break;
        const vec3 wi_world = sh.frame.to_world(bs->wi);
        const float C = shading_correction(wo_world, wi_world, sh.frame.n, si.ng);
        beta *= bs->weight() * C;
        if (is_black(beta)) break;
        eta_scale *= sqr(bs->eta);
        ray = spawn_ray(si, wi_world);
        if (depth >= st.rr_depth) {
            const float q = std::min(max_component(beta) * eta_scale, 0.95f);
            if (sampler.next_1d() >= q) break;
            beta /= q;
        }
    }
}

}  // namespace candela
