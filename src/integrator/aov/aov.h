#pragma once
// The values of Mitsuba's `aov` integrator (src/integrators/aov.cpp) at the first surface a
// camera ray hits. They use no random numbers, so the nested integrator draws exactly the samples
// it would draw alone: its image is the same as without the wrapper.
#include <algorithm>
#include <vector>
#include "integrator/desc.h"
#include "scene/scene.h"

namespace candela {

// Writes aov_channel_count(aovs) floats to `out`: zeros where the ray hits nothing (Mitsuba zeroes
// the interaction). Depth is the distance from the camera's pinhole (`eye`) to the hit along the
// ray. Counts its one closest-hit ray in *rays.
// The channels are those of aov_channel_names(aovs); a Moment spec (always the last) is left for
// write_moment, which needs the sample's radiance.
void eval_aovs(const Scene& scene, const std::vector<AovSpec>& aovs, vec3 eye, const Ray& ray, float* out,
               uint64_t* rays);

// Where the moment channels start in the aov values, or -1 without a moment wrapper.
inline int moment_offset(const std::vector<AovSpec>& aovs) {
    if (aovs.empty() || aovs.back().type != AovType::Moment) return -1;
    return aov_channel_count(aovs) - aov_channel_count(AovType::Moment);
}

// The moment wrapper's values for a sample of radiance L (linear sRGB, finite): L as CIE XYZ
// (Mitsuba's srgb_to_xyz matrix) and the square of each component.
inline void write_moment(float* out, vec3 L) {
    const float x = 0.412453f * L.x + 0.357580f * L.y + 0.180423f * L.z;
    const float y = 0.212671f * L.x + 0.715160f * L.y + 0.072169f * L.z;
    const float z = 0.019334f * L.x + 0.119193f * L.y + 0.950227f * L.z;
    out[0] = x, out[1] = y, out[2] = z;
    // A finite radiance above 1.8e19 would square to infinity, which must not reach the film.
    constexpr float kMax = 3.4e38f;
    out[3] = std::min(x * x, kMax), out[4] = std::min(y * y, kMax), out[5] = std::min(z * z, kMax);
}

}  // namespace candela
