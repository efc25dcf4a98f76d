#pragma once
#include <atomic>
#include "film/film.h"
#include "scene/scene.h"

namespace candela {

struct PassStats {
    uint64_t samples = 0;
    uint64_t rays = 0;
    bool completed = true;  // false when cancelled part-way
};

// Renders passes of the path tracer into a film: tiles of 16 x 16 pixels are shared out to OpenMP
// threads dynamically. Sample s of pixel p always draws the same random numbers (the sampler is
// seeded from (p, s, seed)), and each pixel's samples are summed in sample order, so the image is
// the same bit for bit whatever the number of threads.
class Renderer {
public:
    static constexpr int kTileSize = 16;

    // Renders samples [first_sample, first_sample + spp) of every pixel, through the scene's camera
    // set to the film's size. `threads` <= 0 uses all
    // cores. Returns early (completed = false) when *cancel becomes true; tiles already done stay.
    static PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                 const std::atomic<bool>* cancel = nullptr);
};

}  // namespace candela
