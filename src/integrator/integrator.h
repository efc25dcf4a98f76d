#pragma once
// Integrators are coarse objects: one virtual call renders one pass (ARCHITECTURE.md, "Growing
// it"; pbrt-v4 cpu/integrators.h). Renderer::render_pass, the headless loop, the viewer's session
// and the tests all drive them through it. Inside a pass nothing is virtual: each integrator runs
// the shared tile loop (integrator/tiles.h) with its own radiance estimator inlined.
#include <atomic>
#include <cstdint>
#include <memory>
#include "film/film.h"
#include "scene/scene.h"

namespace candela {

struct PassStats {
    uint64_t samples = 0;
    uint64_t rays = 0;
    uint64_t splats = 0;    // light-path contributions added to the film's splats
    bool completed = true;  // false when cancelled part-way
};

class Integrator {
public:
    virtual ~Integrator() = default;
    // Renders samples [first_sample, first_sample + spp) of every pixel of `film` (whose layout
    // fits the scene's settings: configure_film) through the scene's camera set to the film's size,
    // on `threads` threads (> 0). Sample s of pixel p draws the same random numbers whatever the
    // thread count, and every pixel's sums are added in a fixed order, so the film is the same bit
    // for bit. Returns early (completed = false) when *cancel becomes true.
    virtual PassStats render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                  const std::atomic<bool>* cancel) const = 0;
};

// The integrator the scene's settings name (settings.integrator).
std::unique_ptr<Integrator> make_integrator(const Scene& scene);

// Sets the film's layout for the settings: weighted unless the filter is the box, and one channel
// per AOV. Clears the film when the layout changes.
void configure_film(Film& film, const RenderSettings& settings);
bool film_fits(const Film& film, const RenderSettings& settings);

}  // namespace candela
