#include "render/launch.h"
#include "core/error.h"
#include "integrator/caps.h"
#include "scene/cornell.h"

namespace candela {

namespace {

// The command line's depth, checked by the scene file's rule (integrator/depth.h).
int depth_option(const char* option, int value, const char* (*error)(int)) {
    if (const char* e = error(value)) throw UsageError(std::string(option) + ": " + e);
    return value;
}

void apply_overrides(RenderSettings& st, const SceneOverrides& ov) {
    if (ov.width) st.width = *ov.width;
    if (ov.height) st.height = *ov.height;
    if (ov.max_depth) st.max_depth = max_depth_from_mitsuba(depth_option("--max-depth", *ov.max_depth, max_depth_error));
    if (ov.rr_depth) st.rr_depth = depth_option("--rr-depth", *ov.rr_depth, rr_depth_error);
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
        // its max depth 2).
        st.integrator.type = *ov.integrator;
        st.integrator.spectral_mis = ov.spectral_mis;
        if (!reads(*ov.integrator).aovs && !st.integrator.aovs.empty())
            throw Error(std::string("--integrator ") + integrator_type_name(*ov.integrator) +
                        ": the scene's aov or moment integrator needs camera rays per pixel, which it does not trace");
    }
    if (ov.denoise_aux && reads(st.integrator.type).aovs) add_denoise_aovs(st.integrator.aovs);
}

// What the integrator does not read (integrator/caps.h): an option given on the command line is
// refused; a value of the scene's own that differs from the default is noted in its warnings.
void check_reads(SceneDescription& desc, const SceneOverrides& ov) {
    const RenderSettings& st = desc.settings;
    const IntegratorCaps& c = reads(st.integrator.type);
    const std::string name = integrator_type_name(st.integrator.type);
    auto refuse = [&](const char* option, const char* why) {
        throw UsageError(std::string(option) + ": the " + name + " integrator does not read it (" + why + ")");
    };
    auto note = [&](const std::string& what) {
        desc.warnings.push_back(desc.source + ": the " + name + " integrator ignores " + what);
    };
    if (!c.sampling) {
        if (ov.sampling) refuse("--sampling", "it weighs its own strategies");
        if (st.sampling != SamplingMode::Mis) note(std::string("the sampling mode ") + sampling_mode_name(st.sampling));
    }
    if (!c.sampler) {
        if (ov.sampler) refuse("--sampler", "its Markov chains draw their own random numbers");
        if (st.sampler.type != SamplerType::Independent)
            note(std::string("the scene's sampler ") + sampler_type_name(st.sampler.type) +
                 " (its Markov chains draw their own random numbers)");
    }
    if (!c.filter && !st.filter.is_box())
        note(std::string("the film's ") + filter_name(st.filter.type) + " filter");
    const int scene_max_depth = max_depth_to_mitsuba(st.max_depth);
    if (!c.max_depth) {
        if (ov.max_depth) refuse("--max-depth", "it has no depth");
        // A direct scene's depth is its own (2); other values come from the scene's path integrator.
        if (ov.integrator && scene_max_depth != -1 && scene_max_depth != 2)
            note("the scene's max_depth " + std::to_string(scene_max_depth));
    }
    if (!c.rr_depth) {
        if (ov.rr_depth) refuse("--rr-depth", "it has no Russian roulette");
        if (ov.integrator && st.rr_depth != 5) note("the scene's rr_depth " + std::to_string(st.rr_depth));
    }
    if (!c.hide_emitters && st.integrator.hide_emitters) note("the scene's hide_emitters");
    if (!c.media && !desc.media.empty()) {
        if (ov.integrator) refuse("--integrator", "the scene has participating media: use volpath");
        throw Error(desc.source, desc.media_line, "the " + name + " integrator does not render participating media; use volpath");
    }
}

}  // namespace

std::shared_ptr<const Scene> prepare_scene(const std::string& path, const SceneOverrides& ov) {
    SceneDescription desc = path.empty() ? make_cornell_box() : load_scene(path, ov.defines);
    apply_overrides(desc.settings, ov);
    check_reads(desc, ov);
    if (ov.denoise_box_filter && !desc.settings.filter.is_box()) {
        desc.warnings.push_back((path.empty() ? std::string("the scene") : path) + ": rendered with the box filter, not " +
                                filter_name(desc.settings.filter.type) +
                                ", for the denoiser (it keeps noise that a wider filter correlates between pixels)");
        desc.settings.filter = FilterDesc{};
    }
    return build_scene(std::move(desc), ov.accel);
}

void check_run_features(const RenderSettings& st, const RunFeatures& f) {
    const IntegratorCaps& c = reads(st.integrator.type);
    auto require = [&](bool asked, bool supported, const char* option, const char* why) {
        if (asked && !supported)
            throw UsageError(std::string(option) + ": not available with the " + integrator_type_name(st.integrator.type) +
                             " integrator (" + why + ")");
    };
    require(f.mpi, c.mpi, "mpirun", "its sample indices do not split across ranks: render it in one process");
    require(f.adaptive, c.adaptive, "--target-error", "it needs camera samples per pixel; splats land anywhere");
    require(f.checkpoint, c.checkpoint, "--checkpoint", "its state is not saved");
    require(f.time_limit, c.time_limit, "--time-limit", "its passes cannot be cut");
}

std::string integrator_summary(const RenderSettings& st) {
    const IntegratorCaps& c = reads(st.integrator.type);
    std::string s;
    auto add = [&](const std::string& item) { s += (s.empty() ? "" : ", ") + item; };
    if (c.max_depth) add("max_depth " + std::to_string(max_depth_to_mitsuba(st.max_depth)));
    if (c.rr_depth) add("rr_depth " + std::to_string(st.rr_depth));
    if (c.sampling) add(sampling_mode_name(st.sampling));
    const bool mis = st.integrator.type == IntegratorType::Volpath && st.integrator.spectral_mis;
    return std::string(mis ? "volpathmis" : integrator_type_name(st.integrator.type)) + (s.empty() ? "" : " (" + s + ")");
}

IntegratorType parse_integrator_type(const std::string& s) {
    if (s == "path") return IntegratorType::Path;
    if (s == "direct") return IntegratorType::Direct;
    if (s == "ptracer") return IntegratorType::Ptracer;
    if (s == "bdpt") return IntegratorType::Bdpt;
    if (s == "pssmlt") return IntegratorType::Pssmlt;
    if (s == "mmlt") return IntegratorType::Mmlt;
    if (s == "volpath" || s == "volpathmis") return IntegratorType::Volpath;  // SceneOverrides::spectral_mis
    throw Error("unknown integrator '" + s + "' (expected path, volpath, volpathmis, direct, ptracer, bdpt, pssmlt or mmlt)");
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
