#pragma once
// Factories of the <integrator> and <rfilter> plugin families (Mitsuba 3 names and defaults,
// docs/scene-format.md). They read one element's parameters; the XML reader walks the nesting
// (the `moment` and `aov` wrappers hold the integrator that renders the image).
#include <string>
#include "scene/params.h"
#include "scene/scene.h"

namespace candela {

enum class IntegratorRole { Renders, Wraps };

// Reads the parameters of an integrator of type `type` into `st` (the integrator description and
// the path depths). Wraps: a wrapper (moment, aov) whose nested integrator the caller must read
// next. Throws Error at the parameter's line for a bad value, or at the element's `line` (in
// p.file()) naming the supported types for an unknown one. Reports unused parameters.
IntegratorRole read_integrator(const std::string& type, const ParamSet& p, RenderSettings& st, int line);

// Reads an <rfilter>: box, tent (radius, default 1), gaussian (stddev, default 0.5). A filter of
// radius 0.5 is the box, as in Mitsuba's image block.
FilterDesc read_rfilter(const std::string& type, const ParamSet& p, int line);

}  // namespace candela
