// The texture family of the XML reader: Mitsuba 3's `bitmap`, `checkerboard` and
// `mesh_attribute`, and the constant spectra `srgb`, `d65`, `uniform`, `rawconstant`, as nested elements of the plugins that take them or as top-level elements
// referenced by id.
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

Texture make_bitmap(XmlLoader& L, Object& o) {
    BitmapTexture t;
    const std::string file = o.params.get_string("filename", "");
    if (file.empty()) throw L.error(o.node, "bitmap needs a filename");
    const bool raw = o.params.get_bool("raw", false);
    const std::string path = L.resolve(o.node, file);
    try {
        t.texels = load_texels(path, raw);
    } catch (const Error& e) {
        throw o.params.error("filename", e.what());  // the image's problem, at the scene's line
    }
    const std::string filter = o.params.get_string("filter_type", "bilinear");
    if (filter == "bilinear") t.filter = TextureFilter::Bilinear;
    else if (filter == "nearest") t.filter = TextureFilter::Nearest;
    else throw o.params.error("filter_type", "filter_type must be bilinear or nearest, not '" + filter + "'");
    const std::string wrap = o.params.get_string("wrap_mode", "repeat");
    if (wrap == "repeat") t.wrap = TextureWrap::Repeat;
    else if (wrap == "mirror") t.wrap = TextureWrap::Mirror;
    else if (wrap == "clamp") t.wrap = TextureWrap::Clamp;
    else throw o.params.error("wrap_mode", "wrap_mode must be repeat, mirror or clamp, not '" + wrap + "'");
    t.to_uv = UvTransform::from_mat4(o.params.get_transform("to_uv", mat4(1.f)));
    t.name = file;
    return Texture{t};
}

Texture make_checkerboard(XmlLoader& L, Object& o) {
    CheckerboardTexture t;
    t.color0 = rgb_or_texture(L, o, "color0", vec3(0.4f));
    t.color1 = rgb_or_texture(L, o, "color1", vec3(0.2f));
    t.to_uv = UvTransform::from_mat4(o.params.get_transform("to_uv", mat4(1.f)));
    return Texture{t};
}

Texture make_mesh_attribute(XmlLoader&, Object& o) {
    MeshAttributeTexture t;
    t.name = o.params.get_string("name", "");
    if (t.name != "vertex_color")
        throw o.params.error("name", "mesh_attribute '" + t.name + "' is not supported (only vertex_color)");
    if (o.params.has("scale") && o.params.get_float("scale", 1.f) != 1.f)
        throw o.params.error("scale", "mesh_attribute scale is not supported");
    return Texture{t};
}

// Mitsuba's constant spectra, which its RGB variants evaluate as these colours (measured with
// 3.9.1's scalar_rgb: srgb and d65 give their colour, d65 times its scale, uniform and rawconstant
// their value).
Texture make_srgb(XmlLoader& L, Object& o) {
    if (!o.params.has("color")) throw L.error(o.node, "srgb needs a 'color'");
    const vec3 c = o.params.get_rgb("color", vec3(0.f));
    const bool unbounded = o.params.get_bool("unbounded", false);
    if (!all_finite(c) || (!unbounded && !(min_component(c) >= 0.f && max_component(c) <= 1.f)))
        throw o.params.error("color", unbounded ? "color must be finite"
                                                : "a reflectance color must be in [0, 1] (set 'unbounded' for others)");
    return constant_texture(c);
}

Texture make_d65(XmlLoader&, Object& o) {
    const vec3 c = o.params.get_rgb("color", vec3(1.f)) * o.params.get_float("scale", 1.f);
    if (!all_finite(c) || !(min_component(c) >= 0.f)) throw o.params.error("color", "d65 color x scale must be finite and >= 0");
    return constant_texture(c);
}

Texture make_uniform(XmlLoader&, Object& o) {
    const float v = o.params.get_float("value", 1.f);
    if (!std::isfinite(v)) throw o.params.error("value", "value must be finite");
    return constant_texture(vec3(v));
}

Texture make_rawconstant(XmlLoader& L, Object& o) {
    if (!o.params.has("value")) throw L.error(o.node, "rawconstant needs a 'value'");
    const vec3 c = o.params.get_rgb("value", vec3(0.f));
    if (!all_finite(c)) throw o.params.error("value", "value must be finite");
    return constant_texture(c);
}

}  // namespace

const PluginTable<TextureFactory>& texture_plugins() {
    static const PluginTable<TextureFactory> table = {
        {"bitmap", make_bitmap},
        {"checkerboard", make_checkerboard},
        {"mesh_attribute", make_mesh_attribute},
        {"srgb", make_srgb},
        {"d65", make_d65},
        {"uniform", make_uniform},
        {"rawconstant", make_rawconstant},
    };
    return table;
}

std::shared_ptr<const Texture> load_texture(XmlLoader& L, pugi::xml_node n) {
    auto it = L.textures.find(n.internal_object());
    if (it != L.textures.end()) return it->second;
    Object o = L.read_object(n, "texture");
    TextureFactory make = L.find_plugin(texture_plugins(), o);
    auto t = std::make_shared<const Texture>(make(L, o));
    L.finish(o);
    L.textures[n.internal_object()] = t;
    return t;
}

std::shared_ptr<const Texture> nested_texture(XmlLoader& L, Object& o, const std::string& name) {
    for (Nested& c : o.nested) {
        if (c.used || (c.tag != "texture" && c.tag != "ref")) continue;
        if (L.attr(c.node, "name") != name) continue;
        if (c.tag == "ref" && L.object_by_id(c.node, L.attr(c.node, "id"), "").tag != "texture") continue;
        c.used = true;
        return load_texture(L, L.definition(c, "texture"));
    }
    return nullptr;
}

std::shared_ptr<const Texture> rgb_or_texture(XmlLoader& L, Object& o, const std::string& name, vec3 def) {
    if (auto t = nested_texture(L, o, name)) {
        if (o.params.has(name)) throw o.params.error(name, "'" + name + "' is given both as a value and as a texture");
        return t;
    }
    return std::make_shared<const Texture>(constant_texture(o.params.get_rgb(name, def)));
}

}  // namespace xml
}  // namespace candela
