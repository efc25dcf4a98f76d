// The integrator family of the XML reader: Mitsuba 3's integrators as RenderSettings.
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

void make_path(XmlLoader&, Object& o, RenderSettings& s) {
    int max_depth = o.params.get_int("max_depth", -1);
    int rr_depth = o.params.get_int("rr_depth", 5);
    bool hide = o.params.get_bool("hide_emitters", false);
    if (max_depth < -1) throw o.params.error("max_depth", "max_depth must be -1 (unbounded) or positive");
    // Mitsuba's max_depth counts path segments, candela's counts scattering events. A Mitsuba depth
    // of 0 renders black; that is never what a user wants, so it is rejected.
    if (max_depth == 0) throw o.params.error("max_depth", "max_depth 0 renders a black image; use -1 or a value >= 1");
    if (rr_depth <= 0) throw o.params.error("rr_depth", "rr_depth must be greater than zero");
    if (hide) throw o.params.error("hide_emitters", "hide_emitters=true is not supported");
    s.max_depth = max_depth < 0 ? -1 : max_depth - 1;
    s.rr_depth = rr_depth;
}

}  // namespace

const PluginTable<IntegratorFactory>& integrator_plugins() {
    static const PluginTable<IntegratorFactory> table = {
        {"path", make_path},
    };
    return table;
}

void load_integrator(XmlLoader& L, pugi::xml_node n) {
    Object o = L.read_object(n, "integrator");
    IntegratorFactory make = L.find_plugin(integrator_plugins(), o);
    RenderSettings s = L.scene().settings;
    make(L, o, s);
    L.finish(o);
    L.scene().settings = s;
}

}  // namespace xml
}  // namespace candela
