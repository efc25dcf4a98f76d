// The shape family of the XML reader: triangle shapes (obj, rectangle, cube) and analytic shapes
// placed in world space with their bsdf and area emitter; shapegroup and instance
// (xml/instancing.cpp).
#include <glm/glm.hpp>
#include <fstream>
#include "scene/obj.h"
#include "scene/shapes_analytic.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

ShapeGeometry make_obj(XmlLoader& L, Object& o) {
    if (!o.params.has("filename")) throw L.error(o.node, "shape 'obj' needs a 'filename' string");
    std::string file = o.params.get_string("filename", "");
    bool face_normals = o.params.get_bool("face_normals", false);
    o.params.get_bool("flip_tex_coords", true);  // candela reads no texture coordinates
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
    return g;
}

ShapeGeometry make_rectangle(XmlLoader&, Object&) {
    ShapeGeometry g;
    g.analytic = true;
    g.positions = {vec3(-1.f, -1.f, 0.f), vec3(1.f, -1.f, 0.f), vec3(1.f, 1.f, 0.f), vec3(-1.f, 1.f, 0.f)};
    g.normals.assign(4, vec3(0.f, 0.f, 1.f));
    g.triangles = {uvec3(0, 1, 2), uvec3(0, 2, 3)};  // counter-clockwise seen from +z: normal +z
    return g;
}

ShapeGeometry make_cube(XmlLoader&, Object&) {
    ShapeGeometry g;
    g.analytic = true;
    // Four corners per face (no shared vertices), wound so that every normal points outwards.
    for (int axis = 0; axis < 3; ++axis)
        for (int s = -1; s <= 1; s += 2) {
            vec3 n(0.f);
            n[axis] = float(s);
            vec3 u(0.f), v(0.f);
            u[(axis + 1) % 3] = 1.f;
            v[(axis + 2) % 3] = 1.f;
            if (s < 0) std::swap(u, v);  // keeps cross(u, v) == n
            uint32_t b = uint32_t(g.positions.size());
            g.positions.push_back(n - u - v);
            g.positions.push_back(n + u - v);
            g.positions.push_back(n + u + v);
            g.positions.push_back(n - u + v);
            g.normals.insert(g.normals.end(), 4, n);
            g.triangles.push_back(uvec3(b, b + 1, b + 2));
            g.triangles.push_back(uvec3(b, b + 2, b + 3));
        }
    return g;
}

}  // namespace

const PluginTable<ShapeFactory>& shape_plugins() {
    static const PluginTable<ShapeFactory> table = {
        {"obj", make_obj},
        {"rectangle", make_rectangle},
        {"cube", make_cube},
    };
    return table;
}

void load_shape(XmlLoader& L, pugi::xml_node n) {
    Object o = L.read_object(n, "shape");
    if (o.type == "shapegroup") return load_shapegroup(L, o);
    if (o.type == "instance") return load_instance(L, o);
    const bool analytic = is_analytic_shape_type(o.type);  // intersected exactly, not tessellated
    ShapeFactory make =
        analytic ? nullptr : L.find_plugin(shape_plugins(), o, ", sphere, disk, cylinder, shapegroup, instance");
    ++L.shape_counter;
    mat4 m = o.params.get_transform("to_world", mat4(1.f));
    bool flip = o.params.get_bool("flip_normals", false);
    ShapeGeometry g = make ? make(L, o) : ShapeGeometry{};
    AnalyticShape a = analytic ? make_analytic_shape(o.type, o.params, o.line, m, flip) : AnalyticShape{};
    uint32_t material = L.material_for(o);

    int32_t emitter = -1;
    for (Nested& c : o.nested) {
        if (c.tag != "emitter") continue;
        if (emitter >= 0) throw L.error(c.node, "a shape takes one emitter");
        emitter = load_shape_emitter(L, c.node);
        c.used = true;
    }
    L.finish(o);
    if (analytic) {
        L.scene().add_analytic_shape(n.attribute("id") ? L.attr(n, "id") : o.type + std::to_string(L.shape_counter), a,
                                     material, emitter);
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
                       : o.type == "obj" ? o.params.get_string("filename", "obj")
                                         : o.type + std::to_string(L.shape_counter);
    L.scene().add_shape(name, g.positions, g.normals, g.triangles, material, emitter);
}

}  // namespace xml
}  // namespace candela
