// The medium family of the XML reader: Mitsuba 3's `homogeneous` medium (src/media/homogeneous.cpp)
// with its phase functions `isotropic` and `hg` (src/phase/), and the media that shapes and the
// sensor name. docs/media.md lists what is read and what is refused.
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

// A medium parameter given as a value (float, rgb, spectrum) or as a nested constvolume.
vec3 medium_value(XmlLoader& L, Object& o, const std::string& name, vec3 def) {
    for (Nested& c : o.nested) {
        if (c.tag != "volume" || L.attr(c.node, "name") != name) continue;
        if (o.params.has(name)) throw L.error(c.node, o.what() + ": '" + name + "' given twice");
        Object v = L.read_object(c.node, "volume");
        if (v.type != "constvolume")
            throw L.error(c.node, "unsupported volume type '" + v.type + "' (candela supports: constvolume)");
        const vec3 value = v.params.get_rgb("value", vec3(1.f));
        v.params.get_transform("to_world", mat4(1.f));  // a constant has no place
        L.finish(v);
        c.used = true;
        return value;
    }
    return o.params.get_rgb(name, def);
}

float phase_g(XmlLoader& L, Object& medium) {
    float g = 0.f;  // isotropic when none is given
    bool seen = false;
    for (Nested& c : medium.nested) {
        if (c.tag != "phase") continue;
        if (seen) throw L.error(c.node, medium.what() + " takes one phase function");
        seen = true;
        Object ph = L.read_object(c.node, "phase");
        if (ph.type == "hg") {
            g = ph.params.get_float("g", 0.8f);  // Mitsuba's default
            if (!(g > -1.f && g < 1.f)) throw ph.params.error("g", "the hg phase function's g must lie in (-1, 1)");
        } else if (ph.type != "isotropic") {
            throw L.error(c.node, "unsupported phase type '" + ph.type + "' (candela supports: isotropic, hg)");
        }
        L.finish(ph);
        c.used = true;
    }
    return g;
}

}  // namespace

int32_t load_medium(XmlLoader& L, pugi::xml_node n) {
    auto it = L.media.find(n.internal_object());
    if (it != L.media.end()) return it->second;
    Object o = L.read_object(n, "medium");
    if (o.type != "homogeneous")
        throw L.error(n, "unsupported medium type '" + o.type + "' (candela supports: homogeneous)");
    Medium m;
    m.name = n.attribute("id") ? L.attr(n, "id") : std::string("medium");
    const vec3 sigma_t = medium_value(L, o, "sigma_t", vec3(1.f));
    m.albedo = medium_value(L, o, "albedo", vec3(0.75f));
    const float scale = o.params.get_float("scale", 1.f);
    if (!(scale >= 0.f) || !std::isfinite(scale)) throw o.params.error("scale", "scale must be finite and >= 0");
    m.sigma_t = sigma_t * scale;
    for (int c = 0; c < 3; ++c) {
        if (!(sigma_t[c] >= 0.f) || !std::isfinite(m.sigma_t[c]))
            throw L.error(n, o.what() + ": sigma_t must be finite and >= 0 (a negative density has no meaning)");
        if (!(m.albedo[c] >= 0.f && m.albedo[c] <= 1.f)) throw L.error(n, o.what() + ": albedo must lie in [0, 1]");
    }
    // Mitsuba's switches of its estimator, which leave the image's expectation as it is.
    o.params.get_bool("sample_emitters", true);
    o.params.get_bool("has_spectral_extinction", true);
    if (o.params.has("radiance") || o.params.has("emission"))
        throw L.error(n, "emissive media are not supported (docs/media.md)");
    m.g = phase_g(L, o);
    L.finish(o);
    SceneDescription& sc = L.scene();
    if (sc.media.empty()) sc.media_line = L.line(n);
    sc.media.push_back(m);
    const int32_t index = int32_t(sc.media.size() - 1);
    L.media[n.internal_object()] = index;
    return index;
}

bool is_medium_child(XmlLoader& L, const Nested& c) {
    if (c.tag == "medium") return true;
    return c.tag == "ref" && L.object_by_id(c.node, L.required_attr(c.node, "id"), "").tag == "medium";
}

int32_t nested_medium(XmlLoader& L, Nested& c) {
    c.used = true;
    return load_medium(L, c.tag == "ref" ? L.definition(c, "medium") : c.node);
}

void load_shape_media(XmlLoader& L, Object& shape, int32_t& interior, int32_t& exterior) {
    for (Nested& c : shape.nested) {
        if (!is_medium_child(L, c)) continue;
        const std::string name = L.attr(c.node, "name");
        int32_t& slot = name == "interior" ? interior : name == "exterior" ? exterior : interior;
        if (name != "interior" && name != "exterior")
            throw L.error(c.node, "a shape's medium must be named \"interior\" or \"exterior\"");
        if (slot >= 0) throw L.error(c.node, "a shape takes one " + name + " medium");
        slot = nested_medium(L, c);
    }
}

}  // namespace xml
}  // namespace candela
