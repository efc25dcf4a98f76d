// The sensor family of the XML reader: sensors (the camera), and the film, reconstruction filter
// and sampler nested in them (the settings they set).
#include <glm/glm.hpp>
#include "scene/plugins/render_factories.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

Camera make_perspective(XmlLoader&, Object& o) {
    Camera cam;
    if (o.params.has("fov")) {
        cam.fov_deg = o.params.get_float("fov", 0.f);
        if (!(cam.fov_deg > 0.f && cam.fov_deg < 180.f)) throw o.params.error("fov", "fov must be in (0, 180) degrees");
        std::string axis = o.params.get_string("fov_axis", "x");
        if (axis == "x") cam.fov_axis = FovAxis::X;
        else if (axis == "y") cam.fov_axis = FovAxis::Y;
        else if (axis == "diagonal") cam.fov_axis = FovAxis::Diagonal;
        else if (axis == "smaller") cam.fov_axis = FovAxis::Smaller;
        else if (axis == "larger") cam.fov_axis = FovAxis::Larger;
        else throw o.params.error("fov_axis", "unknown fov_axis '" + axis + "' (x, y, diagonal, smaller or larger)");
    } else {
        // Mitsuba's default: a 50 mm lens on a 36 x 24 mm film, measured on the diagonal.
        cam.fov_deg = glm::degrees(2.f * std::atan(std::sqrt(36.f * 36.f + 24.f * 24.f) / (2.f * 50.f)));
        cam.fov_axis = FovAxis::Diagonal;
        if (o.params.has("fov_axis")) o.params.get_string("fov_axis", "");  // ignored without fov, as in Mitsuba
    }
    cam.near_clip = o.params.get_float("near_clip", 1e-2f);
    cam.far_clip = o.params.get_float("far_clip", 1e4f);
    if (!(cam.near_clip > 0.f)) throw o.params.error("near_clip", "near_clip must be positive");
    if (!(cam.far_clip > cam.near_clip)) throw o.params.error("far_clip", "far_clip must be greater than near_clip");
    cam.to_world = o.params.get_transform("to_world", mat4(1.f));
    for (int col = 0; col < 3; ++col)
        if (std::abs(glm::dot(vec3(cam.to_world[col]), vec3(cam.to_world[col])) - 1.f) > 1e-3f)
            throw o.params.error("to_world", "the sensor's to_world must not scale (Mitsuba rejects it too)");
    return cam;
}

void make_hdrfilm(XmlLoader& L, Object& o, RenderSettings& s) {
    int w = o.params.get_int("width", 768), h = o.params.get_int("height", 576);
    if (w <= 0) throw o.params.error("width", "film width must be positive");
    if (h <= 0) throw o.params.error("height", "film height must be positive");
    // Output format choices that do not change the rendered values.
    std::string pf = o.params.get_string("pixel_format", "rgb");
    if (pf != "rgb" && pf != "rgba") throw o.params.error("pixel_format", "unsupported pixel_format '" + pf + "' (rgb or rgba)");
    std::string cf = o.params.get_string("component_format", "float16");
    if (cf != "float16" && cf != "float32")
        throw o.params.error("component_format", "unsupported component_format '" + cf + "' (float16 or float32)");
    std::string ff = o.params.get_string("file_format", "openexr");
    if (ff != "openexr") throw o.params.error("file_format", "unsupported file_format '" + ff + "' (openexr)");
    load_rfilters(L, o, s);
    s.width = w;
    s.height = h;
}

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
        {"perspective", make_perspective},
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
        {"independent", make_independent},
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
    s.width = 768;  // Mitsuba's film and sampler defaults, when those are absent
    s.height = 576;
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
        }
    }
    L.finish(o);
    L.scene().camera = cam;
}

}  // namespace xml
}  // namespace candela
