// The sensor family of the XML reader: sensors (the camera), and the film, reconstruction filter
// and sampler nested in them (the settings they set).
#include <glm/glm.hpp>
#include "scene/plugins/render_factories.h"
#include "scene/sensors.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

// The three projective sensors share one factory (src/scene/sensors.cpp), on the parameters alone.
Camera make_projective(XmlLoader&, Object& o) { return make_sensor(o.type, o.params); }

// The film completes the camera built before it: its size, the crop window (the image is the
// window) and alpha.
void make_hdrfilm(XmlLoader& L, Object& o, RenderSettings& s) {
    FilmDesc f = candela::make_hdrfilm(o.params);
    for (std::string& n : f.notes) L.scene().warnings.push_back(std::move(n));
    load_rfilters(L, o, s);
    ivec2 image = apply_film(f, L.scene().camera);
    s.width = image.x;
    s.height = image.y;
    s.alpha = f.alpha;
}

// The sampler plugins: sample_count and seed for all (Mitsuba's defaults 4 and 0), jitter for the
// stratified ones (and strength for orthogonal); sobol and zsobol are candela's own (docs/samplers.md). The sample count is
// rounded up to what the sampler stratifies over, as Mitsuba does (a warning says so).
void read_sampler(XmlLoader& L, Object& o, RenderSettings& s, SamplerType type) {
    int spp = o.params.get_int("sample_count", 4);
    int seed = o.params.get_int("seed", 0);
    if (spp <= 0) throw o.params.error("sample_count", "sample_count must be positive");
    if (seed < 0) throw o.params.error("seed", "seed must not be negative");
    s.sampler = SamplerDesc();
    s.sampler.type = type;
    if (type == SamplerType::Stratified || type == SamplerType::Multijitter || type == SamplerType::Orthogonal)
        s.sampler.jitter = o.params.get_bool("jitter", true);
    // Mitsuba's strength other than 2 (Bush's construction) loses the 2D stratification its
    // documentation recommends it for; candela has the strength-2 (Bose) array only.
    if (type == SamplerType::Orthogonal && o.params.get_int("strength", 2) != 2)
        throw o.params.error("strength", "orthogonal sampler: only strength 2 is supported");
    const uint32_t rounded = sampler_sample_count(type, uint32_t(spp));
    if (rounded != uint32_t(spp))
        L.scene().warnings.push_back(L.file_of(o.node) + ":" + std::to_string(o.line) + ": " + o.type + " sampler: sample_count " +
                                     std::to_string(spp) + " rounded up to " + std::to_string(rounded));
    s.spp = int(rounded);
    s.seed = uint64_t(seed);
}

void make_independent(XmlLoader& L, Object& o, RenderSettings& s) { read_sampler(L, o, s, SamplerType::Independent); }
void make_stratified(XmlLoader& L, Object& o, RenderSettings& s) { read_sampler(L, o, s, SamplerType::Stratified); }
void make_multijitter(XmlLoader& L, Object& o, RenderSettings& s) { read_sampler(L, o, s, SamplerType::Multijitter); }
void make_ldsampler(XmlLoader& L, Object& o, RenderSettings& s) { read_sampler(L, o, s, SamplerType::LdSampler); }
void make_sobol(XmlLoader& L, Object& o, RenderSettings& s) { read_sampler(L, o, s, SamplerType::Sobol); }
void make_zsobol(XmlLoader& L, Object& o, RenderSettings& s) { read_sampler(L, o, s, SamplerType::ZSobol); }
void make_orthogonal(XmlLoader& L, Object& o, RenderSettings& s) { read_sampler(L, o, s, SamplerType::Orthogonal); }

}  // namespace

const PluginTable<SensorFactory>& sensor_plugins() {
    static const PluginTable<SensorFactory> table = {
        {"perspective", make_projective},
        {"thinlens", make_projective},
        {"orthographic", make_projective},
    };
    return table;
}

const PluginTable<FilmFactory>& film_plugins() {
    static const PluginTable<FilmFactory> table = {
        {"hdrfilm", make_hdrfilm},
    };
    return table;
}

const PluginTable<SamplerFactory>& sampler_plugins() {
    static const PluginTable<SamplerFactory> table = {
        {"independent", make_independent}, {"stratified", make_stratified}, {"multijitter", make_multijitter},
        {"ldsampler", make_ldsampler},     {"sobol", make_sobol},           {"zsobol", make_zsobol},
        {"orthogonal", make_orthogonal},
    };
    return table;
}

void load_rfilters(XmlLoader& L, Object& film, RenderSettings& s) {
    bool have_filter = false;
    s.filter = gaussian_filter();  // Mitsuba's default without an <rfilter>
    for (Nested& c : film.nested) {
        if (c.tag != "rfilter") continue;
        if (have_filter) throw L.error(c.node, "more than one <rfilter>");
        Object f = L.read_object(c.node, "rfilter");
        s.filter = read_rfilter(f.type, f.params, f.line);  // scene/plugins/render_factories.cpp
        L.finish(f);
        c.used = have_filter = true;
    }
}

void load_sensor(XmlLoader& L, pugi::xml_node n) {
    Object o = L.read_object(n, "sensor");
    SensorFactory make = L.find_plugin(sensor_plugins(), o);
    Camera cam = make(L, o);

    RenderSettings& s = L.scene().settings;
    // Mitsuba's film and sampler defaults, when those are absent; a <film> overrides them.
    ivec2 image = apply_film(FilmDesc(), cam);
    s.width = image.x;
    s.height = image.y;
    s.alpha = false;
    L.scene().camera = cam;
    s.spp = 4;
    s.filter = gaussian_filter();
    s.seed = 0;
    bool film = false, sampler = false;
    for (Nested& c : o.nested) {
        if (c.tag == "film") {
            if (film) throw L.error(c.node, "more than one <film> in the sensor");
            Object f = L.read_object(c.node, "film");
            FilmFactory mf = L.find_plugin(film_plugins(), f);
            mf(L, f, s);
            L.finish(f);
            c.used = film = true;
        } else if (c.tag == "sampler") {
            if (sampler) throw L.error(c.node, "more than one <sampler> in the sensor");
            Object sm = L.read_object(c.node, "sampler");
            SamplerFactory ms = L.find_plugin(sampler_plugins(), sm);
            ms(L, sm, s);
            L.finish(sm);
            c.used = sampler = true;
        } else if (is_medium_child(L, c)) {
            // Mitsuba's sensor takes any medium among its objects, whatever its name.
            if (L.scene().camera_medium >= 0) throw L.error(c.node, "a sensor takes one medium");
            L.scene().camera_medium = nested_medium(L, c);
        }
    }
    L.finish(o);
}

}  // namespace xml
}  // namespace candela
