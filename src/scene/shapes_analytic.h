#pragma once
// The scene-file factory of Mitsuba's analytic shapes: `sphere`, `disk`, `cylinder`
// (geometry/analytic.h for their definitions).
#include <string>
#include "geometry/analytic.h"
#include "scene/params.h"

namespace candela {

bool is_analytic_shape_type(const std::string& type);

// Reads the shape's own parameters (sphere: center, radius; cylinder: p0, p1, radius) with
// Mitsuba's defaults; `to_world` and `flip_normals` are read by the caller. Throws Error
// "file:line: what" for a negative, zero or non-finite radius, coincident cylinder ends, or a
// to_world the shape cannot take (singular, shearing, non-uniform); `line` is the shape element's,
// used where the fault is not one parameter's.
AnalyticShape make_analytic_shape(const std::string& type, const ParamSet& params, int line, const mat4& to_world,
                                  bool flip_normals);

}  // namespace candela
