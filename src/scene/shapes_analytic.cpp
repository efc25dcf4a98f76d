#include "scene/shapes_analytic.h"
#include "core/error.h"

namespace candela {

bool is_analytic_shape_type(const std::string& type) {
    return type == "sphere" || type == "disk" || type == "cylinder";
}

AnalyticShape make_analytic_shape(const std::string& type, const ParamSet& params, int line, const mat4& to_world,
                                  bool flip) {
    auto at = [&](const std::string& name) {
        int l = params.line_of(name);
        return l > 0 ? l : line;
    };
    auto radius = [&] {
        float r = params.get_float("radius", 1.f);  // Mitsuba's default for both shapes
        if (!(r > 0.f) || !std::isfinite(r))
            throw Error(params.file(), at("radius"), params.object() + ": radius must be positive and finite, not " +
                                                         std::to_string(r));
        return r;
    };
    try {
        if (type == "sphere") {
            vec3 c = params.get_point("center", vec3(0.f));
            if (!all_finite(c)) throw Error(params.file(), at("center"), params.object() + ": center is not finite");
            float r = radius();
            return make_sphere(to_world, c, r, flip);
        }
        if (type == "disk") return make_disk(to_world, flip);
        if (type == "cylinder") {
            vec3 p0 = params.get_point("p0", vec3(0.f)), p1 = params.get_point("p1", vec3(0.f, 0.f, 1.f));
            if (!all_finite(p0) || !all_finite(p1))
                throw Error(params.file(), at(all_finite(p0) ? "p1" : "p0"), params.object() + ": p0/p1 is not finite");
            if (p0 == p1) throw Error(params.file(), at("p1"), params.object() + ": p0 and p1 must differ");
            float r = radius();
            return make_cylinder(to_world, p0, p1, r, flip);
        }
    } catch (const Error& e) {
        std::string what = e.what();
        if (what.rfind(params.file() + ":", 0) == 0) throw;  // already located
        throw Error(params.file(), at("to_world"), params.object() + ": " + what);
    }
    throw Error(params.file(), line, "unsupported shape type '" + type + "'");
}

}  // namespace candela
