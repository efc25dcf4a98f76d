#pragma once
// BDPT's per-sample templates (included by bdpt.h): the subpaths' random walk and the loop over
// the strategies.

namespace candela {

namespace bdpt_detail {

// The light tracer's C (ptracer.h): the adjoint BSDF's shading-normal correction.
inline float shading_correction(vec3 wo, vec3 wi, vec3 ns, vec3 ng) {
    const float a = glm::dot(wo, ns), b = glm::dot(wo, ng), c = glm::dot(wi, ns), d = glm::dot(wi, ng);
    if (!(a * b > 0.f) || !(c * d > 0.f)) return 0.f;
    return std::abs(a * d) / std::abs(b * c);
}

inline TransportMode flip(TransportMode m) {
    return m == TransportMode::Radiance ? TransportMode::Importance : TransportMode::Radiance;
}

}  // namespace bdpt_detail

template <class S>
int Bdpt::walk(S& sampler, Ray ray, vec3 beta, float pdf_sa, BdptVertex* path, ShadingT<false>* sh, int n, int max,
               TransportMode mode, PathStats& stats, bool camera_ray, bool infinite_start) const {
    const Scene& sc = scene_;
    const RenderSettings& st = sc.settings;
    float eta_scale = 1.f, seg_T = 1.f;
    int passes = 0;
    bool first = true;
    while (n < max) {
        BdptVertex& prev = path[n - 1];
        Hit hit;
        ++stats.rays;
        if (!sc.accel->intersect(ray, hit)) {
            // Only camera paths end on a direction: light paths have no use for one.
            if (mode == TransportMode::Radiance && sc.lights.has_infinite() &&
                !(first && camera_ray && st.integrator.hide_emitters)) {
                BdptVertex& v = path[n];
                v = BdptVertex();
                v.kind = BdptVertex::Kind::Escaped;
                v.infinite = true;
                v.w = glm::normalize(ray.d);
                v.beta = beta;
                v.seg_T = seg_T;
                v.pdf_fwd = pdf_sa * seg_T;
                ++n;
            }
            break;
        }
        if (first && camera_ray && st.integrator.hide_emitters && !skip_area_emitters(sc, ray, hit, stats)) break;
        SurfaceInteraction si = sc.interaction(hit);
        const vec3 wo_world = -glm::normalize(ray.d);
        if (masks_) {  // pass straight through with probability 1 - opacity (not a vertex)
            const Material& m = sc.materials[sc.shapes[si.shape].material];
            const float a = m.opacity_at(m.masked ? sc.texture_query(si, hit) : TextureQuery{});
            if (a < 1.f && sampler.next_1d() >= a) {
                if (++passes > 1024) break;
                seg_T *= 1.f - a;
                ray = spawn_ray(si, ray.d);
                continue;
            }
        }
        first = false;
        ShadingT<false>& vs = sh[n];
        shade<false>(sc, hit, si, wo_world, vs);
        BdptVertex& v = path[n];
        v = BdptVertex();
        v.kind = BdptVertex::Kind::Surface;
        v.si = si;
        v.p = si.p;
        v.n = si.ng;
        v.beta = beta;
        v.seg_T = seg_T;
        v.emitter = sc.lights.emitter_of(hit) >= 0;
        v.smooth = vs.has_smooth_component();
        v.pdf_fwd = (infinite_start && n == 1 ? disk_pdf_ * std::abs(glm::dot(v.n, wo_world)) : convert(pdf_sa, prev.p, v)) * seg_T;
        ++n;
        if (n >= max) break;

        const float u1 = sampler.next_1d();
        const vec2 u2 = sampler.next_2d();
        std::optional<BsdfSample> bs = vs.sample(u1, u2, mode);
        if (!bs || !(bs->pdf > 0.f)) break;
        const vec3 wi_world = vs.frame.to_world(bs->wi);
        float pdf_fwd = bs->pdf, pdf_rev = vs.pdf_from(bs->wi, vs.wo, bdpt_detail::flip(mode));
        if (bs->delta) {
            v.delta = true;
            pdf_fwd = pdf_rev = 0.f;
        }
        const float C = mode == TransportMode::Importance
                            ? bdpt_detail::shading_correction(wo_world, wi_world, vs.frame.n, si.ng)
                            : 1.f;
        beta *= bs->weight() * C;
        prev.pdf_rev = convert(pdf_rev, v.p, prev) * seg_T;
        if (is_black(beta)) break;
        eta_scale *= sqr(bs->eta);
        ray = spawn_ray(si, wi_world);
        pdf_sa = pdf_fwd;
        seg_T = 1.f;
        if (n - 1 >= st.rr_depth) {  // v = path[n - 1] is the (n - 1)-th scattering event
            const float q = std::min(max_component(beta) * eta_scale, 0.95f);
            if (sampler.next_1d() >= q) break;
            beta /= q;
        }
    }
    return n;
}

template <class S>
int Bdpt::camera_subpath(S& sampler, ivec2 px, vec2 jitter, Workspace& ws, int max_cam, PathStats& stats) const {
    const vec2 lens = camera_.needs_lens_sample() ? sampler.next_2d() : vec2(0.5f);
    const Ray ray = camera_.generate_ray(px, jitter, lens);
    BdptVertex& z0 = ws.cam[0];
    z0 = BdptVertex();
    z0.kind = BdptVertex::Kind::Camera;
    z0.beta = vec3(1.f);
    const bool ortho = camera_.type == CameraType::Orthographic;
    z0.delta = ortho;  // a delta direction: nothing connects to it (t = 1 is not a strategy)
    float pdf_dir = 1.f;
    if (!ortho) {
        // The ray starts on the near clip plane; the vertex is the pinhole or the lens point.
        z0.p = ray.o - ray.d * (camera_.near_clip / glm::dot(ray.d, camera_.forward()));
        Ray r;
        r.o = z0.p;
        r.d = ray.d;
        float pdf_pos;
        camera_.pdf_We(r, pdf_pos, pdf_dir);
    } else {
        z0.p = ray.o;
    }
    int nc = 1;
    if (pdf_dir > 0.f && max_cam > 1)
        nc = walk(sampler, ray, vec3(1.f), pdf_dir, ws.cam.data(), ws.cam_sh.get(), 1, max_cam, TransportMode::Radiance,
                  stats, true, false);
    return nc;
}

template <class S>
int Bdpt::light_subpath(S& sampler, Workspace& ws, int max_light, PathStats& stats) const {
    const Scene& sc = scene_;
    int nl = 0;
    if (!sc.lights.empty()) {
        const float u_sel = sampler.next_1d();
        const vec2 u_pos = sampler.next_2d(), u_dir = sampler.next_2d();
        SurfaceInteraction lsi;
        int32_t li = -1;
        std::optional<EmissionSample> es = sc.lights.sample_le(u_sel, u_pos, u_dir, &lsi, &li);
        if (es && es->pdf_pos > 0.f && es->pdf_dir > 0.f && !is_black(es->Le)) {
            BdptVertex& y0 = ws.light[0];
            y0 = BdptVertex();
            y0.kind = BdptVertex::Kind::Light;
            y0.light = li;
            y0.Le = es->Le;
            y0.p = es->ray.o;
            y0.w = glm::normalize(es->ray.d);
            y0.infinite = (es->flags & kLightInfinite) != 0;
            y0.delta_light = (es->flags & (kLightDeltaPosition | kLightDeltaDirection)) != 0;
            if (es->flags & kLightArea) {
                y0.si = lsi;
                y0.n = lsi.ng;
            }
            y0.beta = vec3(1.f / es->pdf_pos);
            y0.pdf_fwd = y0.delta_light ? sc.lights.choice_pmf() : y0.infinite ? infinite_density(-y0.w) : es->pdf_pos;
            const float cos0 = glm::dot(es->n, es->n) > 0.f ? std::abs(glm::dot(es->n, y0.w)) : 1.f;
            const vec3 beta = es->Le * (cos0 / (es->pdf_pos * es->pdf_dir));
            nl = 1;
            if (max_light > 1)
                nl = walk(sampler, es->ray, beta, es->pdf_dir, ws.light.data(), ws.light_sh.get(), 1, max_light,
                          TransportMode::Importance, stats, false, y0.infinite);
            // An area light's point: the density next-event estimation from y_1 gives it.
            if ((es->flags & kLightArea) && nl >= 2) y0.pdf_fwd = pdf_light_origin(y0, ws.light[1]);
        }
    }
    return nl;
}

template <class S>
vec3 Bdpt::sample(S& sampler, ivec2 px, Workspace& ws, SplatTile& out, PathStats& stats, bool& covered, vec2& jitter,
                  std::vector<StrategyRecord>* record) const {
    const Scene& sc = scene_;
    const RenderSettings& st = sc.settings;
    const int max_depth = st.max_depth;
    const int max_cam = max_depth < 0 ? kBdptMaxVertices : std::min(max_depth + 2, kBdptMaxVertices);
    const int max_light = max_depth < 0 ? kBdptMaxVertices : std::min(max_depth + 1, kBdptMaxVertices);

    // The camera subpath, then the light subpath.
    jitter = sampler.next_2d();
    const int nc = camera_subpath(sampler, px, jitter, ws, max_cam, stats);
    covered = nc > 1 && ws.cam[1].kind == BdptVertex::Kind::Surface;
    const int nl = light_subpath(sampler, ws, max_light, stats);

    // Every strategy, in a fixed order (the sampler's dimensions follow it). s = 1 takes a fresh light
    // sample, so it is tried whenever the scene has lights, even when the light subpath failed (its
    // emission sample was black, e.g. a dark texel of a textured spot or projector): skipping it
    // there lost those paths' next-event estimates while MIS still counted on them.
    const int s_max = std::max(nl, sc.lights.empty() ? 0 : 1);
    vec3 L(0.f);
    for (int t = 1; t <= nc; ++t)
        for (int s = 0; s <= s_max; ++s) {
            const int depth = s + t - 2;
            if ((s == 1 && t == 1) || depth < 0 || (max_depth >= 0 && depth > max_depth)) continue;
            if (depth == 0 && st.integrator.hide_emitters) continue;
            float u_l = 0.f;
            vec2 u_p(0.f), u_lens(0.f);
            if (s == 1) {
                u_l = sampler.next_1d();
                u_p = sampler.next_2d();
            }
            if (t == 1) u_lens = sampler.next_2d();
            float w = 0.f;
            vec2 raster(0.f);
            bool splat = false;
            const vec3 c = connect(ws, s, t, u_l, u_p, u_lens, stats, w, raster, splat);
            if (is_black(c)) continue;
            if (record) record->push_back({s, t, splat, raster, c * w, c});
            if (splat) out.add(width_, height_, raster, c * w);
            else L += c * w;
        }
    return L;
}

template <class S>
vec3 Bdpt::sample_strategy(S& sampler, int depth, Workspace& ws, PathStats& stats, vec2& raster) const {
    const RenderSettings& st = scene_.settings;
    if (depth == 0 && st.integrator.hide_emitters) return vec3(0.f);
    // The strategy: (0, 2) alone for depth 0 ((1, 1) is no strategy), else s uniform in 0..depth+1.
    sampler.start_stream(2);
    const int n_strategies = depth == 0 ? 1 : depth + 2;
    const float u_s = sampler.next_1d();
    const int s = depth == 0 ? 0 : std::min(int(u_s * float(n_strategies)), n_strategies - 1);
    const int t = depth + 2 - s;
    float u_l = 0.f;
    vec2 u_p(0.f), u_lens(0.f);
    if (s == 1) {
        u_l = sampler.next_1d();
        u_p = sampler.next_2d();
    }
    if (t == 1) u_lens = sampler.next_2d();
    // The camera subpath of exactly t vertices from the film position the camera stream picks.
    sampler.start_stream(0);
    raster = sampler.next_2d() * vec2(float(width_), float(height_));
    const ivec2 px(std::min(int(raster.x), width_ - 1), std::min(int(raster.y), height_ - 1));
    const vec2 jitter = glm::clamp(raster - vec2(px), vec2(0.f), vec2(0x1.fffffep-1f));
    if (camera_subpath(sampler, px, jitter, ws, t, stats) != t) return vec3(0.f);
    // The light subpath of exactly s vertices (s = 1 samples its light in connect).
    if (s >= 2) {
        sampler.start_stream(1);
        if (light_subpath(sampler, ws, s, stats) != s) return vec3(0.f);
    }
    float w = 0.f;
    bool splat = false;
    vec2 r(0.f);
    const vec3 c = connect(ws, s, t, u_l, u_p, u_lens, stats, w, r, splat);
    if (splat) raster = r;
    return c * (w * float(n_strategies));
}

}  // namespace candela
