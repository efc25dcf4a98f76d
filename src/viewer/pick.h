#pragma once
// What is under a pixel: one camera ray traced through the scene's accelerator. Used by the
// viewer's click-to-inspect; no window system here, so the tests can call it.
#include <string>
#include "scene/scene.h"

namespace candela {

struct PickResult {
    bool hit = false;
    vec3 position{0.f};
    vec3 normal{0.f};    // shading normal
    float distance = 0.f;
    uint32_t shape = ~0u, material = ~0u;
    uint32_t triangle = ~0u;              // the triangle hit, ~0u on an analytic shape (in an
                                          // instance: the triangle of its group's mesh)
    uint32_t instance = ~0u;              // the instance hit (Scene::instances), ~0u outside them
    PrimKind kind = PrimKind::Triangle;   // what was hit: a triangle, or a sphere, disk, cylinder or curve segment
    vec2 uv{0.f};                         // analytic shapes: Mitsuba's (u, v) there
    int32_t emitter = -1;
};

// `camera` must have had set_film_size called for the film the pixel belongs to; `film_pos` is in
// film pixels (x right, y down; the centre of pixel (i, j) is (i + 0.5, j + 0.5)). Reads only the
// scene's geometry (mesh, shapes, accelerator), which is immutable while a session renders.
inline PickResult pick(const Scene& scene, const Camera& camera, vec2 film_pos) {
    PickResult r;
    if (!scene.accel) return r;
    // film_pos is a position in the image: film_position maps it into the film (crop window).
    Ray ray = camera.generate_ray(camera.film_position(ivec2(0), film_pos));
    const vec3 from = camera.type == CameraType::Orthographic ? ray.o : camera.origin();
    Hit hit;
    if (!scene.accel->intersect(ray, hit)) return r;
    SurfaceInteraction si = scene.interaction(hit);
    const Shape& shape = scene.shapes[si.shape];
    r.hit = true;
    r.position = si.p;
    r.normal = si.ns;
    r.distance = glm::length(si.p - from);  // the orthographic camera: from its near plane
    r.shape = si.shape;
    r.material = shape.material;
    r.kind = hit.kind;
    r.triangle = hit.kind == PrimKind::Triangle ? hit.prim : ~0u;
    r.uv = si.uv;
    r.instance = hit.instance;
    r.emitter = shape.emitter;
    return r;
}

}  // namespace candela
