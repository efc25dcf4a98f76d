#include "scene/scene.h"
#include "core/error.h"
#include "film/film.h"

namespace candela {

uint32_t Scene::add_shape(const std::string& name, const std::vector<vec3>& positions, const std::vector<vec3>& normals,
                          const std::vector<uvec3>& triangles, uint32_t material, int32_t emitter) {
    Shape s;
    s.name = name;
    s.material = material;
    s.emitter = emitter;
    s.smooth = !normals.empty();
    s.first_triangle = uint32_t(mesh.triangles.size());
    s.triangle_count = uint32_t(triangles.size());
    uint32_t base = uint32_t(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), positions.begin(), positions.end());
    // Normals are per vertex for the whole mesh: once any shape has them, all vertices get a slot
    // (zero for shapes that shade with face normals; Shape::smooth says which to use).
    if (s.smooth && mesh.normals.size() < base) mesh.normals.resize(base, vec3(0.f));
    if (s.smooth) mesh.normals.insert(mesh.normals.end(), normals.begin(), normals.end());
    else if (!mesh.normals.empty()) mesh.normals.resize(mesh.positions.size(), vec3(0.f));
    uint32_t shape_index = uint32_t(shapes.size());
    for (const uvec3& t : triangles) {
        mesh.triangles.push_back(t + uvec3(base));
        mesh.tri_shape.push_back(shape_index);
    }
    shapes.push_back(s);
    return shape_index;
}

void Scene::finalize(const std::string& accel_name) {
    for (size_t i = 0; i < mesh.positions.size(); ++i)
        if (!all_finite(mesh.positions[i]))
            throw Error(source, 0, "vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
    for (const uvec3& t : mesh.triangles)
        if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
            throw Error(source, 0, "triangle index out of range");
    if (!mesh.normals.empty()) mesh.normals.resize(mesh.positions.size(), vec3(0.f));
    check_film_size(settings.width, settings.height, source);
    camera.set_film_size(settings.width, settings.height);
    accel = make_accel(accel_name, mesh);
    lights.build(mesh, shapes, emitters);
}

SurfaceInteraction Scene::interaction(const Hit& hit) const {
    SurfaceInteraction si;
    si.prim = hit.prim;
    si.shape = mesh.tri_shape[hit.prim];
    const uvec3& t = mesh.triangles[hit.prim];
    vec3 p0 = mesh.positions[t.x], p1 = mesh.positions[t.y], p2 = mesh.positions[t.z];
    float b0 = 1.f - hit.b1 - hit.b2;
    si.p = b0 * p0 + hit.b1 * p1 + hit.b2 * p2;
    si.p_error = gamma_bound(7) * (glm::abs(b0 * p0) + glm::abs(hit.b1 * p1) + glm::abs(hit.b2 * p2));
    vec3 ng = glm::cross(p1 - p0, p2 - p0);
    float len = glm::length(ng);
    si.ng = len > 0.f ? ng / len : vec3(0.f, 0.f, 1.f);
    si.ns = si.ng;
    if (shapes[si.shape].smooth) {
        vec3 n = b0 * mesh.normals[t.x] + hit.b1 * mesh.normals[t.y] + hit.b2 * mesh.normals[t.z];
        float l2 = glm::dot(n, n);
        if (l2 > 0.f && std::isfinite(l2)) si.ns = n / std::sqrt(l2);
    }
    return si;
}

Scene::Memory Scene::memory() const {
    Memory m;
    m.triangles = mesh.triangles.size();
    m.mesh = mesh.positions.capacity() * sizeof(vec3) + mesh.normals.capacity() * sizeof(vec3) +
             mesh.triangles.capacity() * sizeof(uvec3) + mesh.tri_shape.capacity() * sizeof(uint32_t);
    m.accel = accel ? accel->memory_bytes() : 0;
    m.lights = lights.memory_bytes();
    return m;
}

}  // namespace candela
