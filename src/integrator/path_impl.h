#pragma once
// The path tracer's loop (included by path.h; kept apart for readability): trace, then one bounce
// (path/bounce.h, the definition the staged loop runs too), its shadow ray traced at once.

namespace candela {

template <class S, bool DiffuseOnly>
vec3 PathIntegrator::Li(Ray ray, S& sampler, PathStats& stats) const {
    const Scene& sc = scene_;
    const bool hide = sc.settings.integrator.hide_emitters;
    const bool masks = !DiffuseOnly && masks_;
    const BounceSettings bset(sc, masks);
    PathState p;
    p.ray = ray;
    ShadingT<DiffuseOnly> sh;
    for (int depth = 0;; ++depth) {
        Hit hit;
        ++stats.rays;
        if (!sc.accel->intersect(p.ray, hit)) {
            path_escaped(sc, p, depth);
            break;
        }
        // A camera ray that goes on through hidden area emitters and leaves sees no infinite light
        // either (it is still at depth 0).
        if (depth == 0 && hide && !skip_area_emitters(sc, p.ray, hit, stats)) break;
        if (depth == 0 && p.passes == 0) ++stats.camera_hits;
        SurfaceInteraction si = sc.interaction(hit);
        const BounceResult b =
            path_bounce<DiffuseOnly>(sc, bset, hit, si, depth, p, sampler, sh, stats, [&](const ShadowRequest& r) {
                const float T = shadow_transmittance(sc, r.ray, masks, stats.rays);
                if (T > 0.f) p.L += r.contribution(T);
            });
        if (b == BounceResult::End) break;
        if (b == BounceResult::PassThrough) --depth;  // not a vertex
    }
    return p.L;
}

}  // namespace candela
