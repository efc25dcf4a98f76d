#include "scene/scene.h"
#include "core/error.h"
#include "accel/instances.h"
#include "accel/with_analytic.h"
#include "film/film.h"
#include "integrator/caps.h"
#include "integrator/desc.h"  // integrator_type_name

namespace candela {

uint32_t SceneDescription::add_shape(const std::string& name, const std::vector<vec3>& positions,
                                     const std::vector<vec3>& normals, const std::vector<uvec3>& triangles,
                                     uint32_t material, int32_t emitter, const std::vector<vec2>& uvs,
                                     const std::vector<vec3>& colors) {
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
    s.first_vertex = base;
    if (!uvs.empty()) {
        if (uvs.size() != positions.size()) throw Error(name, 0, "texture coordinates are not one per vertex");
        s.uv_offset = uint32_t(mesh.uvs.size());
        mesh.uvs.insert(mesh.uvs.end(), uvs.begin(), uvs.end());
    }
    if (!colors.empty()) {
        if (colors.size() != positions.size()) throw Error(name, 0, "vertex colours are not one per vertex");
        s.color_offset = uint32_t(mesh.colors.size());
        mesh.colors.insert(mesh.colors.end(), colors.begin(), colors.end());
    }
    uint32_t shape_index = uint32_t(shapes.size());
    for (const uvec3& t : triangles) {
        mesh.triangles.push_back(t + uvec3(base));
        mesh.tri_shape.push_back(shape_index);
    }
    shapes.push_back(s);
    return shape_index;
}

uint32_t SceneDescription::add_analytic_shapes(const std::string& name, std::vector<AnalyticShape> parts,
                                               uint32_t material) {
    Shape s;
    s.name = name;
    s.material = material;
    s.first_triangle = uint32_t(mesh.triangles.size());
    s.analytic = int32_t(analytic.size());  // the first part; Shape::analytic of a curve
    const uint32_t index = uint32_t(shapes.size());
    for (AnalyticShape& a : parts) a.shape = index;
    analytic.insert(analytic.end(), parts.begin(), parts.end());
    shapes.push_back(s);
    return index;
}

uint32_t SceneDescription::add_analytic_shape(const std::string& name, AnalyticShape a, uint32_t material,
                                              int32_t emitter) {
    Shape s;
    s.name = name;
    s.material = material;
    s.emitter = emitter;
    s.first_triangle = uint32_t(mesh.triangles.size());
    s.analytic = int32_t(analytic.size());
    a.shape = uint32_t(shapes.size());
    analytic.push_back(a);
    shapes.push_back(s);
    return a.shape;
}

namespace {

// The checks every parameter set must pass against the geometry it is rendered with.
void check_params(const std::string& source, const std::vector<Shape>& shapes, const SceneParams& p) {
    check_film_size(p.settings.width, p.settings.height, source);
    if (p.settings.max_depth < -1) throw Error(source, 0, "max depth must be -1 (unbounded) or >= 0");
    if (p.settings.rr_depth < 0) throw Error(source, 0, "Russian roulette depth must be >= 0");
    for (const Shape& s : shapes) {
        if (s.material >= p.materials.size())
            throw Error(source, 0, "shape '" + s.name + "' names material " + std::to_string(s.material) + " of " +
                                       std::to_string(p.materials.size()));
        if (s.emitter >= 0 && size_t(s.emitter) >= p.emitters.size())
            throw Error(source, 0, "shape '" + s.name + "' names emitter " + std::to_string(s.emitter) + " of " +
                                       std::to_string(p.emitters.size()));
    }
    for (const Light& l : p.lights) {
        const vec3 v = light_strength(l.model);
        if (!all_finite(v) || !(min_component(v) >= 0.f))
            throw Error(source, 0, "emitter '" + l.name + "': " + light_strength_name(l.model) +
                                       " must be finite and not negative");
    }
}

// A shape's uvs and colours are found from its vertex indices: they must stay in its run. Checks
// the shapes of `mesh`: the scene's own (group -1) or those of one shapegroup.
void check_vertex_runs(const std::string& source, const Mesh& mesh, const std::vector<Shape>& shapes, int32_t group) {
    for (const Shape& s : shapes) {
        if (s.group != group || (!s.has_uv() && !s.has_color())) continue;
        for (uint32_t i = s.first_triangle; i < s.first_triangle + s.triangle_count && i < mesh.triangles.size(); ++i)
            for (int k = 0; k < 3; ++k) {
                uint32_t v = mesh.triangles[i][k];
                bool ok = v >= s.first_vertex &&
                          (!s.has_uv() || uint64_t(v - s.first_vertex) + s.uv_offset < mesh.uvs.size()) &&
                          (!s.has_color() || uint64_t(v - s.first_vertex) + s.color_offset < mesh.colors.size());
                if (!ok) throw Error(source, 0, "shape '" + s.name + "' has a vertex without its uv or colour");
            }
    }
}

std::vector<Material> prepared(std::vector<Material> materials) {
    for (Material& m : materials) prepare(m);
    return materials;
}

// The camera ready for the scene's own film (a renderer of another film size sets its own copy).
Camera sized(Camera c, const RenderSettings& st) {
    c.set_film_size(st.width, st.height);
    return c;
}

bool same_emitters(const std::vector<AreaEmitter>& a, const std::vector<AreaEmitter>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i].radiance != b[i].radiance || a[i].texture != b[i].texture) return false;
    return true;
}

bool same_lights(const std::vector<Light>& a, const std::vector<Light>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (!same_light(a[i], b[i])) return false;
    return true;
}

}  // namespace

Scene::Scene(std::string source_, std::shared_ptr<const Geometry> geometry_, std::shared_ptr<const Accel> accel_,
             std::shared_ptr<const LightSet> lights_, const SceneParams& p, std::vector<std::string> warnings_)
    : source(std::move(source_)),
      geometry(std::move(geometry_)),
      mesh(geometry->mesh),
      shapes(geometry->shapes),
      analytic(geometry->analytic),
      groups(geometry->groups),
      instances(geometry->instances),
      accel(std::move(accel_)),
      light_set(std::move(lights_)),
      lights(*light_set),
      camera(sized(p.camera, p.settings)),
      settings(p.settings),
      materials(prepared(p.materials)),
      emitters(p.emitters),
      light_params(p.lights),
      media(p.media),
      warnings(std::move(warnings_)) {}

namespace {

// Media indices in range and valid values; and an integrator that renders media (integrator/caps.h)
// when there are any: the others refuse the scene rather than render it without them.
void check_media(const std::string& source, int line, const std::vector<Medium>& media, int32_t camera_medium,
                 const std::vector<Shape>& shapes, const RenderSettings& st) {
    auto in_range = [&](int32_t i) { return i >= -1 && i < int32_t(media.size()); };
    if (!in_range(camera_medium)) throw Error(source, 0, "camera medium index out of range");
    for (const Shape& s : shapes)
        if (!in_range(s.interior) || !in_range(s.exterior))
            throw Error(source, 0, "shape '" + s.name + "': medium index out of range");
    for (const Medium& m : media)
        if (const char* e = medium_error(m)) throw Error(source, line, "medium '" + m.name + "': " + e);
    if (!media.empty() && !reads(st.integrator.type).media)
        throw Error(source, line, std::string("the ") + integrator_type_name(st.integrator.type) +
                                      " integrator does not render participating media (the scene has " +
                                      std::to_string(media.size()) + "); use volpath");
}

}  // namespace

std::shared_ptr<const Scene> build_scene(SceneDescription desc, const std::string& accel_name) {
    Mesh& mesh = desc.mesh;
    for (size_t i = 0; i < mesh.positions.size(); ++i)
        if (!all_finite(mesh.positions[i]))
            throw Error(desc.source, 0, "vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
    for (const uvec3& t : mesh.triangles)
        if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
            throw Error(desc.source, 0, "triangle index out of range");
    if (!mesh.normals.empty()) mesh.normals.resize(mesh.positions.size(), vec3(0.f));
    for (size_t i = 0; i < mesh.uvs.size(); ++i)
        if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y))
            throw Error(desc.source, 0, "vertex " + std::to_string(i) + " has a NaN or infinite texture coordinate");
    for (size_t i = 0; i < mesh.colors.size(); ++i)
        if (!all_finite(mesh.colors[i]))
            throw Error(desc.source, 0, "vertex " + std::to_string(i) + " has a NaN or infinite colour");
    check_vertex_runs(desc.source, mesh, desc.shapes, -1);
    for (ShapeGroup& g : desc.groups) {
        for (const vec3& p : g.mesh.positions)
            if (!all_finite(p)) throw Error(desc.source, 0, "shapegroup '" + g.id + "' has a NaN or infinite vertex");
        for (const uvec3& t : g.mesh.triangles)
            if (t.x >= g.mesh.positions.size() || t.y >= g.mesh.positions.size() || t.z >= g.mesh.positions.size())
                throw Error(desc.source, 0, "shapegroup '" + g.id + "': triangle index out of range");
        for (const vec2& uv : g.mesh.uvs)
            if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
                throw Error(desc.source, 0, "shapegroup '" + g.id + "' has a NaN or infinite texture coordinate");
        for (const vec3& c : g.mesh.colors)
            if (!all_finite(c)) throw Error(desc.source, 0, "shapegroup '" + g.id + "' has a NaN or infinite colour");
        check_vertex_runs(desc.source, g.mesh, desc.shapes, int32_t(&g - desc.groups.data()));
        if (!g.mesh.normals.empty()) g.mesh.normals.resize(g.mesh.positions.size(), vec3(0.f));
    }
    for (Instance& in : desc.instances) {
        if (in.group >= desc.groups.size()) throw Error(desc.source, 0, "instance of an unknown shapegroup");
        in.bounds = transform_box(in.to_world, desc.groups[in.group].bounds());
    }
    SceneParams params{desc.camera, desc.settings, std::move(desc.materials), std::move(desc.emitters),
                       std::move(desc.lights), std::move(desc.media)};
    check_params(desc.source, desc.shapes, params);
    check_media(desc.source, desc.media_line, params.media, desc.camera_medium, desc.shapes, params.settings);

    desc.mesh.compute_face_normals();
    for (ShapeGroup& g : desc.groups) g.mesh.compute_face_normals();
    auto geometry = std::make_shared<Geometry>();
    geometry->mesh = std::move(desc.mesh);
    geometry->shapes = std::move(desc.shapes);
    geometry->analytic = std::move(desc.analytic);
    geometry->groups = std::move(desc.groups);
    geometry->instances = std::move(desc.instances);
    geometry->camera_medium = desc.camera_medium;
    geometry->bounds = geometry->mesh.bounds();
    for (const AnalyticShape& a : geometry->analytic) geometry->bounds.expand(a.bounds());
    for (const Instance& in : geometry->instances) geometry->bounds.expand(in.bounds);
    std::unique_ptr<Accel> tri_accel = make_accel(accel_name, geometry->mesh);
    // Only a scene with analytic shapes pays for querying them, and only one with instances for
    // the instance level.
    if (!geometry->analytic.empty())
        tri_accel = std::make_unique<WithAnalyticAccel>(std::move(tri_accel), geometry->analytic);
    if (!geometry->instances.empty()) {
        bool own = !geometry->mesh.triangles.empty() || !geometry->analytic.empty();
        tri_accel = std::make_unique<InstanceAccel>(own ? std::move(tri_accel) : nullptr, geometry->groups,
                                                    geometry->instances, accel_name);
    }
    std::shared_ptr<const Accel> accel(std::move(tri_accel));
    auto lights = std::make_shared<LightSet>();
    lights->build(geometry->mesh, geometry->shapes, params.emitters, &geometry->analytic, &params.lights,
                  geometry->bounds);
    return std::shared_ptr<const Scene>(
        new Scene(std::move(desc.source), std::move(geometry), std::move(accel), std::move(lights), params,
                  std::move(desc.warnings)));
}

std::shared_ptr<const Scene> Scene::with_params(const SceneParams& p) const {
    check_params(source, shapes, p);
    // The media are edited in place (the viewer): their number is the geometry's, as the shapes
    // index them.
    if (p.media.size() != media.size())
        throw Error(source, 0, "the scene has " + std::to_string(media.size()) + " media, the parameters " +
                                   std::to_string(p.media.size()));
    check_media(source, 0, p.media, geometry->camera_medium, shapes, p.settings);
    std::shared_ptr<const LightSet> lights_for = light_set;
    if (!same_emitters(emitters, p.emitters) || !same_lights(light_params, p.lights)) {
        auto rebuilt = std::make_shared<LightSet>();
        rebuilt->build(mesh, shapes, p.emitters, &analytic, &p.lights, geometry->bounds);
        lights_for = std::move(rebuilt);
    }
    return std::shared_ptr<const Scene>(new Scene(source, geometry, accel, std::move(lights_for), p, warnings));
}

namespace {

SurfaceInteraction triangle_interaction(const Mesh& mesh, const std::vector<Shape>& shapes, const Hit& hit) {
    SurfaceInteraction si;
    si.prim = hit.prim;
    si.shape = mesh.tri_shape[hit.prim];
    const uvec3& t = mesh.triangles[hit.prim];
    vec3 p0 = mesh.positions[t.x], p1 = mesh.positions[t.y], p2 = mesh.positions[t.z];
    float b0 = 1.f - hit.b1 - hit.b2;
    si.p = b0 * p0 + hit.b1 * p1 + hit.b2 * p2;
    si.p_error = gamma_bound(7) * (abs3(b0 * p0) + abs3(hit.b1 * p1) + abs3(hit.b2 * p2));
    si.ng = mesh.face_normals.empty() ? face_normal(p0, p1, p2) : mesh.face_normals[hit.prim];
    si.ns = si.ng;
    if (shapes[si.shape].smooth) {
        vec3 n = b0 * mesh.normals[t.x] + hit.b1 * mesh.normals[t.y] + hit.b2 * mesh.normals[t.z];
        float l2 = glm::dot(n, n);
        if (l2 > 0.f && std::isfinite(l2)) si.ns = n / std::sqrt(l2);
    }
    // Mitsuba 3's mesh parameterisation (Mesh::compute_surface_interaction).
    vec3 dp0 = p1 - p0, dp1 = p2 - p0;
    const Shape& shape = shapes[si.shape];
    if (shape.has_uv()) {
        const vec2* uv = mesh.uvs.data() + shape.uv_offset - shape.first_vertex;
        vec2 uv0 = uv[t.x], uv1 = uv[t.y], uv2 = uv[t.z];
        si.uv = b0 * uv0 + hit.b1 * uv1 + hit.b2 * uv2;
        vec2 duv0 = uv1 - uv0, duv1 = uv2 - uv0;
        float det = duv0.x * duv1.y - duv0.y * duv1.x;
        if (det != 0.f && std::isfinite(1.f / det)) {
            float inv = 1.f / det;
            si.dpdu = (duv1.y * dp0 - duv0.y * dp1) * inv;
            si.dpdv = (duv0.x * dp1 - duv1.x * dp0) * inv;
        } else {
            Frame f(si.ng);
            si.dpdu = f.s;
            si.dpdv = f.t;
        }
    } else {
        si.uv = vec2(hit.b1, hit.b2);
        si.dpdu = dp0;
        si.dpdv = dp1;
    }
    return si;
}

vec3 transform_normal(const glm::mat3& inv_t, vec3 n) {
    vec3 w = inv_t * n;
    float l2 = glm::dot(w, w);
    return l2 > 0.f && std::isfinite(l2) ? w / std::sqrt(l2) : n;
}

}  // namespace

SurfaceInteraction Scene::interaction(const Hit& hit) const {
    // One test for both rare cases: an analytic shape (kind != 0) or an instance (instance != ~0u).
    if (__builtin_expect((uint32_t(hit.kind) | (hit.instance + 1u)) != 0u, 0)) {
        if (hit.instance == ~0u) return analytic_interaction(analytic[hit.prim], hit);
        const Instance& in = instances[hit.instance];
        const ShapeGroup& g = groups[in.group];
        SurfaceInteraction si = hit.kind == PrimKind::Triangle ? triangle_interaction(g.mesh, shapes, hit)
                                                               : analytic_interaction(g.analytic[hit.prim], hit);
        si.p = transform_point_error(in.to_world, si.p, si.p_error, &si.p_error);
        glm::mat3 inv_t = glm::transpose(glm::mat3(in.to_object));
        si.ng = transform_normal(inv_t, si.ng);
        si.ns = transform_normal(inv_t, si.ns);
        glm::mat3 lin(in.to_world);
        si.dpdu = lin * si.dpdu;
        si.dpdv = lin * si.dpdv;
        si.instance = hit.instance;
        return si;
    }
    return triangle_interaction(mesh, shapes, hit);
}

vec3 Scene::vertex_color(const Hit& hit) const {
    const Mesh& m = hit.instance == ~0u ? mesh : groups[instances[hit.instance].group].mesh;
    const Shape& shape = shapes[m.tri_shape[hit.prim]];
    if (!shape.has_color()) return vec3(0.f);
    const vec3* c = m.colors.data() + shape.color_offset - shape.first_vertex;
    const uvec3& t = m.triangles[hit.prim];
    return (1.f - hit.b1 - hit.b2) * c[t.x] + hit.b1 * c[t.y] + hit.b2 * c[t.z];
}

Scene::Memory Scene::memory() const {
    Memory m;
    m.triangles = mesh.triangles.size();
    m.mesh = mesh.memory_bytes();
    m.instances = instances.size();
    for (const ShapeGroup& g : groups) {
        m.triangles += g.mesh.triangles.size();
        m.mesh += g.mesh.memory_bytes() + g.analytic.capacity() * sizeof(AnalyticShape);
    }
    m.mesh += instances.capacity() * sizeof(Instance);
    m.accel = accel ? accel->memory_bytes() : 0;
    m.lights = lights.memory_bytes();
    return m;
}

}  // namespace candela
