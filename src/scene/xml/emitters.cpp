// The emitter family of the XML reader: area emitters nested in shapes. Emitters elsewhere (point,
// spot, directional, constant, envmap) are issue 13 part 2 and stay errors.
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

AreaEmitter make_area(XmlLoader&, Object& e) {
    vec3 radiance = e.params.get_rgb("radiance", vec3(1.f));
    if (!(min_component(radiance) >= 0.f)) throw e.params.error("radiance", "radiance must not be negative");
    return AreaEmitter{radiance};
}

}  // namespace

const PluginTable<AreaEmitterFactory>& area_emitter_plugins() {
    static const PluginTable<AreaEmitterFactory> table = {
        {"area", make_area},
    };
    return table;
}

int32_t load_shape_emitter(XmlLoader& L, pugi::xml_node n) {
    Object e = L.read_object(n, "emitter");
    AreaEmitterFactory make = nullptr;
    for (const auto& p : area_emitter_plugins())
        if (e.type == p.type) make = p.make;
    if (!make) throw L.error(n, "unsupported emitter type '" + e.type + "' inside a shape (area)");
    AreaEmitter a = make(L, e);
    L.finish(e);
    L.scene().emitters.push_back(a);
    return int32_t(L.scene().emitters.size() - 1);
}

void load_emitter(XmlLoader& L, pugi::xml_node n) {
    if (L.attr(n, "type") == "area" && n.attribute("id")) return;  // built by the shapes that <ref> it
    Object e = L.read_object(n, "emitter");
    if (e.type == "area") throw L.error(n, "an area emitter must be nested inside a <shape> or referenced by one");
    throw L.error(n, "unsupported emitter type '" + e.type + "' (candela supports area emitters on shapes)");
}

}  // namespace xml
}  // namespace candela
