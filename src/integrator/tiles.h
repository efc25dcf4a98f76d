#pragma once
// The tile loop every integrator's pass runs: 16 x 16 tiles shared out to OpenMP threads
// dynamically, each pixel sample seeded from (pixel, sample index, seed), its camera ray jittered
// uniformly in the pixel, its radiance estimated by `li` and added to the film.
//
//   li(S& sampler, Ray camera_ray, PathStats& stats) -> vec3 radiance
//
// S is the pass's sampler type (sampling/samplers.h), chosen once per pass (render_pass_for):
// each tile copies the prototype and seeds it per pixel sample.
//
// Box filter (the film unweighted): each sample goes to its own pixel, which only its tile
// writes, in sample order: the plain loop of before, at its speed.
// Other filters (the film weighted): a sample splats into every pixel within the filter's radius,
// also across tiles. Each tile accumulates into its own FilmTile (the tile plus the filter's
// reach); after all tiles the FilmTiles are merged in tile order into a zeroed layer, which is then
// added to the film (Film::add). The pass runs one sample index at a time (all tiles for index s,
// merge, add, then s + 1), so the film is the sum in index order of per-index layers, whatever the
// thread count and the split of the samples into passes: the image is the same bit for bit.
// AOVs (the aov wrapper): computed for the camera ray before `li` runs, filtered the same way;
// the moment wrapper's channels from the sample's radiance after it.
#include <omp.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <type_traits>
#include <vector>
#include "film/filter.h"
#include "integrator/aov/aov.h"
#include "integrator/integrator.h"
#include "integrator/path.h"
#include "sampling/sampler.h"
#include "sampling/samplers.h"

namespace candela {

constexpr int kTileSize = 16;

namespace detail {

// Mitsuba's ImageBlock::put (scalar, non-coalesced): the pixels whose centres lie within the radius
// of `pos`, with separable discretised weights evaluated in float.
inline void splat(FilmTile& t, const PixelFilter& f, int film_w, int film_h, vec2 pos, vec3 L, const float* aov,
                  bool covered = false) {
    float wx[PixelFilter::kMaxReach], wy[PixelFilter::kMaxReach];
    int lo_x, lo_y;
    const int nx = f.weights_1d(pos.x, std::max(0, t.x0), std::min(film_w, t.x0 + t.width) - 1, lo_x, wx);
    const int ny = f.weights_1d(pos.y, std::max(0, t.y0), std::min(film_h, t.y0 + t.height) - 1, lo_y, wy);
    if (nx == 0 || ny == 0) return;
    // (L, 1) w added to (sum, weight) as two pairs of doubles (GCC/Clang vector extensions, any
    // target): two multiplies and two adds per pixel. Each sum gets the operations that separate
    // adds would give it, so the image is the same bit for bit.
    using D2 = double __attribute__((vector_size(16)));
    const D2 lxy = {double(L.x), double(L.y)}, lz1 = {double(L.z), 1.0};
    for (int y = 0; y < ny; ++y) {
        double* p = &t.sum_weight[size_t(lo_y + y - t.y0) * size_t(t.width) + size_t(lo_x - t.x0)].x;
        const float wy_y = wy[y];
        for (int x = 0; x < nx; ++x, p += 4) {
            const double w = double(wx[x] * wy_y);
            D2 a, b;
            std::memcpy(&a, p, sizeof a);
            std::memcpy(&b, p + 2, sizeof b);
            a += lxy * w;
            b += lz1 * w;
            std::memcpy(p, &a, sizeof a);
            std::memcpy(p + 2, &b, sizeof b);
        }
    }
    const int nc = t.aov_channels;
    const bool alpha = !t.alpha.empty() && covered;
    if (!alpha && nc == 0) return;
    // Alpha and AOVs (rare): the same weights, in a second sweep that the common case skips.
    for (int y = 0; y < ny; ++y) {
        size_t j = size_t(lo_y + y - t.y0) * size_t(t.width) + size_t(lo_x - t.x0);
        for (int x = 0; x < nx; ++x, ++j) {
            const double w = double(wx[x] * wy[y]);
            if (alpha) t.alpha[j] += w;
            for (int k = 0; k < nc; ++k) t.aov[j * size_t(nc) + size_t(k)] += double(aov[k]) * w;
        }
    }
}

struct TileRange {
    int x0, y0, x1, y1;
};
inline TileRange tile_range(int tile, int tiles_x, int w, int h) {
    const int x0 = (tile % tiles_x) * kTileSize, y0 = (tile / tiles_x) * kTileSize;
    return {x0, y0, std::min(x0 + kTileSize, w), std::min(y0 + kTileSize, h)};
}

// What every pass's tile loop shares: the film's tiles, the camera set to the film's size, the
// totals and the cancel flag; and the two loops, one per film layout. `body` runs inside an OpenMP
// parallel loop (omp_get_thread_num() picks per-thread scratch) and adds its rays and samples.
class TilePass {
public:
    TilePass(const Scene& scene, const Film& film, const std::atomic<bool>* cancel)
        : w(film.width()), h(film.height()), tiles_x((w + kTileSize - 1) / kTileSize),
          n_tiles(tiles_x * ((h + kTileSize - 1) / kTileSize)), camera(scene.camera), cancel_(cancel) {
        camera.set_film_size(w, h);  // a preview renders the same view at a smaller size
    }
    const int w, h, tiles_x, n_tiles;
    Camera camera;

    bool cancelled() {
        if (stopped_.load(std::memory_order_relaxed)) return true;
        if (cancel_ && cancel_->load(std::memory_order_relaxed)) {
            stopped_ = true;
            return true;
        }
        return false;
    }
    void add(uint64_t rays, uint64_t samples) {
        rays_.fetch_add(rays, std::memory_order_relaxed);
        samples_.fetch_add(samples, std::memory_order_relaxed);
    }
    PassStats stats() const {
        PassStats out;
        out.rays = rays_.load();
        out.samples = samples_.load();
        out.completed = !stopped_.load();
        return out;
    }

    // Unweighted film: body(TileRange) per tile. Each tile writes only its own pixels.
    template <class Body>
    void unweighted(int n_threads, const Body& body) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads)
        for (int tile = 0; tile < n_tiles; ++tile) {
            if (cancelled()) continue;
            body(tile_range(tile, tiles_x, w, h));
        }
    }
    // Weighted film: one sample index s at a time, body(TileRange, s, FilmTile&) per tile into its
    // own FilmTile, then the tiles merged in tile order into a zeroed layer, which is added to the
    // film: the film is the sum of per-index layers in index order, what an MPI rank 0 can
    // rebuild from layers rendered elsewhere (Film::add).
    template <class Body>
    void weighted(Film& film, float reach, int spp, int n_threads, const Body& body) {
        std::vector<FilmTile> tiles(static_cast<size_t>(n_tiles));
        std::vector<char> done(static_cast<size_t>(n_tiles));
        Film layer(w, h);
        layer.set_layout(true, film.aov_channels());
        if (film.has_alpha()) layer.enable_alpha();
        for (int s = 0; s < spp && !cancelled(); ++s) {
            std::fill(done.begin(), done.end(), 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads)
            for (int tile = 0; tile < n_tiles; ++tile) {
                if (cancelled()) continue;
                const TileRange tr = tile_range(tile, tiles_x, w, h);
                FilmTile& ft = tiles[size_t(tile)];
                ft.reset(film, tr.x0, tr.y0, tr.x1, tr.y1, reach);
                body(tr, s, ft);
                done[size_t(tile)] = 1;
            }
            layer.clear();
            for (int tile = 0; tile < n_tiles; ++tile)
                if (done[size_t(tile)]) layer.merge(tiles[size_t(tile)]);
            film.add(layer);
        }
    }

private:
    const std::atomic<bool>* cancel_;
    std::atomic<uint64_t> rays_{0}, samples_{0};
    std::atomic<bool> stopped_{false};
};

}  // namespace detail

// A camera sample of pixel (x, y) with sample index `index`: the sampler seeded for them, then its
// first dimensions, the pixel jitter (2, uniform over the pixel) and the lens (2, a thin lens with
// an aperture only); the integrator's follow. `jitter` gets the position in the pixel.
template <class S>
inline Ray camera_sample(S& sampler, const Camera& camera, int x, int y, uint32_t index, vec2& jitter) {
    sampler.start_pixel_sample(camera.sampler_pixel(ivec2(x, y)), index);
    jitter = sampler.next_2d();
    const vec2 lens = camera.needs_lens_sample() ? sampler.next_2d() : vec2(0.5f);
    return camera.generate_ray(ivec2(x, y), jitter, lens);
}

// The sampler of a pass over `film`: the scene's, its seed and sample_count, and the range of the
// sampler pixels (the film's pixels shifted by a crop window's offset).
inline SamplerSetup sampler_setup(const Scene& scene, const Film& film) {
    Camera camera = scene.camera;
    camera.set_film_size(film.width(), film.height());
    SamplerSetup s;
    s.desc = scene.settings.sampler;
    s.seed = scene.settings.seed;
    s.sample_count = uint32_t(std::max(1, scene.settings.spp));
    s.resolution = camera.sampler_pixel(ivec2(film.width() - 1, film.height() - 1)) + 1;
    return s;
}

template <class S, class Li>
PassStats render_tiles(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                       const std::atomic<bool>* cancel, const S& prototype, const Li& li) {
    detail::TilePass pass(scene, film, cancel);
    const Camera& camera = pass.camera;
    const std::vector<AovSpec>& aovs = scene.settings.integrator.aovs;
    const int n_aov = film.aov_channels();
    const int moment_at = moment_offset(aovs);
    const vec3 eye = camera.origin();
    const bool alpha = film.has_alpha();
    if (!film.weighted()) {
        // Adaptive sampling (film/adaptive.h): pixels the stopping rule marked inactive between
        // passes are skipped; a sample's index parity picks its half of the film.
        const bool adaptive = film.adaptive();
        pass.unweighted(n_threads, [&](const detail::TileRange& tr) {
            S sampler = prototype;
            PathStats ps;
            uint64_t samples = 0;
            float aov[64];
            for (int y = tr.y0; y < tr.y1; ++y)
                for (int x = tr.x0; x < tr.x1; ++x) {
                    if (adaptive && !film.active(x, y)) continue;
                    for (int s = 0; s < spp; ++s) {
                        vec2 jitter;
                        Ray ray = camera_sample(sampler, camera, x, y, first_sample + uint32_t(s), jitter);
                        if (n_aov > 0) eval_aovs(scene, aovs, eye, ray, aov, &ps.rays);
                        const uint64_t hits = ps.camera_hits;
                        vec3 L = li(sampler, ray, ps);
                        if (adaptive) {
                            film.add_adaptive_sample(ivec2(x, y), L, first_sample + uint32_t(s));
                            ++samples;
                            continue;  // no AOVs nor alpha (refused with --target-error)
                        }
                        film.add_sample(ivec2(x, y), L);
                        if (moment_at >= 0) write_moment(aov + moment_at, all_finite(L) ? L : vec3(0.f));
                        if (alpha) film.add_coverage(ivec2(x, y), ps.camera_hits != hits);
                        if (n_aov > 0) film.add_aov(ivec2(x, y), aov);
                        ++samples;
                    }
                }
            pass.add(ps.rays, samples);
        });
    } else {
        const PixelFilter filter(scene.settings.filter);
        pass.weighted(film, filter.reach(), spp, n_threads, [&](const detail::TileRange& tr, int s, FilmTile& ft) {
            S sampler = prototype;
            PathStats ps;
            uint64_t samples = 0;
            float aov[64];
            for (int y = tr.y0; y < tr.y1; ++y)
                for (int x = tr.x0; x < tr.x1; ++x) {
                    vec2 jitter;
                    Ray ray = camera_sample(sampler, camera, x, y, first_sample + uint32_t(s), jitter);
                    // The filter works in this film's pixels (a crop window only shifts them).
                    const vec2 pos = vec2(float(x), float(y)) + jitter;
                    if (n_aov > 0) eval_aovs(scene, aovs, eye, ray, aov, &ps.rays);
                    const uint64_t hits = ps.camera_hits;
                    vec3 L = li(sampler, ray, ps);
                    if (!all_finite(L)) {
                        film.count_nonfinite();
                        L = vec3(0.f);
                    }
                    film.count_sample(ivec2(x, y));
                    if (moment_at >= 0) write_moment(aov + moment_at, L);
                    detail::splat(ft, filter, pass.w, pass.h, pos, L, aov, ps.camera_hits != hits);
                    ++samples;
                }
            pass.add(ps.rays, samples);
        });
    }
    return pass.stats();
}

// A pass of a per-ray integrator (`Integrator(scene).Li<S, DiffuseOnly>(ray, sampler, stats)`)
// over all tiles with the sampler type S, instantiated for the scene's materials: DiffuseOnly when
// every material is diffuse. Chosen per pass, so that a material edited in the viewer (which
// restarts the accumulation) switches the instantiation too; both give the same image, the
// specialisation only drops code. The sampler type is chosen per pass too
// (integrator/sampled_pass.h): the independent sampler's instantiation lives in the integrator's
// own translation unit, as it always did, the others each in their own (integrator/samplers/), so
// that no instantiation changes how the compiler inlines another.
template <class Integrator, class S>
PassStats render_pass_for(const Scene& scene, Film& film, uint32_t first_sample, int spp, int n_threads,
                          const std::atomic<bool>* cancel) {
    const S prototype = make_sampler<S>(sampler_setup(scene, film));
    auto run = [&](auto diffuse_only) {
        const Integrator integrator(scene);
        return render_tiles(scene, film, first_sample, spp, n_threads, cancel, prototype,
                            [&](S& sampler, Ray ray, PathStats& ps) {
                                return integrator.template Li<S, decltype(diffuse_only)::value>(ray, sampler, ps);
                            });
    };
    return scene_is_diffuse_only(scene) ? run(std::true_type{}) : run(std::false_type{});
}

}  // namespace candela
