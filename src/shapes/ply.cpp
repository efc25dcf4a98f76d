// Stanford PLY reader. Debian 12 ships no maintained C++ PLY library (no tinyply, rply or
// happly package), so this is a small reader of its own, written against the format as Mitsuba 3
// reads it (src/shapes/ply.h and ply.cpp): the same header grammar and type names, the same
// property names for normals, uvs and colours, the same check for trailing content.
// Beyond Mitsuba 3.9.1, which refuses them: `obj_info` header lines, and faces with more than three
// corners (fan-triangulated, as Mitsuba's OBJ reader does).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include "core/error.h"
#include "shapes/mesh_file.h"

namespace candela {

std::string read_file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, 0, "cannot open file");
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw Error(path, 0, "read error");
    return bytes;
}

namespace {

enum class Type { I8, U8, I16, U16, I32, U32, I64, U64, F16, F32, F64 };

size_t type_size(Type t) {
    switch (t) {
        case Type::I8: case Type::U8: return 1;
        case Type::I16: case Type::U16: case Type::F16: return 2;
        case Type::I32: case Type::U32: case Type::F32: return 4;
        default: return 8;
    }
}
bool is_float(Type t) { return t == Type::F16 || t == Type::F32 || t == Type::F64; }

bool type_of(const std::string& s, Type& t) {
    static const std::pair<const char*, Type> names[] = {
        {"char", Type::I8},     {"uchar", Type::U8},    {"short", Type::I16},   {"ushort", Type::U16},
        {"int", Type::I32},     {"uint", Type::U32},    {"float", Type::F32},   {"double", Type::F64},
        {"int8", Type::I8},     {"uint8", Type::U8},    {"int16", Type::I16},   {"uint16", Type::U16},
        {"int32", Type::I32},   {"uint32", Type::U32},  {"long", Type::I64},    {"ulong", Type::U64},
        {"half", Type::F16},    {"float16", Type::F16}, {"float32", Type::F32}, {"float64", Type::F64},
    };
    for (const auto& n : names)
        if (s == n.first) {
            t = n.second;
            return true;
        }
    return false;
}

float half_to_float(uint16_t h) {
    uint32_t sign = uint32_t(h >> 15) << 31, exp = (h >> 10) & 0x1f, man = h & 0x3ff;
    float v;
    if (exp == 0) v = std::ldexp(float(man), -24);                          // zero, subnormal
    else if (exp == 31) v = man ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
    else v = std::ldexp(float(man | 0x400), int(exp) - 25);
    return sign ? -v : v;
}

struct Property {
    std::string name;
    Type type = Type::F32;
    bool list = false;
    Type count_type = Type::U8;
};

struct Element {
    std::string name;
    uint64_t count = 0;
    int line = 0;
    std::vector<Property> props;
};

// What a value is, for messages; rendered only when there is an error.
struct What {
    const std::string* prop;
    const std::string* elem;
    uint64_t index;
    bool count = false;
    std::string str() const {
        return "property '" + *prop + "'" + (count ? " (list length)" : "") + " of " + *elem + " " + std::to_string(index);
    }
};

// Where a vertex property goes: position, normal, uv or colour component, or nowhere.
enum Slot { X, Y, Z, NX, NY, NZ, U, V, R, G, B, kSlots, Ignore = -1 };

class PlyReader {
public:
    PlyReader(const std::string& name, const std::string& bytes) : name_(name), data_(bytes) {}

    MeshFile read() {
        parse_header();
        for (const Element& e : elements_) read_element(e);
        if (ascii_) {
            skip_space();
            if (pos_ < data_.size()) throw Error(name_, line_, "unexpected data after the last element");
        } else if (pos_ != data_.size()) {
            throw at_byte(pos_, std::to_string(data_.size() - pos_) + " bytes of trailing data after the last element");
        }
        if (!seen_vertex_) throw Error(name_, 0, "no 'vertex' element");
        if (!seen_face_) throw Error(name_, 0, "no 'face' element");
        if (out_.triangles.empty()) throw Error(name_, 0, "no faces");
        for (size_t f = 0; f < out_.triangles.size(); ++f) {
            const uvec3& t = out_.triangles[f];
            if (t.x >= out_.positions.size() || t.y >= out_.positions.size() || t.z >= out_.positions.size())
                throw Error(name_, 0, "triangle " + std::to_string(f) + " has a vertex index out of range (" +
                                          std::to_string(out_.positions.size()) + " vertices)");
        }
        return std::move(out_);
    }

private:
    Error at_byte(size_t b, const std::string& what) const {
        return Error(name_, 0, "byte " + std::to_string(b) + ": " + what);
    }
    // Errors in the body: the line in ASCII files, the byte offset in binary ones.
    Error body_error(size_t b, const std::string& what) const {
        return ascii_ ? Error(name_, line_, what) : at_byte(b, what);
    }

    void parse_header() {
        size_t p = 0;
        int line = 0;
        bool have_format = false;
        auto next_line = [&](std::vector<std::string>& tokens) {
            if (p >= data_.size()) throw Error(name_, line, "the header ends without 'end_header'");
            size_t e = data_.find('\n', p);
            if (e == std::string::npos) e = data_.size();
            std::string text = data_.substr(p, e - p);
            p = e + 1;
            ++line;
            tokens.clear();
            size_t i = 0;
            while (i < text.size()) {
                while (i < text.size() && std::isspace((unsigned char)text[i])) ++i;
                size_t j = i;
                while (j < text.size() && !std::isspace((unsigned char)text[j])) ++j;
                if (j > i) tokens.push_back(text.substr(i, j - i));
                i = j;
            }
        };
        if (data_.compare(0, 3, "ply") != 0 || (data_.size() > 3 && data_[3] != '\n' && data_[3] != '\r'))
            throw Error(name_, 1, "not a PLY file (it must start with the line 'ply')");
        std::vector<std::string> tk;
        next_line(tk);  // "ply"
        for (;;) {
            next_line(tk);
            if (tk.empty() || tk[0] == "comment" || tk[0] == "obj_info") continue;
            const std::string& key = tk[0];
            if (key == "format") {
                if (have_format) throw Error(name_, line, "duplicate 'format' line");
                if (tk.size() != 3) throw Error(name_, line, "'format' needs a format and a version");
                if (tk[1] == "ascii") ascii_ = true;
                else if (tk[1] == "binary_little_endian") big_endian_ = false;
                else if (tk[1] == "binary_big_endian") big_endian_ = true;
                else throw Error(name_, line, "unknown format '" + tk[1] + "' (ascii, binary_little_endian, binary_big_endian)");
                if (tk[2] != "1.0") throw Error(name_, line, "unknown PLY version '" + tk[2] + "' (1.0)");
                have_format = true;
            } else if (key == "element") {
                if (tk.size() != 3) throw Error(name_, line, "'element' needs a name and a count");
                Element e;
                e.name = tk[1];
                e.line = line;
                const std::string& c = tk[2];
                errno = 0;
                char* end = nullptr;
                unsigned long long n = std::strtoull(c.c_str(), &end, 10);
                if (c.empty() || c[0] == '-' || *end != '\0' || errno == ERANGE)
                    throw Error(name_, line, "element count '" + c + "' is not a non-negative integer");
                e.count = n;
                elements_.push_back(e);
            } else if (key == "property") {
                if (!have_format) throw Error(name_, line, "'property' before 'format'");
                if (elements_.empty()) throw Error(name_, line, "'property' before any 'element'");
                Property pr;
                if (tk.size() >= 2 && tk[1] == "list") {
                    if (tk.size() != 5) throw Error(name_, line, "'property list' needs a count type, an item type and a name");
                    if (!type_of(tk[2], pr.count_type)) throw Error(name_, line, "unknown type '" + tk[2] + "'");
                    if (!type_of(tk[3], pr.type)) throw Error(name_, line, "unknown type '" + tk[3] + "'");
                    if (is_float(pr.count_type)) throw Error(name_, line, "a list count must have an integer type, not " + tk[2]);
                    pr.list = true;
                    pr.name = tk[4];
                } else {
                    if (tk.size() != 3) throw Error(name_, line, "'property' needs a type and a name");
                    if (!type_of(tk[1], pr.type)) throw Error(name_, line, "unknown type '" + tk[1] + "'");
                    pr.name = tk[2];
                }
                for (const Property& q : elements_.back().props)
                    if (q.name == pr.name) throw Error(name_, line, "duplicate property '" + pr.name + "'");
                elements_.back().props.push_back(pr);
            } else if (key == "end_header") {
                if (tk.size() != 1) throw Error(name_, line, "unexpected text after 'end_header'");
                break;
            } else if (key == "ply") {
                throw Error(name_, line, "duplicate 'ply' line");
            } else {
                throw Error(name_, line, "unknown header line '" + key + "'");
            }
        }
        if (!have_format) throw Error(name_, line, "no 'format' line in the header");
        pos_ = p;
        line_ = line + 1;
        for (const Element& e : elements_)
            if (e.props.empty() && e.count > 0)
                throw Error(name_, e.line, "element '" + e.name + "' has entries but no properties");
    }

    // ---- reading values ----
    void skip_space() {
        while (pos_ < data_.size() && std::isspace((unsigned char)data_[pos_])) {
            if (data_[pos_] == '\n') ++line_;
            ++pos_;
        }
    }
    std::string token(const What& what) {
        skip_space();
        if (pos_ >= data_.size()) throw Error(name_, line_, "the file ends before " + what.str());
        size_t b = pos_;
        while (pos_ < data_.size() && !std::isspace((unsigned char)data_[pos_])) ++pos_;
        return data_.substr(b, pos_ - b);
    }
    const unsigned char* bytes(size_t n, const What& what) {
        if (n > data_.size() - pos_) throw at_byte(pos_, "the file ends before " + what.str());
        const unsigned char* p = reinterpret_cast<const unsigned char*>(data_.data()) + pos_;
        pos_ += n;
        return p;
    }
    template <typename T>
    T load(const unsigned char* p) const {
        unsigned char b[sizeof(T)];
        std::memcpy(b, p, sizeof(T));
        bool host_big = false;  // x86-64 and every target candela builds for are little-endian
        if (big_endian_ != host_big)
            for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
        T v;
        std::memcpy(&v, b, sizeof(T));
        return v;
    }

    // One scalar as a double (integers up to 2^53 exactly, which covers every index candela takes).
    double value(Type t, const What& what) {
        if (ascii_) {
            std::string s = token(what);
            const char* c = s.c_str();
            char* end = nullptr;
            errno = 0;
            if (is_float(t)) {
                double d = std::strtod(c, &end);
                if (*end != '\0' || end == c) throw Error(name_, line_, "could not parse '" + s + "' as a number for " + what.str());
                return d;
            }
            bool is_unsigned = t == Type::U8 || t == Type::U16 || t == Type::U32 || t == Type::U64;
            double d;
            if (is_unsigned) {
                if (s[0] == '-') throw Error(name_, line_, "'" + s + "' is negative for the unsigned " + what.str());
                d = double(std::strtoull(c, &end, 10));
            } else {
                d = double(std::strtoll(c, &end, 10));
            }
            if (*end != '\0' || end == c || errno == ERANGE)
                throw Error(name_, line_, "could not parse '" + s + "' as an integer for " + what.str());
            double lo = 0, hi = 0;
            switch (t) {
                case Type::I8: lo = -128, hi = 127; break;
                case Type::U8: hi = 255; break;
                case Type::I16: lo = -32768, hi = 32767; break;
                case Type::U16: hi = 65535; break;
                case Type::I32: lo = -2147483648.0, hi = 2147483647.0; break;
                case Type::U32: hi = 4294967295.0; break;
                default: lo = -1.8446744073709552e19, hi = 1.8446744073709552e19; break;
            }
            if (d < lo || d > hi) throw Error(name_, line_, "'" + s + "' is out of range for " + what.str());
            return d;
        }
        const unsigned char* p = bytes(type_size(t), what);
        switch (t) {
            case Type::I8: return double(int8_t(p[0]));
            case Type::U8: return double(p[0]);
            case Type::I16: return double(load<int16_t>(p));
            case Type::U16: return double(load<uint16_t>(p));
            case Type::I32: return double(load<int32_t>(p));
            case Type::U32: return double(load<uint32_t>(p));
            case Type::I64: return double(load<int64_t>(p));
            case Type::U64: return double(load<uint64_t>(p));
            case Type::F16: return double(half_to_float(load<uint16_t>(p)));
            case Type::F32: return double(load<float>(p));
            case Type::F64: return load<double>(p);
        }
        return 0.0;
    }

    // The least number of bytes one entry of the element occupies (lists may be empty).
    size_t min_entry_bytes(const Element& e) const {
        size_t n = 0;
        for (const Property& p : e.props) n += ascii_ ? 2 : type_size(p.list ? p.count_type : p.type);
        return n;
    }

    void read_element(const Element& e) {
        // A count the rest of the file cannot hold is an error before anything is allocated.
        size_t remaining = data_.size() - pos_, least = min_entry_bytes(e);
        if (e.count > 0 && least > 0 && e.count > (remaining + 1) / least)
            throw Error(name_, e.line,
                        "element '" + e.name + "' declares " + std::to_string(e.count) +
                            " entries, more than the rest of the file can hold (" + std::to_string(remaining) + " bytes)");
        if (e.name == "vertex") read_vertices(e);
        else if (e.name == "face") read_faces(e);
        else skip(e);
    }

    void skip_list(const Property& p, What what) {
        what.count = true;
        double n = value(p.count_type, what);
        what.count = false;
        if (n < 0) throw body_error(pos_, "negative list length for " + what.str());
        for (double i = 0; i < n; ++i) value(p.type, what);
    }

    void skip(const Element& e) {
        for (uint64_t i = 0; i < e.count; ++i)
            for (const Property& p : e.props) {
                What what{&p.name, &e.name, i};
                if (p.list) skip_list(p, what);
                else value(p.type, what);
            }
    }

    void read_vertices(const Element& e) {
        if (seen_vertex_) throw Error(name_, e.line, "more than one 'vertex' element");
        seen_vertex_ = true;
        if (e.count > 0xffffffffull) throw Error(name_, e.line, "more than 2^32 - 1 vertices");
        std::vector<int> slot(e.props.size(), Ignore);
        auto find = [&](const char* n) -> int {
            for (size_t i = 0; i < e.props.size(); ++i)
                if (!e.props[i].list && e.props[i].name == n) return int(i);
            return -1;
        };
        auto assign = [&](std::initializer_list<const char*> names, int first) {
            std::vector<int> ix;
            for (const char* n : names) ix.push_back(find(n));
            for (int i : ix)
                if (i < 0) return false;
            for (size_t k = 0; k < ix.size(); ++k) slot[size_t(ix[k])] = first + int(k);
            return true;
        };
        if (!assign({"x", "y", "z"}, X)) throw Error(name_, e.line, "the 'vertex' element needs properties x, y and z");
        bool normals = assign({"nx", "ny", "nz"}, NX);  // partial normals are ignored, as in Mitsuba
        bool uvs = assign({"u", "v"}, U) || assign({"texture_u", "texture_v"}, U) || assign({"s", "t"}, U);
        bool colors = assign({"r", "g", "b"}, R) || assign({"red", "green", "blue"}, R);
        size_t n = size_t(e.count);
        out_.positions.resize(n);
        if (normals) out_.normals.resize(n);
        if (uvs) out_.uvs.resize(n);
        if (colors) out_.colors.resize(n);
        for (size_t i = 0; i < n; ++i) {
            float v[kSlots] = {};
            for (size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                What what{&p.name, &e.name, i};
                if (slot[k] == Ignore || p.list) {
                    if (p.list) skip_list(p, what);
                    else value(p.type, what);
                    continue;
                }
                size_t at = pos_;
                float f = float(value(p.type, what));
                if (!std::isfinite(f))
                    throw body_error(at, "vertex " + std::to_string(i) + ": '" + p.name + "' is NaN or infinite (or beyond float range)");
                v[slot[k]] = f;
            }
            out_.positions[i] = vec3(v[X], v[Y], v[Z]);
            if (normals) out_.normals[i] = vec3(v[NX], v[NY], v[NZ]);
            if (uvs) out_.uvs[i] = vec2(v[U], v[V]);
            if (colors) out_.colors[i] = vec3(v[R], v[G], v[B]);
        }
    }

    void read_faces(const Element& e) {
        if (seen_face_) throw Error(name_, e.line, "more than one 'face' element");
        seen_face_ = true;
        int index_prop = -1;
        for (const char* want : {"vertex_index", "vertex_indices"}) {
            for (size_t i = 0; i < e.props.size() && index_prop < 0; ++i)
                if (e.props[i].list && e.props[i].name == want) index_prop = int(i);
            if (index_prop >= 0) break;
        }
        if (index_prop < 0) throw Error(name_, e.line, "the 'face' element has no list 'vertex_index' or 'vertex_indices'");
        if (is_float(e.props[size_t(index_prop)].type))
            throw Error(name_, e.line, "vertex indices must have an integer type");
        out_.triangles.reserve(size_t(e.count));
        std::vector<uint32_t> corners;
        for (uint64_t f = 0; f < e.count; ++f) {
            for (size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                What what{&p.name, &e.name, f};
                if (int(k) != index_prop) {
                    if (p.list) skip_list(p, what);
                    else value(p.type, what);
                    continue;
                }
                size_t at = pos_;
                what.count = true;
                double n = value(p.count_type, what);
                what.count = false;
                if (n < 3) throw body_error(at, "face " + std::to_string(f) + " has " + std::to_string(int64_t(n)) + " corners (at least 3)");
                // Each corner takes at least one byte (binary) or two (ASCII): a longer list is truncated data.
                size_t left = data_.size() - pos_;
                if (n > double(left) / (ascii_ ? 1.0 : double(type_size(p.type))))
                    throw body_error(at, "face " + std::to_string(f) + " has " + std::to_string(int64_t(n)) + " corners, more than the rest of the file holds");
                corners.clear();
                for (double c = 0; c < n; ++c) {
                    size_t ca = pos_;
                    double ix = value(p.type, what);
                    if (ix < 0 || ix > 4294967294.0)
                        throw body_error(ca, "face " + std::to_string(f) + " has the vertex index " + std::to_string(int64_t(ix)) + " out of range");
                    corners.push_back(uint32_t(ix));
                }
                for (size_t c = 2; c < corners.size(); ++c) out_.triangles.push_back(uvec3(corners[0], corners[c - 1], corners[c]));
            }
        }
    }

    std::string name_;
    const std::string& data_;
    std::vector<Element> elements_;
    bool ascii_ = false, big_endian_ = false;
    size_t pos_ = 0;
    int line_ = 0;  // ASCII: the line of pos_
    bool seen_vertex_ = false, seen_face_ = false;
    MeshFile out_;
};

}  // namespace

MeshFile parse_ply(const std::string& name, const std::string& bytes) {
    return PlyReader(name, bytes).read();
}

MeshFile read_ply(const std::string& path) {
    std::string bytes = read_file_bytes(path);
    return parse_ply(path, bytes);
}

}  // namespace candela
