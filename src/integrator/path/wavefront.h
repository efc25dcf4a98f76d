#pragma once
// The path tracer in stages over a batch of paths: the start of the SIMD wavefront of issue 18
// (docs/wavefront.md has the plan and the measurements).
//
// A tile's paths (its pixels times the pass's samples) advance together, one bounce per round:
//   1. the closest hit of every live path (traversal stays per ray: it is at Embree's speed);
//   2. hit reconstruction of the round's triangle hits in SIMD lanes (hit_soa.h); then per path,
//      emission and shading, and the numbers of its light sample, BSDF sample and roulette, drawn
//      in Li's order;
//   3. in SIMD lanes, the light samples when the lights are emissive triangles (the shadow ray
//      and its contribution, computed as if unoccluded) and the diffuse step: BSDF sample,
//      throughput, next ray, roulette (diffuse_step.h);
//   4. the round's shadow rays, in path order; each adds its contribution when unoccluded (the
//      shadow ray's outcome changes no sampler draw and no throughput, so the path went on before).
// Each path makes the operations of PathIntegrator::Li<S, true> (path_impl.h) in the same order,
// and the film gets the samples in the scalar loop's order: the image is the same bit for bit
// (tests/test_staged.cpp compares the films on every SIMD target).
//
// Scope (staged_pass_applies): the diffuse-only instantiation (no masks) without textures, the
// independent sampler, an unweighted film (box filter) without adaptive sampling, AOVs or alpha.
// The path pass uses the per-path loop otherwise, and with CANDELA_STAGED=0.
#include <climits>
#include <vector>
#include "integrator/path.h"
#include "integrator/path/diffuse_step.h"
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
    // The diffuse step's lanes (diffuse_step.h): per lane, its path and its arrays.
    std::vector<uint32_t> step_path;
    std::vector<float> sf[9], wo_z, albedo[3], u[2], u_rr, eta_scale, sp[3], serr[3], sng[3], beta[3], pdf, o[3], dir[3];
    std::vector<int32_t> rr, alive;
    // The light samples' lanes (the same lanes).
    std::vector<float> u_l, u_lp[2], so[3], sd[3], sL[3];
    std::vector<int32_t> shadow;
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
    // The diffuse step's arrays: room for every path of the batch, padded.
    const size_t cap = (paths.size() + kDiffuseStepAlign - 1) / kDiffuseStepAlign * kDiffuseStepAlign;
    if (x.step_path.size() < cap) {
        x.step_path.resize(cap);
        for (auto& v : x.sf) v.resize(cap);
        for (int k = 0; k < 3; ++k) {
            for (auto* v : {&x.albedo[k], &x.sp[k], &x.serr[k], &x.sng[k], &x.beta[k], &x.o[k], &x.dir[k]}) v->resize(cap);
        }
        for (auto* v : {&x.wo_z, &x.u[0], &x.u[1], &x.u_rr, &x.eta_scale, &x.pdf, &x.u_l, &x.u_lp[0], &x.u_lp[1]})
            v->resize(cap);
        for (int k = 0; k < 3; ++k) x.so[k].resize(cap), x.sd[k].resize(cap), x.sL[k].resize(cap);
        x.shadow.resize(cap);
        x.rr.resize(cap);
        x.alive.resize(cap);
    }
    // Light samples in lanes: area lights that are emissive triangles only, in MIS or light mode.
    LightSet::AreaTriangleTables tables;
    const bool lanes_nee = mode != SamplingMode::Bsdf && sc.lights.area_triangle_tables(tables);
    x.smooth.resize(sc.shapes.size());
    for (size_t s = 0; s < sc.shapes.size(); ++s) x.smooth[s] = sc.shapes[s].smooth ? 1 : 0;
    while (!live.empty()) {
        x.next.clear();
        x.shadowed.clear();
        x.hit_path.clear();
        x.hits.clear();
        size_t ns = 0;  // lanes of this round's diffuse step
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
        size_t batched = 0;
        for (size_t j = 0; j < m; ++j) {
            const Hit& h = x.hits[j];
            if (h.kind != PrimKind::Triangle || h.instance != ~0u) continue;
            x.batched[j] = 1;
            x.prim[j] = h.prim;
            x.b1[j] = h.b1;
            x.b2[j] = h.b2;
            ++batched;
        }
        // (A scene of analytic shapes only has an empty mesh: nothing to gather from.)
        if (batched > 0)
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
            add_emission(sc, hit, si, wo_world, p.beta, p.after_delta, mode, p.prev_p, p.prev_pdf, p.L);
            if (st.max_depth >= 0 && p.depth >= st.max_depth) continue;
            shade<true>(sc, hit, si, wo_world, sh);
            const size_t q = ns++;  // every shaded path (diffuse: one smooth lobe) takes a lane
            if (lanes_nee) {
                // The light sample in lanes (stage 2c): its numbers now, in Li's order.
                x.u_l[q] = p.sampler.next_1d();
                const vec2 up = p.sampler.next_2d();
                x.u_lp[0][q] = up.x;
                x.u_lp[1][q] = up.y;
            } else if (mode != SamplingMode::Bsdf && have_lights && sh.has_smooth_component()) {
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
            // The BSDF sample's numbers, and the roulette's when it applies: drawn now, in Li's
            // order. Li skips the roulette draw only for a path that has ended, whose sampler is
            // never used again, so drawing it first changes no number any path uses.
            p.sampler.next_1d();  // u1: the diffuse BSDF has one lobe
            const vec2 u2 = p.sampler.next_2d();
            const bool rr = p.depth + 1 >= st.rr_depth;
            const float u_rr = rr ? p.sampler.next_1d() : 0.f;
            const DiffuseBsdf& bsdf = std::get<DiffuseBsdf>(*sh.bsdf);
            x.step_path[q] = i;
            for (int k = 0; k < 3; ++k) {
                x.sf[k][q] = sh.frame.s[k];
                x.sf[3 + k][q] = sh.frame.t[k];
                x.sf[6 + k][q] = sh.frame.n[k];
                x.albedo[k][q] = bsdf.albedo[k];
                x.sp[k][q] = si.p[k];
                x.serr[k][q] = si.p_error[k];
                x.sng[k][q] = si.ng[k];
                x.beta[k][q] = p.beta[k];
            }
            x.wo_z[q] = sh.wo.z;
            x.u[0][q] = u2.x;
            x.u[1][q] = u2.y;
            x.u_rr[q] = u_rr;
            x.rr[q] = rr ? 1 : 0;
            x.eta_scale[q] = p.eta_scale;
        }
        // Stage 2c: the light samples in SIMD lanes (when the lights allow), then the diffuse step
        // (BSDF sample, throughput, next ray, roulette), then the paths that go on, in path order.
        if (ns > 0) {
            // Padding lanes up to the SIMD batch's multiple: finite values, results ignored.
            const size_t padded_ns = (ns + kDiffuseStepAlign - 1) / kDiffuseStepAlign * kDiffuseStepAlign;
            for (size_t q = ns; q < padded_ns; ++q) {
                x.u_l[q] = 0.5f;
                x.u_lp[0][q] = x.u_lp[1][q] = 0.25f;
                for (auto& v : x.sf) v[q] = 0.f;
                for (int k = 0; k < 3; ++k) x.albedo[k][q] = x.sp[k][q] = x.serr[k][q] = x.sng[k][q] = x.beta[k][q] = 0.f;
                x.wo_z[q] = x.u_rr[q] = 0.f;
                x.u[0][q] = x.u[1][q] = 0.5f;
                x.rr[q] = 0;
                x.eta_scale[q] = 1.f;
            }
            if (lanes_nee) {
                area_light_step(ns, tables.cdf, tables.tri, tables.radiance, tables.entries, mode == SamplingMode::Mis,
                                AreaLightStepBatch{x.u_l.data(),
                                                   {x.u_lp[0].data(), x.u_lp[1].data()},
                                                   {x.sp[0].data(), x.sp[1].data(), x.sp[2].data()},
                                                   {x.serr[0].data(), x.serr[1].data(), x.serr[2].data()},
                                                   {x.sng[0].data(), x.sng[1].data(), x.sng[2].data()},
                                                   {x.sf[6].data(), x.sf[7].data(), x.sf[8].data()},
                                                   x.wo_z.data(),
                                                   {x.albedo[0].data(), x.albedo[1].data(), x.albedo[2].data()},
                                                   {x.beta[0].data(), x.beta[1].data(), x.beta[2].data()},
                                                   x.shadow.data(),
                                                   {x.so[0].data(), x.so[1].data(), x.so[2].data()},
                                                   {x.sd[0].data(), x.sd[1].data(), x.sd[2].data()},
                                                   {x.sL[0].data(), x.sL[1].data(), x.sL[2].data()}});
                for (size_t j = 0; j < ns; ++j) {
                    if (!x.shadow[j]) continue;
                    StagedPath<S>& p = paths[x.step_path[j]];
                    p.shadow = Ray();
                    p.shadow.o = vec3(x.so[0][j], x.so[1][j], x.so[2][j]);
                    p.shadow.d = vec3(x.sd[0][j], x.sd[1][j], x.sd[2][j]);
                    p.shadow.tmax = 1.f - kShadowEpsilon;
                    p.shadow_L = vec3(x.sL[0][j], x.sL[1][j], x.sL[2][j]);
                    ++stats.rays;
                    x.shadowed.push_back(x.step_path[j]);
                }
            }
            diffuse_step(ns, DiffuseStepBatch{{x.sf[0].data(), x.sf[1].data(), x.sf[2].data()},
                                              {x.sf[3].data(), x.sf[4].data(), x.sf[5].data()},
                                              {x.sf[6].data(), x.sf[7].data(), x.sf[8].data()},
                                              x.wo_z.data(),
                                              {x.albedo[0].data(), x.albedo[1].data(), x.albedo[2].data()},
                                              {x.u[0].data(), x.u[1].data()},
                                              x.u_rr.data(),
                                              x.rr.data(),
                                              x.eta_scale.data(),
                                              {x.sp[0].data(), x.sp[1].data(), x.sp[2].data()},
                                              {x.serr[0].data(), x.serr[1].data(), x.serr[2].data()},
                                              {x.sng[0].data(), x.sng[1].data(), x.sng[2].data()},
                                              {x.beta[0].data(), x.beta[1].data(), x.beta[2].data()},
                                              x.pdf.data(),
                                              {x.o[0].data(), x.o[1].data(), x.o[2].data()},
                                              {x.dir[0].data(), x.dir[1].data(), x.dir[2].data()},
                                              x.alive.data()});
            for (size_t j = 0; j < ns; ++j) {
                if (!x.alive[j]) continue;
                StagedPath<S>& p = paths[x.step_path[j]];
                p.beta = vec3(x.beta[0][j], x.beta[1][j], x.beta[2][j]);
                p.after_delta = false;
                p.prev_pdf = x.pdf[j];
                p.prev_p = vec3(x.sp[0][j], x.sp[1][j], x.sp[2][j]);
                p.ray = Ray();
                p.ray.o = vec3(x.o[0][j], x.o[1][j], x.o[2][j]);
                p.ray.d = vec3(x.dir[0][j], x.dir[1][j], x.dir[2][j]);
                ++p.depth;
                x.next.push_back(x.step_path[j]);
            }
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
    // The lanes gather with 32-bit indices (3 floats per vertex and per triangle).
    constexpr size_t kMaxGathered = size_t(INT32_MAX) / 3;
    if (scene.mesh.positions.size() > kMaxGathered || scene.mesh.triangles.size() > kMaxGathered) return false;
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
