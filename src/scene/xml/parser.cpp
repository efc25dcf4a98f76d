// The parser core of the Mitsuba 3 XML reader (parser.h): documents and includes, defaults and
// $name substitution, version upgrades, properties (spectra included), transforms, ids and refs.
// It knows no plugin: every object element is handed to its family (plugins.h).
#include "scene/xml/parser.h"
#include <glm/gtc/matrix_transform.hpp>
#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include "core/interrupt.h"
#include "scene/obj.h"
#include "scene/xml/plugins.h"
#include "scene/xml/spectrum.h"

namespace candela {
namespace xml {

namespace fs = std::filesystem;

namespace {

bool is_property_tag(const std::string& t) {
    return t == "integer" || t == "float" || t == "boolean" || t == "string" || t == "rgb" || t == "point" ||
           t == "vector" || t == "transform" || t == "spectrum";
}
ParamType property_type(const std::string& t) {
    if (t == "integer") return ParamType::Integer;
    if (t == "float") return ParamType::Float;
    if (t == "boolean") return ParamType::Boolean;
    if (t == "string") return ParamType::String;
    if (t == "rgb") return ParamType::Rgb;
    if (t == "spectrum") return ParamType::Spectrum;
    if (t == "point") return ParamType::Point;
    if (t == "vector") return ParamType::Vector;
    return ParamType::Transform;
}
bool is_object_tag(const std::string& t) {
    return t == "bsdf" || t == "emitter" || t == "shape" || t == "sensor" || t == "film" || t == "sampler" ||
           t == "rfilter" || t == "integrator" || t == "texture" || t == "medium" || t == "phase" || t == "volume";
}

// Mitsuba's parameters whose spectra are not reflectances (src/core/xml.cpp, is_unbounded_spectrum).
bool is_unbounded_spectrum(const std::string& name) {
    return name == "eta" || name == "k" || name == "int_ior" || name == "ext_ior";
}

std::string dir_of(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

bool is_absolute(const std::string& p) { return !p.empty() && p[0] == '/'; }

bool exists(const std::string& p) {
    std::error_code ec;
    return fs::exists(p, ec);
}

// Mitsuba 3's upgrade of a parameter name written for Mitsuba 0.x: camelCase -> snake_case
// (upgrade_tree: an underscore before each lower->upper step, the upper-case run lowered).
std::string snake_case(std::string name) {
    for (size_t i = 0; i + 1 < name.length(); ++i) {
        if (std::islower((unsigned char)name[i]) && std::isupper((unsigned char)name[i + 1])) {
            name = name.substr(0, i + 1) + "_" + name.substr(i + 1);
            i += 2;
            while (i < name.length() && std::isupper((unsigned char)name[i])) {
                name[i] = char(std::tolower((unsigned char)name[i]));
                ++i;
            }
        }
    }
    return name;
}

// Mitsuba's upgrade_tree for versions before 2.0.0, applied to one document in place.
void upgrade_tree(pugi::xml_node root) {
    for (pugi::xpath_node r : root.select_nodes("//*[@name]")) {
        pugi::xml_node n = r.node();
        if (std::strcmp(n.name(), "default") == 0) continue;
        n.attribute("name").set_value(snake_case(n.attribute("name").value()).c_str());
    }
    for (pugi::xpath_node r : root.select_nodes("//lookAt")) r.node().set_name("lookat");
    for (pugi::xpath_node r : root.select_nodes("//@id")) {
        pugi::xml_attribute a = r.attribute();
        if (a.value()[0] == '_') a.set_value(("ID" + std::string(a.value()) + "__UPGR").c_str());
    }
    for (pugi::xpath_node r : root.select_nodes("//bsdf[@type='diffuse']/*/@name[.='diffuse_reflectance']"))
        r.attribute().set_value("reflectance");
    // uoffset, voffset, uscale, vscale -> a to_uv transform (translate, then scale).
    for (pugi::xpath_node r : root.select_nodes(
             "//node()[float[@name='uoffset' or @name='voffset' or @name='uscale' or @name='vscale']]")) {
        pugi::xml_node n = r.node();
        float offset[2] = {0.f, 0.f}, scale[2] = {1.f, 1.f};
        const char* names[4] = {"uoffset", "voffset", "uscale", "vscale"};
        for (int k = 0; k < 4; ++k) {
            pugi::xml_node f = n.select_node(("float[@name='" + std::string(names[k]) + "']").c_str()).node();
            if (!f) continue;
            float v = 0.f;
            try {
                v = parse_float_strict(f.attribute("value").value());
            } catch (const std::invalid_argument&) {
                continue;  // left in place: reported as it is when read
            }
            (k < 2 ? offset : scale)[k % 2] = v;
            n.remove_child(f);
        }
        pugi::xml_node t = n.append_child("transform");
        t.append_attribute("name") = "to_uv";
        if (offset[0] != 0.f || offset[1] != 0.f) {
            pugi::xml_node e = t.append_child("translate");
            e.append_attribute("x") = std::to_string(offset[0]).c_str();
            e.append_attribute("y") = std::to_string(offset[1]).c_str();
        }
        if (scale[0] != 1.f || scale[1] != 1.f) {
            pugi::xml_node e = t.append_child("scale");
            e.append_attribute("x") = std::to_string(scale[0]).c_str();
            e.append_attribute("y") = std::to_string(scale[1]).c_str();
        }
    }
}

// Mitsuba's coordinate_system(n) (Duff et al. 2017): the first tangent, which lookat uses as
// `up` when none is given.
vec3 first_tangent(vec3 n) {
    float sign = std::copysign(1.f, n.z);
    float a = -1.f / (sign + n.z);
    float b = n.x * n.y * a;
    return vec3(n.x * n.x * a * sign + 1.f, b * sign, -n.x * sign);
}

}  // namespace

XmlLoader::XmlLoader(std::string path, const Defines& defines) : path_(std::move(path)) {
    for (const auto& d : defines) {
        bool seen = false;
        for (auto& v : vars_)
            if (v.first == d.first) v.second = d.second, seen = true;
        if (!seen) vars_.push_back(d);
    }
}

const XmlLoader::Document& XmlLoader::doc_of(pugi::xml_node n) const {
    auto it = doc_by_root_.find(n.root().internal_object());
    return it != doc_by_root_.end() ? *it->second : *docs_.front();
}

const std::string& XmlLoader::file_of(pugi::xml_node n) const { return docs_.empty() ? path_ : doc_of(n).path; }

int XmlLoader::line(pugi::xml_node n) const {
    // Elements made by the version upgrade have no offset: they take their parent's line.
    while (n && n.offset_debug() < 0 && n.parent()) n = n.parent();
    ptrdiff_t offset = n.offset_debug();
    if (offset < 0 || docs_.empty()) return 0;
    const std::vector<size_t>& starts = doc_of(n).line_starts;
    return 1 + int(std::upper_bound(starts.begin(), starts.end(), size_t(offset)) - starts.begin());
}

std::string XmlLoader::resolve(pugi::xml_node from, const std::string& file) const {
    if (is_absolute(file)) return file;
    for (const std::string& dir : search_path_)
        if (exists(dir + file)) return dir + file;
    std::string main = dir_of(path_) + file;
    if (exists(main)) return main;
    std::string local = doc_of(from).dir + file;
    if (exists(local)) return local;
    return main;
}

std::string XmlLoader::attr(pugi::xml_node n, const char* name) const {
    pugi::xml_attribute a = n.attribute(name);
    return a ? std::string(a.value()) : std::string();
}

std::string XmlLoader::required_attr(pugi::xml_node n, const char* name) const {
    if (!n.attribute(name)) throw error(n, "<" + std::string(n.name()) + "> needs a '" + name + "' attribute");
    return attr(n, name);
}

// Mitsuba's rule: the parameters, longest name first, replace every "$name" in the text; a '$'
// left over is an error.
std::string XmlLoader::substitute(pugi::xml_node n, const std::string& text) const {
    if (text.find('$') == std::string::npos) return text;
    std::vector<const std::pair<std::string, std::string>*> order;
    for (const auto& v : vars_) order.push_back(&v);
    std::stable_sort(order.begin(), order.end(), [](auto* a, auto* b) { return a->first.size() > b->first.size(); });
    std::string out = text;
    for (const auto* v : order) {
        std::string key = "$" + v->first;
        for (size_t pos = out.find(key); pos != std::string::npos; pos = out.find(key, pos + v->second.size()))
            out.replace(pos, key.size(), v->second);
    }
    size_t i = out.find('$');
    if (i == std::string::npos) return out;
    size_t j = i + 1;
    while (j < out.size() && (std::isalnum((unsigned char)out[j]) || out[j] == '_')) ++j;
    std::string name = out.substr(i + 1, j - i - 1);
    if (name.empty()) throw error(n, "'$' without a parameter name in '" + text + "'");
    throw error(n, "undefined parameter $" + name + " (add <default name=\"" + name + "\" value=\"...\"/> or pass -D " +
                       name + "=...)");
}

void XmlLoader::substitute_attributes(pugi::xml_node n) {
    for (pugi::xml_attribute a : n.attributes())
        if (std::strchr(a.value(), '$')) a.set_value(substitute(n, a.value()).c_str());
}

void XmlLoader::substitute_tree(pugi::xml_node n) {
    substitute_attributes(n);
    for (pugi::xml_node c : n.children())
        if (c.type() == pugi::node_element) substitute_tree(c);
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

// ---- documents, includes, paths, defaults ------------------------------------------------------

XmlLoader::Document& XmlLoader::parse_document(const std::string& path, pugi::xml_node included_from) {
    auto fail = [&](const std::string& what) -> Error {
        if (included_from) return error(included_from, "included file '" + path + "': " + what);
        return Error(path, 0, what);
    };
    std::error_code ec;
    if (included_from && !fs::is_regular_file(path, ec)) throw fail("not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw fail("cannot open file");
    auto d = std::make_unique<Document>();
    d->path = path;
    d->dir = dir_of(path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw fail("cannot read file");
    for (size_t i = 0; i < text.size(); ++i)
        if (text[i] == '\n') d->line_starts.push_back(i + 1);
    pugi::xml_parse_result res = d->doc.load_buffer(text.data(), text.size(), pugi::parse_default);
    docs_.push_back(std::move(d));
    Document& doc = *docs_.back();
    doc_by_root_[doc.doc.internal_object()] = &doc;
    if (!res) {
        ptrdiff_t off = res.offset;
        int ln = 1 + int(std::upper_bound(doc.line_starts.begin(), doc.line_starts.end(), size_t(off)) - doc.line_starts.begin());
        std::string msg = std::string("malformed XML: ") + res.description();
        if (included_from) msg += " (included at " + file_of(included_from) + ":" + std::to_string(line(included_from)) + ")";
        throw Error(path, ln, msg);
    }
    return doc;
}

// Versions 2.x and 3.x are read as they are; older ones get Mitsuba 3's upgrade rules.
void XmlLoader::check_version(pugi::xml_node root, Document& d, bool required) {
    if (!root.attribute("version")) {
        if (required) throw error(root, "<" + std::string(root.name()) + "> needs a version attribute (e.g. version=\"3.0.0\")");
        return;
    }
    std::string v = root.attribute("version").value();
    d.version = v;
    std::vector<long long> parts;
    try {
        size_t start = 0;
        for (;;) {
            size_t dot = v.find('.', start);
            std::string p = v.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
            if (p.empty() || p.find_first_not_of("0123456789") != std::string::npos) throw std::invalid_argument(p);
            parts.push_back(parse_int_strict(p));
            if (dot == std::string::npos) break;
            start = dot + 1;
        }
    } catch (const std::invalid_argument&) {
        parts.clear();
    }
    if (parts.size() != 3) throw error(root, "could not parse version '" + v + "' (expected major.minor.patch, e.g. 3.0.0)");
    if (parts[0] > 3) throw error(root, "unsupported scene version '" + v + "' (candela reads Mitsuba 3 scenes: 3.x, 2.x, or older with Mitsuba 3's upgrade rules)");
    if (parts[0] < 2) {
        upgrade_tree(root);
        d.upgraded = true;
    }
}

void XmlLoader::load_default(pugi::xml_node n) {
    check_attributes(n, {"name", "value"});
    check_text(n);
    if (n.first_child()) throw error(n, "<default> has no children");
    std::string name = required_attr(n, "name");
    if (name.empty()) throw error(n, "<default> needs a non-empty name");
    if (!n.attribute("value")) throw error(n, "<default> needs a 'value' attribute");
    // A -D define (or an earlier <default>, which Mitsuba also keeps) wins.
    for (const auto& v : vars_)
        if (v.first == name) return;
    vars_.emplace_back(name, attr(n, "value"));
}

// <path value>: a folder searched first (before the earlier ones) for every file named later.
// Relative to the file it is written in, else found through the search path, as Mitsuba. A folder
// that is not there is only a place with nothing to find: a note, and the file is read (Mitsuba
// 3.9 also looks in its working directory, which the scene's author had and candela cannot know).
void XmlLoader::load_path(pugi::xml_node n) {
    check_attributes(n, {"value"});
    check_text(n);
    if (n.first_child()) throw error(n, "<path> has no children");
    std::string value = required_attr(n, "value");
    std::string dir = value;
    if (!is_absolute(value)) {
        dir = doc_of(n).dir + value;
        if (!exists(dir)) dir = resolve(n, value);
    }
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        note(n, "<path>: folder '" + value + "' not found (ignored: files are searched in the other places)");
        return;
    }
    if (dir.back() != '/') dir += '/';
    search_path_.insert(search_path_.begin(), dir);
}

// An included file: relative to the including file, then through the search path.
std::string XmlLoader::find_include(pugi::xml_node from, const std::string& file) const {
    if (is_absolute(file)) return file;
    std::string local = doc_of(from).dir + file;
    if (exists(local)) return local;
    for (const std::string& dir : search_path_)
        if (exists(dir + file)) return dir + file;
    std::string main = dir_of(path_) + file;
    if (exists(main)) return main;
    return std::string();
}

// Mitsuba splices an included <scene>'s children where the <include> stands (at scene level or
// inside an object); a file whose root is one object contributes that object.
void XmlLoader::load_include(pugi::xml_node n, bool scene_level, std::vector<pugi::xml_node>& out, int depth) {
    check_attributes(n, {"filename"});
    check_text(n);
    if (n.first_child()) throw error(n, "<include> has no children");
    std::string file = required_attr(n, "filename");
    std::string path = find_include(n, file);
    if (path.empty()) throw error(n, "included file '" + file + "' not found");
    if (int(include_stack_.size()) > kMaxIncludeDepth)
        throw error(n, "includes nested more than " + std::to_string(kMaxIncludeDepth) + " deep");
    std::error_code ec;
    std::string canon = fs::weakly_canonical(path, ec).string();
    if (ec) canon = path;
    for (const std::string& p : include_stack_)
        if (p == canon) throw error(n, "include cycle: '" + file + "' is already being read (" + canon + ")");
    Document& d = parse_document(path, n);
    pugi::xml_node root;
    for (pugi::xml_node c : d.doc.children()) {
        if (c.type() != pugi::node_element) continue;
        if (root) throw error(c, "more than one root element");
        root = c;
    }
    if (!root) throw Error(path, 0, "no root element (included at " + file_of(n) + ":" + std::to_string(line(n)) + ")");
    include_stack_.push_back(canon);
    std::string rt = root.name();
    if (rt == "scene") {
        check_attributes(root, {"version"});
        check_text(root);
        check_version(root, d, false);
        substitute_attributes(root);
        expand(root, scene_level, out, depth);
    } else if (is_object_tag(rt)) {
        check_version(root, d, true);
        root.remove_attribute("version");
        // Expand the document node itself so that the root object is handled like any child.
        expand(d.doc, scene_level, out, depth);
    } else {
        throw error(root, "the root element of an included file must be <scene> or an object, not <" + rt + ">");
    }
    include_stack_.pop_back();
}

void XmlLoader::expand(pugi::xml_node parent, bool scene_level, std::vector<pugi::xml_node>& out, int depth) {
    for (pugi::xml_node c : parent.children()) {
        if (c.type() != pugi::node_element) continue;
        substitute_attributes(c);
        std::string tag = c.name();
        if (tag == "default") {
            if (!scene_level) throw error(c, "<default> is only allowed directly inside <scene>");
            load_default(c);
        } else if (tag == "path") {
            if (!scene_level) throw error(c, "<path> is only allowed directly inside <scene>");
            load_path(c);
        } else if (tag == "include") {
            load_include(c, scene_level, out, depth + 1);
        } else if (tag == "alias") {
            check_attributes(c, {"id", "as"});
            std::string id = required_attr(c, "id"), as = required_attr(c, "as");
            if (ids_.count(as) || aliases_.count(as)) throw error(c, "duplicate id '" + as + "'");
            aliases_[as] = id;
            ids_[as] = IdEntry{"alias", line(c), c, -1};
        } else {
            for (const char* a : {"id", "name"})
                if (c.attribute(a) && c.attribute(a).value()[0] == '_')
                    throw error(c, std::string("invalid ") + a + " '" + c.attribute(a).value() +
                                       "': a leading underscore is reserved (Mitsuba)");
            out.push_back(c);
            if (is_object_tag(tag)) {
                register_id(c, tag);
                // The pass recurses: a deep nest must be an error before it is a stack overflow.
                int bsdfs = tag == "bsdf" ? 1 : 0;
                if (bsdf_nesting_ + bsdfs > int(kMaxBsdfNesting))
                    throw error(c, "bsdfs nested more than " + std::to_string(kMaxBsdfNesting) + " deep");
                if (object_nesting_ >= kMaxObjectNesting)
                    throw error(c, "objects nested more than " + std::to_string(kMaxObjectNesting) + " deep");
                bsdf_nesting_ += bsdfs;
                ++object_nesting_;
                std::vector<pugi::xml_node> kids;
                expand(c, false, kids, depth);
                bsdf_nesting_ -= bsdfs;
                --object_nesting_;
                children_[c.internal_object()] = std::move(kids);
            } else {
                for (pugi::xml_node g : c.children())
                    if (g.type() == pugi::node_element) substitute_tree(g);
            }
        }
    }
}

const std::vector<pugi::xml_node>& XmlLoader::children(pugi::xml_node n) const {
    static const std::vector<pugi::xml_node> none;
    auto it = children_.find(n.internal_object());
    return it != children_.end() ? it->second : none;
}

// ---- properties --------------------------------------------------------------------------------

Param XmlLoader::read_property(pugi::xml_node n, bool within_emitter) const {
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
    if (p.type == ParamType::Spectrum) return read_spectrum(n, within_emitter);
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

// <spectrum value="v"> is the constant v; <spectrum value="λ1:v1, λ2:v2, ..."> (or
// filename="x.spd", lines "λ v", '#' comments) is converted to linear sRGB as Mitsuba 3.9's RGB
// variants do (spectrum.h). Spectra of emitters and of eta, k, int_ior, ext_ior are unbounded, the
// rest are reflectances.
Param XmlLoader::read_spectrum(pugi::xml_node n, bool within_emitter) const {
    check_attributes(n, {"name", "value", "filename"});
    Param p;
    p.type = ParamType::Spectrum;
    p.line = line(n);
    p.name = required_attr(n, "name");
    bool has_value = bool(n.attribute("value")), has_file = bool(n.attribute("filename"));
    if (has_value == has_file) throw error(n, "<spectrum> needs one of 'value' or 'filename'");
    std::vector<double> wl, vals;
    auto add_pair = [&](const std::string& w, const std::string& v, const std::string& where) {
        try {
            wl.push_back(parse_float_strict(w));
            vals.push_back(parse_float_strict(v));
        } catch (const std::invalid_argument&) {
            throw error(n, "could not parse wavelength:value pair '" + where + "'");
        }
    };
    if (has_value) {
        std::string text = attr(n, "value");
        std::vector<std::string> tokens;
        size_t i = 0;
        while (i < text.size()) {
            size_t j = text.find_first_of(", \t\n\r", i);
            if (j == std::string::npos) j = text.size();
            if (j > i) tokens.push_back(text.substr(i, j - i));
            i = j + 1;
        }
        if (tokens.empty()) throw error(n, "empty <spectrum> value");
        if (tokens.size() == 1 && tokens[0].find(':') == std::string::npos) {
            float v;
            try {
                v = parse_float_strict(tokens[0]);
            } catch (const std::invalid_argument&) {
                throw error(n, "could not parse constant spectrum '" + tokens[0] + "' (a number, or wavelength:value pairs)");
            }
            if (!within_emitter) {
                p.value = tokens[0];  // a uniform reflectance: grey
                return p;
            }
            // Mitsuba 3.9 (Properties::get_texture_impl): a uniform emission spectrum in an RGB
            // variant is v * xyz_to_srgb(1, 1, 1), as the spectral variants would see it.
            vec3 c = xyz_to_linear_srgb(1.0, 1.0, 1.0) * v;
            char buf[96];
            std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g", c.x, c.y, c.z);
            p.value = buf;
            return p;
        }
        if (tokens.size() < 2) throw error(n, "a spectrum needs at least two wavelength:value pairs");
        for (const std::string& t : tokens) {
            size_t colon = t.find(':');
            if (colon == std::string::npos || t.find(':', colon + 1) != std::string::npos)
                throw error(n, "invalid spectrum '" + t + "' (expected wavelength:value pairs)");
            add_pair(t.substr(0, colon), t.substr(colon + 1), t);
        }
    } else {
        std::string file = attr(n, "filename");
        std::string full = resolve(n, file);
        std::error_code ec;
        if (!fs::is_regular_file(full, ec)) throw error(n, "cannot open spectrum file '" + file + "' (" + full + ")");
        std::ifstream in(full);
        std::string row;
        int ln = 0;
        while (std::getline(in, row)) {
            ++ln;
            size_t hash = row.find('#');
            if (hash != std::string::npos) row = row.substr(0, hash);
            std::vector<float> v;
            try {
                v = parse_float_list(row);
            } catch (const std::invalid_argument&) {
                throw Error(full, ln, "could not parse spectrum line '" + row + "' (spectrum at " + file_of(n) + ":" +
                                          std::to_string(line(n)) + ")");
            }
            if (v.empty()) continue;
            if (v.size() != 2)
                throw Error(full, ln, "expected 'wavelength value' (spectrum at " + file_of(n) + ":" + std::to_string(line(n)) + ")");
            wl.push_back(v[0]);
            vals.push_back(v[1]);
        }
        if (wl.size() < 2) throw error(n, "spectrum file '" + file + "' holds fewer than two samples");
    }
    for (size_t k = 1; k < wl.size(); ++k)
        if (!(wl[k] > wl[k - 1])) throw error(n, "spectrum wavelengths must increase");
    vec3 rgb = spectrum_list_to_srgb(wl, vals, !(within_emitter || is_unbounded_spectrum(p.name)), !within_emitter);
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g", rgb.x, rgb.y, rgb.z);
    p.value = buf;
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
        // x/y/z attributes, or value with one number (all three) or three, as Mitsuba's
        // expand_value_to_xyz; `def` fills missing components.
        auto xyz = [&](float def) {
            if (c.attribute("value")) {
                if (c.attribute("x") || c.attribute("y") || c.attribute("z"))
                    throw error(c, "<" + op + "> takes either 'value' or x/y/z attributes, not both");
                std::vector<float> v = numbers(c, "value", {1, 3});
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
            t = glm::translate(mat4(1.f), xyz(0.f));
        } else if (op == "scale") {
            check_attributes(c, {"x", "y", "z", "value"});
            t = glm::scale(mat4(1.f), xyz(1.f));
        } else if (op == "rotate") {
            check_attributes(c, {"x", "y", "z", "value", "angle"});
            vec3 axis = xyz(0.f);
            float angle = c.attribute("angle") ? numbers(c, "angle", {1})[0] : 0.f;
            if (!(glm::length(axis) > 0.f)) throw error(c, "<rotate> needs a non-zero axis (x, y, z or value)");
            // Mitsuba 3.9's matrix, c I + s [a]x + (1 - c) a a^T, with the axis a as given: for a
            // non-unit axis that is not a rotation (it also scales and shears), but published
            // scenes (mdata_hello_teapot) rely on it, so candela builds the same matrix.
            const float rad = glm::radians(angle), s = std::sin(rad), co = std::cos(rad);
            const vec3 a = axis;
            t = mat4(1.f);
            for (int r = 0; r < 3; ++r)
                for (int col = 0; col < 3; ++col) t[col][r] = (1.f - co) * a[r] * a[col] + (r == col ? co : 0.f);
            t[1][0] -= s * a.z, t[2][0] += s * a.y;  // the cross-product matrix [a]x, times sin
            t[0][1] += s * a.z, t[2][1] -= s * a.x;
            t[0][2] -= s * a.y, t[1][2] += s * a.x;
        } else if (op == "matrix") {
            check_attributes(c, {"value"});
            std::vector<float> v = numbers(c, "value", {16, 9});
            int k = v.size() == 16 ? 4 : 3;
            for (int r = 0; r < k; ++r)
                for (int col = 0; col < k; ++col) t[col][r] = v[size_t(r * k + col)];  // row-major text
        } else if (op == "lookat") {
            check_attributes(c, {"origin", "target", "up"});
            std::vector<float> o = numbers(c, "origin", {3}), tg = numbers(c, "target", {3});
            std::vector<float> up = c.attribute("up") ? numbers(c, "up", {3}) : std::vector<float>{0.f, 0.f, 0.f};
            vec3 origin(o[0], o[1], o[2]), target(tg[0], tg[1], tg[2]), upv(up[0], up[1], up[2]);
            vec3 dir = target - origin;
            if (!(glm::length(dir) > 0.f)) throw error(c, "<lookat> target equals origin");
            if (glm::dot(upv, upv) == 0.f) upv = first_tangent(glm::normalize(dir));  // Mitsuba's default up
            vec3 side = glm::cross(upv, glm::normalize(dir));
            if (!(glm::length(side) > 1e-6f * std::max(1.f, glm::length(upv))))
                throw error(c, "<lookat> up vector is parallel to the viewing direction");
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
    for (pugi::xml_node c : children(n)) {
        std::string ct = c.name();
        if (is_property_tag(ct)) {
            o.params.add(read_property(c, tag == "emitter"));
        } else if (is_object_tag(ct) || ct == "ref") {
            o.nested.push_back({c, ct, false});
        } else if (ct == "resource") {
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

// ---- ids and references ------------------------------------------------------------------------

void XmlLoader::register_id(pugi::xml_node n, const std::string& tag) {
    if (!n.attribute("id")) return;
    std::string id = attr(n, "id");
    if (id.empty()) throw error(n, "empty id");
    auto it = ids_.find(id);
    if (it != ids_.end()) {
        if (it->second.node == n) return;
        const std::string& f = file_of(it->second.node);
        throw error(n, "duplicate id '" + id + "' (first defined at " + (f == file_of(n) ? "" : f + ":") + "line " +
                           std::to_string(it->second.line) + ")");
    }
    ids_[id] = IdEntry{tag, line(n), n, -1};
}

XmlLoader::IdEntry& XmlLoader::object_by_id(pugi::xml_node ref_node, const std::string& id0, const std::string& tag) {
    std::string id = id0;
    for (int hops = 0; aliases_.count(id) && hops < 64; ++hops) id = aliases_[id];
    auto it = ids_.find(id);
    if (it == ids_.end() || it->second.tag == "alias") throw error(ref_node, "reference to unknown id '" + id0 + "'");
    IdEntry& e = it->second;
    if (!tag.empty() && e.tag != tag) {
        const std::string& f = file_of(e.node);
        throw error(ref_node, "id '" + id0 + "' is a <" + e.tag + "> (" + (f == file_of(ref_node) ? "" : f + ":") + "line " +
                                  std::to_string(e.line) + "), not a <" + tag + ">");
    }
    return e;
}

pugi::xml_node XmlLoader::definition(const Nested& c, const std::string& tag) {
    if (c.tag != "ref") return c.node;
    check_attributes(c.node, {"id", "name"});
    check_text(c.node);
    if (c.node.first_child()) throw error(c.node, "<ref> has no children");
    return object_by_id(c.node, required_attr(c.node, "id"), tag).node;
}

// ---- bsdfs -------------------------------------------------------------------------------------

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

// A <bsdf> element, built once: one with an id may have been built already through a <ref>.
uint32_t XmlLoader::bsdf_element(pugi::xml_node n, const std::string& fallback_name) {
    if (!n.attribute("id")) return load_bsdf(n, fallback_name);
    IdEntry& e = ids_.at(attr(n, "id"));
    if (e.material < 0) e.material = int(load_bsdf(n, fallback_name));
    return uint32_t(e.material);
}

uint32_t XmlLoader::bsdf_by_id(pugi::xml_node ref_node, const std::string& id) {
    IdEntry& e = object_by_id(ref_node, id, "bsdf");
    if (e.material < 0 && std::find(bsdf_stack_.begin(), bsdf_stack_.end(), e.node) != bsdf_stack_.end())
        throw error(ref_node, "cyclic reference: bsdf '" + id + "' (line " + std::to_string(e.line) + ") contains itself");
    if (e.material < 0) e.material = int(load_bsdf(e.node, attr(e.node, "id")));  // referenced before its definition
    return uint32_t(e.material);
}

Material XmlLoader::nested_bsdf(Object& wrapper) {
    Nested* inner = nullptr;
    for (Nested& c : wrapper.nested) {
        if (c.tag != "bsdf" && c.tag != "ref") continue;
        if (inner) throw error(c.node, wrapper.what() + " takes exactly one nested bsdf (candela)");
        inner = &c;
    }
    if (!inner) throw error(wrapper.node, wrapper.what() + " needs a nested <bsdf>");
    return nested_bsdf(wrapper, *inner);
}

Material XmlLoader::nested_bsdf(Object&, Nested& c) {
    Nested* inner = &c;
    inner->used = true;
    if (inner->tag == "ref") {
        definition(*inner, "bsdf");
        return scene_.materials[bsdf_by_id(inner->node, attr(inner->node, "id"))];
    }
    if (inner->node.attribute("id")) return scene_.materials[bsdf_element(inner->node, "nested")];  // referable: kept
    uint32_t idx = load_bsdf(inner->node, "nested");
    Material m = scene_.materials[idx];
    scene_.materials.pop_back();  // only the wrapper is a material of the scene
    return m;
}

// Mitsuba's shape takes its one BSDF among its nested objects whatever their names. A <ref> in a
// shape must name a bsdf: the other objects Mitsuba lets a shape reference (emitters, media,
// sensors) are nested elements in candela.
uint32_t XmlLoader::material_for(Object& shape) {
    int found = -1;
    pugi::xml_node first;
    // A shape's refs name its bsdf or its area emitter (Mitsuba allows both); the emitter is the
    // shape family's to build.
    auto refers_to_emitter = [&](const Nested& c) {
        return c.tag == "ref" && object_by_id(c.node, required_attr(c.node, "id"), "").tag == "emitter";
    };
    for (Nested& c : shape.nested) {
        if (refers_to_emitter(c) || is_medium_child(*this, c)) continue;  // the shape family's
        if (c.tag == "ref") definition(c, "bsdf");
        else if (c.tag != "bsdf") continue;
        if (found >= 0) throw error(c.node, "a shape takes one bsdf (another was given at line " + std::to_string(line(first)) + ")");
        if (c.tag == "ref") {
            found = int(bsdf_by_id(c.node, attr(c.node, "id")));
        } else {
            found = int(bsdf_element(c.node, "shape" + std::to_string(shape_counter) + ".bsdf"));
        }
        c.used = true;
        first = c.node;
    }
    if (found < 0) {
        // Mitsuba gives such a shape a diffuse BSDF with reflectance 0.5, or 0 when it emits
        // (Shape::Shape in Mitsuba 3; checked against 3.9.1): a bare light does not scatter.
        bool emits = false;
        for (const Nested& c : shape.nested) emits = emits || c.tag == "emitter" || refers_to_emitter(c);
        scene_.materials.push_back({"default", DiffuseBsdf{vec3(emits ? 0.f : 0.5f)}, false});
        found = int(scene_.materials.size() - 1);
    }
    return uint32_t(found);
}

// ---- the scene ---------------------------------------------------------------------------------

SceneDescription XmlLoader::load() {
    std::error_code ec;
    Document& d = parse_document(path_, pugi::xml_node());
    pugi::xml_node root;
    for (pugi::xml_node c : d.doc.children()) {
        if (c.type() != pugi::node_element) continue;
        if (root) throw error(c, "more than one root element");
        root = c;
    }
    if (!root) throw Error(path_, 0, "no <scene> element");
    if (std::string(root.name()) != "scene") throw error(root, "the root element must be <scene>, not <" + std::string(root.name()) + ">");
    check_attributes(root, {"version"});
    check_text(root);
    check_version(root, d, true);
    std::string canon = fs::weakly_canonical(path_, ec).string();
    include_stack_.push_back(ec ? path_ : canon);

    scene_.source = path_;
    scene_.settings = RenderSettings();
    scene_.settings.max_depth = -1;  // Mitsuba's path integrator defaults
    scene_.settings.rr_depth = 5;

    try {
        // The whole tree first, in Mitsuba's order: every id is then known, so a <ref> may name an
        // object defined further down or in a later include.
        std::vector<pugi::xml_node> top;
        expand(root, true, top, 0);

        pugi::xml_node sensor, integrator;
        for (pugi::xml_node c : top) {
            throw_if_interrupted();  // a scene of many shapes; each OBJ polls as it is read
            std::string tag = c.name();
            if (tag == "integrator") {
                if (integrator) throw error(c, "more than one <integrator> (first at line " + std::to_string(line(integrator)) + ")");
                integrator = c;
                load_integrator(*this, c);
            } else if (tag == "sensor") {
                if (sensor) throw error(c, "more than one <sensor> (first at line " + std::to_string(line(sensor)) + ")");
                sensor = c;
                load_sensor(*this, c);
            } else if (tag == "bsdf") {
                bsdf_element(c, "bsdf");
            } else if (tag == "shape") {
                load_shape(*this, c);
            } else if (tag == "emitter") {
                load_emitter(*this, c);
            } else if (tag == "texture") {
                load_texture(*this, c);  // checked now; used where a <ref> names it
            } else if (tag == "medium") {
                load_medium(*this, c);  // a medium that shapes or the sensor reference
            } else if (is_property_tag(tag) || tag == "ref") {
                throw error(c, "unexpected <" + tag + "> directly inside <scene>");
            } else if (is_object_tag(tag)) {
                throw error(c, "unsupported element <" + tag + "> (see docs/scene-format.md)");
            } else if (tag == "resource") {
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
        // pssmlt's mutations_per_pixel is the render's sample count, whichever of the sensor and
        // the integrator came first.
        if (scene_.settings.integrator.mlt.mutations_per_pixel > 0)
            scene_.settings.spp = scene_.settings.integrator.mlt.mutations_per_pixel;
    } catch (const Error& e) {
        // What Mitsuba 3's upgrade rules leave for a 0.x/1.x file (other plugin names, parameters
        // that were removed) surfaces as an ordinary error; say which rules were applied.
        for (const auto& doc : docs_)
            if (doc->upgraded)
                throw Error(std::string(e.what()) + " (" + doc->path + " is version " + doc->version +
                            ", read with Mitsuba 3's upgrade rules)");
        throw;
    }
    return std::move(scene_);
}

}  // namespace xml

SceneDescription load_mitsuba_xml(const std::string& path, const Defines& defines) {
    xml::XmlLoader loader(path, defines);
    return loader.load();
}

}  // namespace candela
