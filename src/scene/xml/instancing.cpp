// The shape family's `shapegroup` and `instance` (Mitsuba 3 src/shapes/shapegroup.cpp,
// instance.cpp). A group's shapes are read by the ordinary shape code into the world description,
// then moved out of it into the group (group space is the space their own to_world puts them in).
// A group is built once, when first met: at its definition, or at an instance that refers to it
// before it (Mitsuba resolves references after parsing).
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

// The group defined by element `gn`, built on first use. Returns its index in scene().groups.
uint32_t group_of(XmlLoader& L, pugi::xml_node gn) {
    SceneDescription& d = L.scene();
    const std::string id = gn.attribute("id") ? L.attr(gn, "id") : std::string();
    if (!id.empty())
        for (uint32_t i = 0; i < d.groups.size(); ++i)
            if (d.groups[i].id == id) return i;
    Object o = L.read_object(gn, "shape");
    ShapeGroup g;
    g.id = id.empty() ? "shapegroup@" + std::to_string(o.line) : id;
    const uint32_t gi = uint32_t(d.groups.size());
    for (Nested& c : o.nested) {
        if (c.tag != "shape" && c.tag != "ref") continue;  // anything else: finish() names it
        c.used = true;
        pugi::xml_node sn = L.definition(c, "shape");
        const std::string type = L.attr(sn, "type");
        if (type == "shapegroup") throw L.error(c.node, "shapegroup '" + g.id + "': nested ShapeGroup is not permitted");
        if (type == "instance") throw L.error(c.node, "shapegroup '" + g.id + "': nested instancing is not permitted");
        const size_t pos0 = d.mesh.positions.size(), nrm0 = d.mesh.normals.size(), tri0 = d.mesh.triangles.size(),
                     uv0 = d.mesh.uvs.size(), col0 = d.mesh.colors.size(), an0 = d.analytic.size(),
                     shape0 = d.shapes.size();
        load_shape(L, sn);
        for (size_t s = shape0; s < d.shapes.size(); ++s)
            if (d.shapes[s].emitter >= 0)
                throw L.error(sn, "shapegroup '" + g.id + "': instancing of emitters is not supported (as in Mitsuba)");
        // Move what the shape appended from the world description into the group.
        Mesh& w = d.mesh;
        const uint32_t gpos = uint32_t(g.mesh.positions.size()), gtri = uint32_t(g.mesh.triangles.size()),
                       gan = uint32_t(g.analytic.size()), guv = uint32_t(g.mesh.uvs.size()),
                       gcol = uint32_t(g.mesh.colors.size());
        g.mesh.uvs.insert(g.mesh.uvs.end(), w.uvs.begin() + long(uv0), w.uvs.end());
        g.mesh.colors.insert(g.mesh.colors.end(), w.colors.begin() + long(col0), w.colors.end());
        g.mesh.positions.insert(g.mesh.positions.end(), w.positions.begin() + long(pos0), w.positions.end());
        if (w.normals.size() > pos0) {
            g.mesh.normals.resize(gpos, vec3(0.f));
            g.mesh.normals.insert(g.mesh.normals.end(), w.normals.begin() + long(pos0), w.normals.end());
        }
        if (!g.mesh.normals.empty()) g.mesh.normals.resize(g.mesh.positions.size(), vec3(0.f));
        for (size_t t = tri0; t < w.triangles.size(); ++t) {
            g.mesh.triangles.push_back(w.triangles[t] - uvec3(uint32_t(pos0)) + uvec3(gpos));
            g.mesh.tri_shape.push_back(w.tri_shape[t]);
        }
        g.analytic.insert(g.analytic.end(), d.analytic.begin() + long(an0), d.analytic.end());
        w.positions.resize(pos0);
        w.normals.resize(std::min(nrm0, pos0));
        w.triangles.resize(tri0);
        w.tri_shape.resize(tri0);
        w.uvs.resize(uv0);
        w.colors.resize(col0);
        d.analytic.resize(an0);
        for (size_t s = shape0; s < d.shapes.size(); ++s) {
            Shape& sh = d.shapes[s];
            sh.group = int32_t(gi);
            sh.first_triangle = sh.first_triangle - uint32_t(tri0) + gtri;
            if (sh.analytic >= 0) sh.analytic = sh.analytic - int32_t(an0) + int32_t(gan);
            sh.first_vertex = sh.first_vertex - uint32_t(pos0) + gpos;
            if (sh.has_uv()) sh.uv_offset = sh.uv_offset - uint32_t(uv0) + guv;
            if (sh.has_color()) sh.color_offset = sh.color_offset - uint32_t(col0) + gcol;
        }
    }
    L.finish(o);
    d.groups.push_back(std::move(g));
    return gi;
}

}  // namespace

void load_shapegroup(XmlLoader& L, Object& o) {
    for (Nested& c : o.nested) c.used = true;  // read by group_of
    group_of(L, o.node);
}

void load_instance(XmlLoader& L, Object& o) {
    mat4 m = o.params.get_transform("to_world", mat4(1.f));
    double det = glm::determinant(glm::dmat3(glm::mat3(m)));
    if (!(std::abs(det) > 0.0) || !std::isfinite(det) || !all_finite(vec3(m[3])))
        throw o.params.error("to_world", "instance: to_world is singular or not finite");
    int found = -1;
    for (Nested& c : o.nested) {
        if (c.tag != "shape" && c.tag != "ref") continue;
        if (found >= 0) throw L.error(c.node, "an instance takes one shapegroup");
        pugi::xml_node gn = L.definition(c, "shape");
        const std::string type = L.attr(gn, "type");
        if (type != "shapegroup")
            throw L.error(c.node, "instance: " +
                                      (c.tag == "ref" ? "'" + L.attr(c.node, "id") + "' is a shape '" + type + "'"
                                                      : "the nested shape is a '" + type + "'") +
                                      ", not a shapegroup");
        found = int(group_of(L, gn));
        c.used = true;
    }
    if (found < 0) throw L.error(o.node, "instance needs a shapegroup: <ref id=\"...\"/> to one");
    L.finish(o);
    Instance in;
    in.group = uint32_t(found);
    in.to_world = m;
    in.to_object = glm::inverse(m);
    L.scene().instances.push_back(in);
}

}  // namespace xml
}  // namespace candela
