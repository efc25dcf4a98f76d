#pragma once
// Rendering for the image tests: the batch-means estimate they compare with references.
#include <memory>
#include <vector>
#include "film/film.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "support/stats.h"

namespace candela::test {

// K independent batches of `spp` samples of `scene` rendered with the parameters `p` and seeds
// 1..K, each on its own film of the settings' size; the estimate comes from the spread of the
// batch means (stats::ImageEstimate::from_batches).
inline stats::ImageEstimate render_batch_estimate(const Scene& scene, SceneParams p, int batches, int spp) {
    std::vector<std::unique_ptr<Film>> films;
    std::vector<const Film*> ptrs;
    for (int b = 0; b < batches; ++b) {
        p.settings.seed = uint64_t(b + 1);
        films.push_back(std::make_unique<Film>(p.settings.width, p.settings.height));
        Renderer::render_pass(*scene.with_params(p), *films.back(), 0, spp, 0);
        ptrs.push_back(films.back().get());
    }
    return stats::ImageEstimate::from_batches(ptrs);
}

}  // namespace candela::test
