// The sensor family of the XML reader: sensors (the camera), and the film, reconstruction filter
// and sampler nested in them (the settings they set).
#include <glm/glm.hpp>
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
    load_rfilters(L, o, s);
    ivec2 image = apply_film(f, L.scene().camera);
    s.width = image.x;
    s.height = image.y;
    s.alpha = f.alpha;
}

void make_box(XmlLoader&, Object&, RenderSettings&) {}

void make_independent(XmlLoader&, Object& o, RenderSettings& s) {
    int spp = o.params.get_int("sample_count", 4);
    int seed = o.params.get_int("seed", 0);
    if (spp <= 0) throw o.params.error("sample_count", "sample_count must be positive");
    if (seed < 0) throw o.params.error("seed", "seed must not be negative");
    s.spp = spp;
    s.seed = uint64_t(seed);
}

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

const PluginTable<RFilterFactory>& rfilter_plugins() {
    static const PluginTable<RFilterFactory> table = {
        {"box", make_box},
    };
    return table;
}

const PluginTable<SamplerFactory>& sampler_plugins() {
    static const PluginTable<SamplerFactory> table = {
        {"independent", make_independent},
    };
    return table;
}

void load_rfilters(XmlLoader& L, Object& film, RenderSettings& s) {
    bool have_filter = false;
    for (Nested& c : film.nested) {
        if (c.tag != "rfilter") continue;
        if (have_filter) throw L.error(c.node, "more than one <rfilter>");
        Object f = L.read_object(c.node, "rfilter");
        RFilterFactory make = L.find_plugin(rfilter_plugins(), f);
        make(L, f, s);
        L.finish(f);
        c.used = have_filter = true;
    }
    if (!have_filter)  // no filters yet; many scenes omit rfilter, so this is not an error
        L.scene().warnings.push_back(L.file_of(film.node) + ":" + std::to_string(L.line(film.node)) +
                                     ": film without <rfilter>: candela renders with a box filter, where Mitsuba 3 "
                                     "would use its default gaussian");
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
        }
    }
    L.finish(o);
}

}  // namespace xml
}  // namespace candela
