// The bsdf family of the XML reader: Mitsuba 3's BSDF plugins as candela Materials.
#include <algorithm>
#include "bsdf/fresnel.h"
#include "bsdf/microfacet.h"
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
};

// The textures nested in a BSDF, each bound to the parameter it names; a texture for a parameter
// that candela does not texture (e.g. a roughness) is an error, not a silent constant.
Material with_textures(XmlLoader& L, Object& o, Material m, std::initializer_list<TexturableParam> params) {
    for (const TexturableParam& p : params)
        if (auto t = nested_texture(L, o, p.name)) {
            if (o.params.has(p.name)) throw o.params.error(p.name, std::string("'") + p.name + "' is given both as a value and as a texture");
            m.textures.push_back(TextureSlot{t, p.apply, p.name});
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

constexpr TexturableParam kConductorTextures[] = {
    {"specular_reflectance", set_field<ConductorBsdf, &ConductorBsdf::specular_reflectance>}};

Material make_conductor(XmlLoader& L, Object& o) {
    return with_textures(L, o, Material{"", conductor_params(o), false}, {kConductorTextures[0]});
}

Material make_roughconductor(XmlLoader& L, Object& o) {
    ConductorBsdf c = conductor_params(o);
    c.alpha = microfacet_alpha(o, 0.1f);
    return with_textures(L, o, Material{"", c, false}, {kConductorTextures[0]});
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
    p.alpha = microfacet_alpha(o, 0.1f);
    if (p.int_ior == p.ext_ior) throw o.params.error("int_ior", "int_ior and ext_ior must differ");
    p.prepare();
    return with_textures(L, o, Material{"", p, false}, {kPlasticTextures[0], kPlasticTextures[1]});
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

constexpr TexturableParam kDielectricTextures[] = {
    {"specular_reflectance", set_field<DielectricBsdf, &DielectricBsdf::specular_reflectance>},
    {"specular_transmittance", set_field<DielectricBsdf, &DielectricBsdf::specular_transmittance>}};

Material make_dielectric(XmlLoader& L, Object& o) {
    return with_textures(L, o, Material{"", dielectric_params(o), false}, {kDielectricTextures[0], kDielectricTextures[1]});
}

Material make_roughdielectric(XmlLoader& L, Object& o) {
    DielectricBsdf d = dielectric_params(o);
    d.alpha = microfacet_alpha(o, 0.1f);
    return with_textures(L, o, Material{"", d, false}, {kDielectricTextures[0], kDielectricTextures[1]});
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
        {"dielectric", make_dielectric},
        {"roughdielectric", make_roughdielectric},
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
