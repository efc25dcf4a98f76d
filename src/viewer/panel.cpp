#include "viewer/panel.h"
#include <imgui.h>
#include <algorithm>

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

// One editor per BSDF type. Overload resolution picks the exact one; the template catches types
// that have none yet, so adding a BSDF to the variant never breaks the viewer's build.
bool edit_bsdf(DiffuseBsdf& b) { return reflectance("albedo", b.albedo); }

template <class T>
bool edit_bsdf(T&) {
    ImGui::TextDisabled("(no editable parameters)");
    return false;
}

struct TypeName {
    const char* operator()(const DiffuseBsdf&) const { return "diffuse"; }
    template <class T>
    const char* operator()(const T&) const { return "bsdf"; }
};

}  // namespace

const char* bsdf_type_name(const Bsdf& b) { return std::visit(TypeName{}, b); }

bool edit_material(Material& m) {
    bool changed = std::visit([](auto& b) { return edit_bsdf(b); }, m.bsdf);
    changed |= ImGui::Checkbox("two-sided", &m.two_sided);
    return changed;
}

bool edit_emitter(AreaEmitter& e) { return drag_positive("radiance", e.radiance, 0.05f); }

}  // namespace candela
