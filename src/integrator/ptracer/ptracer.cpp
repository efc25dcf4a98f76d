// The light tracer's passes: light paths owned by pixel samples, their splats merged in a fixed
// order so that the image does not depend on the thread count or on how the samples are split
// into passes.
#include "integrator/ptracer/ptracer.h"
#include "integrator/splat_pass.h"

namespace candela {

namespace {

// S: the scene's sampler (visit_sampler); each light path is the pixel sample that owns it, so the
// sampler's stratification applies to the light path's dimensions in their order (ptracer.h).
template <bool DiffuseOnly, class S>
PassStats light_tracer_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                            const std::atomic<bool>* cancel, const S& prototype) {
    Camera camera = scene.camera;
    camera.set_film_size(film.width(), film.height());
    const LightTracer tracer(scene, camera, film.width(), film.height());
    // The splat pass (integrator/splat_pass.h): the light paths' splats only; each pixel counts
    // the samples that own its light paths.
    auto work = [&](uint32_t index, int, const detail::TileRange& tr, Film&, SplatTile& st, PathStats& ps) {
        S sampler = prototype;
        for (int y = tr.y0; y < tr.y1; ++y)
            for (int x = tr.x0; x < tr.x1; ++x) {
                sampler.start_pixel_sample(camera.sampler_pixel(ivec2(x, y)), index);
                tracer.trace<S, DiffuseOnly>(sampler, st, ps);
                ++st.paths;
            }
    };
    auto merge_tile = [&](int, const detail::TileRange& tr, Film& layer) {
        for (int y = tr.y0; y < tr.y1; ++y)
            for (int x = tr.x0; x < tr.x1; ++x) layer.count_sample(ivec2(x, y));
    };
    return splat_pass(film, scene.settings.filter, first_sample, spp, n_threads, cancel, work, merge_tile);
}

}  // namespace

PassStats LightTracerPass::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                       const std::atomic<bool>* cancel) const {
    const bool diffuse_only = scene_is_diffuse_only(scene);
    return visit_sampler(sampler_setup(scene, film), [&](const auto& prototype) {
        return diffuse_only ? light_tracer_pass<true>(scene, film, first_sample, spp, threads, cancel, prototype)
                            : light_tracer_pass<false>(scene, film, first_sample, spp, threads, cancel, prototype);
    });
}

}  // namespace candela
