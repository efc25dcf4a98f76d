#include "scene/plugins/render_factories.h"
#include <cmath>
#include <sstream>
#include "integrator/depth.h"

namespace candela {

namespace {

// path, volpath: Mitsuba's MonteCarloIntegrator parameters, checked and converted by the same
// rules as --max-depth and --rr-depth (integrator/desc.h).
// `default_depth` is Mitsuba's: -1 for the C++ integrators, 6 for the Python (differentiable) ones.
void read_depths(const ParamSet& p, RenderSettings& st, int default_depth = -1) {
    const int max_depth = p.get_int("max_depth", default_depth);
    const int rr_depth = p.get_int("rr_depth", 5);
    if (const char* e = max_depth_error(max_depth)) throw p.error("max_depth", e);
    if (const char* e = rr_depth_error(rr_depth)) throw p.error("rr_depth", e);
    st.max_depth = max_depth_from_mitsuba(max_depth);
    st.rr_depth = rr_depth;
}

int sample_count(const ParamSet& p, const std::string& name, int def) {
    int n = p.get_int(name, def);
    if (n < 0 || n > 1 << 16) throw p.error(name, name + " must be in [0, 65536]");
    return n;
}

std::vector<AovSpec> parse_aovs(const ParamSet& p) {
    if (!p.has("aovs")) throw p.error("aovs", "integrator 'aov' needs an 'aovs' string (\"name:type,...\")");
    std::string text = p.get_string("aovs", "");
    std::vector<AovSpec> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        // Mitsuba's string::tokenize drops white space around items.
        const size_t b = item.find_first_not_of(" \t\n"), e = item.find_last_not_of(" \t\n");
        item = b == std::string::npos ? std::string() : item.substr(b, e - b + 1);
        if (item.empty()) continue;
        const size_t colon = item.find(':');
        if (colon == std::string::npos || colon == 0 || colon + 1 == item.size() ||
            item.find(':', colon + 1) != std::string::npos)
            throw p.error("aovs", "invalid AOV '" + item + "': expected <name>:<type>");
        AovSpec a;
        a.name = item.substr(0, colon);
        const std::string type = item.substr(colon + 1);
        if (!parse_aov_type(type, a.type)) {
            const bool mitsuba = type == "duv_dx" || type == "duv_dy" || type == "boundary_test";
            throw p.error("aovs", "AOV type '" + type + "' " +
                                      (mitsuba ? "is not supported (candela traces no ray differentials and no "
                                                 "boundary test)"
                                               : "is unknown") +
                                      "; candela writes depth, position, uv, sh_normal, geo_normal, dp_du, dp_dv, "
                                      "albedo, prim_index, shape_index");
        }
        out.push_back(a);
    }
    if (out.empty()) throw p.error("aovs", "no AOVs in '" + text + "'");
    if (aov_channel_count(out) > 64) throw p.error("aovs", "more than 64 AOV channels");
    return out;
}

// The parameters of Mitsuba's projective-sampling integrators (ad/integrators/common.py,
// PSIntegrator) steer only the derivative's estimator: read and checked, no effect on the image.
void read_projective(const ParamSet& p) {
    for (const char* n : {"sppc", "sppp", "sppi"})
        if (p.has(n)) sample_count(p, n, 0);
    const std::string guiding = p.get_string("guiding", "octree");
    if (guiding != "none" && guiding != "grid" && guiding != "octree")
        throw p.error("guiding", "guiding must be none, grid or octree");
    p.get_bool("guiding_proj", true);
    if (p.get_int("guiding_rounds", 1) < 0) throw p.error("guiding_rounds", "guiding_rounds must be >= 0");
    const std::string seed = p.get_string("project_seed", "both");
    if (seed != "both" && seed != "bsdf" && seed != "emitter")
        throw p.error("project_seed", "project_seed must be both, bsdf or emitter");
}

}  // namespace

IntegratorRole read_integrator(const std::string& type, const ParamSet& p, RenderSettings& st, int line) {
    IntegratorDesc& d = st.integrator;
    if (type == "path" || type == "volpath" || type == "volpathmis") {
        // volpath and volpathmis (volpath with spectral MIS) render media (integrator/volpath/);
        // in a scene without media they are the path tracer, bit for bit.
        read_depths(p, st);
        d.type = type == "path" ? IntegratorType::Path : IntegratorType::Volpath;
        d.spectral_mis = type == "volpathmis";
        d.hide_emitters = p.get_bool("hide_emitters", false);
        p.report_unused();
        return IntegratorRole::Renders;
    }
    if (type == "prb" || type == "prbvolpath" || type == "prb_projective" || type == "prb_basic" ||
        type == "direct_projective") {
        // Mitsuba's differentiable integrators (Python, ad/integrators/), read for their primal
        // image, which is the path tracer's: emitter and BSDF sampling combined by MIS, Russian
        // roulette on the throughput times eta^2 from rr_depth, and Mitsuba's default depth for
        // them (6, not unbounded). prb_basic samples the BSDF only (so point, spot and directional
        // lights contribute nothing, as in Mitsuba); direct_projective reads max_depth and rr_depth
        // (checked the same way) and then fixes the depth at 2 segments, one scattering event.
        read_depths(p, st, 6);
        if (type == "prb_projective" || type == "direct_projective") read_projective(p);
        if (type == "prb_basic") st.sampling = SamplingMode::Bsdf;
        if (type == "direct_projective") st.max_depth = max_depth_from_mitsuba(2);
        d.type = IntegratorType::Path;
        d.hide_emitters = p.get_bool("hide_emitters", false);
        p.report_unused();
        return IntegratorRole::Renders;
    }
    if (type == "direct") {
        if (p.has("shading_samples") && (p.has("emitter_samples") || p.has("bsdf_samples")))
            throw p.error("shading_samples", "cannot give both 'shading_samples' and 'emitter_samples'/'bsdf_samples'");
        int shading = sample_count(p, "shading_samples", 1);
        d.type = IntegratorType::Direct;
        d.emitter_samples = sample_count(p, "emitter_samples", shading);
        d.bsdf_samples = sample_count(p, "bsdf_samples", shading);
        if (d.emitter_samples + d.bsdf_samples == 0)
            throw p.error(p.has("bsdf_samples") ? "bsdf_samples" : "shading_samples",
                          "direct needs at least one BSDF or emitter sample");
        d.hide_emitters = p.get_bool("hide_emitters", false);
        // The direct integrator has no depth: it is one scattering event (Mitsuba's max_depth 2),
        // which --integrator path keeps.
        st.max_depth = max_depth_from_mitsuba(2);
        p.report_unused();
        return IntegratorRole::Renders;
    }
    if (type == "ptracer") {
        // Mitsuba's ptracer: light paths connected to the camera (integrator/ptracer/). Its
        // samples_per_pass only splits Mitsuba's work into passes: the image does not depend on it.
        read_depths(p, st);
        d.type = IntegratorType::Ptracer;
        d.hide_emitters = p.get_bool("hide_emitters", false);
        p.get_int("samples_per_pass", -1);
        p.report_unused();
        return IntegratorRole::Renders;
    }
    if (type == "bdpt") {
        // Bidirectional path tracing (integrator/bdpt/), Mitsuba 0.6's bdpt with Mitsuba 3's
        // depth and hide_emitters meanings.
        read_depths(p, st);
        d.type = IntegratorType::Bdpt;
        d.hide_emitters = p.get_bool("hide_emitters", false);
        p.report_unused();
        return IntegratorRole::Renders;
    }
    if (type == "pssmlt" || type == "mmlt") {
        // Primary-sample-space MLT over the path tracer, multiplexed MLT over BDPT
        // (integrator/mlt/, docs/mlt.md).
        read_depths(p, st);
        d.type = type == "mmlt" ? IntegratorType::Mmlt : IntegratorType::Pssmlt;
        d.hide_emitters = p.get_bool("hide_emitters", false);
        MltParams& m = d.mlt;
        m.bootstrap_samples = p.get_int("bootstrap_samples", m.bootstrap_samples);
        if (m.bootstrap_samples < 1) throw p.error("bootstrap_samples", "needs at least one bootstrap sample");
        m.chains = p.get_int("chains", m.chains);
        if (m.chains < 1) throw p.error("chains", "needs at least one chain");
        m.mutations_per_pixel = p.get_int("mutations_per_pixel", 0);
        if (p.has("mutations_per_pixel") && m.mutations_per_pixel < 1)
            throw p.error("mutations_per_pixel", "must be at least 1");
        m.sigma = p.get_float("sigma", m.sigma);
        if (!(m.sigma > 0.f && m.sigma <= 1.f)) throw p.error("sigma", "must be in (0, 1]");
        m.large_step_probability = p.get_float("large_step_probability", m.large_step_probability);
        if (!(m.large_step_probability >= 0.f && m.large_step_probability <= 1.f))
            throw p.error("large_step_probability", "must be in [0, 1]");
        p.report_unused();
        return IntegratorRole::Renders;
    }
    if (type == "moment") {
        // The image is the nested integrator's; the caller, which knows the nested integrator's
        // name, adds the moment channels (AovType::Moment) once the nesting is read.
        p.report_unused();
        return IntegratorRole::Wraps;
    }
    if (type == "aov") {
        if (!d.aovs.empty()) throw p.error("aovs", "an aov integrator inside another aov integrator");
        d.aovs = parse_aovs(p);
        p.report_unused();
        return IntegratorRole::Wraps;
    }
    throw Error(p.file(), line, "unsupported integrator type '" + type +
                "' (candela supports: path, volpath, volpathmis, direct, ptracer, bdpt, pssmlt, mmlt, moment, aov, "
                "prb, prb_basic, prbvolpath, prb_projective, direct_projective)");
}

FilterDesc read_rfilter(const std::string& type, const ParamSet& p, int line) {
    FilterDesc f;
    if (type == "box") {
        f = box_filter();  // Mitsuba's box has no parameters: radius 0.5
    } else if (type == "tent") {
        float r = p.get_float("radius", 1.f);
        if (!(r > 0.f && r <= 64.f)) throw p.error("radius", "tent radius must be in (0, 64] pixels");
        // Mitsuba's image block takes any filter of radius 0.5 for the box (is_box_filter).
        f = r == 0.5f ? box_filter() : tent_filter(r);
    } else if (type == "gaussian") {
        float s = p.get_float("stddev", 0.5f);
        if (!(s > 0.f && s <= 16.f)) throw p.error("stddev", "gaussian stddev must be in (0, 16] pixels");
        f = 4.f * s == 0.5f ? box_filter() : gaussian_filter(s);
    } else if (type == "mitchell") {
        const float b = p.get_float("B", 1.f / 3.f), c = p.get_float("C", 1.f / 3.f);
        if (!std::isfinite(b) || std::abs(b) > 16.f) throw p.error("B", "B must be finite (|B| <= 16)");
        if (!std::isfinite(c) || std::abs(c) > 16.f) throw p.error("C", "C must be finite (|C| <= 16)");
        f = mitchell_filter(b, c);
    } else if (type == "catmullrom") {
        f = catmullrom_filter();
    } else if (type == "lanczos") {
        const int lobes = p.get_int("lobes", 3);
        if (lobes < 1 || lobes > 64) throw p.error("lobes", "lanczos lobes must be in [1, 64]");
        f = lanczos_filter(lobes);
    } else {
        throw Error(p.file(), line, "unsupported rfilter type '" + type +
                    "' (candela supports: box, tent, gaussian, mitchell, catmullrom, lanczos)");
    }
    p.report_unused();
    return f;
}

}  // namespace candela
