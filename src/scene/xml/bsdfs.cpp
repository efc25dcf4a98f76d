// The bsdf family of the XML reader: Mitsuba 3's BSDF plugins as candela Materials.
#include <algorithm>
#include <cmath>
#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"
#include "bsdf/named_conductors.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

// Colour parameters that a texture may drive, per BSDF: Mitsuba's name and where the value goes.
template <class B, vec3 B::*Field>
void set_field(Bsdf& b, vec3 v) { std::get<B>(b).*Field = v; }

struct TexturableParam {
    const char* name;
    void (*apply)(Bsdf&, vec3);
    bool scalar = false;  // a float parameter: the texture's eval_1 (alpha* are always scalar)
};

// The textures nested in a BSDF, each bound to the parameter it names; a texture for a parameter
// that candela does not texture (e.g. a roughness) is an error, not a silent constant.
std::shared_ptr<const Texture> as_float_texture(std::shared_ptr<const Texture> t);  // below

Material with_textures(XmlLoader& L, Object& o, Material m, std::initializer_list<TexturableParam> params) {
    for (const TexturableParam& p : params)
        if (auto t = nested_texture(L, o, p.name)) {
            if (o.params.has(p.name)) throw o.params.error(p.name, std::string("'") + p.name + "' is given both as a value and as a texture");
            const bool scalar = p.scalar || std::string(p.name).rfind("alpha", 0) == 0;  // a float parameter
            // A constant (srgb, d65, uniform, rawconstant) is folded into the BSDF's value: the
            // material stays untextured and costs nothing per hit.
            if (const ConstantTexture* c = std::get_if<ConstantTexture>(&t->v)) {
                if (!all_finite(c->value) || !(min_component(c->value) >= 0.f))
                    throw L.error(o.node, std::string("'") + p.name + "' must be finite and not negative");
                p.apply(m.bsdf, scalar ? vec3(luminance(c->value)) : c->value);
                continue;
            }
            m.textures.push_back(TextureSlot{scalar ? as_float_texture(t) : t, p.apply, p.name});
        }
    for (const Nested& c : o.nested)
        if (!c.used && c.tag == "texture")
            throw L.error(c.node, "a texture for '" + L.attr(c.node, "name") + "' is not supported in " + o.what());
    return m;
}

Material make_diffuse(XmlLoader& L, Object& o) {
    vec3 r = o.params.get_rgb("reflectance", vec3(0.5f));
    if (!(min_component(r) >= 0.f)) throw o.params.error("reflectance", "reflectance must not be negative");
    return with_textures(L, o, Material{"", DiffuseBsdf{r}, false},  // Mitsuba's BSDFs are one-sided
                         {{"reflectance", set_field<DiffuseBsdf, &DiffuseBsdf::albedo>}});
}

// ---- BSDFs of issue 5 (conductor, plastic, dielectric, twosided) -------------------------------
// Mitsuba 3's parameter names and defaults; what candela does not model (e.g. sample_visible
// false, a texture on the plastic's roughness) is an error rather than a silent difference.

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

// int_ior (default int_default) and ext_ior (default air), which must differ (an interface).
void read_distinct_iors(Object& o, float int_default, float& int_ior, float& ext_ior) {
    int_ior = ior_param(o, "int_ior", int_default);
    ext_ior = ior_param(o, "ext_ior", 1.000277f);
    if (int_ior == ext_ior) throw o.params.error("int_ior", "int_ior and ext_ior must differ");
}

vec3 nonnegative_rgb(Object& o, const std::string& name, vec3 def) {
    vec3 v = o.params.get_rgb(name, def);
    if (!(min_component(v) >= 0.f)) throw o.params.error(name, name + " must not be negative");
    return v;
}

// Microfacet roughness as Mitsuba's MicrofacetDistribution reads it: `distribution` beckmann (the
// default) or ggx; `alpha`, or both `alpha_u` and `alpha_v` (anisotropic; not both forms). A
// roughness may also be a nested texture (float value: the luminance of its colour, as Mitsuba's
// eval_1); the constant then holds the default and bsdf_at overwrites it at each point.
struct MicrofacetParams {
    MicrofacetType type = MicrofacetType::Beckmann;
    float alpha_u = 0.1f, alpha_v = 0.1f;
};

bool has_texture_named(const Object& o, const char* name, XmlLoader& L) {
    for (const Nested& c : o.nested)
        if (c.tag == "texture" && L.attr(c.node, "name") == name) return true;
    return false;
}

MicrofacetParams microfacet_params(XmlLoader& L, Object& o, bool anisotropic_allowed) {
    MicrofacetParams mp;
    std::string d = o.params.get_string("distribution", "beckmann");
    std::transform(d.begin(), d.end(), d.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (d == "ggx") mp.type = MicrofacetType::GGX;
    else if (d != "beckmann") throw o.params.error("distribution", "distribution '" + d + "' is invalid: must be beckmann or ggx");
    if (!o.params.get_bool("sample_visible", true))
        throw o.params.error("sample_visible", "only visible-normal sampling is implemented");
    const bool has_a = o.params.has("alpha") || has_texture_named(o, "alpha", L);
    const bool has_u = o.params.has("alpha_u") || has_texture_named(o, "alpha_u", L);
    const bool has_v = o.params.has("alpha_v") || has_texture_named(o, "alpha_v", L);
    if (!anisotropic_allowed && (has_u || has_v)) {
        const char* n = has_u ? "alpha_u" : "alpha_v";
        if (o.params.has(n)) throw o.params.error(n, std::string(n) + ": " + o.what() + " is isotropic (give alpha)");
        throw L.error(o.node, std::string("a texture for '") + n + "': " + o.what() + " is isotropic (give alpha)");
    }
    auto checked = [&](const char* name, float def) {
        float a = o.params.get_float(name, def);
        if (!(a >= 0.f) || a > 4.f) throw o.params.error(name, std::string(name) + " must be in [0, 4]");
        return std::max(a, kMinAlpha);  // Mitsuba clamps too; alpha 0 is the smooth plugin's job
    };
    if (has_a && (has_u || has_v)) throw L.error(o.node, o.what() + ": give either alpha or alpha_u/alpha_v, not both");
    if (has_u != has_v) throw L.error(o.node, o.what() + ": both alpha_u and alpha_v must be given");
    if (has_u) {
        mp.alpha_u = checked("alpha_u", 0.1f);
        mp.alpha_v = checked("alpha_v", 0.1f);
    } else {
        mp.alpha_u = mp.alpha_v = checked("alpha", 0.1f);
    }
    return mp;
}

// Mitsuba reads a checkerboard as a float (eval_1) with its colours the other way round from the
// colour reading (eval: color0 where both fractional parts are on the same side of 1/2; eval_1:
// where they differ; measured in 3.9.1 too). A float parameter driven by a checkerboard gets a
// copy with the colours swapped, so it agrees with Mitsuba (nested checkerboards inside its
// colours are kept as they are).
std::shared_ptr<const Texture> as_float_texture(std::shared_ptr<const Texture> t) {
    if (std::holds_alternative<CheckerboardTexture>(t->v)) {
        auto swapped = std::make_shared<Texture>(*t);
        auto& sc = std::get<CheckerboardTexture>(swapped->v);
        std::swap(sc.color0, sc.color1);
        return swapped;
    }
    return t;
}

// Texture slots for the roughness of a conductor or dielectric (both have alpha_u, alpha_v).
template <class B>
void set_alpha(Bsdf& b, vec3 v) {
    B& x = std::get<B>(b);
    x.alpha_u = x.alpha_v = std::max(luminance(v), kMinAlpha);
}
template <class B>
void set_alpha_u(Bsdf& b, vec3 v) { std::get<B>(b).alpha_u = std::max(luminance(v), kMinAlpha); }
template <class B>
void set_alpha_v(Bsdf& b, vec3 v) { std::get<B>(b).alpha_v = std::max(luminance(v), kMinAlpha); }

ConductorBsdf conductor_params(Object& o) {
    ConductorBsdf c;
    std::string material = o.params.get_string("material", "none");
    if (material != "none") {
        // Mitsuba: a named material, or eta and k, not both.
        if (o.params.has("eta") || o.params.has("k"))
            throw o.params.error(o.params.has("eta") ? "eta" : "k", "give either material or eta and k, not both");
        const NamedConductor* nc = named_conductor(material);
        if (!nc) throw o.params.error("material", "unknown conductor material '" + material + "' (see docs/materials.md for Mitsuba's names)");
        c.eta = nc->eta;
        c.k = nc->k;
    } else {
        c.eta = nonnegative_rgb(o, "eta", vec3(0.f));
        c.k = nonnegative_rgb(o, "k", vec3(1.f));
    }
    c.specular_reflectance = nonnegative_rgb(o, "specular_reflectance", vec3(1.f));
    return c;
}

constexpr TexturableParam kConductorTextures[] = {
    {"specular_reflectance", set_field<ConductorBsdf, &ConductorBsdf::specular_reflectance>},
    {"alpha", set_alpha<ConductorBsdf>},
    {"alpha_u", set_alpha_u<ConductorBsdf>},
    {"alpha_v", set_alpha_v<ConductorBsdf>}};

Material make_conductor(XmlLoader& L, Object& o) {
    return with_textures(L, o, Material{"", conductor_params(o), false}, {kConductorTextures[0]});
}

Material make_roughconductor(XmlLoader& L, Object& o) {
    ConductorBsdf c = conductor_params(o);
    const MicrofacetParams mp = microfacet_params(L, o, true);
    c.distribution = mp.type;
    c.alpha_u = mp.alpha_u;
    c.alpha_v = mp.alpha_v;
    return with_textures(L, o, Material{"", c, false},
                         {kConductorTextures[0], kConductorTextures[1], kConductorTextures[2], kConductorTextures[3]});
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

constexpr TexturableParam kPlasticTextures[] = {
    {"diffuse_reflectance", set_field<PlasticBsdf, &PlasticBsdf::diffuse_reflectance>},
    {"specular_reflectance", set_field<PlasticBsdf, &PlasticBsdf::specular_reflectance>}};

Material make_plastic(XmlLoader& L, Object& o) {
    PlasticBsdf p = plastic_params(o);
    p.prepare();
    return with_textures(L, o, Material{"", p, false}, {kPlasticTextures[0], kPlasticTextures[1]});
}

Material make_roughplastic(XmlLoader& L, Object& o) {
    PlasticBsdf p = plastic_params(o);
    const MicrofacetParams mp = microfacet_params(L, o, false);  // Mitsuba: isotropic, no texture
    p.distribution = mp.type;
    p.alpha = mp.alpha_u;
    if (p.int_ior == p.ext_ior) throw o.params.error("int_ior", "int_ior and ext_ior must differ");
    p.prepare();
    return with_textures(L, o, Material{"", p, false}, {kPlasticTextures[0], kPlasticTextures[1]});
}

// Mitsuba's pplastic: the plastic's IORs and reflectances, a microfacet roughness that may be
// anisotropic (but not textured: Mitsuba reads it as a float), no `nonlinear`.
Material make_pplastic(XmlLoader& L, Object& o) {
    PPlasticBsdf p;
    read_distinct_iors(o, 1.49f, p.int_ior, p.ext_ior);
    p.diffuse_reflectance = nonnegative_rgb(o, "diffuse_reflectance", vec3(0.5f));
    p.specular_reflectance = nonnegative_rgb(o, "specular_reflectance", vec3(1.f));
    for (const char* n : {"alpha", "alpha_u", "alpha_v"})
        if (has_texture_named(o, n, L))
            throw L.error(o.node, std::string("a texture for '") + n + "': pplastic's roughness is a number");
    const MicrofacetParams mp = microfacet_params(L, o, true);
    p.distribution = mp.type;
    p.alpha_u = mp.alpha_u;
    p.alpha_v = mp.alpha_v;
    return with_textures(L, o, Material{"", p, false},
                         {{"diffuse_reflectance", set_field<PPlasticBsdf, &PPlasticBsdf::diffuse_reflectance>},
                          {"specular_reflectance", set_field<PPlasticBsdf, &PPlasticBsdf::specular_reflectance>}});
}

DielectricBsdf dielectric_params(Object& o) {
    DielectricBsdf d;
    read_distinct_iors(o, 1.5046f, d.int_ior, d.ext_ior);
    d.specular_reflectance = nonnegative_rgb(o, "specular_reflectance", vec3(1.f));
    d.specular_transmittance = nonnegative_rgb(o, "specular_transmittance", vec3(1.f));
    return d;
}

constexpr TexturableParam kDielectricTextures[] = {
    {"specular_reflectance", set_field<DielectricBsdf, &DielectricBsdf::specular_reflectance>},
    {"specular_transmittance", set_field<DielectricBsdf, &DielectricBsdf::specular_transmittance>},
    {"alpha", set_alpha<DielectricBsdf>},
    {"alpha_u", set_alpha_u<DielectricBsdf>},
    {"alpha_v", set_alpha_v<DielectricBsdf>}};

Material make_dielectric(XmlLoader& L, Object& o) {
    return with_textures(L, o, Material{"", dielectric_params(o), false}, {kDielectricTextures[0], kDielectricTextures[1]});
}

Material make_roughdielectric(XmlLoader& L, Object& o) {
    DielectricBsdf d = dielectric_params(o);
    const MicrofacetParams mp = microfacet_params(L, o, true);
    d.distribution = mp.type;
    d.alpha_u = mp.alpha_u;
    d.alpha_v = mp.alpha_v;
    return with_textures(L, o, Material{"", d, false},
                         {kDielectricTextures[0], kDielectricTextures[1], kDielectricTextures[2], kDielectricTextures[3],
                          kDielectricTextures[4]});
}

// Mitsuba's thindielectric: the IORs and the two tints, no roughness, no textures here.
Material make_thindielectric(XmlLoader& L, Object& o) {
    ThinDielectricBsdf t;
    t.int_ior = ior_param(o, "int_ior", 1.5046f);
    t.ext_ior = ior_param(o, "ext_ior", 1.000277f);
    t.specular_reflectance = nonnegative_rgb(o, "specular_reflectance", vec3(1.f));
    t.specular_transmittance = nonnegative_rgb(o, "specular_transmittance", vec3(1.f));
    return with_textures(L, o, Material{"", t, false}, {});
}

// ---- principled (Mitsuba 3.9's src/bsdfs/principled.cpp) ----------------------------------------
template <float PrincipledBsdf::*Field>
void set_principled(Bsdf& b, vec3 v) { std::get<PrincipledBsdf>(b).*Field = luminance(v); }

// Mitsuba's get_flag: a lobe is on when its parameter is given as a texture or a float other than 0.
bool principled_flag(XmlLoader& L, Object& o, const char* name) {
    return has_texture_named(o, name, L) || (o.params.has(name) && o.params.get_float(name, 0.f) != 0.f);
}

Material make_principled(XmlLoader& L, Object& o) {
    PrincipledBsdf p;
    p.base_color = nonnegative_rgb(o, "base_color", vec3(0.5f));
    auto unit = [&](const char* name, float def) {
        const float v = o.params.get_float(name, def);
        if (!(v >= 0.f && v <= 1.f)) throw o.params.error(name, std::string(name) + " must be in [0, 1]");
        return v;
    };
    p.roughness = unit("roughness", 0.5f);
    p.anisotropic = unit("anisotropic", 0.f);
    p.metallic = unit("metallic", 0.f);
    p.spec_tint = unit("spec_tint", 0.f);
    p.sheen = unit("sheen", 0.f);
    p.sheen_tint = unit("sheen_tint", 0.f);
    p.clearcoat = unit("clearcoat", 0.f);
    p.clearcoat_gloss = unit("clearcoat_gloss", 0.f);
    p.spec_trans = unit("spec_trans", 0.f);
    p.flatness = unit("flatness", 0.f);
    p.has_spec_trans = principled_flag(L, o, "spec_trans");
    auto rate = [&](const char* name) {
        const float v = o.params.get_float(name, 1.f);
        if (!(v >= 0.f) || !std::isfinite(v)) throw o.params.error(name, std::string(name) + " must not be negative");
        return v;
    };
    p.main_specular_sampling_rate = rate("main_specular_sampling_rate");
    p.clearcoat_sampling_rate = rate("clearcoat_sampling_rate");
    p.diffuse_reflectance_sampling_rate = rate("diffuse_reflectance_sampling_rate");
    // eta and specular are one parameter in two forms (Mitsuba refuses both); with a transmission
    // lobe Mitsuba moves eta 1 to 1.001 and specular 0 to 1e-3 (eta 1 refracts nothing).
    if (o.params.has("eta") && o.params.has("specular")) throw o.params.error("specular", "give either eta or specular, not both");
    if (o.params.has("eta")) {
        p.eta = o.params.get_float("eta", 1.5f);
        if (!(p.eta > 0.f) || !std::isfinite(p.eta)) throw o.params.error("eta", "eta must be positive");
        if (p.has_spec_trans && p.eta == 1.f) p.eta = 1.001f;
    } else {
        float s = o.params.get_float("specular", 0.5f);
        if (!(s >= 0.f && s < 12.5f)) throw o.params.error("specular", "specular must be in [0, 12.5) (eta = 2 / (1 - sqrt(0.08 specular)) - 1)");
        if (p.has_spec_trans && s == 0.f) s = 1e-3f;
        p.eta = PrincipledBsdf::eta_from_specular(s);
    }
    // Mitsuba textures everything but eta, specular and the sampling rates.
    using P = PrincipledBsdf;
    return with_textures(L, o, Material{"", p, false},
                         {{"base_color", set_field<P, &P::base_color>},
                          {"roughness", set_principled<&P::roughness>, true},
                          {"anisotropic", set_principled<&P::anisotropic>, true},
                          {"metallic", set_principled<&P::metallic>, true},
                          {"spec_tint", set_principled<&P::spec_tint>, true},
                          {"sheen", set_principled<&P::sheen>, true},
                          {"sheen_tint", set_principled<&P::sheen_tint>, true},
                          {"clearcoat", set_principled<&P::clearcoat>, true},
                          {"clearcoat_gloss", set_principled<&P::clearcoat_gloss>, true},
                          {"spec_trans", set_principled<&P::spec_trans>, true},
                          {"flatness", set_principled<&P::flatness>, true}});
}

Material make_twosided(XmlLoader& L, Object& o) {
    Material m = L.nested_bsdf(o);
    if (std::holds_alternative<DielectricBsdf>(m.bsdf))
        throw L.error(o.node, "twosided around a dielectric is meaningless (a dielectric has two sides already)");
    m.two_sided = true;  // the integrator flips the frame to the side the ray comes from
    return m;
}

}  // namespace

// One function plus one row per plugin.
const PluginTable<BsdfFactory>& bsdf_plugins() {
    static const PluginTable<BsdfFactory> table = {
        {"diffuse", make_diffuse},
        {"conductor", make_conductor},
        {"roughconductor", make_roughconductor},
        {"plastic", make_plastic},
        {"roughplastic", make_roughplastic},
        {"pplastic", make_pplastic},
        {"dielectric", make_dielectric},
        {"roughdielectric", make_roughdielectric},
        {"thindielectric", make_thindielectric},
        {"principled", make_principled},
        {"twosided", make_twosided},
        {"blendbsdf", blendbsdf_factory()},
        {"mask", mask_factory()},
        {"null", null_factory()},
        {"bumpmap", bumpmap_factory()},
        {"normalmap", normalmap_factory()},
    };
    return table;
}

}  // namespace xml
}  // namespace candela
