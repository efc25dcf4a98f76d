#pragma once
// The path tracer in stages over a batch of paths: the start of the SIMD wavefront of issue 18
// (docs/wavefront.md has the plan and the measurements).
//
// A tile's paths (its pixels times the pass's samples) advance together, one bounce per round:
//   1. the closest hit of every live path (traversal stays per ray: it is at Embree's speed). A
//      hit on the scene's own triangles with a plain, untextured diffuse material takes a lane;
//   2. the lanes' hit reconstruction in SIMD lanes (hit_soa.h), then per lane emission and the
//      numbers of this bounce, drawn in Li's order. Every other hit (other materials, analytic
//      shapes, instances) makes its whole bounce here, per path: path_bounce (path/bounce.h), the
//      function Li runs, its shadow ray queued for stage 4;
//   3. in SIMD lanes: the shading (frame, wo, albedo), the light samples when the lights are
//      emissive triangles (the shadow ray and its contribution, computed as if unoccluded; per
//      path otherwise) and the diffuse step: BSDF sample, throughput, next ray, roulette
//      (diffuse_step.h);
//   4. the round's shadow rays; each adds its contribution when unoccluded (the shadow ray's
//      outcome changes no sampler draw and no throughput, so the path went on before).
// Each path makes the operations of PathIntegrator::Li (path_impl.h, path/bounce.h) in the same
// order, and the film gets the samples in the scalar loop's order: the image is the same bit for
// bit (tests/test_staged.cpp compares the films on every SIMD target).
//
// Scope (staged_pass_applies): scenes without masks or textured emitters, any sampler, films
// without adaptive sampling, AOVs or alpha (any pixel filter). The path pass uses the per-path
// loop otherwise, and with CANDELA_STAGED=0.
#include <climits>
#include <vector>
#include "integrator/path.h"
#include "integrator/path/diffuse_step.h"
#include "integrator/path/hit_soa.h"
#include "integrator/tiles.h"

namespace candela {

// A path of the staged loop: its state (path/bounce.h), its sampler, and this round's light
// sample: its shadow ray and what it adds when nothing is in the way.
template <class S>
struct StagedPath : PathState {
    S sampler;
    Ray shadow;
    vec3 shadow_L{0.f};
};

// What the stages look up per shape, and the light tables: built once per pass.
struct StagedTables {
    std::vector<int32_t> smooth;     // Shape::smooth (1/0)
    std::vector<uint8_t> lane;       // its material is plain, diffuse and untextured: shaded in lanes
    std::vector<float> albedo;       // the diffuse albedo of such a material (3 floats; else 0)
    std::vector<int32_t> two_sided;  // its material is two-sided (1/0)
    LightSet::AreaTriangleTables lights;
    bool lanes_nee = false;          // light samples in lanes: every light an emissive triangle

    explicit StagedTables(const Scene& sc) {
        for (const Shape& shape : sc.shapes) {
            const Material& m = sc.materials[shape.material];
            const DiffuseBsdf* diffuse = std::get_if<DiffuseBsdf>(&m.bsdf);
            const bool in_lanes = diffuse && m.plain() && !m.textured();
            const vec3 a = in_lanes ? diffuse->albedo : vec3(0.f);
            smooth.push_back(shape.smooth ? 1 : 0);
            lane.push_back(in_lanes ? 1 : 0);
            albedo.insert(albedo.end(), {a.x, a.y, a.z});
            two_sided.push_back(m.two_sided ? 1 : 0);
        }
        lanes_nee = sc.settings.sampling != SamplingMode::Bsdf && sc.lights.area_triangle_tables(lights);
    }
};

// What trace_staged reuses from round to round (one per thread). The arrays are the round's
// lanes (its hits shaded in lanes, in path order), padded for the SIMD batches.
struct StagedScratch {
    std::vector<uint32_t> next, shadowed;
    std::vector<uint32_t> lane_path;                        // per lane: its path
    std::vector<Hit> lane_hit;                              // per lane: its hit
    std::vector<std::pair<uint32_t, Hit>> other;            // the round's other hits and their paths
    std::vector<uint32_t> prim, shape;
    std::vector<float> b1, b2, p[3], err[3], ng[3], ns[3];  // what Scene::interaction gives
    std::vector<float> ray_d[3], beta[3], eta_scale;       // the path's ray and throughput
    std::vector<float> n[3], sng[3], wo_z, albedo[3];      // its shading (shade_diffuse)
    std::vector<float> u_l, u_lp[2], u[2], u_rr;           // its numbers for this bounce
    std::vector<float> pdf, o[3], dir[3];                  // its next ray
    std::vector<int32_t> alive, shadow;
    std::vector<float> so[3], sd[3], sL[3];                // its shadow ray

    void reserve(size_t cap) {
        if (prim.size() >= cap) return;
        for (auto* v : {&lane_path, &prim, &shape}) v->resize(cap);
        lane_hit.resize(cap);
        for (auto* v : {&alive, &shadow}) v->resize(cap);
        for (auto* v : {&b1, &b2, &eta_scale, &wo_z, &u_l, &u_lp[0], &u_lp[1], &u[0], &u[1], &u_rr, &pdf}) v->resize(cap);
        for (int k = 0; k < 3; ++k)
            for (auto* v : {&p[k], &err[k], &ng[k], &ns[k], &ray_d[k], &beta[k], &n[k], &sng[k], &albedo[k], &o[k],
                            &dir[k], &so[k], &sd[k], &sL[k]})
                v->resize(cap);
    }
};

// A light sample's shadow ray kept for the end of the round, with its contribution when unoccluded
// (no masks in the staged loop's scope: T is 1 or 0).
template <class S>
inline void queue_shadow(StagedPath<S>& p, const ShadowRequest& r) {
    p.shadow = r.ray;
    p.shadow_L = r.contribution(1.f);
}

// Runs the paths whose indices are in `live` (all at depth 0; emptied on return) to their end.
// Scenes without masks (staged_pass_applies).
template <class S>
void trace_staged(const Scene& sc, const StagedTables& tab, std::vector<StagedPath<S>>& paths,
                  std::vector<uint32_t>& live, StagedScratch& x, PathStats& stats) {
    const RenderSettings& st = sc.settings;
    const SamplingMode mode = st.sampling;
    const bool have_lights = !sc.lights.empty();
    constexpr size_t kAlign = kDiffuseStepAlign > kHitBatchAlign ? kDiffuseStepAlign : kHitBatchAlign;
    static_assert(kAlign % kDiffuseStepAlign == 0 && kAlign % kHitBatchAlign == 0);
    x.reserve((paths.size() + kAlign - 1) / kAlign * kAlign);
    ShadingT<true> sh;   // a lane's shading, when its light sample is made per path
    ShadingT<false> shg; // another hit's
    const BounceSettings bset(sc, false);  // no masks in the scope
    // Every live path is at the same depth: they start together and each round is one bounce.
    for (int depth = 0; !live.empty(); ++depth) {
        x.next.clear();
        x.shadowed.clear();
        x.other.clear();
        // Stage 1: closest hits. A hit on the scene's own triangles with a plain, untextured
        // diffuse material takes a lane; any other is shaded per path.
        size_t nl = 0;
        for (const uint32_t i : live) {
            StagedPath<S>& p = paths[i];
            Hit hit;
            ++stats.rays;
            if (!sc.accel->intersect(p.ray, hit)) {
                path_escaped(sc, p, depth);
                continue;
            }
            if (depth == 0 && st.integrator.hide_emitters && !skip_area_emitters(sc, p.ray, hit, stats)) continue;
            if (depth == 0) ++stats.camera_hits;
            if (hit.kind != PrimKind::Triangle || hit.instance != ~0u || !tab.lane[sc.mesh.tri_shape[hit.prim]]) {
                x.other.emplace_back(i, hit);
                continue;
            }
            const size_t q = nl++;
            x.lane_path[q] = i;
            x.lane_hit[q] = hit;
            x.prim[q] = hit.prim;
            x.b1[q] = hit.b1;
            x.b2[q] = hit.b2;
            for (int k = 0; k < 3; ++k) {
                x.ray_d[k][q] = p.ray.d[k];
                x.beta[k][q] = p.beta[k];
            }
            x.eta_scale[q] = p.eta_scale;
        }
        // Padding lanes: finite values, results ignored.
        const size_t padded = (nl + kAlign - 1) / kAlign * kAlign;
        for (size_t q = nl; q < padded; ++q) {
            x.prim[q] = 0;  // a valid triangle
            x.b1[q] = x.b2[q] = 0.f;
            for (int k = 0; k < 3; ++k) {
                x.beta[k][q] = 0.f;
                x.ray_d[k][q] = k == 2 ? 1.f : 0.f;
            }
            x.eta_scale[q] = 1.f;
            x.u_l[q] = 0.5f;
            x.u_lp[0][q] = x.u_lp[1][q] = 0.25f;
            x.u[0][q] = x.u[1][q] = 0.5f;
            x.u_rr[q] = 0.f;
        }
        // Stage 2a: the lanes' hit reconstruction in SIMD lanes.
        if (nl > 0)
            reconstruct_triangle_hits(sc.mesh, tab.smooth.data(), nl, HitBatch{x.prim.data(), x.b1.data(), x.b2.data()},
                                      SurfaceBatch{{x.p[0].data(), x.p[1].data(), x.p[2].data()},
                                                   {x.err[0].data(), x.err[1].data(), x.err[2].data()},
                                                   {x.ng[0].data(), x.ng[1].data(), x.ng[2].data()},
                                                   {x.ns[0].data(), x.ns[1].data(), x.ns[2].data()},
                                                   x.shape.data()});
        // Stage 2b: per lane, emission and the numbers of this bounce, drawn in Li's order: the
        // light sample's (when Li draws them), the BSDF sample's (u1: the diffuse BSDF has one
        // lobe, then u2), the roulette's when it applies. Li skips the roulette draw only for a
        // path that has ended, whose sampler is never used again: drawing it first changes no
        // number any path uses.
        const bool bounce = !(st.max_depth >= 0 && depth >= st.max_depth);
        const bool rr = depth + 1 >= st.rr_depth;
        for (size_t q = 0; q < nl; ++q) {
            StagedPath<S>& p = paths[x.lane_path[q]];
            const Hit& hit = x.lane_hit[q];
            if (sc.lights.emitter_of(hit) >= 0) {
                // uv, dpdu and dpdv stay unset: no untextured emitter reads them.
                SurfaceInteraction si;
                si.p = vec3(x.p[0][q], x.p[1][q], x.p[2][q]);
                si.p_error = vec3(x.err[0][q], x.err[1][q], x.err[2][q]);
                si.ng = vec3(x.ng[0][q], x.ng[1][q], x.ng[2][q]);
                si.ns = vec3(x.ns[0][q], x.ns[1][q], x.ns[2][q]);
                si.prim = hit.prim;
                si.shape = x.shape[q];
                add_emission(sc, hit, si, -glm::normalize(p.ray.d), p.beta, p.after_delta, mode, p.prev_p, p.prev_pdf,
                             p.L);
            }
            if (!bounce) continue;
            if (mode != SamplingMode::Bsdf) {
                x.u_l[q] = p.sampler.next_1d();
                const vec2 up = p.sampler.next_2d();
                x.u_lp[0][q] = up.x;
                x.u_lp[1][q] = up.y;
            }
            p.sampler.next_1d();
            const vec2 u2 = p.sampler.next_2d();
            x.u[0][q] = u2.x;
            x.u[1][q] = u2.y;
            x.u_rr[q] = rr ? p.sampler.next_1d() : 0.f;
        }
        // Stage 2c: every other hit makes its whole bounce here (path_bounce, as Li), but for its
        // shadow ray, traced with the round's (no masks: its transmittance is 0 or 1).
        for (const auto& [i, hit] : x.other) {
            StagedPath<S>& p = paths[i];
            SurfaceInteraction si = sc.interaction(hit);
            const BounceResult b =
                path_bounce<false>(sc, bset, hit, si, depth, p, p.sampler, shg, stats, [&](const ShadowRequest& r) {
                    queue_shadow(p, r);
                    x.shadowed.push_back(i);
                });
            if (b == BounceResult::Continue) x.next.push_back(i);
        }
        if (!bounce) break;  // no path goes on
        if (nl > 0) {
            // Stage 3a: the lanes' shading.
            shade_diffuse(nl, tab.albedo.data(), tab.two_sided.data(),
                          ShadeDiffuseBatch{{x.ray_d[0].data(), x.ray_d[1].data(), x.ray_d[2].data()},
                                            {x.ns[0].data(), x.ns[1].data(), x.ns[2].data()},
                                            {x.ng[0].data(), x.ng[1].data(), x.ng[2].data()},
                                            x.shape.data(),
                                            {x.n[0].data(), x.n[1].data(), x.n[2].data()},
                                            {x.sng[0].data(), x.sng[1].data(), x.sng[2].data()},
                                            x.wo_z.data(),
                                            {x.albedo[0].data(), x.albedo[1].data(), x.albedo[2].data()}});
            // Stage 3b: the lanes' light samples, in SIMD lanes when the lights allow, else per
            // path; each computed as if unoccluded.
            if (tab.lanes_nee) {
                area_light_step(nl, tab.lights.cdf, tab.lights.tri, tab.lights.radiance, tab.lights.entries,
                                mode == SamplingMode::Mis,
                                AreaLightStepBatch{x.u_l.data(),
                                                   {x.u_lp[0].data(), x.u_lp[1].data()},
                                                   {x.p[0].data(), x.p[1].data(), x.p[2].data()},
                                                   {x.err[0].data(), x.err[1].data(), x.err[2].data()},
                                                   {x.sng[0].data(), x.sng[1].data(), x.sng[2].data()},
                                                   {x.n[0].data(), x.n[1].data(), x.n[2].data()},
                                                   x.wo_z.data(),
                                                   {x.albedo[0].data(), x.albedo[1].data(), x.albedo[2].data()},
                                                   {x.beta[0].data(), x.beta[1].data(), x.beta[2].data()},
                                                   x.shadow.data(),
                                                   {x.so[0].data(), x.so[1].data(), x.so[2].data()},
                                                   {x.sd[0].data(), x.sd[1].data(), x.sd[2].data()},
                                                   {x.sL[0].data(), x.sL[1].data(), x.sL[2].data()}});
                for (size_t q = 0; q < nl; ++q) {
                    if (!x.shadow[q]) continue;
                    StagedPath<S>& p = paths[x.lane_path[q]];
                    p.shadow = Ray();
                    p.shadow.o = vec3(x.so[0][q], x.so[1][q], x.so[2][q]);
                    p.shadow.d = vec3(x.sd[0][q], x.sd[1][q], x.sd[2][q]);
                    p.shadow.tmax = 1.f - kShadowEpsilon;
                    p.shadow_L = vec3(x.sL[0][q], x.sL[1][q], x.sL[2][q]);
                    ++stats.rays;
                    x.shadowed.push_back(x.lane_path[q]);
                }
            } else if (mode != SamplingMode::Bsdf && have_lights) {
                for (size_t q = 0; q < nl; ++q) {
                    StagedPath<S>& p = paths[x.lane_path[q]];
                    SurfaceInteraction si;  // what Scene::interaction gives, shaded as Li does
                    si.p = vec3(x.p[0][q], x.p[1][q], x.p[2][q]);
                    si.p_error = vec3(x.err[0][q], x.err[1][q], x.err[2][q]);
                    si.ng = vec3(x.ng[0][q], x.ng[1][q], x.ng[2][q]);
                    si.ns = vec3(x.ns[0][q], x.ns[1][q], x.ns[2][q]);
                    si.prim = x.lane_hit[q].prim;
                    si.shape = x.shape[q];
                    shade<true>(sc, x.lane_hit[q], si, -glm::normalize(p.ray.d), sh);
                    ShadowRequest r;
                    if (!light_sample(sc, si, sh, p.beta, x.u_l[q], vec2(x.u_lp[0][q], x.u_lp[1][q]), r)) continue;
                    ++stats.rays;
                    queue_shadow(p, r);
                    x.shadowed.push_back(x.lane_path[q]);
                }
            }
            // Stage 3c: the lanes' diffuse step (BSDF sample, throughput, next ray, roulette),
            // then the paths that go on.
            diffuse_step(nl, DiffuseStepBatch{{x.n[0].data(), x.n[1].data(), x.n[2].data()},
                                              x.wo_z.data(),
                                              {x.albedo[0].data(), x.albedo[1].data(), x.albedo[2].data()},
                                              {x.u[0].data(), x.u[1].data()},
                                              x.u_rr.data(),
                                              rr,
                                              x.eta_scale.data(),
                                              {x.p[0].data(), x.p[1].data(), x.p[2].data()},
                                              {x.err[0].data(), x.err[1].data(), x.err[2].data()},
                                              {x.sng[0].data(), x.sng[1].data(), x.sng[2].data()},
                                              {x.beta[0].data(), x.beta[1].data(), x.beta[2].data()},
                                              x.pdf.data(),
                                              {x.o[0].data(), x.o[1].data(), x.o[2].data()},
                                              {x.dir[0].data(), x.dir[1].data(), x.dir[2].data()},
                                              x.alive.data()});
            for (size_t q = 0; q < nl; ++q) {
                if (!x.alive[q]) continue;
                StagedPath<S>& p = paths[x.lane_path[q]];
                p.beta = vec3(x.beta[0][q], x.beta[1][q], x.beta[2][q]);
                p.after_delta = false;
                p.prev_pdf = x.pdf[q];
                p.prev_p = vec3(x.p[0][q], x.p[1][q], x.p[2][q]);
                p.ray = Ray();
                p.ray.o = vec3(x.o[0][q], x.o[1][q], x.o[2][q]);
                p.ray.d = vec3(x.dir[0][q], x.dir[1][q], x.dir[2][q]);
                x.next.push_back(x.lane_path[q]);
            }
        }
        // Stage 4: the round's shadow rays. Each path has at most one, and its contribution
        // comes before the emission the next round adds, as in Li.
        for (const uint32_t i : x.shadowed) {
            StagedPath<S>& p = paths[i];
            if (!sc.accel->occluded(p.shadow)) p.L += p.shadow_L;
        }
        live.swap(x.next);
    }
    live.clear();
}

// Whether render_tiles_staged can render this pass (see the scope above).
inline bool staged_pass_applies(const Scene& scene, const Film& film) {
    if (scene_has_masks(scene) || scene.lights.has_textured_emitter()) return false;
    // The lanes gather with 32-bit indices (3 floats per vertex and per triangle).
    constexpr size_t kMaxGathered = size_t(INT32_MAX) / 3;
    if (scene.mesh.positions.size() > kMaxGathered || scene.mesh.triangles.size() > kMaxGathered) return false;
    return !film.adaptive() && film.aov_channels() == 0 && !film.has_alpha();
}

// render_tiles (tiles.h) with the paths of a tile's samples traced together by trace_staged: the
// same samples, added to the film in the same order.
template <class S>
PassStats render_tiles_staged(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                              const std::atomic<bool>* cancel, const S& prototype) {
    detail::TilePass pass(scene, film, cancel);
    const Camera& camera = pass.camera;
    const StagedTables tables(scene);
    struct Scratch {
        std::vector<StagedPath<S>> paths;
        std::vector<uint32_t> live;
        std::vector<vec2> pos;  // weighted film: each path's film position
        StagedScratch staged;
    };
    std::vector<Scratch> scratch(size_t(std::max(1, n_threads)));
    // One path per pixel sample, in the scalar loop's order (pixel by pixel, samples s0..s1 - 1).
    auto start = [&](Scratch& t, const detail::TileRange& tr, int s0, int s1) {
        t.paths.clear();
        t.live.clear();
        t.pos.clear();
        for (int y = tr.y0; y < tr.y1; ++y)
            for (int x = tr.x0; x < tr.x1; ++x)
                for (int s = s0; s < s1; ++s) {
                    StagedPath<S> p{PathState{}, prototype, Ray(), vec3(0.f)};
                    vec2 jitter;
                    p.ray = camera_sample(p.sampler, camera, x, y, first_sample + uint32_t(s), jitter);
                    t.pos.push_back(vec2(float(x), float(y)) + jitter);
                    t.live.push_back(uint32_t(t.paths.size()));
                    t.paths.push_back(p);
                }
    };
    if (!film.weighted()) {
        // A batch holds at most kMaxBatch paths (a pass of many samples per pixel goes in chunks of
        // samples): each pixel still gets its samples in index order, which is all its sums see.
        constexpr int kMaxBatch = 4096;
        const int chunk = std::max(1, kMaxBatch / (kTileSize * kTileSize));
        pass.unweighted(n_threads, [&](const detail::TileRange& tr) {
            Scratch& t = scratch[size_t(omp_get_thread_num())];
            PathStats ps;
            uint64_t samples = 0;
            for (int s0 = 0; s0 < spp; s0 += chunk) {
                const int s1 = std::min(spp, s0 + chunk);
                start(t, tr, s0, s1);
                trace_staged(scene, tables, t.paths, t.live, t.staged, ps);
                size_t k = 0;
                for (int y = tr.y0; y < tr.y1; ++y)
                    for (int x = tr.x0; x < tr.x1; ++x)
                        for (int s = s0; s < s1; ++s) film.add_sample(ivec2(x, y), t.paths[k++].L);
                samples += t.paths.size();
            }
            pass.add(ps.rays, samples);
        });
    } else {
        const PixelFilter filter(scene.settings.filter);
        pass.weighted(film, filter.reach(), spp, n_threads, [&](const detail::TileRange& tr, int s, FilmTile& ft) {
            Scratch& t = scratch[size_t(omp_get_thread_num())];
            PathStats ps;
            start(t, tr, s, s + 1);
            trace_staged(scene, tables, t.paths, t.live, t.staged, ps);
            size_t k = 0;
            for (int y = tr.y0; y < tr.y1; ++y)
                for (int x = tr.x0; x < tr.x1; ++x, ++k) {
                    vec3 L = t.paths[k].L;
                    if (!all_finite(L)) {
                        film.count_nonfinite();
                        L = vec3(0.f);
                    }
                    film.count_sample(ivec2(x, y));
                    detail::splat(ft, filter, pass.w, pass.h, t.pos[k], L, nullptr);
                }
            pass.add(ps.rays, t.paths.size());
        });
    }
    return pass.stats();
}

// The staged pass with the scene's sampler. Every sampler's numbers after start_pixel_sample
// depend only on (pixel, index, seed) (sampling/samplers.h), so a copy of the prototype per path
// draws what the per-path loop's one sampler per tile draws. The independent sampler's loop is
// instantiated where this is called; the others each in integrator/samplers/path_<sampler>.cpp,
// as the per-path loop's are (integrator/sampled_pass.h).
template <class S>
PassStats render_staged_for(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                            const std::atomic<bool>* cancel) {
    return render_tiles_staged(scene, film, first_sample, spp, n_threads, cancel,
                               make_sampler<S>(sampler_setup(scene, film)));
}
#define CANDELA_STAGED_EXTERN(S)                                                                           \
    extern template PassStats render_staged_for<S>(const Scene&, Film&, uint32_t, int, int,             \
                                                   const std::atomic<bool>*);
CANDELA_FOR_EACH_SAMPLER_COMPILED_APART(CANDELA_STAGED_EXTERN)
#undef CANDELA_STAGED_EXTERN

inline PassStats render_staged_sampled_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp,
                                            int n_threads, const std::atomic<bool>* cancel) {
    return visit_sampler_type(scene.settings.sampler.type, [&](auto tag) {
        using S = typename decltype(tag)::type;
        return render_staged_for<S>(scene, film, first_sample, spp, n_threads, cancel);
    });
}

}  // namespace candela
