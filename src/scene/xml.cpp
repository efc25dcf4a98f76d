// Mitsuba 3 XML subset (docs/scene-format.md): every element is either understood exactly as
// Mitsuba understands it, or rejected with file:line. Silently ignoring a parameter would render
// a different image than the Mitsuba reference of the same file.
#include <pugixml.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include "core/error.h"
#include "core/interrupt.h"
#include "scene/loaders.h"
#include "scene/obj.h"
#include "scene/params.h"
#include "scene/plugins/render_factories.h"

namespace candela {

namespace {

bool is_property_tag(const std::string& t) {
    return t == "integer" || t == "float" || t == "boolean" || t == "string" || t == "rgb" || t == "point" ||
           t == "vector" || t == "transform";
}
ParamType property_type(const std::string& t) {
    if (t == "integer") return ParamType::Integer;
    if (t == "float") return ParamType::Float;
    if (t == "boolean") return ParamType::Boolean;
    if (t == "string") return ParamType::String;
    if (t == "rgb") return ParamType::Rgb;
    if (t == "point") return ParamType::Point;
    if (t == "vector") return ParamType::Vector;
    return ParamType::Transform;
}
bool is_object_tag(const std::string& t) {
    return t == "bsdf" || t == "emitter" || t == "shape" || t == "sensor" || t == "film" || t == "sampler" ||
           t == "rfilter" || t == "integrator" || t == "texture" || t == "medium" || t == "phase" || t == "volume";
}
// Mitsuba tags that candela does not read (a clearer message than "unknown tag").
bool is_unsupported_mitsuba_tag(const std::string& t) {
    return t == "spectrum" || t == "include" || t == "alias" || t == "path" || t == "resource";
}

// A child object element (<bsdf>, <film>, <ref>...) of an object; the factory must consume it.
struct Nested {
    pugi::xml_node node;
    std::string tag;
    bool used = false;
};

// One object element as its factory sees it: parameters plus nested objects and refs.
struct Object {
    pugi::xml_node node;
    std::string tag, type;
    int line = 0;
    ParamSet params;
    std::vector<Nested> nested;

    Object(pugi::xml_node n, std::string tg, std::string ty, int ln, const std::string& file)
        : node(n), tag(std::move(tg)), type(std::move(ty)), line(ln), params(file, tag + " '" + type + "'") {}
    std::string what() const { return tag + " '" + type + "'"; }
};

class XmlLoader;
using BsdfFactory = Material (*)(XmlLoader&, Object&);
struct ShapeGeometry {
    std::vector<vec3> positions, normals;  // object space; normals empty or per vertex
    std::vector<uvec3> triangles;
    // Mitsuba's rectangle and cube: under a mirroring to_world their geometric normal follows the
    // transformed winding but their shading normal is to_world^-T n_local, so the two disagree
    // (Mitsuba 3.9 checked). `normals` then become vertex normals, and are dropped otherwise.
    bool analytic = false;
    bool recompute_normals = false;  // obj without normals, face_normals false (Mitsuba's default)
};
using ShapeFactory = ShapeGeometry (*)(XmlLoader&, Object&);

Material make_diffuse(XmlLoader& L, Object& o);
// BSDFs of issue 5 (materials): defined after make_diffuse.
Material make_conductor(XmlLoader& L, Object& o);
Material make_roughconductor(XmlLoader& L, Object& o);
Material make_plastic(XmlLoader& L, Object& o);
Material make_roughplastic(XmlLoader& L, Object& o);
Material make_dielectric(XmlLoader& L, Object& o);
Material make_roughdielectric(XmlLoader& L, Object& o);
Material make_twosided(XmlLoader& L, Object& o);
ShapeGeometry make_obj(XmlLoader& L, Object& o);
ShapeGeometry make_rectangle(XmlLoader& L, Object& o);
ShapeGeometry make_cube(XmlLoader& L, Object& o);

// The extension points: one factory per plugin type. A new BSDF (conductor, plastic, twosided...)
// is one function plus one row here; its type then disappears from kPlannedBsdfs.
const std::pair<const char*, BsdfFactory> kBsdfPlugins[] = {
    {"diffuse", make_diffuse},
    {"conductor", make_conductor},
    {"roughconductor", make_roughconductor},
    {"plastic", make_plastic},
    {"roughplastic", make_roughplastic},
    {"dielectric", make_dielectric},
    {"roughdielectric", make_roughdielectric},
    {"twosided", make_twosided},
};
const std::pair<const char*, ShapeFactory> kShapePlugins[] = {
    {"obj", make_obj},
    {"rectangle", make_rectangle},
    {"cube", make_cube},
};

class XmlLoader {
public:
    XmlLoader(std::string path, const Defines& defines) : path_(std::move(path)) {
        size_t slash = path_.find_last_of('/');
        dir_ = slash == std::string::npos ? std::string() : path_.substr(0, slash + 1);
        for (const auto& d : defines) vars_[d.first] = d.second;
    }

    SceneDescription load();

    // ---- helpers the factories use ----
    const std::string& path() const { return path_; }
    int line(pugi::xml_node n) const { return line_of_offset(n.offset_debug()); }
    Error error(pugi::xml_node n, const std::string& what) const { return Error(path_, line(n), what); }
    std::string resolve(const std::string& file) const {
        return (!file.empty() && file[0] == '/') ? file : dir_ + file;
    }
    uint32_t material_for(Object& shape);
    // The one <bsdf> (or <ref> to one) nested in a wrapper such as twosided, built by its factory.
    Material nested_bsdf(Object& wrapper);

private:
    int line_of_offset(ptrdiff_t offset) const {
        if (offset < 0) return 0;
        return 1 + int(std::upper_bound(line_starts_.begin(), line_starts_.end(), size_t(offset)) - line_starts_.begin());
    }
    std::string substitute(pugi::xml_node n, const std::string& text) const;
    std::string attr(pugi::xml_node n, const char* name) const {
        pugi::xml_attribute a = n.attribute(name);
        return a ? substitute(n, a.value()) : std::string();
    }
    std::string required_attr(pugi::xml_node n, const char* name) const {
        if (!n.attribute(name)) throw error(n, "<" + std::string(n.name()) + "> needs a '" + name + "' attribute");
        return attr(n, name);
    }
    void check_attributes(pugi::xml_node n, std::initializer_list<const char*> allowed) const;
    void check_text(pugi::xml_node n) const;
    std::vector<float> numbers(pugi::xml_node n, const char* name, std::initializer_list<size_t> counts) const;

    Object read_object(pugi::xml_node n, const std::string& expected_tag);
    void finish(Object& o) const;  // unused parameters and nested objects are errors
    Param read_property(pugi::xml_node n) const;
    mat4 read_transform(pugi::xml_node n) const;

    void load_default(pugi::xml_node n);
    void load_integrator(pugi::xml_node n);
    void load_sensor(pugi::xml_node n);
    void load_film(pugi::xml_node n);
    void load_sampler(pugi::xml_node n);
    uint32_t load_bsdf(pugi::xml_node n, const std::string& fallback_name);
    uint32_t bsdf_by_id(pugi::xml_node ref_node, const std::string& id);
    void load_shape(pugi::xml_node n);
    void register_id(pugi::xml_node n, const std::string& tag);

    std::string path_, dir_;
    std::vector<size_t> line_starts_;  // byte offsets where lines 2, 3, ... begin
    std::map<std::string, std::string> vars_;
    struct IdEntry {
        std::string tag;
        int line = 0;
        pugi::xml_node node;
        int material = -1;  // bsdfs: the material once created
    };
    std::map<std::string, IdEntry> ids_;
    // The bsdfs being built, outermost first: wrappers (twosided) recurse through nested bsdfs and
    // refs, so a ref cycle or a deep nest must be an error before it is a stack overflow.
    std::vector<pugi::xml_node> bsdf_stack_;
    static constexpr size_t kMaxBsdfNesting = 64;
    SceneDescription scene_;
    int shape_counter_ = 0;
};

std::string XmlLoader::substitute(pugi::xml_node n, const std::string& text) const {
    if (text.find('$') == std::string::npos) return text;
    std::string out;
    for (size_t i = 0; i < text.size();) {
        if (text[i] != '$') {
            out += text[i++];
            continue;
        }
        size_t j = i + 1;
        while (j < text.size() && (std::isalnum((unsigned char)text[j]) || text[j] == '_')) ++j;
        std::string name = text.substr(i + 1, j - i - 1);
        if (name.empty()) throw error(n, "'$' without a parameter name in '" + text + "'");
        auto it = vars_.find(name);
        if (it == vars_.end())
            throw error(n, "undefined parameter $" + name + " (add <default name=\"" + name +
                               "\" value=\"...\"/> or pass -D " + name + "=...)");
        out += it->second;
        i = j;
    }
    return out;
}

void XmlLoader::check_attributes(pugi::xml_node n, std::initializer_list<const char*> allowed) const {
    for (pugi::xml_attribute a : n.attributes()) {
        bool ok = false;
        for (const char* name : allowed) ok = ok || std::string(a.name()) == name;
        if (!ok) throw error(n, "unexpected attribute '" + std::string(a.name()) + "' in <" + n.name() + ">");
    }
}

// Text inside elements means nothing in Mitsuba's format; it is usually a broken tag.
void XmlLoader::check_text(pugi::xml_node n) const {
    for (pugi::xml_node c : n.children())
        if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata)
            throw error(n, "unexpected text '" + std::string(c.value()).substr(0, 40) + "' in <" + n.name() + ">");
}

std::vector<float> XmlLoader::numbers(pugi::xml_node n, const char* name, std::initializer_list<size_t> counts) const {
    std::string text = required_attr(n, name);
    std::vector<float> v;
    try {
        v = parse_float_list(text);
    } catch (const std::invalid_argument&) {
        throw error(n, "could not parse '" + text + "' as numbers in attribute '" + name + "'");
    }
    if (std::find(counts.begin(), counts.end(), v.size()) == counts.end()) {
        std::string want;
        for (size_t c : counts) want += (want.empty() ? "" : " or ") + std::to_string(c);
        throw error(n, "attribute '" + std::string(name) + "' of <" + n.name() + "> needs " + want + " numbers, got " +
                           std::to_string(v.size()));
    }
    return v;
}

Param XmlLoader::read_property(pugi::xml_node n) const {
    std::string tag = n.name();
    Param p;
    p.type = property_type(tag);
    p.line = line(n);
    p.name = required_attr(n, "name");
    if (p.type == ParamType::Transform) {
        check_attributes(n, {"name"});
        p.transform = read_transform(n);
        return p;
    }
    check_text(n);
    if (n.first_child()) throw error(n.first_child(), "unexpected <" + std::string(n.first_child().name()) + "> in <" + tag + ">");
    if (p.type == ParamType::Point || p.type == ParamType::Vector) {
        check_attributes(n, {"name", "value", "x", "y", "z"});
        if (n.attribute("value")) {
            p.value = attr(n, "value");
        } else {
            p.value = (n.attribute("x") ? attr(n, "x") : "0") + " " + (n.attribute("y") ? attr(n, "y") : "0") + " " +
                      (n.attribute("z") ? attr(n, "z") : "0");
        }
        return p;
    }
    check_attributes(n, {"name", "value"});
    p.value = required_attr(n, "value");
    return p;
}

// Each operation is applied after the previous ones (M = op * M), as in Mitsuba.
mat4 XmlLoader::read_transform(pugi::xml_node n) const {
    check_text(n);
    mat4 m(1.f);
    for (pugi::xml_node c : n.children()) {
        if (c.type() != pugi::node_element) continue;
        std::string op = c.name();
        check_text(c);
        if (c.first_child()) throw error(c, "unexpected child element in <" + op + ">");
        mat4 t(1.f);
        // x/y/z attributes, or value="x y z"; `def` fills missing components.
        auto xyz = [&](float def, bool value_may_be_scalar) {
            if (c.attribute("value")) {
                if (c.attribute("x") || c.attribute("y") || c.attribute("z"))
                    throw error(c, "<" + op + "> takes either 'value' or x/y/z attributes, not both");
                std::vector<float> v = value_may_be_scalar ? numbers(c, "value", {1, 3}) : numbers(c, "value", {3});
                return v.size() == 1 ? vec3(v[0]) : vec3(v[0], v[1], v[2]);
            }
            vec3 r(def);
            const char* names[3] = {"x", "y", "z"};
            for (int k = 0; k < 3; ++k)
                if (c.attribute(names[k])) r[k] = numbers(c, names[k], {1})[0];
            return r;
        };
        if (op == "translate") {
            check_attributes(c, {"x", "y", "z", "value"});
            t = glm::translate(mat4(1.f), xyz(0.f, false));
        } else if (op == "scale") {
            check_attributes(c, {"x", "y", "z", "value"});
            t = glm::scale(mat4(1.f), xyz(1.f, true));
        } else if (op == "rotate") {
            check_attributes(c, {"x", "y", "z", "value", "angle"});
            vec3 axis = xyz(0.f, false);
            float angle = c.attribute("angle") ? numbers(c, "angle", {1})[0] : 0.f;
            if (!(glm::length(axis) > 0.f)) throw error(c, "<rotate> needs a non-zero axis (x, y, z or value)");
            t = glm::rotate(mat4(1.f), glm::radians(angle), glm::normalize(axis));
        } else if (op == "matrix") {
            check_attributes(c, {"value"});
            std::vector<float> v = numbers(c, "value", {16, 9});
            int k = v.size() == 16 ? 4 : 3;
            for (int r = 0; r < k; ++r)
                for (int col = 0; col < k; ++col) t[col][r] = v[size_t(r * k + col)];  // row-major text
        } else if (op == "lookat") {
            check_attributes(c, {"origin", "target", "up"});
            std::vector<float> o = numbers(c, "origin", {3}), tg = numbers(c, "target", {3}), up = numbers(c, "up", {3});
            vec3 origin(o[0], o[1], o[2]), target(tg[0], tg[1], tg[2]), upv(up[0], up[1], up[2]);
            vec3 dir = target - origin;
            if (!(glm::length(dir) > 0.f)) throw error(c, "<lookat> target equals origin");
            vec3 side = glm::cross(upv, glm::normalize(dir));
            if (!(glm::length(side) > 1e-6f * std::max(1.f, glm::length(upv))))
                throw error(c, "<lookat> up vector is zero or parallel to the viewing direction");
            t = look_at(origin, target, upv);
        } else {
            throw error(c, "unknown transform operation <" + op + "> (expected translate, scale, rotate, matrix or lookat)");
        }
        m = t * m;
    }
    for (int col = 0; col < 4; ++col)
        if (!all_finite(vec3(m[col])) || !std::isfinite(m[col][3])) throw error(n, "transform is not finite");
    return m;
}

Object XmlLoader::read_object(pugi::xml_node n, const std::string& expected_tag) {
    std::string tag = n.name();
    if (tag != expected_tag) throw error(n, "expected <" + expected_tag + ">, found <" + tag + ">");
    check_attributes(n, {"type", "id", "name"});
    Object o(n, tag, required_attr(n, "type"), line(n), path_);
    check_text(n);
    for (pugi::xml_node c : n.children()) {
        if (c.type() != pugi::node_element) continue;
        std::string ct = c.name();
        if (is_property_tag(ct)) {
            o.params.add(read_property(c));
        } else if (is_object_tag(ct) || ct == "ref") {
            o.nested.push_back({c, ct, false});
        } else if (ct == "default") {
            throw error(c, "<default> is only allowed directly inside <scene>");
        } else if (is_unsupported_mitsuba_tag(ct)) {
            throw error(c, "unsupported tag <" + ct + "> in " + o.what());
        } else {
            throw error(c, "unknown tag <" + ct + "> in " + o.what());
        }
    }
    return o;
}

void XmlLoader::finish(Object& o) const {
    o.params.report_unused();
    for (const Nested& c : o.nested)
        if (!c.used) {
            std::string desc = c.tag == "ref" ? "<ref id=\"" + attr(c.node, "id") + "\">"
                                              : "<" + c.tag + " type=\"" + attr(c.node, "type") + "\">";
            throw error(c.node, "unexpected " + desc + " in " + o.what());
        }
}

void XmlLoader::register_id(pugi::xml_node n, const std::string& tag) {
    if (!n.attribute("id")) return;
    std::string id = attr(n, "id");
    if (id.empty()) throw error(n, "empty id");
    auto it = ids_.find(id);
    if (it != ids_.end()) {
        if (it->second.node == n) return;
        throw error(n, "duplicate id '" + id + "' (first defined at line " + std::to_string(it->second.line) + ")");
    }
    ids_[id] = IdEntry{tag, line(n), n, -1};
}

void XmlLoader::load_default(pugi::xml_node n) {
    check_attributes(n, {"name", "value"});
    check_text(n);
    if (n.first_child()) throw error(n, "<default> has no children");
    std::string name = required_attr(n, "name");
    if (!n.attribute("value")) throw error(n, "<default> needs a 'value' attribute");
    std::string value = attr(n, "value");
    // A -D define (or an earlier <default>, which Mitsuba also keeps) wins.
    vars_.emplace(name, value);
}

void XmlLoader::load_integrator(pugi::xml_node n) {
    // Wrappers (moment, aov) hold the integrator that renders the image: one, read in turn.
    for (int level = 0;; ++level) {
        Object o = read_object(n, "integrator");
        if (read_integrator(o.type, o.params, scene_.settings, o.line) == IntegratorRole::Renders) {
            finish(o);
            return;
        }
        Nested* inner = nullptr;
        for (Nested& c : o.nested) {
            if (c.tag != "integrator") continue;
            if (inner) throw error(c.node, o.what() + " with more than one nested integrator (candela renders one)");
            inner = &c;
        }
        if (!inner) throw error(n, o.what() + " needs a nested <integrator>");
        if (level >= 8) throw error(n, "integrators nested more than 8 deep");
        inner->used = true;
        finish(o);
        n = inner->node;
    }
}

void XmlLoader::load_film(pugi::xml_node n) {
    Object o = read_object(n, "film");
    if (o.type != "hdrfilm") throw error(n, "unsupported film type '" + o.type + "' (candela supports: hdrfilm)");
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
    bool have_filter = false;
    scene_.settings.filter = gaussian_filter();  // Mitsuba's default without an <rfilter>
    for (Nested& c : o.nested) {
        if (c.tag != "rfilter") continue;
        if (have_filter) throw error(c.node, "more than one <rfilter>");
        Object f = read_object(c.node, "rfilter");
        scene_.settings.filter = read_rfilter(f.type, f.params, f.line);
        finish(f);
        c.used = have_filter = true;
    }
    finish(o);
    scene_.settings.width = w;
    scene_.settings.height = h;
}

void XmlLoader::load_sampler(pugi::xml_node n) {
    Object o = read_object(n, "sampler");
    if (o.type != "independent") throw error(n, "unsupported sampler type '" + o.type + "' (candela supports: independent)");
    int spp = o.params.get_int("sample_count", 4);
    int seed = o.params.get_int("seed", 0);
    if (spp <= 0) throw o.params.error("sample_count", "sample_count must be positive");
    if (seed < 0) throw o.params.error("seed", "seed must not be negative");
    finish(o);
    scene_.settings.spp = spp;
    scene_.settings.seed = uint64_t(seed);
}

void XmlLoader::load_sensor(pugi::xml_node n) {
    Object o = read_object(n, "sensor");
    if (o.type != "perspective") throw error(n, "unsupported sensor type '" + o.type + "' (candela supports: perspective)");
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

    scene_.settings.width = 768;  // Mitsuba's film and sampler defaults, when those are absent
    scene_.settings.height = 576;
    scene_.settings.filter = gaussian_filter();
    scene_.settings.spp = 4;
    scene_.settings.seed = 0;
    bool film = false, sampler = false;
    for (Nested& c : o.nested) {
        if (c.tag == "film") {
            if (film) throw error(c.node, "more than one <film> in the sensor");
            load_film(c.node);
            c.used = film = true;
        } else if (c.tag == "sampler") {
            if (sampler) throw error(c.node, "more than one <sampler> in the sensor");
            load_sampler(c.node);
            c.used = sampler = true;
        }
    }
    finish(o);
    scene_.camera = cam;
}

Material make_diffuse(XmlLoader&, Object& o) {
    vec3 r = o.params.get_rgb("reflectance", vec3(0.5f));
    if (!(min_component(r) >= 0.f)) throw o.params.error("reflectance", "reflectance must not be negative");
    return Material{"", DiffuseBsdf{r}, false};  // Mitsuba's BSDFs are one-sided
}

// ---- BSDFs of issue 5 (conductor, plastic, dielectric, twosided) -------------------------------
// Mitsuba 3's parameter names and defaults; what candela does not model (textures, Beckmann,
// anisotropy, named conductor spectra) is an error rather than a silent difference.

// An IOR given as a number or as one of Mitsuba's material names ("bk7", "air", "diamond"...).
float ior_param(Object& o, const std::string& name, float def) {
    if (!o.params.has(name)) return def;
    float v;
    try {
        v = o.params.get_float(name, def);
    } catch (const Error&) {
        std::string s = o.params.get_string(name, "");
        std::optional<float> ior = ior_from_name(s);
        if (!ior) throw o.params.error(name, "unknown index of refraction name '" + s + "'");
        v = *ior;
    }
    if (!(v > 0.f)) throw o.params.error(name, name + " must be positive");
    return v;
}

vec3 nonnegative_rgb(Object& o, const std::string& name, vec3 def) {
    vec3 v = o.params.get_rgb(name, def);
    if (!(min_component(v) >= 0.f)) throw o.params.error(name, name + " must not be negative");
    return v;
}

// GGX roughness: distribution must say ggx (Mitsuba's default is beckmann, which candela lacks).
float microfacet_alpha(Object& o, float def) {
    std::string d = o.params.get_string("distribution", "beckmann");
    if (d != "ggx")
        throw o.params.error("distribution", "distribution '" + d + "' is not supported (only ggx" +
                                                 std::string(o.params.has("distribution") ? "" : "; Mitsuba's default is beckmann") + ")");
    if (o.params.has("alpha_u") || o.params.has("alpha_v"))
        throw o.params.error(o.params.has("alpha_u") ? "alpha_u" : "alpha_v", "anisotropic roughness is not supported");
    if (!o.params.get_bool("sample_visible", true))
        throw o.params.error("sample_visible", "only visible-normal sampling is implemented");
    float a = o.params.get_float("alpha", def);
    if (!(a >= 0.f) || a > 4.f) throw o.params.error("alpha", "alpha must be in [0, 4]");
    return std::max(a, kMinAlpha);  // Mitsuba clamps too; alpha 0 is the smooth plugin's job
}

ConductorBsdf conductor_params(Object& o) {
    ConductorBsdf c;
    std::string material = o.params.get_string("material", "none");
    if (material != "none")
        throw o.params.error("material", "named conductor '" + material + "' is not supported: give eta and k");
    c.eta = nonnegative_rgb(o, "eta", vec3(0.f));
    c.k = nonnegative_rgb(o, "k", vec3(1.f));
    c.specular_reflectance = nonnegative_rgb(o, "specular_reflectance", vec3(1.f));
    return c;
}

Material make_conductor(XmlLoader&, Object& o) {
    return Material{"", conductor_params(o), false};
}

Material make_roughconductor(XmlLoader&, Object& o) {
    ConductorBsdf c = conductor_params(o);
    c.alpha = microfacet_alpha(o, 0.1f);
    return Material{"", c, false};
}

PlasticBsdf plastic_params(Object& o) {
    PlasticBsdf p;
    p.int_ior = ior_param(o, "int_ior", 1.49f);
    p.ext_ior = ior_param(o, "ext_ior", 1.000277f);
    p.diffuse_reflectance = nonnegative_rgb(o, "diffuse_reflectance", vec3(0.5f));
    p.specular_reflectance = nonnegative_rgb(o, "specular_reflectance", vec3(1.f));
    p.nonlinear = o.params.get_bool("nonlinear", false);
    return p;
}

Material make_plastic(XmlLoader&, Object& o) {
    PlasticBsdf p = plastic_params(o);
    p.prepare();
    return Material{"", p, false};
}

Material make_roughplastic(XmlLoader&, Object& o) {
    PlasticBsdf p = plastic_params(o);
    p.alpha = microfacet_alpha(o, 0.1f);
    if (p.int_ior == p.ext_ior) throw o.params.error("int_ior", "int_ior and ext_ior must differ");
    p.prepare();
    return Material{"", p, false};
}

DielectricBsdf dielectric_params(Object& o) {
    DielectricBsdf d;
    d.int_ior = ior_param(o, "int_ior", 1.5046f);
    d.ext_ior = ior_param(o, "ext_ior", 1.000277f);
    if (d.int_ior == d.ext_ior) throw o.params.error("int_ior", "int_ior and ext_ior must differ");
    d.specular_reflectance = nonnegative_rgb(o, "specular_reflectance", vec3(1.f));
    d.specular_transmittance = nonnegative_rgb(o, "specular_transmittance", vec3(1.f));
    return d;
}

Material make_dielectric(XmlLoader&, Object& o) {
    return Material{"", dielectric_params(o), false};
}

Material make_roughdielectric(XmlLoader&, Object& o) {
    DielectricBsdf d = dielectric_params(o);
    d.alpha = microfacet_alpha(o, 0.1f);
    return Material{"", d, false};
}

Material make_twosided(XmlLoader& L, Object& o) {
    Material m = L.nested_bsdf(o);
    if (std::holds_alternative<DielectricBsdf>(m.bsdf))
        throw L.error(o.node, "twosided around a dielectric is meaningless (a dielectric has two sides already)");
    m.two_sided = true;  // the integrator flips the frame to the side the ray comes from
    return m;
}

Material XmlLoader::nested_bsdf(Object& wrapper) {
    Nested* inner = nullptr;
    for (Nested& c : wrapper.nested) {
        if (c.tag != "bsdf" && c.tag != "ref") continue;
        if (inner) throw error(c.node, wrapper.what() + " takes exactly one nested bsdf (candela)");
        inner = &c;
    }
    if (!inner) throw error(wrapper.node, wrapper.what() + " needs a nested <bsdf>");
    inner->used = true;
    if (inner->tag == "ref") {
        check_attributes(inner->node, {"id", "name"});
        return scene_.materials[bsdf_by_id(inner->node, required_attr(inner->node, "id"))];
    }
    register_id(inner->node, "bsdf");
    uint32_t idx = load_bsdf(inner->node, "nested");
    Material m = scene_.materials[idx];
    if (inner->node.attribute("id")) {
        ids_[attr(inner->node, "id")].material = int(idx);  // referable elsewhere: keep it
    } else {
        scene_.materials.pop_back();  // only the wrapper is a material of the scene
    }
    return m;
}

uint32_t XmlLoader::load_bsdf(pugi::xml_node n, const std::string& fallback_name) {
    if (bsdf_stack_.size() >= kMaxBsdfNesting)
        throw error(n, "bsdfs nested more than " + std::to_string(kMaxBsdfNesting) + " deep");
    bsdf_stack_.push_back(n);
    struct Pop {
        std::vector<pugi::xml_node>& stack;
        ~Pop() { stack.pop_back(); }
    } pop{bsdf_stack_};
    Object o = read_object(n, "bsdf");
    BsdfFactory make = nullptr;
    for (const auto& p : kBsdfPlugins)
        if (o.type == p.first) make = p.second;
    if (!make) {
        std::string known;
        for (const auto& p : kBsdfPlugins) known += (known.empty() ? "" : ", ") + std::string(p.first);
        throw error(n, "unsupported bsdf type '" + o.type + "' (candela supports: " + known + ")");
    }
    Material m = make(*this, o);
    finish(o);
    m.name = n.attribute("id") ? attr(n, "id") : fallback_name;
    scene_.materials.push_back(m);
    return uint32_t(scene_.materials.size() - 1);
}

uint32_t XmlLoader::bsdf_by_id(pugi::xml_node ref_node, const std::string& id) {
    auto it = ids_.find(id);
    if (it == ids_.end()) throw error(ref_node, "reference to unknown id '" + id + "'");
    IdEntry& e = it->second;
    if (e.tag != "bsdf")
        throw error(ref_node, "id '" + id + "' is a <" + e.tag + "> (line " + std::to_string(e.line) + "), not a <bsdf>");
    if (e.material < 0 && std::find(bsdf_stack_.begin(), bsdf_stack_.end(), e.node) != bsdf_stack_.end())
        throw error(ref_node, "cyclic reference: bsdf '" + id + "' (line " + std::to_string(e.line) + ") contains itself");
    if (e.material < 0) e.material = int(load_bsdf(e.node, id));  // referenced before its definition
    return uint32_t(e.material);
}

uint32_t XmlLoader::material_for(Object& shape) {
    int found = -1;
    pugi::xml_node first;
    for (Nested& c : shape.nested) {
        if (c.tag != "bsdf" && c.tag != "ref") continue;
        if (found >= 0) throw error(c.node, "a shape takes one bsdf (another was given at line " + std::to_string(line(first)) + ")");
        if (c.tag == "ref") {
            check_attributes(c.node, {"id", "name"});
            check_text(c.node);
            if (c.node.first_child()) throw error(c.node, "<ref> has no children");
            if (c.node.attribute("name") && attr(c.node, "name") != "bsdf")
                throw error(c.node, "a shape's <ref> must be named 'bsdf', not '" + attr(c.node, "name") + "'");
            found = int(bsdf_by_id(c.node, required_attr(c.node, "id")));
        } else {
            register_id(c.node, "bsdf");
            found = int(load_bsdf(c.node, "shape" + std::to_string(shape_counter_) + ".bsdf"));
            if (c.node.attribute("id")) ids_[attr(c.node, "id")].material = found;
        }
        c.used = true;
        first = c.node;
    }
    if (found < 0) {
        // Mitsuba gives such a shape a diffuse BSDF with reflectance 0.5.
        scene_.materials.push_back({"default", DiffuseBsdf{vec3(0.5f)}, false});
        found = int(scene_.materials.size() - 1);
    }
    return uint32_t(found);
}

ShapeGeometry make_obj(XmlLoader& L, Object& o) {
    if (!o.params.has("filename")) throw L.error(o.node, "shape 'obj' needs a 'filename' string");
    std::string file = o.params.get_string("filename", "");
    bool face_normals = o.params.get_bool("face_normals", false);
    o.params.get_bool("flip_tex_coords", true);  // candela reads no texture coordinates
    std::string full = L.resolve(file);
    if (!std::ifstream(full)) throw o.params.error("filename", "cannot open OBJ file '" + file + "' (" + full + ")");
    ObjData obj;
    try {
        obj = read_obj(full, false);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (shape at " + L.path() + ":" + std::to_string(o.line) + ")");
    }
    ShapeGeometry g;
    g.positions = obj.positions;
    for (const ObjGroup& grp : obj.groups) g.triangles.insert(g.triangles.end(), grp.triangles.begin(), grp.triangles.end());
    if (!face_normals) {
        if (obj.all_have_normals()) g.normals = obj.normals;
        else g.recompute_normals = true;
    }
    return g;
}

ShapeGeometry make_rectangle(XmlLoader&, Object&) {
    ShapeGeometry g;
    g.analytic = true;
    g.positions = {vec3(-1.f, -1.f, 0.f), vec3(1.f, -1.f, 0.f), vec3(1.f, 1.f, 0.f), vec3(-1.f, 1.f, 0.f)};
    g.normals.assign(4, vec3(0.f, 0.f, 1.f));
    g.triangles = {uvec3(0, 1, 2), uvec3(0, 2, 3)};  // counter-clockwise seen from +z: normal +z
    return g;
}

ShapeGeometry make_cube(XmlLoader&, Object&) {
    ShapeGeometry g;
    g.analytic = true;
    // Four corners per face (no shared vertices), wound so that every normal points outwards.
    for (int axis = 0; axis < 3; ++axis)
        for (int s = -1; s <= 1; s += 2) {
            vec3 n(0.f);
            n[axis] = float(s);
            vec3 u(0.f), v(0.f);
            u[(axis + 1) % 3] = 1.f;
            v[(axis + 2) % 3] = 1.f;
            if (s < 0) std::swap(u, v);  // keeps cross(u, v) == n
            uint32_t b = uint32_t(g.positions.size());
            g.positions.push_back(n - u - v);
            g.positions.push_back(n + u - v);
            g.positions.push_back(n + u + v);
            g.positions.push_back(n - u + v);
            g.normals.insert(g.normals.end(), 4, n);
            g.triangles.push_back(uvec3(b, b + 1, b + 2));
            g.triangles.push_back(uvec3(b, b + 2, b + 3));
        }
    return g;
}

void XmlLoader::load_shape(pugi::xml_node n) {
    Object o = read_object(n, "shape");
    ShapeFactory make = nullptr;
    for (const auto& p : kShapePlugins)
        if (o.type == p.first) make = p.second;
    if (!make) throw error(n, "unsupported shape type '" + o.type + "' (candela supports: obj, rectangle, cube)");
    ++shape_counter_;
    mat4 m = o.params.get_transform("to_world", mat4(1.f));
    bool flip = o.params.get_bool("flip_normals", false);
    ShapeGeometry g = make(*this, o);
    uint32_t material = material_for(o);

    int32_t emitter = -1;
    for (Nested& c : o.nested) {
        if (c.tag != "emitter") continue;
        if (emitter >= 0) throw error(c.node, "a shape takes one emitter");
        Object e = read_object(c.node, "emitter");
        if (e.type != "area") throw error(c.node, "unsupported emitter type '" + e.type + "' inside a shape (area)");
        vec3 radiance = e.params.get_rgb("radiance", vec3(1.f));
        if (!(min_component(radiance) >= 0.f)) throw e.params.error("radiance", "radiance must not be negative");
        finish(e);
        scene_.emitters.push_back({radiance});
        emitter = int32_t(scene_.emitters.size() - 1);
        c.used = true;
    }
    finish(o);

    // To world space: points by M, normals by the inverse transpose.
    glm::mat3 lin(m);
    if (g.analytic && glm::determinant(lin) > 0.f) g.normals.clear();  // flat: face normals suffice
    glm::mat3 nmat = glm::transpose(glm::inverse(lin));
    for (vec3& p : g.positions) p = vec3(m * glm::vec4(p, 1.f));
    for (vec3& nv : g.normals) {
        vec3 t = nmat * nv;
        float len = glm::length(t);
        nv = len > 0.f ? t / len : vec3(0.f);
    }
    if (!(std::abs(glm::determinant(lin)) > 0.f)) throw o.params.error("to_world", "to_world is singular");
    auto reverse = [&] {
        for (uvec3& t : g.triangles) std::swap(t.y, t.z);
    };
    if (g.recompute_normals) g.normals = compute_vertex_normals(g.positions, g.triangles);
    if (flip) {
        reverse();
        for (vec3& nv : g.normals) nv = -nv;
    }
    std::string name = n.attribute("id") ? attr(n, "id")
                       : o.type == "obj" ? o.params.get_string("filename", "obj")
                                         : o.type + std::to_string(shape_counter_);
    scene_.add_shape(name, g.positions, g.normals, g.triangles, material, emitter);
}

SceneDescription XmlLoader::load() {
    std::ifstream in(path_, std::ios::binary);
    if (!in) throw Error(path_, 0, "cannot open file");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (size_t i = 0; i < text.size(); ++i)
        if (text[i] == '\n') line_starts_.push_back(i + 1);

    pugi::xml_document doc;
    pugi::xml_parse_result res = doc.load_buffer(text.data(), text.size(), pugi::parse_default);
    if (!res) throw Error(path_, line_of_offset(res.offset), std::string("malformed XML: ") + res.description());

    pugi::xml_node root;
    for (pugi::xml_node c : doc.children()) {
        if (c.type() != pugi::node_element) continue;
        if (root) throw error(c, "more than one root element");
        root = c;
    }
    if (!root) throw Error(path_, 0, "no <scene> element");
    if (std::string(root.name()) != "scene") throw error(root, "the root element must be <scene>, not <" + std::string(root.name()) + ">");
    check_attributes(root, {"version"});
    check_text(root);
    if (!root.attribute("version")) throw error(root, "<scene> needs a version attribute (e.g. version=\"3.0.0\")");
    std::string version = attr(root, "version");
    if (version.rfind("3.", 0) != 0 && version.rfind("2.", 0) != 0)
        throw error(root, "unsupported scene version '" + version + "' (this subset follows Mitsuba 3: use 3.x)");

    scene_.source = path_;
    scene_.settings = RenderSettings();
    scene_.settings.max_depth = -1;  // Mitsuba's path integrator defaults
    scene_.settings.rr_depth = 5;

    // Ids first, so that a <ref> may name a bsdf defined further down, as Mitsuba allows.
    for (pugi::xml_node c : root.children())
        if (c.type() == pugi::node_element && c.attribute("id")) {
            try {
                register_id(c, c.name());
            } catch (const Error&) {
                // A $variable in an id may need a <default> that comes later; retried in order below.
                if (std::string(c.attribute("id").value()).find('$') == std::string::npos) throw;
            }
        }

    pugi::xml_node sensor, integrator;
    for (pugi::xml_node c : root.children()) {
        throw_if_interrupted();  // a scene of many shapes; each OBJ polls as it is read
        if (c.type() != pugi::node_element) continue;
        std::string tag = c.name();
        if (tag == "default") {
            load_default(c);
        } else if (tag == "integrator") {
            if (integrator) throw error(c, "more than one <integrator> (first at line " + std::to_string(line(integrator)) + ")");
            integrator = c;
            load_integrator(c);
        } else if (tag == "sensor") {
            if (sensor) throw error(c, "more than one <sensor> (first at line " + std::to_string(line(sensor)) + ")");
            sensor = c;
            load_sensor(c);
        } else if (tag == "bsdf") {
            register_id(c, "bsdf");
            IdEntry* e = c.attribute("id") ? &ids_[attr(c, "id")] : nullptr;
            if (!e || e->material < 0) {
                uint32_t m = load_bsdf(c, "bsdf");
                if (e) e->material = int(m);
            }
        } else if (tag == "shape") {
            register_id(c, "shape");
            load_shape(c);
        } else if (tag == "emitter") {
            Object e = read_object(c, "emitter");
            if (e.type == "area") throw error(c, "an area emitter must be nested inside a <shape>");
            throw error(c, "unsupported emitter type '" + e.type + "' (candela supports area emitters on shapes)");
        } else if (is_property_tag(tag) || tag == "ref") {
            throw error(c, "unexpected <" + tag + "> directly inside <scene>");
        } else if (is_object_tag(tag)) {
            throw error(c, "unsupported element <" + tag + "> (see docs/scene-format.md)");
        } else if (is_unsupported_mitsuba_tag(tag)) {
            throw error(c, "unsupported tag <" + tag + ">");
        } else {
            throw error(c, "unknown tag <" + tag + ">");
        }
    }
    if (!sensor) {
        set_default_camera(scene_);
        scene_.settings.width = 768;
        scene_.settings.height = 576;
        scene_.settings.spp = 4;
        scene_.settings.filter = gaussian_filter();
    }
    return std::move(scene_);
}

}  // namespace

SceneDescription load_mitsuba_xml(const std::string& path, const Defines& defines) {
    XmlLoader loader(path, defines);
    return loader.load();
}

}  // namespace candela
