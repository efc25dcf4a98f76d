#include "integrator/integrator.h"
#include "integrator/bdpt/bdpt.h"
#include "integrator/direct/direct.h"
#include "integrator/mlt/pssmlt.h"
#include "integrator/path/path_pass.h"
#include "integrator/ptracer/ptracer.h"
#include "integrator/volpath/volpath.h"

namespace candela {

std::unique_ptr<Integrator> make_integrator(const Scene& scene) {
    switch (scene.settings.integrator.type) {
        case IntegratorType::Direct: return std::make_unique<DirectPass>();
        case IntegratorType::Ptracer: return std::make_unique<LightTracerPass>();
        case IntegratorType::Bdpt: return std::make_unique<BdptPass>();
        case IntegratorType::Pssmlt: return std::make_unique<PssmltPass>();
        case IntegratorType::Mmlt: return std::make_unique<MmltPass>();
        // Without media volpath is the path tracer (the same image bit for bit, and its speed).
        case IntegratorType::Volpath:
            if (!scene.media.empty()) return std::make_unique<VolpathPass>();
            break;
        case IntegratorType::Path: break;
    }
    return std::make_unique<PathPass>();
}

bool film_fits(const Film& film, const RenderSettings& st) {
    return film.weighted() == !st.filter.is_box() && film.aov_channels() == aov_channel_count(st.integrator.aovs);
}

void configure_film(Film& film, const RenderSettings& st) {
    if (!film_fits(film, st)) film.set_layout(!st.filter.is_box(), aov_channel_count(st.integrator.aovs));
}

}  // namespace candela
