// BDPT: the densities, the connections, and the passes (bdpt.h).
#include "integrator/bdpt/bdpt.h"
#include <omp.h>
#include "integrator/splat_pass.h"

namespace candela {

using Kind = BdptVertex::Kind;

Bdpt::Bdpt(const Scene& scene, const Camera& camera, int width, int height)
    : scene_(scene), camera_(camera), width_(width), height_(height), masks_(scene_has_masks(scene)) {
    const float r = scene.lights.scene_sphere().radius;
    disk_pdf_ = 1.f / (kPi * r * r);
}

Bdpt::Workspace::Workspace()
    : cam(kBdptMaxVertices), light(kBdptMaxVertices), cam_sh(new ShadingT<false>[kBdptMaxVertices]),
      light_sh(new ShadingT<false>[kBdptMaxVertices]) {}

float Bdpt::convert(float pdf_sa, vec3 from, const BdptVertex& to) {
    if (to.infinite) return pdf_sa;  // a direction keeps solid angle
    const vec3 d = to.p - from;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.f)) return 0.f;
    float pdf = pdf_sa / dist2;
    if (glm::dot(to.n, to.n) > 0.f) pdf *= std::abs(glm::dot(to.n, d)) / std::sqrt(dist2);
    return pdf;
}

namespace {

// The unit direction from `from` towards `to` (a direction vertex: towards the light, or along
// the escaped ray).
vec3 direction(const BdptVertex& from, const BdptVertex& to) {
    if (to.infinite) return to.kind == Kind::Escaped ? to.w : -to.w;
    if (from.infinite) return from.kind == Kind::Escaped ? -from.w : from.w;
    return glm::normalize(to.p - from.p);
}

}  // namespace

float Bdpt::infinite_density(vec3 w_escape) const {
    float pdf = 0.f;
    scene_.lights.for_each_infinite(w_escape, [&](vec3, float p) { pdf += p; });
    return pdf;
}

float Bdpt::pdf_light(const BdptVertex& light, const BdptVertex& next) const {
    const LightSet& ls = scene_.lights;
    if (light.infinite) {  // directional, constant, envmap: rays start on the bounding disk
        const vec3 w = light.kind == Kind::Escaped ? -light.w : light.w;  // the direction light travels
        return disk_pdf_ * (glm::dot(next.n, next.n) > 0.f ? std::abs(glm::dot(next.n, w)) : 1.f);
    }
    const vec3 w = direction(light, next);
    // An area light emits cosine-distributed about its shading normal (LightSet::sample_le).
    if (light.kind == Kind::Surface || light.light < 0) return convert(std::max(glm::dot(w, light.si.ns), 0.f) * kInvPi, light.p, next);
    float pdf_pos = 0.f, pdf_dir = 0.f;
    ls.pdf_le(size_t(light.light), w, pdf_pos, pdf_dir);
    return convert(pdf_dir, light.p, next);
}

float Bdpt::pdf_light_origin(const BdptVertex& light, const BdptVertex& next) const {
    if (light.kind == Kind::Escaped) return infinite_density(light.w);
    if (light.delta_light) return scene_.lights.choice_pmf();
    if (light.infinite) return infinite_density(-light.w);
    // An area light's point: next-event estimation's solid-angle density from `next`, in area measure.
    const vec3 d = light.p - next.p;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.f)) return 0.f;
    return scene_.lights.pdf_li(next.p, light.si) * std::abs(glm::dot(light.si.ng, d)) / (dist2 * std::sqrt(dist2));
}

float Bdpt::pdf(const BdptVertex* prev, const BdptVertex& cur, const ShadingT<false>* cur_sh, const BdptVertex& next,
                TransportMode mode) const {
    if (cur.kind == Kind::Light) return pdf_light(cur, next);
    if (cur.kind == Kind::Camera) {
        Ray r;
        r.o = cur.p;
        r.d = direction(cur, next);
        float pdf_pos, pdf_dir;
        camera_.pdf_We(r, pdf_pos, pdf_dir);
        return convert(pdf_dir, cur.p, next);
    }
    if (!prev || !cur_sh) return 0.f;
    const vec3 wo = cur_sh->frame.to_local(direction(cur, *prev)), wi = cur_sh->frame.to_local(direction(cur, next));
    return convert(cur_sh->pdf_from(wo, wi, mode), cur.p, next);
}

vec3 Bdpt::connect(const Workspace& ws, int s, int t, float u_l, vec2 u_p, vec2 u_lens, PathStats& stats, float& weight,
                   vec2& raster, bool& splat) const {
    const Scene& sc = scene_;
    const BdptVertex* y = ws.light.data();
    const BdptVertex* z = ws.cam.data();
    splat = false;
    weight = 0.f;
    BdptVertex sampled;  // s = 1: the light sample; t = 1: the camera point
    vec3 L(0.f);
    float T = 1.f;
    if (t >= 2 && z[t - 1].kind == Kind::Escaped && s > 0) return vec3(0.f);
    if (s == 0) {
        const BdptVertex& e = z[t - 1];
        if (e.kind == Kind::Escaped) {
            vec3 Le(0.f);
            sc.lights.for_each_infinite(e.w, [&](vec3 le, float) { Le += le; });
            L = e.beta * Le;
        } else if (e.emitter) {
            L = e.beta * sc.lights.emitted(e.si, direction(e, z[t - 2]));
        }
    } else if (t == 1) {
        const BdptVertex& q = y[s - 1];
        if (camera_.type == CameraType::Orthographic || q.kind != Kind::Surface || !q.smooth) return vec3(0.f);
        // Hidden emitters are not seen by the camera, as camera paths pass through them.
        if (q.emitter && sc.settings.integrator.hide_emitters) return vec3(0.f);
        CameraWiSample cs;
        if (!camera_.sample_wi(q.p, u_lens, cs)) return vec3(0.f);
        const ShadingT<false>& sh = ws.light_sh[size_t(s - 1)];
        const float C = bdpt_detail::shading_correction(sh.frame.to_world(sh.wo), cs.wi, sh.frame.n, q.si.ng);
        if (!(C > 0.f)) return vec3(0.f);
        const vec3 f = sh.eval(sh.frame.to_local(cs.wi), TransportMode::Importance) * C;
        if (is_black(f)) return vec3(0.f);
        T = camera_visibility(q.si, cs.p, stats);
        if (!(T > 0.f)) return vec3(0.f);
        L = q.beta * f * (cs.Wi * T / cs.pdf);
        sampled.kind = Kind::Camera;
        sampled.p = cs.p;
        raster = cs.raster;
        splat = true;
    } else if (s == 1) {
        const BdptVertex& p = z[t - 1];
        if (p.kind != Kind::Surface || !p.smooth) return vec3(0.f);
        LightSample ls;
        if (!sc.lights.sample_li(p.p, u_l, u_p, ls) || !(ls.pdf > 0.f)) return vec3(0.f);
        const ShadingT<false>& sh = ws.cam_sh[size_t(t - 1)];
        const vec3 f = sh.eval(sh.frame.to_local(ls.wi));
        if (is_black(f)) return vec3(0.f);
        ++stats.rays;
        T = shadow_transmittance(sc, shadow_ray(p.si, ls), masks_, stats.rays);
        if (!(T > 0.f)) return vec3(0.f);
        L = p.beta * f * ls.Le * (T / ls.pdf);
        sampled.kind = Kind::Light;
        sampled.light = ls.light;
        sampled.p = ls.p;
        sampled.n = ls.n;
        sampled.w = -ls.wi;
        sampled.infinite = ls.infinite;
        sampled.delta_light = ls.delta;
        if (ls.light < 0) {  // an area light: pdf_light and pdf_li need the point's interaction
            sampled.si.p = ls.p;
            sampled.si.p_error = ls.p_error;
            // Both normals, as the other strategies' emitter vertices carry them (from sample_le or
            // a hit): the direction density is about the shading normal, the measures' cosines
            // are geometric (light/emitter.h).
            sampled.si.ng = ls.n;
            sampled.si.ns = ls.ns;
        }
        // The origin density (pdf_light_origin), here straight from the sample.
        if (ls.delta) sampled.pdf_fwd = sc.lights.choice_pmf();
        else if (ls.infinite) sampled.pdf_fwd = infinite_density(ls.wi);
        else sampled.pdf_fwd = ls.pdf * std::abs(glm::dot(ls.n, ls.wi)) / (ls.dist * ls.dist);
    } else {
        const BdptVertex& q = y[s - 1];
        const BdptVertex& p = z[t - 1];
        if (q.kind != Kind::Surface || !q.smooth || p.kind != Kind::Surface || !p.smooth) return vec3(0.f);
        const vec3 d = p.p - q.p;
        const float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f)) return vec3(0.f);
        const vec3 w = d / std::sqrt(dist2);  // q -> p
        const ShadingT<false>& qs = ws.light_sh[size_t(s - 1)];
        const ShadingT<false>& ps = ws.cam_sh[size_t(t - 1)];
        const float C = bdpt_detail::shading_correction(qs.frame.to_world(qs.wo), w, qs.frame.n, q.si.ng);
        if (!(C > 0.f)) return vec3(0.f);
        const vec3 f = qs.eval(qs.frame.to_local(w), TransportMode::Importance) * C * ps.eval(ps.frame.to_local(-w));
        if (is_black(f)) return vec3(0.f);
        ++stats.rays;
        T = shadow_transmittance(sc, spawn_ray_to(p.si, q.p, q.si.p_error, q.si.ng), masks_, stats.rays);
        if (!(T > 0.f)) return vec3(0.f);
        L = q.beta * f * p.beta * (T / dist2);
    }
    if (is_black(L) || !all_finite(L)) return vec3(0.f);

    // The MIS weight: the subpaths' densities with the connection's in place (mis.h).
    MisVertex ml[kBdptMaxVertices], mc[kBdptMaxVertices];
    auto mis = [](const BdptVertex& v) { return MisVertex{v.pdf_fwd, v.pdf_rev, v.delta, v.infinite}; };
    for (int i = 0; i < s; ++i) ml[i] = mis(y[i]);
    for (int i = 0; i < t; ++i) mc[i] = mis(z[i]);
    const BdptVertex* qv = s == 0 ? nullptr : s == 1 ? &sampled : &y[s - 1];
    const BdptVertex* pv = t == 1 ? &sampled : &z[t - 1];
    if (s == 1) ml[0] = mis(sampled);
    if (t == 1) mc[0] = mis(sampled);
    const ShadingT<false>* q_sh = s >= 2 ? &ws.light_sh[size_t(s - 1)] : nullptr;
    const ShadingT<false>* p_sh = t >= 2 ? &ws.cam_sh[size_t(t - 1)] : nullptr;
    const BdptVertex* qm = s >= 2 ? &y[s - 2] : nullptr;
    const BdptVertex* pm = t >= 2 ? &z[t - 2] : nullptr;
    using TM = TransportMode;
    if (s == 0) {
        mc[t - 1].pdf_rev = pdf_light_origin(*pv, *pm);
        mc[t - 2].pdf_rev = pdf_light(*pv, *pm) * pv->seg_T;
    } else {
        mc[t - 1].pdf_rev = pdf(qm, *qv, q_sh, *pv, TM::Importance) * T;
        if (pm) mc[t - 2].pdf_rev = pdf(qv, *pv, p_sh, *pm, TM::Importance) * pv->seg_T;
        ml[s - 1].pdf_rev = pdf(pm, *pv, p_sh, *qv, TM::Radiance) * T;
        if (qm) ml[s - 2].pdf_rev = pdf(pv, *qv, q_sh, *qm, TM::Radiance) * qv->seg_T;
    }
    const bool delta_light = s == 0 ? false : s == 1 ? sampled.delta_light : y[0].delta_light;
    weight = mis_weight(ml, s, mc, t, delta_light);
    return L;
}

float Bdpt::camera_visibility(const SurfaceInteraction& from, vec3 cam_p, PathStats& stats) const {
    const Scene& sc = scene_;
    Ray r = spawn_ray_to(from, cam_p, vec3(0.f), vec3(0.f));
    ++stats.rays;
    if (!sc.settings.integrator.hide_emitters) return shadow_transmittance(sc, r, masks_, stats.rays);
    // The camera's first segment passes through area emitters (skip_area_emitters): so does the
    // connection to it. (Masks on that segment count as opaque here.)
    for (int i = 0; i < 1024; ++i) {
        Hit h;
        if (!sc.accel->intersect(r, h)) return 1.f;
        if (sc.lights.emitter_of(h) < 0) return 0.f;
        const SurfaceInteraction s = sc.interaction(h);
        r.o = offset_ray_origin(s.p, s.p_error, s.ng, r.d);
        r.d = cam_p - r.o;
        r.tmax = 1.f - kShadowEpsilon;
        ++stats.rays;
    }
    return 0.f;
}

namespace {

// The splat pass (integrator/splat_pass.h): each tile's camera samples go to their own pixels of
// the zeroed layer (the box filter: a pixel is written by its tile only; other filters: the tile's
// FilmTile, merged in tile order), its splats to its SplatTile.
template <class S>
PassStats bdpt_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                    const std::atomic<bool>* cancel, const S& prototype) {
    const int w = film.width(), h = film.height();
    const int n_tiles = ((w + kTileSize - 1) / kTileSize) * ((h + kTileSize - 1) / kTileSize);
    Camera camera = scene.camera;
    camera.set_film_size(w, h);
    const Bdpt bdpt(scene, camera, w, h);
    const bool weighted = film.weighted(), alpha = film.has_alpha();
    const PixelFilter filter(scene.settings.filter);
    std::vector<FilmTile> ftiles(weighted ? static_cast<size_t>(n_tiles) : 0);
    std::vector<std::unique_ptr<Bdpt::Workspace>> spaces(static_cast<size_t>(std::max(1, n_threads)));
    auto work = [&](uint32_t index, int tile, const detail::TileRange& tr, Film& layer, SplatTile& st, PathStats& ps) {
        std::unique_ptr<Bdpt::Workspace>& wsp = spaces[size_t(omp_get_thread_num())];
        if (!wsp) wsp = std::make_unique<Bdpt::Workspace>();
        S sampler = prototype;
        if (weighted) ftiles[size_t(tile)].reset(film, tr.x0, tr.y0, tr.x1, tr.y1, filter.reach());
        for (int y = tr.y0; y < tr.y1; ++y)
            for (int x = tr.x0; x < tr.x1; ++x) {
                sampler.start_pixel_sample(camera.sampler_pixel(ivec2(x, y)), index);
                bool covered = false;
                vec2 jitter(0.5f);
                vec3 L = bdpt.sample(sampler, ivec2(x, y), *wsp, st, ps, covered, jitter, nullptr);
                ++st.paths;
                if (!weighted) {
                    layer.add_sample(ivec2(x, y), L);
                    if (alpha) layer.add_coverage(ivec2(x, y), covered);
                    continue;
                }
                if (!all_finite(L)) {
                    layer.count_nonfinite();
                    L = vec3(0.f);
                }
                layer.count_sample(ivec2(x, y));
                detail::splat(ftiles[size_t(tile)], filter, w, h, vec2(float(x), float(y)) + jitter, L, nullptr, covered);
            }
    };
    auto merge_tile = [&](int tile, const detail::TileRange&, Film& layer) {
        if (weighted) layer.merge(ftiles[size_t(tile)]);
    };
    return splat_pass(film, scene.settings.filter, first_sample, spp, n_threads, cancel, work, merge_tile);
}

}  // namespace

PassStats BdptPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                const std::atomic<bool>* cancel) const {
    return visit_sampler(sampler_setup(scene, film), [&](const auto& prototype) {
        return bdpt_pass(scene, film, first_sample, spp, threads, cancel, prototype);
    });
}

std::vector<StrategyImage> render_bdpt_strategies(const Scene& scene, int w, int h, int spp, int threads, int max_length) {
    Camera camera = scene.camera;
    camera.set_film_size(w, h);
    const Bdpt bdpt(scene, camera, w, h);
    Film probe(w, h);
    const SamplerSetup setup = sampler_setup(scene, probe);
    std::vector<StrategyImage> out;
    auto index = [&](int s, int t) -> int {
        const int len = s + t - 2;  // strategies of length len: s = 0..len + 1
        if (len < 0 || len > max_length || t < 1) return -1;
        return (len * (len + 1)) / 2 + len + s;  // sum_{l < len} (l + 2) + s
    };
    for (int len = 0; len <= max_length; ++len)
        for (int s = 0; s <= len + 1; ++s)
            out.push_back({s, len + 2 - s, std::vector<float>(size_t(w) * size_t(h) * 3, 0.f),
                           std::vector<float>(size_t(w) * size_t(h) * 3, 0.f)});
    std::vector<dvec3> sum_w(out.size() * size_t(w) * size_t(h)), sum_u(sum_w.size());
    // Each strategy's image unfiltered (a box), camera samples and splats alike.
    const SplatFilter box(box_filter(), w, h);
    const int rows_per_chunk = 1;
    const int n_chunks = (h + rows_per_chunk - 1) / rows_per_chunk;
    std::vector<std::vector<std::pair<uint32_t, StrategyRecord>>> recs(static_cast<size_t>(n_chunks));
    visit_sampler(setup, [&](const auto& prototype) {
        using S = std::decay_t<decltype(prototype)>;
        for (int si = 0; si < spp; ++si) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
            for (int c = 0; c < n_chunks; ++c) {
                Bdpt::Workspace ws;
                S sampler = prototype;
                PathStats ps;
                SplatTile st;
                std::vector<StrategyRecord> rec;
                auto& r = recs[size_t(c)];
                r.clear();
                for (int y = c * rows_per_chunk; y < std::min(h, (c + 1) * rows_per_chunk); ++y)
                    for (int x = 0; x < w; ++x) {
                        sampler.start_pixel_sample(camera.sampler_pixel(ivec2(x, y)), uint32_t(si));
                        bool covered;
                        vec2 jitter;
                        rec.clear();
                        bdpt.sample(sampler, ivec2(x, y), ws, st, ps, covered, jitter, &rec);
                        for (const StrategyRecord& e : rec) r.push_back({uint32_t(y) * uint32_t(w) + uint32_t(x), e});
                    }
            }
            for (const auto& r : recs)
                for (const auto& [pix, e] : r) {
                    const int k = index(e.s, e.t);
                    if (k < 0) continue;
                    const size_t base = size_t(k) * size_t(w) * size_t(h);
                    if (e.splat) {  // in the pixel it lands in, as the camera samples here
                        if (!(e.raster.x >= 0.f && e.raster.y >= 0.f && e.raster.x < float(w) && e.raster.y < float(h)))
                            continue;
                        box.add(&sum_w[base], e.raster, e.weighted, 0, h);
                        box.add(&sum_u[base], e.raster, e.unweighted, 0, h);
                        continue;
                    }
                    sum_w[base + pix] += dvec3(e.weighted);
                    sum_u[base + pix] += dvec3(e.unweighted);
                }
        }
    });
    // Each strategy's image is its mean over the samples per pixel (a splat is one light path of
    // the spp x N traced: N / (spp N) = 1 / spp, as the film's splats).
    for (size_t k = 0; k < out.size(); ++k)
        for (size_t p = 0; p < size_t(w) * size_t(h); ++p)
            for (int c = 0; c < 3; ++c) {
                out[k].weighted[3 * p + size_t(c)] = float(sum_w[k * size_t(w) * size_t(h) + p][c] / double(spp));
                out[k].unweighted[3 * p + size_t(c)] = float(sum_u[k * size_t(w) * size_t(h) + p][c] / double(spp));
            }
    return out;
}

}  // namespace candela
