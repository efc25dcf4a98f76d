#pragma once
// The values of Mitsuba's `aov` integrator (src/integrators/aov.cpp) at the first surface a
// camera ray hits. They use no random numbers, so the nested integrator draws exactly the samples
// it would draw alone: its image is the same as without the wrapper.
#include <vector>
#include "integrator/desc.h"
#include "scene/scene.h"

namespace candela {

// Writes aov_channel_count(aovs) floats to `out`: zeros where the ray hits nothing (Mitsuba zeroes
// the interaction). Depth is the distance from the camera's pinhole (`eye`) to the hit along the
// ray. Counts its one closest-hit ray in *rays.
void eval_aovs(const Scene& scene, const std::vector<AovSpec>& aovs, vec3 eye, const Ray& ray, float* out,
               uint64_t* rays);

}  // namespace candela
