// The integrator family of the XML reader: Mitsuba 3's integrators as RenderSettings.
#include "integrator/caps.h"
#include "scene/plugins/render_factories.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

// The factories themselves are in scene/plugins/render_factories.cpp (path, volpath, direct and
// the moment and aov wrappers); this walks the wrappers' nesting.
void load_integrator(XmlLoader& L, pugi::xml_node n) {
    RenderSettings s = L.scene().settings;
    std::string moment;  // the name of the integrator a moment wrapper holds, once one is read
    for (int level = 0;; ++level) {
        Object o = L.read_object(n, "integrator");
        if (read_integrator(o.type, o.params, s, o.line) == IntegratorRole::Renders) {
            // The aov and moment wrappers take values of camera rays (integrator/caps.h).
            if (!reads(s.integrator.type).aovs && (level > 0 || !moment.empty()))
                throw L.error(n, o.type + " cannot be nested in an aov or moment integrator (it traces no camera ray "
                                          "per pixel sample)");
            L.finish(o);
            break;
        }
        Nested* inner = nullptr;
        for (Nested& c : o.nested) {
            if (c.tag != "integrator") continue;
            if (inner) throw L.error(c.node, o.what() + " with more than one nested integrator (candela renders one)");
            inner = &c;
        }
        if (!inner) throw L.error(n, o.what() + " needs a nested <integrator>");
        if (level >= 8) throw L.error(n, "integrators nested more than 8 deep");
        if (o.type == "moment") {
            if (!moment.empty()) throw L.error(n, "a moment integrator inside another moment integrator");
            // Mitsuba names an unnamed child object "_arg_<index>"; the only child here is the first.
            moment = L.attr(inner->node, "name");
            if (moment.empty()) moment = "_arg_0";
        }
        inner->used = true;
        L.finish(o);
        n = inner->node;
    }
    if (!moment.empty()) s.integrator.aovs.push_back(AovSpec{moment, AovType::Moment});
    L.scene().settings = s;
}

}  // namespace xml
}  // namespace candela
