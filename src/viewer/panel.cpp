#include "viewer/panel.h"
#include <imgui.h>
#include <algorithm>
#include <type_traits>
#include <utility>

namespace candela {

namespace {

// Generic widgets. Colours that are reflectances stay in [0, 1]; values that may exceed 1
// (radiance, IOR) use drag fields.
bool reflectance(const char* label, vec3& c) {
    return ImGui::ColorEdit3(label, &c.x, ImGuiColorEditFlags_Float);
}
bool drag_positive(const char* label, vec3& v, float speed) {
    bool changed = ImGui::DragFloat3(label, &v.x, speed, 0.f, 1e9f, "%.3f");
    if (changed) v = glm::max(v, vec3(0.f));
    return changed;
}

// Member detection: the BSDFs are plain structs of parameters with conventional names, so one
// generic editor shows the widgets for exactly the parameters a type has.
#define CANDELA_HAS_MEMBER(name)                                                                    \
    template <class T, class M, class = void>                                                       \
    struct has_##name : std::false_type {};                                                         \
    template <class T, class M>                                                                     \
    struct has_##name<T, M, std::void_t<decltype(std::declval<T&>().name)>>                         \
        : std::is_same<decltype(std::declval<T&>().name), M> {};
CANDELA_HAS_MEMBER(albedo)
CANDELA_HAS_MEMBER(diffuse_reflectance)
CANDELA_HAS_MEMBER(specular_reflectance)
CANDELA_HAS_MEMBER(specular_transmittance)
CANDELA_HAS_MEMBER(eta)
CANDELA_HAS_MEMBER(k)
CANDELA_HAS_MEMBER(int_ior)
CANDELA_HAS_MEMBER(ext_ior)
CANDELA_HAS_MEMBER(alpha)
CANDELA_HAS_MEMBER(alpha_u)
CANDELA_HAS_MEMBER(alpha_v)
CANDELA_HAS_MEMBER(distribution)
CANDELA_HAS_MEMBER(nonlinear)
#undef CANDELA_HAS_MEMBER

bool ior(const char* label, float& v) {
    bool changed = ImGui::DragFloat(label, &v, 0.005f, 1.f, 4.f, "%.4f");
    if (changed) v = std::clamp(v, 1.f, 4.f);
    return changed;
}

// One editor per BSDF: the generic one below, unless a type needs its own overload (overload
// resolution prefers a non-template function), e.g. edit_bsdf(DiffuseBsdf&).
template <class T>
bool edit_bsdf(T& b) {
    bool changed = false, any = false;
    if constexpr (has_albedo<T, vec3>::value) any = true, changed |= reflectance("albedo", b.albedo);
    if constexpr (has_diffuse_reflectance<T, vec3>::value)
        any = true, changed |= reflectance("diffuse", b.diffuse_reflectance);
    if constexpr (has_specular_reflectance<T, vec3>::value)
        any = true, changed |= reflectance("specular tint", b.specular_reflectance);
    if constexpr (has_specular_transmittance<T, vec3>::value)
        any = true, changed |= reflectance("transmission tint", b.specular_transmittance);
    if constexpr (has_eta<T, vec3>::value) any = true, changed |= drag_positive("eta", b.eta, 0.01f);
    if constexpr (has_k<T, vec3>::value) any = true, changed |= drag_positive("k", b.k, 0.01f);
    if constexpr (has_int_ior<T, float>::value) any = true, changed |= ior("interior IOR", b.int_ior);
    if constexpr (has_ext_ior<T, float>::value) any = true, changed |= ior("exterior IOR", b.ext_ior);
    if constexpr (has_distribution<T, MicrofacetType>::value) {
        // Beckmann / GGX; index = the enum's value.
        int d = int(b.distribution);
        const char* names[] = {"beckmann", "ggx"};
        any = true;
        if (ImGui::Combo("distribution", &d, names, 2)) b.distribution = MicrofacetType(d), changed = true;
    }
    if constexpr (has_alpha<T, float>::value)
        any = true, changed |= ImGui::SliderFloat("roughness", &b.alpha, 0.f, 1.f, "alpha %.3f");
    if constexpr (has_alpha_u<T, float>::value && has_alpha_v<T, float>::value) {
        // Both 0 is the smooth (delta) model; one slider each, as Mitsuba's alpha_u / alpha_v.
        any = true;
        changed |= ImGui::SliderFloat("roughness u", &b.alpha_u, 0.f, 1.f, "alpha_u %.3f");
        changed |= ImGui::SliderFloat("roughness v", &b.alpha_v, 0.f, 1.f, "alpha_v %.3f");
    }
    if constexpr (has_nonlinear<T, bool>::value)
        any = true, changed |= ImGui::Checkbox("nonlinear", &b.nonlinear);
    if (!any) ImGui::TextDisabled("(no editable parameters)");
    // Derived data (the plastic coat's tables) is not computed here: the render worker prepares
    // the materials when it builds the edited scene (Scene::with_params), off the window's thread.
    return changed;
}

// The principled BSDF's main parameters (Mitsuba's names); specular is shown as eta's other form.
bool edit_bsdf(PrincipledBsdf& b) {
    bool changed = reflectance("base color", b.base_color);
    auto unit = [&](const char* label, float& v) { changed |= ImGui::SliderFloat(label, &v, 0.f, 1.f, "%.3f"); };
    unit("roughness", b.roughness);
    unit("metallic", b.metallic);
    float specular = PrincipledBsdf::specular_from_eta(b.eta);
    if (ImGui::SliderFloat("specular", &specular, 0.f, 1.f, "%.3f")) {
        // Mitsuba keeps specular 0 (eta 1) away from a transmitting surface.
        b.eta = PrincipledBsdf::eta_from_specular(std::max(specular, 1e-3f));
        changed = true;
    }
    changed |= ior("eta", b.eta);
    if (b.eta == 1.f) b.eta = 1.001f;
    unit("spec tint", b.spec_tint);
    unit("anisotropic", b.anisotropic);
    unit("sheen", b.sheen);
    unit("sheen tint", b.sheen_tint);
    unit("clearcoat", b.clearcoat);
    unit("clearcoat gloss", b.clearcoat_gloss);
    if (ImGui::SliderFloat("spec trans", &b.spec_trans, 0.f, 1.f, "%.3f")) {
        b.has_spec_trans = true;  // as Mitsuba's parameters_changed turns the lobe on
        changed = true;
    }
    unit("flatness", b.flatness);
    return changed;
}

const char* model_name(const PrincipledBsdf&) { return "principled"; }
const char* model_name(const PPlasticBsdf&) { return "pplastic"; }

// Model names, recognised by their parameters as well (the variant may grow).
template <class T>
const char* model_name(const T&) {
    if constexpr (has_albedo<T, vec3>::value) return "diffuse";
    else if constexpr (has_diffuse_reflectance<T, vec3>::value) return "plastic";
    else if constexpr (has_specular_transmittance<T, vec3>::value)
        return has_alpha_u<T, float>::value ? "dielectric" : "thindielectric";
    else if constexpr (has_k<T, vec3>::value) return "conductor";
    else return "bsdf";
}

}  // namespace

const char* bsdf_type_name(const Bsdf& b) {
    return std::visit([](const auto& x) { return model_name(x); }, b);
}

bool edit_medium(Medium& m) {
    bool changed = false;
    if (!m.heterogeneous()) changed |= drag_positive("sigma_t", m.sigma_t_base, 0.01f);
    else ImGui::TextDisabled("sigma_t: a grid (%s), times scale", "gridvolume");
    if (!m.albedo_grid) changed |= reflectance("albedo", m.albedo);
    else ImGui::TextDisabled("albedo: a grid");
    if (ImGui::DragFloat("scale", &m.scale, 0.01f, 0.f, 1e6f, "%.4f", ImGuiSliderFlags_AlwaysClamp)) changed = true;
    if (ImGui::SliderFloat("g", &m.g, -0.99f, 0.99f, "%.3f", ImGuiSliderFlags_AlwaysClamp)) changed = true;
    if (changed) {
        m.scale = std::max(m.scale, 0.f);
        m.albedo = glm::clamp(m.albedo, vec3(0.f), vec3(1.f));
        refresh_medium(m);
    }
    return changed;
}

bool edit_material(Material& m) {
    bool changed = std::visit([](auto& b) { return edit_bsdf(b); }, m.bsdf);
    // A textured parameter takes its value from the texture at each point: its slider has no effect.
    for (const TextureSlot& t : m.textures) ImGui::TextDisabled("%s: a texture (the slider above has no effect)", t.parameter);
    changed |= ImGui::Checkbox("two-sided", &m.two_sided);
    // The wrappers' own parameters (docs/materials.md): the blend weights, the opacity, the bump
    // scale. The leaves of a blend beyond the first are not listed (their BSDF sliders would need
    // a tree view); a textured weight or opacity has no slider.
    for (size_t i = 0; i < m.blend.size(); ++i) {
        ImGui::PushID(int(i));
        if (m.blend[i].weight_texture) ImGui::TextDisabled("blend weight %zu: a texture", i);
        else changed |= ImGui::SliderFloat("blend weight", &m.blend[i].weight, 0.f, 1.f, "%.3f");
        ImGui::PopID();
    }
    if (m.masked) {
        if (m.opacity_texture) ImGui::TextDisabled("opacity: a texture");
        else changed |= ImGui::SliderFloat("opacity", &m.opacity, 0.f, 1.f, "%.3f");
    }
    if (m.perturbation == Perturbation::Bump) changed |= ImGui::DragFloat("bump scale", &m.bump_scale, 0.005f, -10.f, 10.f, "%.4f");
    if (m.perturbation != Perturbation::None) changed |= ImGui::Checkbox("shadow terminator", &m.shadow_terminator);
    return changed;
}

bool edit_emitter(AreaEmitter& e) { return drag_positive("radiance", e.radiance, 0.05f); }

bool edit_light(Light& l) {
    bool changed = drag_positive(light_strength_name(l.model), light_strength(l.model), 0.05f);
    if (EnvmapLight* e = std::get_if<EnvmapLight>(&l.model)) {
        // A turn of the map about its up axis: only the frame changes, the sampling table stays.
        if (ImGui::SliderFloat("rotation", &e->rotation, -180.f, 180.f, "%.1f deg")) {
            e->update();
            changed = true;
        }
    }
    return changed;
}

}  // namespace candela
