// The parser core of the Mitsuba 3 XML reader (parser.h): document structure, defaults and $name
// substitution, properties, transforms, ids and refs. It knows no plugin: every object element is
// handed to its family (plugins.h).
#include "scene/xml/parser.h"
#include <glm/gtc/matrix_transform.hpp>
#include <algorithm>
#include <fstream>
#include "scene/obj.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

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

}  // namespace

XmlLoader::XmlLoader(std::string path, const Defines& defines) : path_(std::move(path)) {
    size_t slash = path_.find_last_of('/');
    dir_ = slash == std::string::npos ? std::string() : path_.substr(0, slash + 1);
    for (const auto& d : defines) vars_[d.first] = d.second;
}

const std::string& XmlLoader::file_of(pugi::xml_node) const { return path_; }

int XmlLoader::line(pugi::xml_node n) const { return line_of_offset(n.offset_debug()); }

int XmlLoader::line_of_offset(ptrdiff_t offset) const {
    if (offset < 0) return 0;
    return 1 + int(std::upper_bound(line_starts_.begin(), line_starts_.end(), size_t(offset)) - line_starts_.begin());
}

std::string XmlLoader::resolve(pugi::xml_node, const std::string& file) const {
    return (!file.empty() && file[0] == '/') ? file : dir_ + file;
}

std::string XmlLoader::attr(pugi::xml_node n, const char* name) const {
    pugi::xml_attribute a = n.attribute(name);
    return a ? substitute(n, a.value()) : std::string();
}

std::string XmlLoader::required_attr(pugi::xml_node n, const char* name) const {
    if (!n.attribute(name)) throw error(n, "<" + std::string(n.name()) + "> needs a '" + name + "' attribute");
    return attr(n, name);
}

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
    Object o(n, tag, required_attr(n, "type"), line(n), file_of(n));
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
    BsdfFactory make = find_plugin(bsdf_plugins(), o);
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
            found = int(load_bsdf(c.node, "shape" + std::to_string(shape_counter) + ".bsdf"));
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
        if (c.type() != pugi::node_element) continue;
        std::string tag = c.name();
        if (tag == "default") {
            load_default(c);
        } else if (tag == "integrator") {
            if (integrator) throw error(c, "more than one <integrator> (first at line " + std::to_string(line(integrator)) + ")");
            integrator = c;
            load_integrator(*this, c);
        } else if (tag == "sensor") {
            if (sensor) throw error(c, "more than one <sensor> (first at line " + std::to_string(line(sensor)) + ")");
            sensor = c;
            load_sensor(*this, c);
        } else if (tag == "bsdf") {
            register_id(c, "bsdf");
            IdEntry* e = c.attribute("id") ? &ids_[attr(c, "id")] : nullptr;
            if (!e || e->material < 0) {
                uint32_t m = load_bsdf(c, "bsdf");
                if (e) e->material = int(m);
            }
        } else if (tag == "shape") {
            register_id(c, "shape");
            load_shape(*this, c);
        } else if (tag == "emitter") {
            load_emitter(*this, c);
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
    }
    return std::move(scene_);
}

}  // namespace xml

SceneDescription load_mitsuba_xml(const std::string& path, const Defines& defines) {
    xml::XmlLoader loader(path, defines);
    return loader.load();
}

}  // namespace candela
