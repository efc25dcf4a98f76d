// The medium family of the XML reader: Mitsuba 3's `homogeneous` medium (src/media/homogeneous.cpp)
// with its phase functions `isotropic` and `hg` (src/phase/), and the media that shapes and the
// sensor name. docs/media.md lists what is read and what is refused.
#include <glm/gtc/matrix_transform.hpp>
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

// A medium parameter: a value (float, rgb, spectrum), a nested constvolume, or (heterogeneous media
// only) a nested gridvolume with its world-to-grid transform.
struct MediumValue {
    vec3 value{0.f};
    std::shared_ptr<const VolumeGrid> grid;
    glm::mat4 to_local{1.f};
};

MediumValue medium_value(XmlLoader& L, Object& o, const std::string& name, vec3 def, bool grids) {
    MediumValue out;
    for (Nested& c : o.nested) {
        if (c.tag != "volume" || L.attr(c.node, "name") != name) continue;
        if (o.params.has(name)) throw L.error(c.node, o.what() + ": '" + name + "' given twice");
        Object v = L.read_object(c.node, "volume");
        const glm::mat4 to_world = v.params.get_transform("to_world", glm::mat4(1.f));
        if (v.type == "constvolume") {
            out.value = v.params.get_rgb("value", vec3(1.f));
        } else if (v.type == "gridvolume" && grids) {
            const std::string file = v.params.get_string("filename", "");
            if (file.empty()) throw L.error(c.node, "gridvolume needs a 'filename'");
            const std::string filter = v.params.get_string("filter_type", "trilinear");
            if (filter != "trilinear" && filter != "nearest")
                throw v.params.error("filter_type", "filter_type must be trilinear or nearest");
            const std::string wrap = v.params.get_string("wrap_mode", "clamp");
            if (wrap != "clamp") throw v.params.error("wrap_mode", "candela reads wrap_mode clamp only");
            const bool grid_bbox = v.params.get_bool("use_grid_bbox", false);
            v.params.get_bool("raw", false);    // sRGB to spectrum in Mitsuba's spectral modes: none in RGB
            v.params.get_bool("accel", true);   // Mitsuba's texture storage
            VolumeGrid g;
            try {
                g = read_vol(L.resolve(c.node, file));
            } catch (const Error& e) {
                throw Error(std::string(e.what()) + " (gridvolume at " + L.file_of(c.node) + ":" +
                            std::to_string(L.line(c.node)) + ")");
            }
            g.nearest = filter == "nearest";
            glm::mat4 m = to_world;
            if (grid_bbox) {  // the unit cube onto the file's box, then to_world
                const vec3 e = g.bbox.extent();
                if (!(e.x > 0.f && e.y > 0.f && e.z > 0.f) || !all_finite(e))
                    throw L.error(c.node, "use_grid_bbox: the .vol file's bounding box is empty");
                m = m * glm::translate(glm::mat4(1.f), g.bbox.min) * glm::scale(glm::mat4(1.f), e);
            }
            if (!(std::abs(glm::determinant(glm::mat3(m))) > 0.f)) throw L.error(c.node, "gridvolume's to_world is singular");
            out.to_local = glm::inverse(m);
            out.grid = std::make_shared<const VolumeGrid>(std::move(g));
        } else {
            throw L.error(c.node, "unsupported volume type '" + v.type + "' for " + o.what() + " (candela supports: " +
                                      (grids ? "constvolume, gridvolume" : "constvolume") + ")");
        }
        L.finish(v);
        c.used = true;
        return out;
    }
    out.value = o.params.get_rgb(name, def);
    return out;
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
    const bool heterogeneous = o.type == "heterogeneous";
    if (o.type != "homogeneous" && !heterogeneous)
        throw L.error(n, "unsupported medium type '" + o.type + "' (candela supports: homogeneous, heterogeneous)");
    Medium m;
    m.name = n.attribute("id") ? L.attr(n, "id") : std::string("medium");
    const MediumValue st = medium_value(L, o, "sigma_t", vec3(1.f), heterogeneous);
    const MediumValue al = medium_value(L, o, "albedo", vec3(0.75f), heterogeneous);
    const vec3 sigma_t = st.value;
    m.albedo = al.value;
    const float scale = o.params.get_float("scale", 1.f);
    if (!(scale >= 0.f) || !std::isfinite(scale)) throw o.params.error("scale", "scale must be finite and >= 0");
    m.sigma_t_base = sigma_t;
    m.scale = scale;
    m.sigma_t = sigma_t * scale;
    if (heterogeneous) {
        if (!st.grid) throw L.error(n, o.what() + ": candela reads a heterogeneous medium's sigma_t from a gridvolume");
        if (st.grid->channels != 1)
            throw L.error(n, o.what() + ": a sigma_t grid of 3 channels (colour extinction) is not supported: use one channel");
        for (float v : st.grid->data)
            if (v < 0.f) throw L.error(n, o.what() + ": the sigma_t grid has a negative density (a negative density has no meaning)");
        m.density = st.grid;
        m.density_to_local = st.to_local;
        m.albedo_grid = al.grid;
        m.albedo_to_local = al.to_local;
        if (al.grid)
            for (float v : al.grid->data)
                if (!(v >= 0.f && v <= 1.f)) throw L.error(n, o.what() + ": the albedo grid has values outside [0, 1]");
        refresh_medium(m);  // sigma_t = the majorant: checked below like a homogeneous medium's
        m.albedo = al.grid ? vec3(0.5f) : m.albedo;
    }
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
