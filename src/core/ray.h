#pragma once
#include "core/math.h"

namespace candela {

// A ray o + t d for t in [tmin, tmax]. d need not be normalised: intersection routines report t
// in units of d. Accelerators shrink tmax to the closest hit found so far.
struct Ray {
    vec3 o{0.f};
    vec3 d{0.f, 0.f, 1.f};
    float tmin = 0.f;
    float tmax = kInfinity;
    vec3 at(float t) const { return o + t * d; }
};

}  // namespace candela
