#include "render/renderer.h"
#include <omp.h>
#include "core/error.h"

namespace candela {

PassStats Renderer::render_pass(const Scene& scene, Film& film, uint32_t first_sample, int spp, int threads,
                                const std::atomic<bool>* cancel) {
    const int n_threads = threads > 0 ? threads : omp_get_max_threads();
    if (!film_fits(film, scene.settings)) {
        if (film.total_samples() != 0)
            throw Error(scene.source, 0, "internal error: the film's filter or AOV layout changed during a render");
        configure_film(film, scene.settings);
    }
    // One virtual call per pass; the integrator is a few scalars, made per pass so that an edit in
    // the viewer (a new Scene) takes effect at the next pass.
    return make_integrator(scene)->render_pass(scene, film, first_sample, spp, n_threads, cancel);
}

}  // namespace candela
