// libFuzzer target: the curve-file reader (src/shapes/curve_file.cpp) on arbitrary bytes, then what
// the XML linearcurve does with its result (one analytic segment per pair of points) and a few rays
// through every segment's intersector and surface interaction. Any input must parse or throw
// candela::Error; a crash, a sanitizer report, another exception, a leak or a hang is a finding.
#include <cstdint>
#include <string>
#include "core/error.h"
#include "geometry/analytic.h"
#include "shapes/curve_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        const candela::CurveFile f =
            candela::parse_curve_file("fuzz.txt", std::string(reinterpret_cast<const char*>(data), size));
        const candela::vec3 origins[3] = {candela::vec3(3.f, 0.5f, 0.2f), candela::vec3(-2.f, 4.f, 1.f),
                                          candela::vec3(0.1f, -0.3f, -5.f)};
        uint32_t segments = 0;
        for (size_t c = 0; c < f.starts.size() && segments < 256; ++c) {
            const size_t end = c + 1 < f.starts.size() ? f.starts[c + 1] : f.points.size();
            for (size_t i = f.starts[c]; i + 1 < end && segments < 256; ++i, ++segments) {
                const candela::AnalyticShape s = candela::make_curve_segment(
                    f.points[i], f.radii[i], f.points[i + 1], f.radii[i + 1], segments, 256, i == f.starts[c]);
                s.bounds();
                for (const candela::vec3& o : origins) {
                    candela::Ray r;
                    r.o = o;
                    r.d = 0.5f * (f.points[i] + f.points[i + 1]) - o;
                    candela::Hit h;
                    if (candela::intersect_analytic(s, r, h)) candela::analytic_interaction(s, h);
                    candela::occluded_analytic(s, r);
                }
            }
        }
    } catch (const candela::Error&) {
    }
    return 0;
}
