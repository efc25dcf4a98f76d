#pragma once
// The analytic scene of the furnace tests: a unit sphere of diffuse albedo `albedo` at the origin
// under a constant sky of radiance 1, seen from z = 4, 16 x 16 pixels. With albedo 1 every pixel
// is exactly 1 (the white furnace); no mesh at all.
#include "scene/camera.h"
#include "scene/scene.h"
#include "geometry/analytic.h"

namespace candela::test {

inline SceneDescription sphere_under_sky(float albedo) {
    SceneDescription d;
    d.source = "<white furnace>";
    d.materials.push_back({"ball", DiffuseBsdf{vec3(albedo)}, false});
    d.add_analytic_shape("ball", make_sphere(mat4(1.f), vec3(0.f), 1.f, false), 0, -1);
    d.lights.push_back({"sky", ConstantLight{vec3(1.f)}});
    d.camera.to_world = look_at(vec3(0, 0, 4), vec3(0.f), vec3(0, 1, 0));
    d.camera.fov_deg = 40.f;
    d.settings.width = d.settings.height = 16;
    return d;
}

}  // namespace candela::test
