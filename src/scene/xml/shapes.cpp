// The shape family of the XML reader: triangle shapes (obj, rectangle, cube, and the mesh files
// ply and serialized, read by src/shapes/) and analytic shapes placed in world space with their
// bsdf and area emitter; shapegroup and instance (xml/instancing.cpp).
#include <glm/glm.hpp>
#include <fstream>
#include "scene/obj.h"
#include "scene/shapes_analytic.h"
#include "scene/xml/plugins.h"
#include "shapes/curve_file.h"
#include "shapes/mesh_file.h"

namespace candela {
namespace xml {

namespace {

// A shape's nested <emitter>, or a <ref> to one.
bool is_emitter_child(XmlLoader& L, const Nested& c) {
    if (c.tag == "emitter") return true;
    return c.tag == "ref" && L.object_by_id(c.node, L.required_attr(c.node, "id"), "").tag == "emitter";
}

ShapeGeometry make_obj(XmlLoader& L, Object& o) {
    if (!o.params.has("filename")) throw L.error(o.node, "shape 'obj' needs a 'filename' string");
    std::string file = o.params.get_string("filename", "");
    bool face_normals = o.params.get_bool("face_normals", false);
    bool flip_tex = o.params.get_bool("flip_tex_coords", true);
    std::string full = L.resolve(o.node, file);
    if (!std::ifstream(full)) throw o.params.error("filename", "cannot open OBJ file '" + file + "' (" + full + ")");
    ObjData obj;
    try {
        obj = read_obj(full, false);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (shape at " + L.path() + ":" + std::to_string(o.line) + ")");
    }
    ShapeGeometry g;
    g.positions = obj.positions;
    for (const ObjGroup& grp : obj.groups) g.triangles.insert(g.triangles.end(), grp.triangles.begin(), grp.triangles.end());
    if (!face_normals) {
        if (obj.all_have_normals()) g.normals = obj.normals;
        else g.recompute_normals = true;
    }
    if (obj.all_have_uvs()) g.uvs = obj.uvs;
    if (flip_tex)
        for (vec2& uv : g.uvs) uv.y = 1.f - uv.y;
    return g;
}

// ply and serialized: the file's data, with Mitsuba's mesh flags.
ShapeGeometry mesh_file_geometry(MeshFile f, bool face_normals, bool flip_tex) {
    ShapeGeometry g;
    g.positions = std::move(f.positions);
    g.triangles = std::move(f.triangles);
    g.uvs = std::move(f.uvs);
    g.colors = std::move(f.colors);
    if (!face_normals) {
        if (!f.normals.empty()) g.normals = std::move(f.normals);
        else g.recompute_normals = true;
    }
    if (flip_tex)
        for (vec2& uv : g.uvs) uv.y = 1.f - uv.y;
    return g;
}

std::string mesh_file_path(XmlLoader& L, Object& o, const char* what) {
    if (!o.params.has("filename")) throw L.error(o.node, o.what() + " needs a 'filename' string");
    std::string file = o.params.get_string("filename", "");
    std::string full = L.resolve(o.node, file);
    if (!std::ifstream(full)) throw o.params.error("filename", std::string("cannot open ") + what + " file '" + file + "' (" + full + ")");
    return full;
}

ShapeGeometry make_ply(XmlLoader& L, Object& o) {
    std::string full = mesh_file_path(L, o, "PLY");
    bool face_normals = o.params.get_bool("face_normals", false);
    bool flip_tex = o.params.get_bool("flip_tex_coords", false);  // Mitsuba's ply default, unlike obj
    try {
        return mesh_file_geometry(read_ply(full), face_normals, flip_tex);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (shape at " + L.path() + ":" + std::to_string(o.line) + ")");
    }
}

ShapeGeometry make_serialized(XmlLoader& L, Object& o) {
    std::string full = mesh_file_path(L, o, "serialized");
    bool face_normals = o.params.get_bool("face_normals", false);
    int index = o.params.get_int("shape_index", 0);
    if (index < 0) throw o.params.error("shape_index", "shape_index must be >= 0");
    MeshFile f;
    try {
        f = read_serialized(full, index);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (shape at " + L.path() + ":" + std::to_string(o.line) + ")");
    }
    // Mitsuba 3.9 reads past a serialized mesh's colours and ignores its face-normals flag
    // (checked against 3.9.1): candela does the same, so both render the same image.
    f.colors.clear();
    return mesh_file_geometry(std::move(f), face_normals, false);
}

ShapeGeometry make_rectangle(XmlLoader&, Object& o) {
    o.params.get_bool("face_normals", false);  // Mitsuba's rectangle is flat either way
    ShapeGeometry g;
    g.analytic = true;
    g.positions = {vec3(-1.f, -1.f, 0.f), vec3(1.f, -1.f, 0.f), vec3(1.f, 1.f, 0.f), vec3(-1.f, 1.f, 0.f)};
    g.uvs = {vec2(0.f, 0.f), vec2(1.f, 0.f), vec2(1.f, 1.f), vec2(0.f, 1.f)};  // Mitsuba: uv = (p.xy + 1) / 2
    g.normals.assign(4, vec3(0.f, 0.f, 1.f));
    g.triangles = {uvec3(0, 1, 2), uvec3(0, 2, 3)};  // counter-clockwise seen from +z: normal +z
    return g;
}

ShapeGeometry make_cube(XmlLoader&, Object& o) {
    bool face_normals = o.params.get_bool("face_normals", false);
    ShapeGeometry g;
    g.analytic = !face_normals;  // Mitsuba's cube is a mesh: face_normals drops its vertex normals
    // Mitsuba 3's cube (src/shapes/cube.cpp): four corners per face, in its order, with its uvs,
    // wound so that every normal points outwards.
    static const float kPos[24][3] = {
        {1, -1, -1}, {1, -1, 1},  {-1, -1, 1}, {-1, -1, -1}, {1, 1, -1},  {-1, 1, -1}, {-1, 1, 1},  {1, 1, 1},
        {1, -1, -1}, {1, 1, -1},  {1, 1, 1},   {1, -1, 1},   {1, -1, 1},  {1, 1, 1},   {-1, 1, 1},  {-1, -1, 1},
        {-1, -1, 1}, {-1, 1, 1},  {-1, 1, -1}, {-1, -1, -1}, {1, 1, -1},  {1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}};
    static const float kUv[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    for (int f = 0; f < 6; ++f) {
        uint32_t b = uint32_t(4 * f);
        for (int k = 0; k < 4; ++k) {
            const float* p = kPos[4 * f + k];
            g.positions.push_back(vec3(p[0], p[1], p[2]));
            g.uvs.push_back(vec2(kUv[k][0], kUv[k][1]));
        }
        g.triangles.push_back(uvec3(b, b + 1, b + 2));
        g.triangles.push_back(uvec3(b + 3, b, b + 2));
        vec3 n = glm::normalize(glm::cross(g.positions[b + 1] - g.positions[b], g.positions[b + 2] - g.positions[b]));
        if (!face_normals) g.normals.insert(g.normals.end(), 4, n);
    }
    return g;
}

}  // namespace

const PluginTable<ShapeFactory>& shape_plugins() {
    static const PluginTable<ShapeFactory> table = {
        {"obj", make_obj},
        {"rectangle", make_rectangle},
        {"cube", make_cube},
        {"ply", make_ply},
        {"serialized", make_serialized},
    };
    return table;
}

// Mitsuba's linearcurve (geometry/analytic.h): the control points of the file under to_world
// (the radii unchanged), one analytic segment per pair of consecutive points of a curve.
void load_linearcurve(XmlLoader& L, pugi::xml_node n, Object& o) {
    ++L.shape_counter;
    const std::string full = mesh_file_path(L, o, "curve");
    const mat4 m = o.params.get_transform("to_world", mat4(1.f));
    o.params.get_bool("flip_normals", false);  // Mitsuba's curves ignore it
    CurveFile f;
    try {
        f = read_curve_file(full);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (shape at " + L.path() + ":" + std::to_string(o.line) + ")");
    }
    const uint32_t material = L.material_for(o);
    for (Nested& c : o.nested)
        if (is_emitter_child(L, c))
            throw L.error(c.node, "a linearcurve cannot be an area emitter (Mitsuba cannot sample points on curves either)");
    L.finish(o);
    std::vector<vec3> world(f.points.size());
    for (size_t i = 0; i < f.points.size(); ++i) world[i] = vec3(m * glm::vec4(f.points[i], 1.f));
    std::vector<AnalyticShape> segments;
    const uint32_t count = uint32_t(f.points.size() - f.starts.size());
    segments.reserve(count);
    for (size_t c = 0; c < f.starts.size(); ++c) {
        const uint32_t end = c + 1 < f.starts.size() ? f.starts[c + 1] : uint32_t(f.points.size());
        for (uint32_t i = f.starts[c]; i + 1 < end; ++i) {
            if (!all_finite(world[i]) || !all_finite(world[i + 1]))
                throw o.params.error("to_world", "a control point is not finite under to_world");
            segments.push_back(make_curve_segment(world[i], f.radii[i], world[i + 1], f.radii[i + 1],
                                                  uint32_t(segments.size()), count, i == f.starts[c]));
        }
    }
    const std::string name = n.attribute("id") ? L.attr(n, "id") : o.params.get_string("filename", o.type);
    L.scene().add_analytic_shapes(name, segments, material);
}

void load_shape(XmlLoader& L, pugi::xml_node n) {
    Object o = L.read_object(n, "shape");
    if (o.type == "shapegroup") return load_shapegroup(L, o);
    if (o.type == "instance") return load_instance(L, o);
    if (o.type == "linearcurve") return load_linearcurve(L, n, o);
    const bool analytic = is_analytic_shape_type(o.type);  // intersected exactly, not tessellated
    ShapeFactory make =
        analytic ? nullptr : L.find_plugin(shape_plugins(), o, ", sphere, disk, cylinder, linearcurve, shapegroup, instance");
    ++L.shape_counter;
    mat4 m = o.params.get_transform("to_world", mat4(1.f));
    bool flip = o.params.get_bool("flip_normals", false);
    ShapeGeometry g = make ? make(L, o) : ShapeGeometry{};
    AnalyticShape a = analytic ? make_analytic_shape(o.type, o.params, o.line, m, flip) : AnalyticShape{};
    uint32_t material = L.material_for(o);

    int32_t emitter = -1;
    for (Nested& c : o.nested) {
        if (!is_emitter_child(L, c)) continue;
        if (emitter >= 0) throw L.error(c.node, "a shape takes one emitter");
        emitter = load_shape_emitter(L, c.tag == "ref" ? L.definition(c, "emitter") : c.node);
        if (analytic && L.scene().emitters[size_t(emitter)].texture)
            throw L.error(c.node, "a textured radiance is supported on meshes only, not on a " + o.type);
        c.used = true;
    }
    int32_t interior = -1, exterior = -1;
    load_shape_media(L, o, interior, exterior);
    L.finish(o);
    auto set_media = [&](uint32_t shape) {
        L.scene().shapes[shape].interior = interior;
        L.scene().shapes[shape].exterior = exterior;
    };
    if (analytic) {
        set_media(L.scene().add_analytic_shape(
            n.attribute("id") ? L.attr(n, "id") : o.type + std::to_string(L.shape_counter), a, material, emitter));
        return;
    }

    // To world space: points by M, normals by the inverse transpose.
    glm::mat3 lin(m);
    if (g.analytic && glm::determinant(lin) > 0.f) g.normals.clear();  // flat: face normals suffice
    glm::mat3 nmat = glm::transpose(glm::inverse(lin));
    for (vec3& p : g.positions) p = vec3(m * glm::vec4(p, 1.f));
    for (vec3& nv : g.normals) {
        vec3 t = nmat * nv;
        float len = glm::length(t);
        nv = len > 0.f ? t / len : vec3(0.f);
    }
    if (!(std::abs(glm::determinant(lin)) > 0.f)) throw o.params.error("to_world", "to_world is singular");
    auto reverse = [&] {
        for (uvec3& t : g.triangles) std::swap(t.y, t.z);
    };
    if (g.recompute_normals) g.normals = compute_vertex_normals(g.positions, g.triangles);
    if (flip) {
        reverse();
        for (vec3& nv : g.normals) nv = -nv;
    }
    std::string name = n.attribute("id") ? L.attr(n, "id")
                       : o.params.has("filename") ? o.params.get_string("filename", o.type)
                                         : o.type + std::to_string(L.shape_counter);
    set_media(L.scene().add_shape(name, g.positions, g.normals, g.triangles, material, emitter, g.uvs, g.colors));
}

}  // namespace xml
}  // namespace candela
