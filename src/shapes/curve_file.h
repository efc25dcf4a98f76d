#pragma once
// Mitsuba 3's curve files (src/shapes/linearcurve.cpp, bsplinecurve.cpp): one control point per
// line, "x y z radius" (more numbers on a line are ignored, as Mitsuba's strtof loop does), a blank
// line between curves, at least two points per curve. Every failure is a candela::Error of one
// line, "file:line: what".
#include <string>
#include <vector>
#include "core/math.h"

namespace candela {

struct CurveFile {
    std::vector<vec3> points;      // object space, as in the file
    std::vector<float> radii;      // per point, >= 0
    std::vector<uint32_t> starts;  // index of each curve's first point; a curve runs to the next start
};

CurveFile read_curve_file(const std::string& path);
CurveFile parse_curve_file(const std::string& name, const std::string& text);

}  // namespace candela
