#include "render/launch.h"
#include "core/error.h"
#include "scene/cornell.h"

namespace candela {

namespace {

void apply_overrides(RenderSettings& st, const SceneOverrides& ov) {
    if (ov.width) st.width = *ov.width;
    if (ov.height) st.height = *ov.height;
    if (ov.max_depth) st.max_depth = *ov.max_depth;
    if (ov.rr_depth) st.rr_depth = *ov.rr_depth;
    if (ov.seed) st.seed = *ov.seed;
    if (ov.sampling) st.sampling = *ov.sampling;
    if (ov.sampler) st.sampler.type = *ov.sampler;
    if (ov.sample_count) {
        if (*ov.sample_count < 1) throw Error("--sample-count must be >= 1");
        st.spp = *ov.sample_count;
    }
    // What the sampler stratifies over (a square, a power of two, ...), as the XML reader rounds it.
    if (ov.sampler || ov.sample_count) st.spp = int(sampler_sample_count(st.sampler.type, uint32_t(st.spp)));
    if (ov.integrator) {
        // Only the type changes: the scene's depths and hide_emitters stay (a direct scene keeps
        // its max depth 1).
        st.integrator.type = *ov.integrator;
        if (*ov.integrator == IntegratorType::Ptracer && !st.integrator.aovs.empty())
            throw Error("--integrator ptracer: the scene's aov or moment integrator needs camera rays, which ptracer has none of");
        if (*ov.integrator == IntegratorType::Bdpt && !st.integrator.aovs.empty())
            throw Error("--integrator bdpt: the scene's aov or moment integrator is not rendered by bdpt");
        if ((*ov.integrator == IntegratorType::Pssmlt || *ov.integrator == IntegratorType::Mmlt) &&
            !st.integrator.aovs.empty())
            throw Error(std::string("--integrator ") + integrator_type_name(*ov.integrator) +
                        ": the scene's aov or moment integrator needs camera rays per pixel");
    }
    if (ov.denoise_aux && (st.integrator.type == IntegratorType::Path || st.integrator.type == IntegratorType::Direct))
        add_denoise_aovs(st.integrator.aovs);
    if (st.max_depth < -1) throw Error("--max-depth must be -1 (unbounded) or >= 0");
    if (st.rr_depth < 0) throw Error("--rr-depth must be >= 0");
}

}  // namespace

std::shared_ptr<const Scene> prepare_scene(const std::string& path, const SceneOverrides& ov) {
    SceneDescription desc = path.empty() ? make_cornell_box() : load_scene(path, ov.defines);
    apply_overrides(desc.settings, ov);
    if (ov.denoise_box_filter && !desc.settings.filter.is_box()) {
        desc.warnings.push_back((path.empty() ? std::string("the scene") : path) + ": rendered with the box filter, not " +
                                filter_name(desc.settings.filter.type) +
                                ", for the denoiser (it keeps noise that a wider filter correlates between pixels)");
        desc.settings.filter = FilterDesc{};
    }
    return build_scene(std::move(desc), ov.accel);
}

IntegratorType parse_integrator_type(const std::string& s) {
    if (s == "path") return IntegratorType::Path;
    if (s == "direct") return IntegratorType::Direct;
    if (s == "ptracer") return IntegratorType::Ptracer;
    if (s == "bdpt") return IntegratorType::Bdpt;
    if (s == "pssmlt") return IntegratorType::Pssmlt;
    if (s == "mmlt") return IntegratorType::Mmlt;
    throw Error("unknown integrator '" + s + "' (expected path, direct, ptracer, bdpt, pssmlt or mmlt)");
}

const char* integrator_type_name(IntegratorType t) {
    switch (t) {
        case IntegratorType::Direct: return "direct";
        case IntegratorType::Ptracer: return "ptracer";
        case IntegratorType::Bdpt: return "bdpt";
        case IntegratorType::Pssmlt: return "pssmlt";
        case IntegratorType::Mmlt: return "mmlt";
        default: return "path";
    }
}

SamplingMode parse_sampling_mode(const std::string& s) {
    if (s == "light") return SamplingMode::Light;
    if (s == "bsdf") return SamplingMode::Bsdf;
    if (s == "mis") return SamplingMode::Mis;
    throw Error("unknown sampling mode '" + s + "' (expected light, bsdf or mis)");
}

SamplerType parse_sampler_name(const std::string& s) {
    SamplerType t;
    if (parse_sampler_type(s, t)) return t;
    throw Error("unknown sampler '" + s + "' (expected independent, stratified, multijitter, ldsampler, sobol, zsobol or orthogonal)");
}

const char* sampling_mode_name(SamplingMode m) {
    switch (m) {
        case SamplingMode::Light: return "light";
        case SamplingMode::Bsdf: return "bsdf";
        default: return "mis";
    }
}

}  // namespace candela
