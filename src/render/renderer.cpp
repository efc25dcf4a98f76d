#include "render/renderer.h"
#include <omp.h>
#include "integrator/path.h"

namespace candela {

namespace {

// One pass over all tiles with the path tracer instantiated for the scene's features.
template <bool DiffuseOnly>
PassStats run_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                   const std::atomic<bool>* cancel) {
    const int w = film.width(), h = film.height();
    const int tiles_x = (w + Renderer::kTileSize - 1) / Renderer::kTileSize;
    const int tiles_y = (h + Renderer::kTileSize - 1) / Renderer::kTileSize;
    const int n_tiles = tiles_x * tiles_y;
    PathIntegrator integrator(scene);
    // The scene's camera for this film: a preview renders the same view at a smaller size.
    Camera camera = scene.camera;
    camera.set_film_size(w, h);
    const bool alpha = film.has_alpha();
    std::atomic<uint64_t> total_rays{0}, total_samples{0};
    std::atomic<bool> stopped{false};

#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads)
    for (int tile = 0; tile < n_tiles; ++tile) {
        if (stopped.load(std::memory_order_relaxed)) continue;
        if (cancel && cancel->load(std::memory_order_relaxed)) {
            stopped = true;
            continue;
        }
        IndependentSampler sampler(scene.settings.seed);
        PathStats ps;
        uint64_t samples = 0;
        const int x0 = (tile % tiles_x) * Renderer::kTileSize, y0 = (tile / tiles_x) * Renderer::kTileSize;
        const int x1 = std::min(x0 + Renderer::kTileSize, w), y1 = std::min(y0 + Renderer::kTileSize, h);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                for (int s = 0; s < spp; ++s) {
                    // Sampler dimensions of a camera sample: the pixel jitter (2), the lens (2, a
                    // thin lens with an aperture only), then the path tracer's.
                    sampler.start_pixel_sample(camera.sampler_pixel(ivec2(x, y)), first_sample + uint32_t(s));
                    vec2 jitter = sampler.next_2d();  // box filter: uniform over the pixel
                    vec2 lens = camera.needs_lens_sample() ? sampler.next_2d() : vec2(0.5f);
                    Ray ray = camera.generate_ray(ivec2(x, y), jitter, lens);
                    const uint64_t hits = ps.camera_hits;
                    vec3 L = integrator.template Li<IndependentSampler, DiffuseOnly>(ray, sampler, ps);
                    film.add_sample(ivec2(x, y), L);
                    if (alpha) film.add_coverage(ivec2(x, y), ps.camera_hits != hits);
                    ++samples;
                }
            }
        total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
        total_samples.fetch_add(samples, std::memory_order_relaxed);
    }
    PassStats out;
    out.rays = total_rays.load();
    out.samples = total_samples.load();
    out.completed = !stopped.load();
    return out;
}

}  // namespace

PassStats Renderer::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                const std::atomic<bool>* cancel) {
    const int n_threads = threads > 0 ? threads : omp_get_max_threads();
    // Chosen per pass, so that a material edited in the viewer (which restarts the accumulation)
    // switches the instantiation too. Both give the same image: the specialisation only drops code.
    if (scene_is_diffuse_only(scene)) return run_pass<true>(scene, film, first_sample, spp, n_threads, cancel);
    return run_pass<false>(scene, film, first_sample, spp, n_threads, cancel);
}

}  // namespace candela
