// The material wrappers of the bsdf family: Mitsuba 3's blendbsdf, mask, bumpmap, normalmap and
// null, building the flat material tree of bsdf.h (Material::blend and friends).
#include "bsdf/wrappers.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

// A float parameter given as a value or as a texture (read through eval_1): the value in `v` (and a
// null texture), or the texture. The value must lie in [0, 1] (Mitsuba clamps textures at lookup).
std::shared_ptr<const Texture> unit_float_or_texture(XmlLoader& L, Object& o, const std::string& name, float& v,
                                                     std::optional<float> def) {
    if (auto t = nested_texture(L, o, name)) {
        if (o.params.has(name)) throw o.params.error(name, "'" + name + "' is given both as a value and as a texture");
        return t;
    }
    if (!def && !o.params.has(name)) throw L.error(o.node, o.what() + " needs '" + name + "' (a float or a texture)");
    v = o.params.get_float(name, def.value_or(0.f));
    if (!(v >= 0.f && v <= 1.f)) throw o.params.error(name, name + " must be in [0, 1]");
    return nullptr;
}

void no_wrapper_inside_blend(XmlLoader& L, Object& o, const Material& m) {
    if (m.masked) throw L.error(o.node, "a mask or null inside blendbsdf is not supported (put the mask around the blend)");
    if (m.perturbation != Perturbation::None)
        throw L.error(o.node, "a bumpmap or normalmap inside blendbsdf is not supported (put it around the blend)");
}

// The child reference of material m's root once its nodes start at `node0` and leaves at `leaf0`.
int shifted(int c, int node0, int leaf0) { return c >= 0 ? c + node0 : -1 - ((-1 - c) + leaf0); }

// (1 - w) a + w b as one material: a new root node over a's and b's trees, laid out flat.
Material blend_of(XmlLoader& L, Object& o, const Material& a, const Material& b, float w,
                  std::shared_ptr<const Texture> wt) {
    no_wrapper_inside_blend(L, o, a);
    no_wrapper_inside_blend(L, o, b);
    if (a.two_sided != b.two_sided)
        throw L.error(o.node, "blendbsdf of a two-sided and a one-sided BSDF is not supported (wrap the blend in twosided)");
    const int leaves_a = 1 + int(a.extra_leaves.size()), leaves_b = 1 + int(b.extra_leaves.size());
    if (leaves_a + leaves_b > kMaxBlendLeaves)
        throw L.error(o.node, "blendbsdf trees are limited to " + std::to_string(kMaxBlendLeaves) + " BSDFs");
    Material m;
    m.bsdf = a.bsdf;
    m.textures = a.textures;
    m.two_sided = a.two_sided;
    m.extra_leaves = a.extra_leaves;
    m.extra_leaves.push_back(MaterialLeaf{b.bsdf, b.textures});
    m.extra_leaves.insert(m.extra_leaves.end(), b.extra_leaves.begin(), b.extra_leaves.end());
    const int node_a = 1, node_b = 1 + int(a.blend.size());
    BlendNode root;
    root.weight = w;
    root.weight_texture = std::move(wt);
    root.child[0] = a.blend.empty() ? -1 : node_a;
    root.child[1] = b.blend.empty() ? -1 - leaves_a : node_b;
    m.blend.push_back(root);
    for (BlendNode n : a.blend) {
        for (int& c : n.child) c = shifted(c, node_a, 0);
        m.blend.push_back(n);
    }
    for (BlendNode n : b.blend) {
        for (int& c : n.child) c = shifted(c, node_b, leaves_a);
        m.blend.push_back(n);
    }
    return m;
}

Material make_blendbsdf(XmlLoader& L, Object& o) {
    float w = 0.5f;
    std::shared_ptr<const Texture> wt = unit_float_or_texture(L, o, "weight", w, std::nullopt);
    std::vector<Material> inner;
    for (Nested& c : o.nested) {
        if (c.used || (c.tag != "bsdf" && c.tag != "ref")) continue;
        if (inner.size() == 2) throw L.error(c.node, "blendbsdf takes exactly two nested BSDFs");
        inner.push_back(L.nested_bsdf(o, c));
    }
    if (inner.size() != 2) throw L.error(o.node, "blendbsdf takes exactly two nested BSDFs");
    return blend_of(L, o, inner[0], inner[1], w, std::move(wt));
}

Material make_mask(XmlLoader& L, Object& o) {
    float a = 0.5f;  // Mitsuba's default opacity
    std::shared_ptr<const Texture> at = unit_float_or_texture(L, o, "opacity", a, 0.5f);
    Material m = L.nested_bsdf(o);
    if (m.masked) throw L.error(o.node, "a mask inside a mask is not supported");
    m.masked = true;
    m.opacity = a;
    m.opacity_texture = std::move(at);
    return m;
}

Material make_null(XmlLoader&, Object&) {
    Material m{"", DiffuseBsdf{vec3(0.f)}, false};
    m.masked = true;  // opacity 0: every path and shadow ray passes
    m.opacity = 0.f;
    return m;
}

void perturbation_options(XmlLoader& L, Object& o, Material& m) {
    if (m.perturbation != Perturbation::None) throw L.error(o.node, "only one bumpmap or normalmap per material is supported");
    m.shadow_terminator = o.params.get_bool("use_shadowing_function", true);
    m.flip_invalid_normals = o.params.get_bool("flip_invalid_normals", true);
}

Material make_bumpmap(XmlLoader& L, Object& o) {
    // Mitsuba takes the one nested texture whatever its name.
    std::shared_ptr<const Texture> t;
    for (Nested& c : o.nested) {
        if (c.used || (c.tag != "texture" && c.tag != "ref")) continue;
        if (c.tag == "ref" && L.object_by_id(c.node, L.attr(c.node, "id"), "").tag != "texture") continue;
        if (t) throw L.error(c.node, "bumpmap takes exactly one nested texture");
        c.used = true;
        t = load_texture(L, L.definition(c, "texture"));
    }
    if (!t) throw L.error(o.node, "bumpmap needs a nested texture (the height)");
    const float scale = o.params.get_float("scale", 1.f);
    if (!std::isfinite(scale)) throw o.params.error("scale", "scale must be finite");
    Material m = L.nested_bsdf(o);
    perturbation_options(L, o, m);
    m.perturbation = Perturbation::Bump;
    m.perturbation_texture = std::move(t);
    m.bump_scale = scale;
    return m;
}

Material make_normalmap(XmlLoader& L, Object& o) {
    std::shared_ptr<const Texture> t = nested_texture(L, o, "normalmap");
    if (!t) throw L.error(o.node, "normalmap needs a texture named 'normalmap'");
    Material m = L.nested_bsdf(o);
    perturbation_options(L, o, m);
    m.perturbation = Perturbation::Normal;
    m.perturbation_texture = std::move(t);
    return m;
}

}  // namespace

BsdfFactory blendbsdf_factory() { return make_blendbsdf; }
BsdfFactory mask_factory() { return make_mask; }
BsdfFactory null_factory() { return make_null; }
BsdfFactory bumpmap_factory() { return make_bumpmap; }
BsdfFactory normalmap_factory() { return make_normalmap; }

}  // namespace xml
}  // namespace candela
