#pragma once
#include <atomic>
#include "film/film.h"
#include "integrator/integrator.h"
#include "scene/scene.h"

namespace candela {

// Renders passes of the scene's integrator (settings.integrator: integrator/integrator.h) into a
// film: tiles of 16 x 16 pixels are shared out to OpenMP threads dynamically. Sample s of pixel p
// always draws the same random numbers (the sampler is seeded from (p, s, seed)), and each pixel's
// sums are added in a fixed order, so the image is the same bit for bit whatever the number of
// threads.
class Renderer {
public:
    static constexpr int kTileSize = 16;

    // Renders samples [first_sample, first_sample + spp) of every pixel, through the scene's camera
    // set to the film's size. `threads` <= 0 uses all cores. A film whose layout does not fit the
    // settings (filter, AOVs) is configured first when it is empty (configure_film); a non-empty one
    // is an error. Returns early (completed = false) when *cancel becomes true; tiles already done stay.
    static PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                 const std::atomic<bool>* cancel = nullptr);
};

}  // namespace candela
