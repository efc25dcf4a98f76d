// Plain OBJ + MTL scenes, and the OBJ reading shared with the XML `obj` shape.
//
// tinyobjloader parses the statements and the MTL files, but it is lenient: it skips unknown
// statements, turns unparsable numbers into 0, and takes out-of-range face indices without a word
// (reading out of bounds later). So a first pass over the text validates every statement and
// reports problems with their line; tinyobjloader only ever sees files that passed.
#include "scene/obj.h"
#include <tiny_obj_loader.h>
#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>
#include "core/error.h"
#include "core/interrupt.h"
#include "scene/loaders.h"

namespace candela {

namespace {

std::string read_text_file(const std::string& path) {
    // A directory opens like a file and then reads as empty (the read error is swallowed by the
    // stream), which would be reported as an "empty OBJ file".
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw Error(path, 0, "is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, 0, "cannot open file");
    // In chunks, so that an interrupt is noticed while a big file is read; a small file gets a
    // chunk of its own size (resize zero-fills the chunk: 4 MB per file of a few hundred bytes
    // was most of the loading time of a scene made of small OBJs).
    std::string text;
    const uintmax_t size = std::filesystem::file_size(path, ec);
    const uintmax_t max_chunk = uintmax_t(1) << 22;
    const size_t chunk = size_t(ec ? max_chunk : std::clamp<uintmax_t>(size + 1, 4096, max_chunk));
    for (;;) {
        throw_if_interrupted();
        const size_t have = text.size();
        text.resize(have + chunk);
        in.read(&text[have], std::streamsize(chunk));
        text.resize(have + size_t(in.gcount()));
        if (size_t(in.gcount()) < chunk) break;
    }
    if (in.bad()) throw Error(path, 0, "cannot read file");
    return text;
}

std::string directory_of(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

std::vector<std::string> split_ws(const std::string& s) {
    std::vector<std::string> out;
    std::istringstream in(s);
    std::string tok;
    while (in >> tok) out.push_back(tok);
    return out;
}

// Counts of the attribute arrays seen so far, to resolve relative (negative) indices and to reject
// references to data not yet defined (as Mitsuba does).
struct ObjCounts {
    long v = 0, vt = 0, vn = 0, faces = 0;
};

void validate_obj_text(const std::string& path, const std::string& text) {
    ObjCounts n;
    int line_no = 0;
    size_t pos = 0;
    bool any_content = false;
    while (pos < text.size()) {
        size_t eol = text.find('\n', pos);
        if (eol == std::string::npos) eol = text.size();
        std::string line = text.substr(pos, eol - pos);
        pos = eol + 1;
        ++line_no;
        throw_if_interrupted();
        auto fail = [&](const std::string& what) { throw Error(path, line_no, what); };

        for (char c : line)
            if (c == '\0' || (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r'))
                fail("binary data: this is not a text OBJ file");
        size_t hash = line.find('#');
        if (hash != std::string::npos) line.resize(hash);
        std::vector<std::string> tok = split_ws(line);
        if (tok.empty()) continue;
        any_content = true;
        const std::string& kw = tok[0];

        auto numbers = [&](size_t first, const char* what) {
            std::vector<double> v;
            for (size_t i = first; i < tok.size(); ++i) {
                char* end = nullptr;
                double x = std::strtod(tok[i].c_str(), &end);
                if (end == tok[i].c_str() || *end != '\0')
                    fail("could not parse number '" + tok[i] + "' in '" + kw + "' statement");
                if (!std::isfinite(x)) fail(std::string(what) + " has a NaN or infinite coordinate");
                v.push_back(x);
            }
            return v;
        };

        if (kw == "v") {
            size_t c = numbers(1, "vertex").size();
            // x y z, optionally w or an r g b vertex colour
            if (c != 3 && c != 4 && c != 6) fail("'v' needs 3 coordinates, got " + std::to_string(c));
            ++n.v;
        } else if (kw == "vn") {
            if (numbers(1, "normal").size() != 3) fail("'vn' needs 3 numbers");
            ++n.vn;
        } else if (kw == "vt") {
            size_t c = numbers(1, "texture coordinate").size();
            if (c < 1 || c > 3) fail("'vt' needs 1 to 3 numbers");
            ++n.vt;
        } else if (kw == "f") {
            if (tok.size() < 4) fail("a face needs at least 3 vertices");
            for (size_t i = 1; i < tok.size(); ++i) {
                // v, v/vt, v//vn or v/vt/vn
                std::vector<std::string> part;
                std::string cur;
                for (char c : tok[i]) {
                    if (c == '/') {
                        part.push_back(cur);
                        cur.clear();
                    } else {
                        cur += c;
                    }
                }
                part.push_back(cur);
                if (part.size() > 3 || part[0].empty() || (part.size() == 3 && part[2].empty()))
                    fail("malformed face vertex '" + tok[i] + "'");
                const long counts[3] = {n.v, n.vt, n.vn};
                const char* names[3] = {"vertex", "texture coordinate", "normal"};
                for (size_t k = 0; k < part.size(); ++k) {
                    if (part[k].empty()) continue;  // the vt slot of v//vn
                    char* end = nullptr;
                    long idx = std::strtol(part[k].c_str(), &end, 10);
                    if (*end != '\0') fail("malformed face vertex '" + tok[i] + "'");
                    long resolved = idx > 0 ? idx - 1 : counts[k] + idx;
                    if (idx == 0 || resolved < 0 || resolved >= counts[k])
                        fail(std::string(names[k]) + " index " + part[k] + " out of range (" +
                             std::to_string(counts[k]) + " defined so far)");
                }
            }
            ++n.faces;
        } else if (kw == "g" || kw == "o" || kw == "s" || kw == "usemtl" || kw == "mtllib" || kw == "l" ||
                   kw == "p" || kw == "vp" || kw == "mg" || kw == "maplib" || kw == "usemap" || kw == "lod" ||
                   kw == "shadow_obj" || kw == "trace_obj" || kw == "bevel" || kw == "c_interp" ||
                   kw == "d_interp") {
            // grouping, materials and display hints; lines and points are not rendered
        } else if (kw == "cstype" || kw == "deg" || kw == "bmat" || kw == "step" || kw == "curv" ||
                   kw == "curv2" || kw == "surf" || kw == "parm" || kw == "trim" || kw == "hole" ||
                   kw == "scrv" || kw == "sp" || kw == "end" || kw == "con") {
            fail("free-form geometry ('" + kw + "') is not supported");
        } else {
            fail("unknown OBJ statement '" + (kw.size() > 20 ? kw.substr(0, 20) + "..." : kw) + "'");
        }
    }
    if (!any_content) throw Error(path, 0, "empty OBJ file");
    if (n.faces == 0) throw Error(path, 0, "no faces in OBJ file");
}

// Accepts every mtllib without reading it: the XML `obj` shape ignores materials, as Mitsuba does.
class IgnoreMaterials : public tinyobj::MaterialReader {
public:
    bool operator()(const std::string&, std::vector<tinyobj::material_t>*, std::map<std::string, int>*,
                    std::string*, std::string*) override {
        return true;
    }
};

// Serves a text to tinyobjloader in chunks and ends it early (EOF) once an interrupt is requested,
// so that a multi-second parse stops within a chunk; read_obj then throws Interrupted. It also
// spares the copy an istringstream would make.
class InterruptibleText : public std::streambuf {
public:
    explicit InterruptibleText(const std::string& text) : next_(text.data()), end_(text.data() + text.size()) {}

protected:
    int_type underflow() override {
        if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
        if (next_ == end_ || interrupt_requested()) return traits_type::eof();
        const size_t n = std::min<size_t>(size_t(end_ - next_), size_t(1) << 16);
        char* b = const_cast<char*>(next_);  // read-only: the get area is never written
        setg(b, b, b + n);
        next_ += n;
        return traits_type::to_int_type(*gptr());
    }

private:
    const char* next_;
    const char* end_;
};

void add_warnings(ObjData& out, const std::string& path, const std::string& text) {
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line))
        if (!line.empty()) out.warnings.push_back(path + ": " + line);
}

}  // namespace

bool ObjData::all_have_normals() const {
    for (unsigned char h : has_normal)
        if (!h) return false;
    return true;
}

bool ObjData::all_have_uvs() const {
    for (unsigned char h : has_uv)
        if (!h) return false;
    return !has_uv.empty();
}

ObjData read_obj(const std::string& path, bool materials) {
    std::string text = read_text_file(path);
    validate_obj_text(path, text);

    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> mtls;
    std::string warn, err;
    InterruptibleText text_buf(text);
    std::istream in(&text_buf);
    tinyobj::MaterialFileReader file_reader(directory_of(path).empty() ? "./" : directory_of(path));
    IgnoreMaterials ignore;
    tinyobj::MaterialReader* reader = materials ? static_cast<tinyobj::MaterialReader*>(&file_reader) : &ignore;
    bool ok = tinyobj::LoadObj(&attrib, &shapes, &mtls, &warn, &err, &in, reader, /*triangulate=*/false);
    throw_if_interrupted();  // before `ok`: an interrupted parse saw a cut text
    if (!ok) {
        std::string msg = err.empty() ? "could not parse OBJ file" : err;
        while (!msg.empty() && (msg.back() == '\n' || msg.back() == '.')) msg.pop_back();
        throw Error(path, 0, msg);
    }

    ObjData out;
    add_warnings(out, path, warn);
    add_warnings(out, path, err);  // MTL problems land in err without failing the load
    for (const tinyobj::material_t& m : mtls) {
        ObjMaterial om;
        om.name = m.name;
        om.kd = vec3(float(m.diffuse[0]), float(m.diffuse[1]), float(m.diffuse[2]));
        om.ke = vec3(float(m.emission[0]), float(m.emission[1]), float(m.emission[2]));
        if (!all_finite(om.kd) || !all_finite(om.ke))
            throw Error(path, 0, "material '" + m.name + "' has a NaN or infinite Kd or Ke");
        out.materials.push_back(om);
    }

    // One vertex per distinct (v, vt, vn) triple, so that shared corners stay shared.
    struct KeyHash {
        size_t operator()(const std::array<int, 3>& k) const {
            return size_t(hash_combine(hash_combine(uint64_t(uint32_t(k[0])), uint64_t(uint32_t(k[1]))),
                                       uint64_t(uint32_t(k[2]))));
        }
    };
    std::unordered_map<std::array<int, 3>, uint32_t, KeyHash> vertex_of;
    auto vertex = [&](const tinyobj::index_t& ix) -> uint32_t {
        std::array<int, 3> key{ix.vertex_index, ix.texcoord_index, ix.normal_index};
        auto it = vertex_of.find(key);
        if (it != vertex_of.end()) return it->second;
        uint32_t id = uint32_t(out.positions.size());
        const auto& v = attrib.vertices;
        size_t p = 3 * size_t(ix.vertex_index);
        // tinyobjloader may read fewer vertices than the line check counted (a 'v' followed by a
        // carriage return, found by fuzz_obj): an index it cannot resolve is an error, not a read.
        if (ix.vertex_index < 0 || p + 2 >= v.size() ||
            (ix.normal_index >= 0 && 3 * size_t(ix.normal_index) + 2 >= attrib.normals.size()))
            throw Error(path, 0, "a face refers to a vertex or normal that the file does not define");
        out.positions.push_back(vec3(float(v[p]), float(v[p + 1]), float(v[p + 2])));
        vec3 nrm(0.f);
        bool has = ix.normal_index >= 0;
        if (has) {
            const auto& nv = attrib.normals;
            size_t q = 3 * size_t(ix.normal_index);
            nrm = vec3(float(nv[q]), float(nv[q + 1]), float(nv[q + 2]));
            float len = glm::length(nrm);
            nrm = len > 0.f ? nrm / len : vec3(0.f);
        }
        out.normals.push_back(nrm);
        out.has_normal.push_back(has ? 1 : 0);
        vec2 uv(0.f);
        bool has_uv = ix.texcoord_index >= 0 && 2 * size_t(ix.texcoord_index) + 1 < attrib.texcoords.size();
        if (has_uv) {
            size_t q = 2 * size_t(ix.texcoord_index);
            uv = vec2(float(attrib.texcoords[q]), float(attrib.texcoords[q + 1]));
        }
        out.uvs.push_back(uv);
        out.has_uv.push_back(has_uv ? 1 : 0);
        vertex_of.emplace(key, id);
        return id;
    };

    for (const tinyobj::shape_t& sh : shapes) {
        std::map<int, size_t> group_of_material;  // this shape's groups, by material
        size_t first = 0;
        for (size_t f = 0; f < sh.mesh.num_face_vertices.size(); ++f) {
            if (f % 4096 == 0) throw_if_interrupted();
            size_t count = sh.mesh.num_face_vertices[f];
            int mat = f < sh.mesh.material_ids.size() ? sh.mesh.material_ids[f] : -1;
            if (mat >= int(out.materials.size())) mat = -1;
            auto it = group_of_material.find(mat);
            if (it == group_of_material.end()) {
                it = group_of_material.emplace(mat, out.groups.size()).first;
                out.groups.push_back({sh.name, mat, {}});
            }
            ObjGroup& g = out.groups[it->second];
            uint32_t v0 = vertex(sh.mesh.indices[first]);
            uint32_t prev = vertex(sh.mesh.indices[first + 1]);
            for (size_t k = 2; k < count; ++k) {
                uint32_t cur = vertex(sh.mesh.indices[first + k]);
                g.triangles.push_back(uvec3(v0, prev, cur));
                prev = cur;
            }
            first += count;
        }
    }
    if (out.groups.empty()) throw Error(path, 0, "no faces in OBJ file");
    return out;
}

std::vector<vec3> compute_vertex_normals(const std::vector<vec3>& positions, const std::vector<uvec3>& triangles) {
    std::vector<vec3> n(positions.size(), vec3(0.f));
    for (const uvec3& t : triangles) {
        throw_if_interrupted();
        vec3 p[3] = {positions[t.x], positions[t.y], positions[t.z]};
        vec3 fn = glm::cross(p[1] - p[0], p[2] - p[0]);
        float len = glm::length(fn);
        if (!(len > 0.f)) continue;  // degenerate: no direction to contribute
        fn /= len;
        for (int i = 0; i < 3; ++i) {
            vec3 d0 = p[(i + 1) % 3] - p[i], d1 = p[(i + 2) % 3] - p[i];
            float l0 = glm::length(d0), l1 = glm::length(d1);
            if (!(l0 > 0.f) || !(l1 > 0.f)) continue;
            float c = glm::clamp(glm::dot(d0, d1) / (l0 * l1), -1.f, 1.f);
            n[t[i]] += fn * std::acos(c);
        }
    }
    for (vec3& v : n) {
        float len = glm::length(v);
        v = len > 0.f ? v / len : vec3(0.f);
    }
    return n;
}

void set_default_camera(SceneDescription& scene) {
    AABB b = scene.mesh.bounds();
    vec3 c(0.f);
    float r = 1.f;
    if (!b.empty()) {
        c = b.center();
        r = 0.5f * glm::length(b.extent());
        if (!(r > 0.f)) r = 1.f;
    }
    // The bounding sphere is tangent to the cone of a 45 degree fov at this distance.
    const float fov = 45.f;
    float d = r / std::sin(glm::radians(0.5f * fov));
    scene.camera = Camera();
    scene.camera.to_world = look_at(c - vec3(0.f, 0.f, d), c, vec3(0.f, 1.f, 0.f));
    scene.camera.fov_deg = fov;
    scene.camera.fov_axis = FovAxis::Smaller;
    // Clip planes relative to the scene size, so tiny and huge scenes both work.
    scene.camera.near_clip = 1e-3f * (d + r);
    scene.camera.far_clip = 10.f * (d + r);
}

SceneDescription load_obj_scene(const std::string& path) {
    ObjData obj = read_obj(path, true);
    SceneDescription scene;
    scene.source = path;
    scene.warnings = obj.warnings;

    // Materials and emitters are made on first use, so unused MTL entries cost nothing.
    std::vector<int> material_index(obj.materials.size(), -1), emitter_index(obj.materials.size(), -1);
    int default_material = -1;
    auto material_for = [&](int m) -> uint32_t {
        if (m < 0) {
            if (default_material < 0) {
                default_material = int(scene.materials.size());
                scene.materials.push_back({"default", DiffuseBsdf{vec3(0.5f)}, true});
            }
            return uint32_t(default_material);
        }
        if (material_index[m] < 0) {
            material_index[m] = int(scene.materials.size());
            scene.materials.push_back({obj.materials[m].name, DiffuseBsdf{obj.materials[m].kd}, true});
        }
        return uint32_t(material_index[m]);
    };
    auto emitter_for = [&](int m) -> int32_t {
        if (m < 0 || is_black(obj.materials[m].ke)) return -1;
        if (emitter_index[m] < 0) {
            emitter_index[m] = int(scene.emitters.size());
            scene.emitters.push_back({obj.materials[m].ke});
        }
        return emitter_index[m];
    };

    // Each group gets its own compact copy of the vertices it uses.
    std::vector<uint32_t> local(obj.positions.size(), UINT32_MAX);
    for (size_t gi = 0; gi < obj.groups.size(); ++gi) {
        throw_if_interrupted();
        const ObjGroup& g = obj.groups[gi];
        std::vector<vec3> pos, nrm;
        std::vector<uint32_t> used;
        std::vector<uvec3> tris;
        bool smooth = true;
        for (const uvec3& t : g.triangles) {
            uvec3 lt;
            for (int k = 0; k < 3; ++k) {
                uint32_t v = t[k];
                if (local[v] == UINT32_MAX) {
                    local[v] = uint32_t(pos.size());
                    used.push_back(v);
                    pos.push_back(obj.positions[v]);
                    nrm.push_back(obj.normals[v]);
                    smooth = smooth && obj.has_normal[v];
                }
                lt[k] = local[v];
            }
            tris.push_back(lt);
        }
        for (uint32_t v : used) local[v] = UINT32_MAX;
        std::string name = g.name.empty() ? "group" + std::to_string(gi) : g.name;
        if (g.material >= 0) name += "/" + obj.materials[g.material].name;
        scene.add_shape(name, pos, smooth ? nrm : std::vector<vec3>{}, tris, material_for(g.material),
                        emitter_for(g.material));
    }

    set_default_camera(scene);
    scene.settings = RenderSettings();
    scene.settings.width = scene.settings.height = 512;
    scene.settings.spp = 64;
    scene.settings.max_depth = -1;
    return scene;
}

}  // namespace candela
