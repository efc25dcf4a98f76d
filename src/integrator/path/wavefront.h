#pragma once
// The path tracer in stages over a batch of paths: the first step towards a SIMD wavefront
// (issue 18). WORK IN PROGRESS on the `wavefront` branch; docs/wavefront-plan.md there has the plan.
//
// A tile's paths (its pixels times the pass's samples) advance together, one bounce per round:
//   1. closest hit of every live path;
//   2. per path, everything up to its next ray: emission, the light sample and its shadow ray,
//      the BSDF sample and Russian roulette (the shadow ray's outcome changes no sampler draw and
//      no throughput, so the path can go on before it is known);
//   3. the shadow rays of the round, whose contribution (computed in 2 as if unoccluded) is added
//      to the path's radiance when nothing is in the way.
// Each path makes the operations of PathIntegrator::Li<S, true> (path_impl.h) in the same order,
// and its radiance is added to the film in the scalar loop's order: the image is the same bit for
// bit. The stages run path by path for now; SoA state and SIMD stages are the next steps.
//
// Scope: the diffuse-only instantiation (no masks) without textures, an unweighted film (box
// filter) without adaptive sampling, AOVs or alpha. render_pass_for falls back to the per-path loop otherwise.
#include <vector>
#include "integrator/path.h"
#include "integrator/path/hit_soa.h"
#include "integrator/tiles.h"

namespace candela {

template <class S>
struct StagedPath {
    Ray ray;
    vec3 L{0.f}, beta{1.f}, prev_p{0.f};
    float prev_pdf = 0.f, eta_scale = 1.f;
    bool after_delta = true;
    int depth = 0;
    S sampler;
    // This round's light sample: its shadow ray and what it adds when nothing is in the way.
    Ray shadow;
    vec3 shadow_L{0.f};
};

// What trace_staged reuses from round to round (one per thread).
struct StagedScratch {
    std::vector<uint32_t> next, shadowed;
    std::vector<uint32_t> hit_path;  // per hit of the round (dense): its path
    std::vector<Hit> hits;
    std::vector<uint8_t> batched;    // the hit went through reconstruct_triangle_hits
    std::vector<uint32_t> prim, shape;
    std::vector<float> b1, b2, f[12];
    std::vector<int32_t> smooth;     // per shape
};

// Runs the paths whose indices are in `live` (emptied on return) to their end. Diffuse-only scenes
// (scene_is_diffuse_only) without textures only (staged_pass_applies).
template <class S>
void trace_staged(const Scene& sc, std::vector<StagedPath<S>>& paths, std::vector<uint32_t>& live,
                  StagedScratch& x, PathStats& stats) {
    const RenderSettings& st = sc.settings;
    const SamplingMode mode = st.sampling;
    const bool have_lights = !sc.lights.empty();
    ShadingT<true> sh;
    x.smooth.resize(sc.shapes.size());
    for (size_t s = 0; s < sc.shapes.size(); ++s) x.smooth[s] = sc.shapes[s].smooth ? 1 : 0;
    while (!live.empty()) {
        x.next.clear();
        x.shadowed.clear();
        x.hit_path.clear();
        x.hits.clear();
        // Stage 1: closest hits.
        for (const uint32_t i : live) {
            StagedPath<S>& p = paths[i];
            Hit hit;
            ++stats.rays;
            if (!sc.accel->intersect(p.ray, hit)) {
                if (sc.lights.has_infinite() && !(p.depth == 0 && st.integrator.hide_emitters))
                    add_infinite(sc.lights, glm::normalize(p.ray.d), p.beta, p.after_delta, mode, p.prev_pdf, p.L);
                continue;
            }
            if (p.depth == 0 && st.integrator.hide_emitters && !skip_area_emitters(sc, p.ray, hit, stats)) continue;
            if (p.depth == 0) ++stats.camera_hits;
            x.hit_path.push_back(i);
            x.hits.push_back(hit);
        }
        // Stage 2a: hit reconstruction in SIMD lanes for the scene's own triangles (analytic shapes
        // and instances: Scene::interaction, per hit).
        const size_t m = x.hits.size();
        const size_t padded = (m + kHitBatchAlign - 1) / kHitBatchAlign * kHitBatchAlign;
        x.prim.assign(padded, 0u);
        x.b1.assign(padded, 0.f);
        x.b2.assign(padded, 0.f);
        x.batched.assign(m, 0);
        x.shape.resize(padded);
        for (auto& v : x.f) v.resize(padded);
        for (size_t j = 0; j < m; ++j) {
            const Hit& h = x.hits[j];
            if (h.kind != PrimKind::Triangle || h.instance != ~0u) continue;
            x.batched[j] = 1;
            x.prim[j] = h.prim;
            x.b1[j] = h.b1;
            x.b2[j] = h.b2;
        }
        if (m > 0)
            reconstruct_triangle_hits(sc.mesh, x.smooth.data(), m, HitBatch{x.prim.data(), x.b1.data(), x.b2.data()},
                                      SurfaceBatch{{x.f[0].data(), x.f[1].data(), x.f[2].data()},
                                                   {x.f[3].data(), x.f[4].data(), x.f[5].data()},
                                                   {x.f[6].data(), x.f[7].data(), x.f[8].data()},
                                                   {x.f[9].data(), x.f[10].data(), x.f[11].data()},
                                                   x.shape.data()});
        // Stage 2b: per path, everything up to its next ray.
        for (size_t j = 0; j < m; ++j) {
            const uint32_t i = x.hit_path[j];
            StagedPath<S>& p = paths[i];
            const Hit& hit = x.hits[j];
            SurfaceInteraction si;
            if (x.batched[j]) {
                // uv, dpdu and dpdv stay unset: nothing untextured and diffuse reads them.
                si.p = vec3(x.f[0][j], x.f[1][j], x.f[2][j]);
                si.p_error = vec3(x.f[3][j], x.f[4][j], x.f[5][j]);
                si.ng = vec3(x.f[6][j], x.f[7][j], x.f[8][j]);
                si.ns = vec3(x.f[9][j], x.f[10][j], x.f[11][j]);
                si.prim = hit.prim;
                si.shape = x.shape[j];
            } else {
                si = sc.interaction(hit);
            }
            const vec3 wo_world = -glm::normalize(p.ray.d);
            if (sc.lights.emitter_of(hit) >= 0) {
                const vec3 Le = sc.lights.emitted(si, wo_world);
                if (!is_black(Le)) {
                    if (p.after_delta || mode == SamplingMode::Bsdf) {
                        p.L += p.beta * Le;
                    } else if (mode == SamplingMode::Mis) {
                        const float light_pdf = sc.lights.pdf_li(p.prev_p, si);
                        p.L += p.beta * Le * power_heuristic(p.prev_pdf, light_pdf);
                    }
                }
            }
            if (st.max_depth >= 0 && p.depth >= st.max_depth) continue;
            shade<true>(sc, hit, si, wo_world, sh);
            if (mode != SamplingMode::Bsdf && have_lights && sh.has_smooth_component()) {
                const float ul = p.sampler.next_1d();
                const vec2 up = p.sampler.next_2d();
                LightSample ls;
                if (sc.lights.sample_li(si.p, ul, up, ls)) {
                    const vec3 wi = sh.frame.to_local(ls.wi);
                    const BsdfEval e = sh.eval_pdf(wi);
                    if (!is_black(e.f)) {
                        p.shadow = shadow_ray(si, ls);
                        ++stats.rays;
                        // Li's weight with transmittance T = 1 (no masks): e.pdf * 1 and 1 * w are exact.
                        const float T = 1.f;
                        const float w = mode == SamplingMode::Mis && !ls.delta ? power_heuristic(ls.pdf, e.pdf * T) : 1.f;
                        p.shadow_L = p.beta * e.f * ls.Le * (T * w / ls.pdf);
                        x.shadowed.push_back(i);
                    }
                }
            } else if (mode != SamplingMode::Bsdf) {
                p.sampler.next_1d();
                p.sampler.next_2d();
            }
            const float u1 = p.sampler.next_1d();
            const vec2 u2 = p.sampler.next_2d();
            const std::optional<BsdfSample> bs = sh.sample(u1, u2);
            if (!bs || !(bs->pdf > 0.f)) continue;
            p.beta *= bs->weight();
            if (is_black(p.beta)) continue;
            p.eta_scale *= sqr(bs->eta);
            p.after_delta = bs->delta;
            p.prev_pdf = bs->pdf;
            p.prev_p = si.p;
            p.ray = spawn_ray(si, sh.frame.to_world(bs->wi));
            if (p.depth + 1 >= st.rr_depth) {
                const float q = std::min(max_component(p.beta) * p.eta_scale, 0.95f);
                if (p.sampler.next_1d() >= q) continue;
                p.beta /= q;
            }
            ++p.depth;
            x.next.push_back(i);
        }
        // The round's shadow rays, in path order: their contributions come before the emission
        // the next round adds, as in Li.
        for (const uint32_t i : x.shadowed) {
            StagedPath<S>& p = paths[i];
            if (!sc.accel->occluded(p.shadow)) p.L += p.shadow_L;
        }
        live.swap(x.next);
    }
}

// Whether render_tiles_staged can render this pass (see the scope above).
inline bool staged_pass_applies(const Scene& scene, const Film& film) {
    if (!scene_is_diffuse_only(scene) || scene.lights.has_textured_emitter()) return false;
    for (const Material& m : scene.materials)
        if (m.textured()) return false;
    return !film.weighted() && !film.adaptive() && film.aov_channels() == 0 && !film.has_alpha();
}

// render_tiles (tiles.h) for an unweighted film, a tile's paths at a time through trace_staged.
template <class S>
PassStats render_tiles_staged(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                              const std::atomic<bool>* cancel, const S& prototype) {
    const int w = film.width(), h = film.height();
    const int tiles_x = (w + kTileSize - 1) / kTileSize;
    const int tiles_y = (h + kTileSize - 1) / kTileSize;
    const int n_tiles = tiles_x * tiles_y;
    Camera camera = scene.camera;
    camera.set_film_size(w, h);
    std::atomic<uint64_t> total_rays{0}, total_samples{0};
    std::atomic<bool> stopped{false};
#pragma omp parallel num_threads(n_threads)
    {
        std::vector<StagedPath<S>> paths;
        std::vector<uint32_t> live;
        StagedScratch scratch;
#pragma omp for schedule(dynamic, 1)
        for (int tile = 0; tile < n_tiles; ++tile) {
            if (stopped.load(std::memory_order_relaxed)) continue;
            if (cancel && cancel->load(std::memory_order_relaxed)) {
                stopped = true;
                continue;
            }
            PathStats ps;
            const detail::TileRange tr = detail::tile_range(tile, tiles_x, w, h);
            // One path per pixel sample, in the scalar loop's order (pixel by pixel, samples within).
            paths.clear();
            live.clear();
            for (int y = tr.y0; y < tr.y1; ++y)
                for (int x = tr.x0; x < tr.x1; ++x)
                    for (int s = 0; s < spp; ++s) {
                        StagedPath<S> p{Ray(), vec3(0.f), vec3(1.f), vec3(0.f), 0.f, 1.f, true, 0, prototype, Ray(),
                                        vec3(0.f)};
                        p.sampler.start_pixel_sample(camera.sampler_pixel(ivec2(x, y)), first_sample + uint32_t(s));
                        const vec2 jitter = p.sampler.next_2d();
                        const vec2 lens = camera.needs_lens_sample() ? p.sampler.next_2d() : vec2(0.5f);
                        p.ray = camera.generate_ray(ivec2(x, y), jitter, lens);
                        live.push_back(uint32_t(paths.size()));
                        paths.push_back(p);
                    }
            trace_staged(scene, paths, live, scratch, ps);
            size_t k = 0;
            for (int y = tr.y0; y < tr.y1; ++y)
                for (int x = tr.x0; x < tr.x1; ++x)
                    for (int s = 0; s < spp; ++s) film.add_sample(ivec2(x, y), paths[k++].L);
            total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
            total_samples.fetch_add(paths.size(), std::memory_order_relaxed);
        }
    }
    PassStats out;
    out.rays = total_rays.load();
    out.samples = total_samples.load();
    out.completed = !stopped.load();
    return out;
}

}  // namespace candela
