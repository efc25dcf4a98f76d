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
#include <memory>
#include <string>
#include <unordered_map>
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
    // A non-fatal message "file:line: what" for SceneDescription::warnings (the app prints them).
    void note(pugi::xml_node n, const std::string& what) {
        scene_.warnings.push_back(file_of(n) + ":" + std::to_string(line(n)) + ": " + what);
    }
    // A file named by the scene (mesh, texture, spectrum) as Mitsuba's file resolver finds it: an
    // absolute path as is; else the first that exists of the <path> folders (latest first), the
    // main scene's folder and the folder of the file that names it (`from`'s document). When none
    // exists, the main folder's candidate (for the error message).
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
    // Every element with an id, in any file and at any depth, is known before the first object is
    // built, so a <ref> may precede its definition (Mitsuba resolves references after parsing).
    // The element with this id (aliases followed), checked to be a <tag> (any tag when empty);
    // errors (unknown id, another kind) name the referencing node. Families use it for refs to
    // their objects: textures, emitters, shapes.
    IdEntry& object_by_id(pugi::xml_node ref_node, const std::string& id, const std::string& tag);
    // The element a nested object stands for: itself, or the definition a <ref> names (checked
    // to be a <tag>).
    pugi::xml_node definition(const Nested& c, const std::string& tag);
    int shape_counter = 0;  // shapes read so far (for default names)
    // Textures built so far, by element: one referenced several times is built once.
    std::map<const void*, std::shared_ptr<const Texture>> textures;
    // Media built so far, by element: index into SceneDescription::media.
    std::map<const void*, int32_t> media;

    // ---- bsdfs, shared by the shape and bsdf families ----
    // The material index of a bsdf element (built once even when referenced several times).
    uint32_t load_bsdf(pugi::xml_node n, const std::string& fallback_name);
    uint32_t bsdf_by_id(pugi::xml_node ref_node, const std::string& id);
    // The shape's one nested <bsdf> or <ref> (Mitsuba's default diffuse when none).
    uint32_t material_for(Object& shape);
    // The one <bsdf> (or <ref> to one) nested in a wrapper such as twosided, built by its factory.
    Material nested_bsdf(Object& wrapper);
    // The material of one nested <bsdf> or <ref> of `wrapper` (marks it used): for wrappers with
    // several nested BSDFs (blendbsdf).
    Material nested_bsdf(Object& wrapper, Nested& inner);

private:
    // One parsed file: the main scene or an included one. Nodes of every document stay valid
    // until the loader is destroyed, so elements of included files are read like the main file's.
    struct Document {
        std::string path, dir;                 // dir ends with '/' (or is empty)
        std::vector<size_t> line_starts;       // byte offsets where lines 2, 3, ... begin
        pugi::xml_document doc;
        std::string version;                   // the root's version attribute, as written
        bool upgraded = false;                 // read with Mitsuba 3's upgrade rules (< 2.0.0)
    };
    const Document& doc_of(pugi::xml_node n) const;
    Document& parse_document(const std::string& path, pugi::xml_node included_from);
    // The pass over the document tree in Mitsuba's order (depth first, includes in place): $name
    // substitution, <default>, <path>, <include>, version upgrades and ids. Fills children_.
    void expand(pugi::xml_node parent, bool scene_level, std::vector<pugi::xml_node>& out, int depth);
    void register_id(pugi::xml_node n, const std::string& tag);
    void substitute_attributes(pugi::xml_node n);
    void substitute_tree(pugi::xml_node n);
    std::string substitute(pugi::xml_node n, const std::string& text) const;
    void check_version(pugi::xml_node root, Document& d, bool required);
    void load_default(pugi::xml_node n);
    void load_path(pugi::xml_node n);
    void load_include(pugi::xml_node n, bool scene_level, std::vector<pugi::xml_node>& out, int depth);
    std::string find_include(pugi::xml_node from, const std::string& file) const;

    std::vector<float> numbers(pugi::xml_node n, const char* name, std::initializer_list<size_t> counts) const;
    Param read_property(pugi::xml_node n, bool within_emitter) const;
    Param read_spectrum(pugi::xml_node n, bool within_emitter) const;
    mat4 read_transform(pugi::xml_node n) const;
    const std::vector<pugi::xml_node>& children(pugi::xml_node n) const;  // includes expanded
    uint32_t bsdf_element(pugi::xml_node n, const std::string& fallback_name);

    std::string path_;
    std::vector<std::unique_ptr<Document>> docs_;
    std::unordered_map<const void*, const Document*> doc_by_root_;  // pugi document node -> Document
    // Element children of every object element and of <scene>, with includes spliced in and
    // <default>/<path>/<include> consumed, in document order.
    std::unordered_map<const void*, std::vector<pugi::xml_node>> children_;
    std::vector<std::string> include_stack_;  // canonical paths of the files being expanded
    std::vector<std::string> search_path_;    // <path> folders, latest first (Mitsuba prepends)
    std::vector<std::pair<std::string, std::string>> vars_;  // $name values, -D first
    std::map<std::string, IdEntry> ids_;
    std::map<std::string, std::string> aliases_;  // <alias id as>: as -> id
    // The bsdfs being built, outermost first: wrappers (twosided) recurse through nested bsdfs and
    // refs, so a ref cycle or a deep nest must be an error before it is a stack overflow.
    std::vector<pugi::xml_node> bsdf_stack_;
    static constexpr size_t kMaxBsdfNesting = 64;
    static constexpr int kMaxIncludeDepth = 15;
    static constexpr int kMaxObjectNesting = 256;
    int bsdf_nesting_ = 0, object_nesting_ = 0;  // while expand() is inside nested objects  // Mitsuba's MI_XML_INCLUDE_MAX_RECURSION
    SceneDescription scene_;
};

}  // namespace xml
}  // namespace candela
