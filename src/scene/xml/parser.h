#pragma once
// The Mitsuba 3 XML reader as a parser core plus plugin families (Mitsuba 3 keeps the same split:
// src/core/xml.cpp knows no plugin, each plugin is created from its Properties).
//
//   parser.cpp      the XML structure: documents, <default>, $name, properties, transforms,
//                   ids and <ref>, and the dispatch of top-level elements to the families.
//   bsdfs.cpp, shapes.cpp, emitters.cpp, sensors.cpp (sensors, films, samplers, rfilters),
//   integrators.cpp, textures.cpp
//                   one table of factories per family (plugins.h): a new plugin is one function
//                   plus one row in its family's table.
//
// A factory reads its parameters from Object::params (each getter marks the parameter used) and
// takes its nested objects from Object::nested (marking them used); XmlLoader::finish() then
// rejects whatever is left, with the file and line, the same way for every family.
#include <pugixml.hpp>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>
#include "core/error.h"
#include "scene/loaders.h"
#include "scene/params.h"

namespace candela {
namespace xml {

// A child object element (<bsdf>, <film>, <ref>...) of an object; the factory must consume it.
struct Nested {
    pugi::xml_node node;
    std::string tag;  // "ref" for a reference
    bool used = false;
};

// One object element as its factory sees it: parameters plus nested objects and refs.
struct Object {
    pugi::xml_node node;
    std::string tag, type;
    int line = 0;
    ParamSet params;
    std::vector<Nested> nested;

    Object(pugi::xml_node n, std::string tg, std::string ty, int ln, const std::string& file)
        : node(n), tag(std::move(tg)), type(std::move(ty)), line(ln), params(file, tag + " '" + type + "'") {}
    std::string what() const { return tag + " '" + type + "'"; }
};

// A family's registry: plugin type name -> factory.
template <class Factory>
struct Plugin {
    const char* type;
    Factory make;
};
template <class Factory>
using PluginTable = std::vector<Plugin<Factory>>;

class XmlLoader {
public:
    XmlLoader(std::string path, const Defines& defines);

    SceneDescription load();

    // ---- the scene being filled ----
    SceneDescription& scene() { return scene_; }

    // ---- locations and errors ----
    const std::string& path() const { return path_; }           // the main scene file
    const std::string& file_of(pugi::xml_node n) const;           // the file a node was read from
    int line(pugi::xml_node n) const;
    Error error(pugi::xml_node n, const std::string& what) const { return Error(file_of(n), line(n), what); }
    // A file named by the scene (mesh, texture), resolved against the directory of the file that
    // names it.
    std::string resolve(pugi::xml_node from, const std::string& file) const;

    // ---- reading elements ----
    std::string attr(pugi::xml_node n, const char* name) const;
    std::string required_attr(pugi::xml_node n, const char* name) const;
    void check_attributes(pugi::xml_node n, std::initializer_list<const char*> allowed) const;
    void check_text(pugi::xml_node n) const;
    // Reads an object element: its parameters and its nested objects (not yet built).
    Object read_object(pugi::xml_node n, const std::string& expected_tag);
    // Unused parameters and nested objects are errors.
    void finish(Object& o) const;

    // The factory of `o.type` in `table`, or an error "unsupported <tag> type '<type>'".
    template <class Factory>
    Factory find_plugin(const PluginTable<Factory>& table, const Object& o, const std::string& supported_note = "") const {
        for (const auto& p : table)
            if (o.type == p.type) return p.make;
        std::string known;
        for (const auto& p : table) known += (known.empty() ? "" : ", ") + std::string(p.type);
        throw error(o.node, "unsupported " + o.tag + " type '" + o.type + "' (candela supports: " +
                                (known.empty() ? "none" : known) + supported_note + ")");
    }

    // ---- ids and references ----
    struct IdEntry {
        std::string tag;
        int line = 0;
        pugi::xml_node node;
        int material = -1;  // bsdfs: the material once created
    };
    void register_id(pugi::xml_node n, const std::string& tag);
    // The element with this id, checked to be a <tag>; errors name the referencing node.
    IdEntry& object_by_id(pugi::xml_node ref_node, const std::string& id, const std::string& tag);
    int shape_counter = 0;  // shapes read so far (for default names)

    // ---- bsdfs, shared by the shape and bsdf families ----
    // The material index of a bsdf element (built once even when referenced several times).
    uint32_t load_bsdf(pugi::xml_node n, const std::string& fallback_name);
    uint32_t bsdf_by_id(pugi::xml_node ref_node, const std::string& id);
    // The shape's one nested <bsdf> or <ref> (Mitsuba's default diffuse when none).
    uint32_t material_for(Object& shape);
    // The one <bsdf> (or <ref> to one) nested in a wrapper such as twosided, built by its factory.
    Material nested_bsdf(Object& wrapper);

private:
    int line_of_offset(ptrdiff_t offset) const;
    std::string substitute(pugi::xml_node n, const std::string& text) const;
    std::vector<float> numbers(pugi::xml_node n, const char* name, std::initializer_list<size_t> counts) const;
    Param read_property(pugi::xml_node n) const;
    mat4 read_transform(pugi::xml_node n) const;
    void load_default(pugi::xml_node n);

    std::string path_, dir_;
    std::vector<size_t> line_starts_;  // byte offsets where lines 2, 3, ... begin
    std::map<std::string, std::string> vars_;
    std::map<std::string, IdEntry> ids_;
    // The bsdfs being built, outermost first: wrappers (twosided) recurse through nested bsdfs and
    // refs, so a ref cycle or a deep nest must be an error before it is a stack overflow.
    std::vector<pugi::xml_node> bsdf_stack_;
    static constexpr size_t kMaxBsdfNesting = 64;
    SceneDescription scene_;
};

}  // namespace xml
}  // namespace candela
