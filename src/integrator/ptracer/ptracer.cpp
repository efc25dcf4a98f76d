// The light tracer's passes: light paths owned by pixel samples, their splats merged in a fixed
// order so that the image does not depend on the thread count or on how the samples are split
// into passes.
#include "integrator/ptracer/ptracer.h"
#include <omp.h>
#include "integrator/tiles.h"

namespace candela {

namespace {

// S: the scene's sampler (visit_sampler); each light path is the pixel sample that owns it, so the
// sampler's stratification applies to the light path's dimensions in their order (ptracer.h).
template <bool DiffuseOnly, class S>
PassStats light_tracer_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                            const std::atomic<bool>* cancel, const S& prototype) {
    const int w = film.width(), h = film.height();
    const int tiles_x = (w + kTileSize - 1) / kTileSize, tiles_y = (h + kTileSize - 1) / kTileSize;
    const int n_tiles = tiles_x * tiles_y;
    Camera camera = scene.camera;
    camera.set_film_size(w, h);
    const LightTracer tracer(scene, camera, w, h);
    std::vector<SplatTile> tiles(static_cast<size_t>(n_tiles));
    Film layer(w, h);
    layer.set_layout(film.weighted(), film.aov_channels());
    if (film.has_alpha()) layer.enable_alpha();
    std::atomic<uint64_t> total_rays{0};
    std::atomic<bool> stopped{false};
    uint64_t samples = 0, splats = 0;
    // One sample index at a time over all tiles, then the tiles' splats in tile order: the
    // additions into a pixel's splat sum happen in the order (sample index, tile, pixel, vertex)
    // whatever the threads and the passes (as the weighted film's merge, integrator/tiles.h).
    for (int s = 0; s < spp; ++s) {
        if (cancel && cancel->load(std::memory_order_relaxed)) stopped = true;
        if (stopped) break;
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads)
        for (int tile = 0; tile < n_tiles; ++tile) {
            if (stopped.load(std::memory_order_relaxed)) continue;
            if (cancel && cancel->load(std::memory_order_relaxed)) {
                stopped = true;
                continue;
            }
            S sampler = prototype;
            PathStats ps;
            SplatTile& st = tiles[size_t(tile)];
            st.clear();
            const detail::TileRange tr = detail::tile_range(tile, tiles_x, w, h);
            for (int y = tr.y0; y < tr.y1; ++y)
                for (int x = tr.x0; x < tr.x1; ++x) {
                    sampler.start_pixel_sample(camera.sampler_pixel(ivec2(x, y)), first_sample + uint32_t(s));
                    tracer.trace<S, DiffuseOnly>(sampler, st, ps);
                    ++st.paths;
                }
            total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
        }
        if (stopped) break;  // a partial sample index is dropped whole: every pixel keeps its count
        // The index's splats go into a zeroed layer that is then added to the film, so that the
        // film is the sum of per-index layers in index order: what MPI's rank 0 rebuilds from
        // layers rendered elsewhere (Film::add, docs/distributed.md), bit for bit.
        layer.clear();
        for (int tile = 0; tile < n_tiles; ++tile) {
            const SplatTile& st = tiles[size_t(tile)];
            layer.add_splats(st);
            splats += st.pixel.size();
            const detail::TileRange tr = detail::tile_range(tile, tiles_x, w, h);
            for (int y = tr.y0; y < tr.y1; ++y)
                for (int x = tr.x0; x < tr.x1; ++x) layer.count_sample(ivec2(x, y));
            samples += st.paths;
        }
        film.add(layer);
    }
    PassStats out;
    out.rays = total_rays.load();
    out.samples = samples;
    out.splats = splats;
    out.completed = !stopped.load();
    return out;
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
