// libFuzzer target: the .vol grid reader (src/medium/grid.cpp) on arbitrary bytes, then lookups of
// the grid it returns (trilinear and nearest, inside and outside the unit cube). Any input must
// parse or throw candela::Error; a crash, a sanitizer report, another exception, a leak or a hang
// is a finding.
#include <cstdint>
#include <string>
#include "core/error.h"
#include "medium/grid.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        candela::VolumeGrid g = candela::parse_vol("fuzz.vol", std::string(reinterpret_cast<const char*>(data), size));
        const candela::vec3 points[4] = {candela::vec3(0.5f), candela::vec3(0.f), candela::vec3(1.f),
                                         candela::vec3(-3.f, 0.2f, 7.f)};
        for (bool nearest : {false, true}) {
            g.nearest = nearest;
            for (const candela::vec3& p : points) g.eval(p);
        }
    } catch (const candela::Error&) {
    }
    return 0;
}
