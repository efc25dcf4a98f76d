#pragma once
// The pass of the integrators whose light paths splat anywhere (the light tracer, BDPT): one sample
// index at a time over all tiles. Each tile's work fills its own SplatTile (and may write its own
// pixels of the zeroed layer); after all tiles, `merge_tile` runs for each tile in tile order, the
// tiles' splats are added to the layer through the scene's filter (Film::add_splats), then the
// layer is added to the film. The additions into
// every sum thus happen in the order (sample index, tile, pixel, vertex) whatever the threads and
// the passes, and the film is the sum of per-index layers in index order: what MPI's rank 0
// rebuilds from layers rendered elsewhere (Film::add, docs/distributed.md), bit for bit.
//
//   work(uint32_t sample_index, int tile, const detail::TileRange&, Film& layer, SplatTile&, PathStats&)
//       runs on a worker thread; the tile's SplatTile has been cleared.
//   merge_tile(int tile, const detail::TileRange&, Film& layer)
//       runs on one thread, in tile order, before the tile's splats go into the layer.
#include <omp.h>
#include <atomic>
#include <vector>
#include "integrator/tiles.h"

namespace candela {

// The same over `n_units` units of work of any kind (MLT's chains): work(index, unit, layer, st, ps)
// and merge_unit(unit, layer), units merged in unit order. The splats go through `filter`, the
// scene's (film/splat_filter.h), when they are merged.
template <class Work, class MergeUnit>
PassStats splat_pass_units(Film& film, const FilterDesc& filter, uint32_t first_sample, int spp, int n_threads,
                           const std::atomic<bool>* cancel, int n_units, const Work& work, const MergeUnit& merge_unit) {
    const SplatFilter splat_filter(filter, film.width(), film.height());
    std::vector<SplatTile> units(static_cast<size_t>(n_units));
    Film layer(film.width(), film.height());
    layer.set_layout(film.weighted(), film.aov_channels());
    if (film.has_alpha()) layer.enable_alpha();
    std::atomic<uint64_t> total_rays{0};
    std::atomic<bool> stopped{false};
    uint64_t samples = 0, splats = 0;
    for (int s = 0; s < spp; ++s) {
        if (cancel && cancel->load(std::memory_order_relaxed)) stopped = true;
        if (stopped) break;
        layer.clear();
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads)
        for (int u = 0; u < n_units; ++u) {
            if (stopped.load(std::memory_order_relaxed)) continue;
            if (cancel && cancel->load(std::memory_order_relaxed)) {
                stopped = true;
                continue;
            }
            PathStats ps;
            SplatTile& st = units[size_t(u)];
            st.clear();
            work(first_sample + uint32_t(s), u, layer, st, ps);
            total_rays.fetch_add(ps.rays, std::memory_order_relaxed);
        }
        if (stopped) break;  // a partial sample index is dropped whole: every pixel keeps its count
        uint64_t index_splats = 0;
        for (int u = 0; u < n_units; ++u) {
            const SplatTile& st = units[size_t(u)];
            merge_unit(u, layer);
            index_splats += st.size();
            samples += st.paths;
        }
        splats += index_splats;
        // In unit order (Film::add_splats), the threads sharing bands of rows only when there are
        // many splats: on the loaded 2-core machine the extra parallel region per sample index
        // cost more than it saved at 128 x 128 (docs/bdpt.md). The bytes are the same either way.
        layer.add_splats(units, splat_filter, index_splats >= (uint64_t(1) << 18) ? n_threads : 1);
        film.add(layer);
    }
    PassStats out;
    out.rays = total_rays.load();
    out.samples = samples;
    out.splats = splats;
    out.completed = !stopped.load();
    return out;
}

template <class Work, class MergeTile>
PassStats splat_pass(Film& film, const FilterDesc& filter, uint32_t first_sample, int spp, int n_threads,
                     const std::atomic<bool>* cancel, const Work& work, const MergeTile& merge_tile) {
    const int w = film.width(), h = film.height();
    const int tiles_x = (w + kTileSize - 1) / kTileSize, tiles_y = (h + kTileSize - 1) / kTileSize;
    return splat_pass_units(
        film, filter, first_sample, spp, n_threads, cancel, tiles_x * tiles_y,
        [&](uint32_t index, int tile, Film& layer, SplatTile& st, PathStats& ps) {
            work(index, tile, detail::tile_range(tile, tiles_x, w, h), layer, st, ps);
        },
        [&](int tile, Film& layer) { merge_tile(tile, detail::tile_range(tile, tiles_x, w, h), layer); });
}

}  // namespace candela
