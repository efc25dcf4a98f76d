// PLY and serialized meshes (src/shapes/): round trips through files written here in every
// encoding the readers take, Mitsuba 3's own meshes against what Mitsuba reads from them
// (tests/data/public_meshes.txt, made by tests/data/make_mesh_reference.py), the XML shape flags
// (to_world, face_normals, flip_normals, flip_tex_coords), Mitsuba's uv conventions and dp/du in
// Scene::interaction, and bad input: every prefix of a file, corrupt data, absurd counts.
#include <gtest/gtest.h>
#include <zlib.h>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include "core/error.h"
#include "scene/loaders.h"
#include "scene/scene.h"
#include "shapes/mesh_file.h"
#include "support/run.h"

using namespace candela;
using namespace candela::test;

namespace {

// ---- a PLY writer for the round trips ----------------------------------------------------------

enum class Enc { Ascii, LE, BE };

struct PlyProp {
    std::string type, name;  // scalar; type "list:<count>:<item>" for lists
};

class PlyWriter {
public:
    explicit PlyWriter(Enc e) : enc_(e) {}
    std::string header;  // everything up to and including end_header
    std::string body;

    void begin(const std::vector<std::pair<std::string, std::pair<size_t, std::vector<PlyProp>>>>& elements,
               const std::string& extra_header = "") {
        std::ostringstream h;
        h << "ply\n"
          << "format " << (enc_ == Enc::Ascii ? "ascii" : enc_ == Enc::LE ? "binary_little_endian" : "binary_big_endian")
          << " 1.0\ncomment written by test_mesh_formats\nobj_info candela\n" << extra_header;
        for (const auto& e : elements) {
            h << "element " << e.first << " " << e.second.first << "\n";
            for (const PlyProp& p : e.second.second) {
                if (p.type.rfind("list:", 0) == 0) {
                    size_t c = p.type.find(':', 5);
                    h << "property list " << p.type.substr(5, c - 5) << " " << p.type.substr(c + 1) << " " << p.name << "\n";
                } else {
                    h << "property " << p.type << " " << p.name << "\n";
                }
            }
        }
        h << "end_header\n";
        header = h.str();
    }
    // One value of a scalar type (a list's count and items are values too).
    void put(const std::string& type, double v) {
        if (enc_ == Enc::Ascii) {
            char buf[64];
            if (type == "float" || type == "float32") std::snprintf(buf, sizeof buf, "%.9g ", v);
            else if (type == "double" || type == "float64") std::snprintf(buf, sizeof buf, "%.17g ", v);
            else std::snprintf(buf, sizeof buf, "%lld ", (long long)v);
            body += buf;
            return;
        }
        unsigned char b[8];
        size_t n = 0;
        auto raw = [&](const void* p, size_t k) {
            std::memcpy(b, p, k);
            n = k;
        };
        if (type == "char" || type == "int8") { int8_t x = int8_t(v); raw(&x, 1); }
        else if (type == "uchar" || type == "uint8") { uint8_t x = uint8_t(v); raw(&x, 1); }
        else if (type == "short" || type == "int16") { int16_t x = int16_t(v); raw(&x, 2); }
        else if (type == "ushort" || type == "uint16") { uint16_t x = uint16_t(v); raw(&x, 2); }
        else if (type == "int" || type == "int32") { int32_t x = int32_t(v); raw(&x, 4); }
        else if (type == "uint" || type == "uint32") { uint32_t x = uint32_t(v); raw(&x, 4); }
        else if (type == "float" || type == "float32") { float x = float(v); raw(&x, 4); }
        else if (type == "double" || type == "float64") { double x = v; raw(&x, 8); }
        else ADD_FAILURE() << "writer: unknown type " << type;
        if (enc_ == Enc::BE)
            for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
        body.append(reinterpret_cast<char*>(b), n);
    }
    void end_entry() {
        if (enc_ == Enc::Ascii) body += "\n";
    }
    std::string bytes() const { return header + body; }

private:
    Enc enc_;
};

// A mesh with every attribute, written with mixed types and an unusual property order.
struct Reference {
    std::vector<vec3> p, n, c;
    std::vector<vec2> uv;
    std::vector<std::vector<uint32_t>> faces;
    std::vector<uvec3> triangles;  // the faces fan-triangulated
};

Reference make_reference(int vertices) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-10.f, 10.f);
    Reference r;
    for (int i = 0; i < vertices; ++i) {
        r.p.push_back(vec3(u(rng), u(rng), u(rng)));
        r.n.push_back(glm::normalize(vec3(u(rng), u(rng), u(rng))));
        r.uv.push_back(vec2(u(rng) * 0.1f, u(rng) * 0.1f));
        r.c.push_back(vec3(float(rng() % 256), float(rng() % 256), float(rng() % 256)));
    }
    r.faces = {{0, 1, 2}, {3, 4, 5, 6}, {1, 6, 7, 2, 0}, {uint32_t(vertices - 1), 0, 5}};
    for (const auto& f : r.faces)
        for (size_t k = 2; k < f.size(); ++k) r.triangles.push_back(uvec3(f[0], f[k - 1], f[k]));
    return r;
}

std::string write_ply(const Reference& r, Enc enc, const char* u = "u", const char* v = "v") {
    PlyWriter w(enc);
    std::vector<PlyProp> vp = {{"uchar", "red"},  {"float", "nx"},      {"double", "x"},  {"float", "y"},
                               {"short", "q_x"},  {"float", "z"},       {"float", "ny"},  {"float", "nz"},
                               {"float", u},      {"float", v},         {"uchar", "green"}, {"uchar", "blue"},
                               {"list:uchar:int", "junk"}};
    std::vector<PlyProp> fp = {{"uchar", "flags"}, {"list:uchar:uint", "vertex_indices"}, {"float", "quality"}};
    std::vector<PlyProp> ep = {{"int", "vertex1"}, {"int", "vertex2"}};
    w.begin({{"vertex", {r.p.size(), vp}}, {"face", {r.faces.size(), fp}}, {"edge", {2, ep}}});
    for (size_t i = 0; i < r.p.size(); ++i) {
        w.put("uchar", r.c[i].x);
        w.put("float", r.n[i].x);
        w.put("double", double(r.p[i].x));
        w.put("float", r.p[i].y);
        w.put("short", -int(i));
        w.put("float", r.p[i].z);
        w.put("float", r.n[i].y);
        w.put("float", r.n[i].z);
        w.put("float", r.uv[i].x);
        w.put("float", r.uv[i].y);
        w.put("uchar", r.c[i].y);
        w.put("uchar", r.c[i].z);
        w.put("uchar", double(i % 3));
        for (size_t k = 0; k < i % 3; ++k) w.put("int", 1000.0 + double(k));
        w.end_entry();
    }
    for (const auto& f : r.faces) {
        w.put("uchar", 9);
        w.put("uchar", double(f.size()));
        for (uint32_t ix : f) w.put("uint", ix);
        w.put("float", 0.5);
        w.end_entry();
    }
    for (int e = 0; e < 2; ++e) {
        w.put("int", e);
        w.put("int", e + 1);
        w.end_entry();
    }
    return w.bytes();
}

void expect_equal_mesh(const MeshFile& m, const Reference& r, bool attributes = true) {
    ASSERT_EQ(m.positions.size(), r.p.size());
    for (size_t i = 0; i < r.p.size(); ++i) EXPECT_EQ(m.positions[i], r.p[i]) << i;
    ASSERT_EQ(m.triangles.size(), r.triangles.size());
    for (size_t i = 0; i < r.triangles.size(); ++i) EXPECT_EQ(m.triangles[i], r.triangles[i]) << i;
    if (!attributes) return;
    ASSERT_EQ(m.normals.size(), r.n.size());
    ASSERT_EQ(m.uvs.size(), r.uv.size());
    ASSERT_EQ(m.colors.size(), r.c.size());
    for (size_t i = 0; i < r.p.size(); ++i) {
        EXPECT_EQ(m.normals[i], r.n[i]) << i;
        EXPECT_EQ(m.uvs[i], r.uv[i]) << i;
        EXPECT_EQ(m.colors[i], r.c[i]) << i;  // uchar colours as the file has them, like Mitsuba 3.9
    }
}

// ---- a serialized writer ----------------------------------------------------------------------

struct SerMesh {
    std::string name = "mesh";
    std::vector<vec3> p, n, c;
    std::vector<vec2> uv;
    std::vector<uvec3> t;
    bool dbl = false, face_normals = false;
};

template <typename T>
void append(std::string& s, T v) {
    s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

std::string ser_stream(const SerMesh& m, int version) {
    std::string body;
    uint32_t flags = (m.n.empty() ? 0 : 1) | (m.uv.empty() ? 0 : 2) | (m.c.empty() ? 0 : 8) |
                     (m.face_normals ? 0x10 : 0) | (m.dbl ? 0x2000 : 0x1000);
    append(body, flags);
    if (version == 4) body += m.name + std::string(1, '\0');
    append(body, uint64_t(m.p.size()));
    append(body, uint64_t(m.t.size()));
    auto arr = [&](const float* f, size_t count) {
        for (size_t i = 0; i < count; ++i) {
            if (m.dbl) append(body, double(f[i]));
            else append(body, f[i]);
        }
    };
    arr(&m.p[0].x, 3 * m.p.size());
    if (!m.n.empty()) arr(&m.n[0].x, 3 * m.n.size());
    if (!m.uv.empty()) arr(&m.uv[0].x, 2 * m.uv.size());
    if (!m.c.empty()) arr(&m.c[0].x, 3 * m.c.size());
    for (const uvec3& t : m.t) {
        append(body, t.x);
        append(body, t.y);
        append(body, t.z);
    }
    uLongf len = compressBound(uLong(body.size()));
    std::string z(len, '\0');
    EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(&z[0]), &len, reinterpret_cast<const Bytef*>(body.data()), uLong(body.size()), 6), Z_OK);
    z.resize(len);
    std::string out;
    append(out, uint16_t(0x041C));
    append(out, uint16_t(version));
    return out + z;
}

std::string write_serialized(const std::vector<SerMesh>& meshes, int version) {
    std::string out;
    std::vector<uint64_t> offsets;
    for (const SerMesh& m : meshes) {
        offsets.push_back(out.size());
        out += ser_stream(m, version);
    }
    for (uint64_t o : offsets) {
        if (version == 4) append(out, o);
        else append(out, uint32_t(o));
    }
    append(out, uint32_t(meshes.size()));
    return out;
}

SerMesh ser_from(const Reference& r, bool dbl) {
    SerMesh m;
    m.p = r.p;
    m.n = r.n;
    m.uv = r.uv;
    m.c = r.c;
    m.t = r.triangles;
    m.dbl = dbl;
    return m;
}

// The message of the Error that `f` throws ("" if it throws none; other exceptions fail the test).
std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not a candela::Error: " << e.what();
        return "?";
    }
    return "";
}

}  // namespace

// ---- PLY ------------------------------------------------------------------------------------

TEST(PlyReader, RoundTripAsciiAndBothEndiannesses) {
    Reference r = make_reference(9);
    for (Enc e : {Enc::Ascii, Enc::LE, Enc::BE}) {
        SCOPED_TRACE(int(e));
        MeshFile m = parse_ply("t.ply", write_ply(r, e));
        expect_equal_mesh(m, r);
    }
}

TEST(PlyReader, UvNamesInMitsubasOrder) {
    Reference r = make_reference(8);
    for (auto names : {std::make_pair("u", "v"), std::make_pair("texture_u", "texture_v"), std::make_pair("s", "t")}) {
        MeshFile m = parse_ply("t.ply", write_ply(r, Enc::LE, names.first, names.second));
        ASSERT_EQ(m.uvs.size(), r.uv.size()) << names.first;
        EXPECT_EQ(m.uvs[3], r.uv[3]);
    }
    // Unrecognised names are not uvs.
    MeshFile m = parse_ply("t.ply", write_ply(r, Enc::LE, "uu", "vv"));
    EXPECT_TRUE(m.uvs.empty());
    // Without colours or normals, none are made up.
    std::string ascii = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                        "property float nx\nproperty float ny\n"  // partial normals: ignored, as in Mitsuba
                        "element face 1\nproperty list uchar int vertex_index\nend_header\n"
                        "0 0 0 1 0\n1 0 0 1 0\n0 1 0 1 0\n3 0 1 2\n";
    MeshFile a = parse_ply("a.ply", ascii);
    EXPECT_TRUE(a.normals.empty());
    EXPECT_TRUE(a.colors.empty());
    EXPECT_EQ(a.triangles.size(), 1u);
}

TEST(PlyReader, FloatColoursAndOtherTypes) {
    // Colours as floats named r g b; positions as int and ushort; indices as ushort with a ushort count.
    std::string ascii =
        "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty int x\r\nproperty ushort y\r\nproperty char z\r\n"
        "property float r\r\nproperty float g\r\nproperty float b\r\n"
        "element face 1\r\nproperty list ushort ushort vertex_indices\r\nend_header\r\n"
        "-5 7 -128 0.25 0.5 1\r\n1 0 127 0 0 0\r\n0 65535 0 1 1 1\r\n3 2 1 0\r\n";
    MeshFile m = parse_ply("c.ply", ascii);
    EXPECT_EQ(m.positions[0], vec3(-5, 7, -128));
    EXPECT_EQ(m.positions[2], vec3(0, 65535, 0));
    ASSERT_EQ(m.colors.size(), 3u);
    EXPECT_EQ(m.colors[0], vec3(0.25f, 0.5f, 1.f));
    EXPECT_EQ(m.triangles[0], uvec3(2, 1, 0));
}

TEST(PlyReader, BadInputIsOneClearError) {
    const std::string good = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                             "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    ASSERT_EQ(error_of([&] { parse_ply("g.ply", good); }), "");
    auto sub = [&](const std::string& from, const std::string& to) {
        std::string s = good;
        size_t at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return s.replace(at, from.size(), to);
    };
    const std::pair<std::string, std::string> cases[] = {
        {"PLY\n" + good.substr(4), "g.ply:1: not a PLY file"},
        {"\x89PNG\r\n", "g.ply:1: not a PLY file"},
        {sub("ascii", "binary_middle_endian"), "g.ply:2: unknown format"},
        {sub("1.0", "2.0"), "g.ply:2: unknown PLY version"},
        {sub("end_header\n", ""), "g.ply:9: unknown header line '0'"},
        {sub("end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", ""), "g.ply:8: the header ends without 'end_header'"},
        {sub("property float y", "property quad y"), "g.ply:5: unknown type 'quad'"},
        {sub("element vertex 3", "element vertex -3"), "g.ply:3: element count '-3'"},
        {sub("element vertex 3", "element vertex 99999999999999999999"), "g.ply:3: element count"},
        {sub("element vertex 3", "element vertex 1000000"), "g.ply:3: element 'vertex' declares 1000000 entries, more than"},
        {sub("element vertex 3", "element vertex 4"), "g.ply:13: face 0 has 2 corners"},
        {sub("3 0 1 2\n", "3 0 1"), "g.ply:13: the file ends before property 'vertex_indices' of face 0"},
        {sub("1 0 0\n", "1 nan 0\n"), "g.ply:11: vertex 1: 'y' is NaN or infinite"},
        {sub("1 0 0\n", "1 1e39 0\n"), "g.ply:11: vertex 1: 'y' is NaN or infinite (or beyond float range)"},
        {sub("1 0 0\n", "1 x 0\n"), "g.ply:11: could not parse 'x' as a number for property 'y' of vertex 1"},
        {sub("3 0 1 2", "3 0 1 3"), "g.ply: triangle 0 has a vertex index out of range (3 vertices)"},
        {sub("3 0 1 2", "3 0 -1 2"), "g.ply:13: face 0 has the vertex index -1 out of range"},
        {sub("3 0 1 2", "2 0 1"), "g.ply:13: face 0 has 2 corners (at least 3)"},
        {sub("3 0 1 2", "300 0 1 2"), "g.ply:13: '300' is out of range for property 'vertex_indices' (list length) of face 0"},
        {sub("3 0 1 2", "200 0 1 2"), "more than the rest of the file holds"},
        {sub("3 0 1 2\n", "3 0 1 2\n7\n"), "g.ply:14: unexpected data after the last element"},
        {sub("vertex_indices", "corners"), "g.ply:7: the 'face' element has no list 'vertex_index' or 'vertex_indices'"},
        {sub("property float z\n", ""), "g.ply:3: the 'vertex' element needs properties x, y and z"},
        {sub("element face 1", "element face 0").substr(0, good.size() - 8), "g.ply: no faces"},
    };
    for (const auto& c : cases) {
        std::string msg = error_of([&] { parse_ply("g.ply", c.first); });
        EXPECT_NE(msg.find(c.second), std::string::npos) << "want '" << c.second << "', got '" << msg << "'";
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
}

TEST(PlyReader, EveryTruncationOfABinaryFileIsAnError) {
    Reference r = make_reference(9);
    for (Enc e : {Enc::LE, Enc::BE, Enc::Ascii}) {
        std::string full = write_ply(r, e);
        size_t checked = 0;
        for (size_t n = 0; n < full.size(); ++n) {
            std::string cut = full.substr(0, n);
            // An ASCII file cut just before its final newline (or between entries' spaces) can
            // still hold every value; all other prefixes must fail.
            std::string msg = error_of([&] { parse_ply("cut.ply", cut); });
            if (e == Enc::Ascii && n >= full.size() - 2) continue;
            EXPECT_NE(msg, "") << "prefix of " << n << " of " << full.size() << " bytes was accepted";
            EXPECT_EQ(msg.rfind("cut.ply:", 0), 0u) << msg;
            ++checked;
        }
        EXPECT_GT(checked, 100u);
    }
}

TEST(PlyReader, BinaryErrorsGiveTheByteOffset) {
    Reference r = make_reference(9);
    std::string full = write_ply(r, Enc::LE);
    // A cut file is mostly caught by the element counts of the header, before any allocation...
    std::string msg = error_of([&] { parse_ply("b.ply", full.substr(0, full.size() - 3)); });
    EXPECT_NE(msg.find("b.ply:23: element 'edge' declares 2 entries, more than the rest of the file can hold (13 bytes)"),
              std::string::npos) << msg;
    // ...and otherwise by the byte where the data runs out.
    msg = error_of([&] { parse_ply("b.ply", full.substr(0, full.size() - 16 - 3)); });
    EXPECT_NE(msg.find("b.ply: byte "), std::string::npos) << msg;
    msg = error_of([&] { parse_ply("b.ply", full + "xyz"); });
    EXPECT_NE(msg.find("3 bytes of trailing data"), std::string::npos) << msg;
    // A NaN position in binary data.
    PlyWriter w(Enc::LE);
    w.begin({{"vertex", {3, {{"float", "x"}, {"float", "y"}, {"float", "z"}}}},
             {"face", {1, {{"list:uchar:int", "vertex_indices"}}}}});
    for (int i = 0; i < 9; ++i) w.put("float", i == 4 ? std::nan("") : 0.0);
    w.put("uchar", 3);
    for (int i = 0; i < 3; ++i) w.put("int", i);
    msg = error_of([&] { parse_ply("n.ply", w.bytes()); });
    EXPECT_NE(msg.find("n.ply: byte " + std::to_string(w.header.size() + 16) + ": vertex 1: 'y' is NaN"), std::string::npos) << msg;
}

// ---- serialized -----------------------------------------------------------------------------

TEST(SerializedReader, RoundTripVersionsPrecisionsAndShapeIndex) {
    Reference r = make_reference(10);
    for (int version : {3, 4})
        for (bool dbl : {false, true}) {
            SCOPED_TRACE(std::to_string(version) + (dbl ? " double" : " single"));
            SerMesh a = ser_from(r, dbl);
            SerMesh b;  // positions only, a second mesh
            b.name = "second";
            b.p = {vec3(1, 2, 3), vec3(4, 5, 6), vec3(7, 8, 9.5f)};
            b.t = {uvec3(2, 1, 0)};
            b.dbl = dbl;
            b.face_normals = true;
            std::string bytes = write_serialized({a, b, a}, version);
            MeshFile m0 = parse_serialized("s.serialized", bytes, 0);
            expect_equal_mesh(m0, r);
            EXPECT_EQ(m0.name, version == 4 ? "mesh" : "");
            MeshFile m1 = parse_serialized("s.serialized", bytes, 1);
            ASSERT_EQ(m1.positions.size(), 3u);
            EXPECT_EQ(m1.positions[2], vec3(7, 8, 9.5f));
            EXPECT_EQ(m1.triangles[0], uvec3(2, 1, 0));
            EXPECT_TRUE(m1.normals.empty() && m1.uvs.empty() && m1.colors.empty());
            EXPECT_TRUE(m1.face_normals);
            expect_equal_mesh(parse_serialized("s.serialized", bytes, 2), r);
            std::string msg = error_of([&] { parse_serialized("s.serialized", bytes, 3); });
            EXPECT_NE(msg.find("shape_index 3 is out of range: the file holds 3 meshes"), std::string::npos) << msg;
        }
}

TEST(SerializedReader, BadInputIsOneClearError) {
    Reference r = make_reference(10);
    std::string good = write_serialized({ser_from(r, false), ser_from(r, true)}, 4);
    ASSERT_EQ(error_of([&] { parse_serialized("s.ser", good, 1); }), "");
    auto expect = [&](const std::string& bytes, int index, const std::string& want) {
        std::string msg = error_of([&] { parse_serialized("s.ser", bytes, index); });
        EXPECT_NE(msg.find(want), std::string::npos) << "want '" << want << "', got '" << msg << "'";
        EXPECT_EQ(msg.rfind("s.ser: ", 0), 0u) << msg;
    };
    std::string bad = good;
    bad[0] = 'X';
    expect(bad, 0, "byte 0: not a Mitsuba serialized file");
    bad = good;
    bad[2] = 5;
    expect(bad, 0, "byte 2: serialized format version 5 is not supported");
    expect(good.substr(0, 3), 0, "too short");
    // Corrupt zlib data: the stream's header, and bytes in its middle.
    bad = good;
    bad[4] ^= 0xff;
    expect(bad, 0, "corrupt compressed data");
    bad = good;
    for (size_t i = 40; i < 60; ++i) bad[i] = char(0x55);
    expect(bad, 0, "corrupt compressed data");
    // The dictionary: an offset beyond the file, a count beyond the dictionary.
    bad = good;
    uint64_t far = 1ull << 40;
    std::memcpy(&bad[bad.size() - 4 - 8], &far, 8);
    expect(bad, 1, "mesh 1 starts at byte 1099511627776, beyond the file");
    far = ~0ull - 1;  // found by fuzz_serialized: offset + 4 wrapped around to a small number
    std::memcpy(&bad[bad.size() - 4 - 8], &far, 8);
    expect(bad, 1, "mesh 1 starts at byte 18446744073709551614, beyond the file");
    bad = good;
    uint32_t many = 1u << 30;
    std::memcpy(&bad[bad.size() - 4], &many, 4);
    expect(bad, 1, "the dictionary of 1073741824 meshes is larger than the file");
    bad = good;
    uint64_t mid = 7;
    std::memcpy(&bad[bad.size() - 4 - 8], &mid, 8);
    expect(bad, 1, "byte 7: mesh 1 does not start with a serialized header");
    // Counts beyond the data, an index out of range, a NaN.
    SerMesh m = ser_from(r, false);
    std::string s = ser_stream(m, 4);
    SerMesh few = m;
    few.t.pop_back();
    std::string body = ser_stream(few, 4);
    SerMesh idx = m;
    idx.t[1].y = 10;
    expect(ser_stream(idx, 4), 0, "triangle 1 has a vertex index out of range (10 vertices)");
    SerMesh nan = m;
    nan.p[4].z = std::nanf("");
    expect(ser_stream(nan, 4), 0, "vertex 4 has a NaN or infinite position");
    SerMesh inf = m;
    inf.uv[2].x = INFINITY;
    expect(ser_stream(inf, 4), 0, "vertex 2 has a NaN or infinite texture coordinate");
}

TEST(SerializedReader, EveryTruncationIsAnErrorAndCountsCannotOverrun) {
    Reference r = make_reference(10);
    std::string one = ser_stream(ser_from(r, true), 4);
    for (size_t n = 0; n < one.size(); ++n) {
        std::string msg = error_of([&] { parse_serialized("cut.serialized", one.substr(0, n), 0); });
        EXPECT_NE(msg, "") << "prefix of " << n << " bytes accepted";
        EXPECT_EQ(msg.rfind("cut.serialized: ", 0), 0u) << msg;
    }
    // A stream that claims 2^32 - 1 vertices but holds ten: an error, not a 48 GB allocation.
    std::string body;
    append(body, uint32_t(0x1000));
    body += std::string("x") + '\0';
    append(body, uint64_t(0xffffffffull));
    append(body, uint64_t(1));
    for (int i = 0; i < 30; ++i) append(body, 1.f);
    uLongf len = compressBound(uLong(body.size()));
    std::string z(len, '\0');
    compress2(reinterpret_cast<Bytef*>(&z[0]), &len, reinterpret_cast<const Bytef*>(body.data()), uLong(body.size()), 6);
    z.resize(len);
    std::string file;
    append(file, uint16_t(0x041C));
    append(file, uint16_t(4));
    file += z;
    std::string msg = error_of([&] { parse_serialized("big.serialized", file, 0); });
    EXPECT_NE(msg.find("the compressed stream ends before the vertex positions"), std::string::npos) << msg;
}

// ---- Mitsuba's own meshes -------------------------------------------------------------------

TEST(MeshFiles, PublicScenesMeshesMatchWhatMitsubaReads) {
    std::ifstream in(std::string(CANDELA_TEST_DATA) + "/public_meshes.txt");
    ASSERT_TRUE(in) << "tests/data/public_meshes.txt";
    std::string line;
    int meshes = 0;
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::string path;
        int index, has_normals, has_uv;
        size_t nv, nf;
        ss >> path >> index >> nv >> nf >> has_normals >> has_uv;
        double v[6 + 9 + 4];
        for (double& x : v) ss >> x;
        uint32_t f[6];
        for (uint32_t& x : f) ss >> x;
        ASSERT_TRUE(ss) << line;
        SCOPED_TRACE(path + "@" + std::to_string(index));
        std::string full = candela::test_paths::asset("scenes-public/" + path);
        MeshFile m = path.size() > 4 && path.substr(path.size() - 4) == ".ply" ? read_ply(full) : read_serialized(full, index);
        ASSERT_EQ(m.positions.size(), nv);
        ASSERT_EQ(m.triangles.size(), nf);
        EXPECT_EQ(!m.uvs.empty(), bool(has_uv));
        AABB b;
        for (const vec3& p : m.positions) b.expand(p);
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(b.min[k], float(v[k]));
            EXPECT_EQ(b.max[k], float(v[3 + k]));
        }
        const size_t at[3] = {0, nv / 2, nv - 1};
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_EQ(m.positions[at[i]][k], float(v[6 + 3 * i + k])) << i;
        if (has_uv) {
            EXPECT_EQ(m.uvs[0], vec2(float(v[15]), float(v[16])));
            EXPECT_EQ(m.uvs[nv - 1], vec2(float(v[17]), float(v[18])));
        }
        EXPECT_EQ(m.triangles[0], uvec3(f[0], f[1], f[2]));
        EXPECT_EQ(m.triangles[nf - 1], uvec3(f[3], f[4], f[5]));
        ++meshes;
    }
    EXPECT_EQ(meshes, 7);
}

// ---- the XML shapes, uv and dp/du ------------------------------------------------------------

namespace {

std::string scene_with(const std::string& dir, const std::string& shapes) {
    std::string path = dir + "/scene.xml";
    write_text(path, "<scene version=\"3.0.0\">\n" + shapes + "</scene>\n");
    return path;
}

// The interaction where a ray from o along d first hits the scene.
SurfaceInteraction hit_at(const Scene& s, vec3 o, vec3 d) {
    Ray ray;
    ray.o = o;
    ray.d = d;
    Hit h;
    EXPECT_TRUE(s.accel->intersect(ray, h)) << o.x << " " << o.y << " " << o.z;
    return s.interaction(h);
}

void expect_near2(vec2 a, vec2 b, float eps = 2e-6f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
}
void expect_near3(vec3 a, vec3 b, float eps = 2e-6f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

}  // namespace

TEST(MeshShapes, RectangleAndCubeUvsAreMitsubas) {
    std::string d = temp_dir("mesh-uv");
    auto scene = build_scene(load_scene(scene_with(d, "<shape type=\"cube\"/>\n")));
    // Mitsuba 3.9.1 at the same points (probed with its Python API: si.uv, si.dp_du, si.dp_dv).
    struct Probe {
        vec3 o, d;
        vec2 uv;
        vec3 dpdu, dpdv;
    } probes[] = {
        {{0.3f, -0.6f, 5}, {0, 0, -1}, {0.2f, 0.65f}, {0, 2, 0}, {2, 0, 0}},
        {{0.3f, -0.6f, -5}, {0, 0, 1}, {0.8f, 0.65f}, {0, -2, 0}, {2, 0, 0}},
        {{5, 0.2f, 0.7f}, {-1, 0, 0}, {0.6f, 0.15f}, {0, 2, 0}, {0, 0, -2}},
        {{-5, 0.2f, 0.7f}, {1, 0, 0}, {0.6f, 0.85f}, {0, 2, 0}, {0, 0, 2}},
        {{0.1f, 5, -0.4f}, {0, -1, 0}, {0.45f, 0.7f}, {-2, 0, 0}, {0, 0, -2}},
        {{0.1f, -5, -0.4f}, {0, 1, 0}, {0.3f, 0.55f}, {0, 0, 2}, {2, 0, 0}},
    };
    for (const Probe& p : probes) {
        SurfaceInteraction si = hit_at(*scene, p.o, p.d);
        expect_near2(si.uv, p.uv);
        expect_near3(si.dpdu, p.dpdu);
        expect_near3(si.dpdv, p.dpdv);
        expect_near3(si.ng, -p.d);
    }
    // A flipped, scaled rectangle: Mitsuba gives uv (0.625, 0.6), dp/du (4,0,0), dp/dv (0,6,0), n -z.
    scene = build_scene(load_scene(scene_with(d, "<shape type=\"rectangle\"><boolean name=\"flip_normals\" value=\"true\"/>"
                                                 "<transform name=\"to_world\"><scale value=\"2 3 1\"/></transform></shape>\n")));
    SurfaceInteraction si = hit_at(*scene, vec3(0.5f, 0.6f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.625f, 0.6f));
    expect_near3(si.dpdu, vec3(4, 0, 0), 1e-5f);
    expect_near3(si.dpdv, vec3(0, 6, 0), 1e-5f);
    expect_near3(si.ng, vec3(0, 0, -1));
    expect_near3(si.ns, vec3(0, 0, -1));
}

TEST(MeshShapes, PlyFlagsAndTransform) {
    std::string d = temp_dir("mesh-ply-flags");
    // A unit quad in z = 0 with uv = (x, y), normals tilted towards +x, colours.
    write_text(d + "/q.ply",
               "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
               "property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n"
               "property uchar r\nproperty uchar g\nproperty uchar b\n"
               "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
               "0 0 0 0.6 0 0.8 0 0 255 0 0\n1 0 0 0.6 0 0.8 1 0 0 255 0\n1 1 0 0.6 0 0.8 1 1 0 0 255\n"
               "0 1 0 0.6 0 0.8 0 1 10 20 30\n4 0 1 2 3\n");
    auto shape = [&](const std::string& params) {
        return "<shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/>" + params + "</shape>\n";
    };
    auto scene = build_scene(load_scene(scene_with(d, shape(""))));
    ASSERT_EQ(scene->mesh.triangle_count(), 2u);
    ASSERT_TRUE(scene->shapes[0].has_uv() && scene->shapes[0].has_color() && scene->shapes[0].smooth);
    SurfaceInteraction si = hit_at(*scene, vec3(0.25f, 0.5f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.25f, 0.5f));
    expect_near3(si.dpdu, vec3(1, 0, 0));
    expect_near3(si.dpdv, vec3(0, 1, 0));
    expect_near3(si.ns, vec3(0.6f, 0, 0.8f));
    EXPECT_EQ(scene->mesh.colors[scene->shapes[0].color_offset + 3], vec3(10, 20, 30));
    {
        // The colour interpolated at a hit: (0.25, 0.5) on triangle (0, 2, 3) has the barycentrics
        // 0.5, 0.25, 0.25 -> 0.5 (255,0,0) + 0.25 (0,0,255) + 0.25 (10,20,30).
        Ray ray;
        ray.o = vec3(0.25f, 0.5f, 1);
        ray.d = vec3(0, 0, -1);
        Hit h;
        ASSERT_TRUE(scene->accel->intersect(ray, h));
        expect_near3(scene->vertex_color(h), vec3(127.5f + 2.5f, 5.f, 63.75f + 7.5f), 1e-4f);
    }
    // flip_tex_coords (Mitsuba's ply default: false): v -> 1 - v, so dp/dv turns round.
    scene = build_scene(load_scene(scene_with(d, shape("<boolean name=\"flip_tex_coords\" value=\"true\"/>"))));
    si = hit_at(*scene, vec3(0.25f, 0.5f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.25f, 0.5f));
    si = hit_at(*scene, vec3(0.25f, 0.125f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.25f, 0.875f));
    expect_near3(si.dpdv, vec3(0, -1, 0));
    // face_normals: the file's normals are dropped.
    scene = build_scene(load_scene(scene_with(d, shape("<boolean name=\"face_normals\" value=\"true\"/>"))));
    EXPECT_FALSE(scene->shapes[0].smooth);
    si = hit_at(*scene, vec3(0.25f, 0.5f, 1), vec3(0, 0, -1));
    expect_near3(si.ns, vec3(0, 0, 1));
    // to_world: positions and dp/du move, normals by the inverse transpose, uv stays.
    scene = build_scene(load_scene(scene_with(
        d, shape("<transform name=\"to_world\"><scale value=\"2 1 1\"/><translate x=\"5\"/></transform>"))));
    si = hit_at(*scene, vec3(5.5f, 0.5f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.25f, 0.5f));
    expect_near3(si.dpdu, vec3(2, 0, 0));
    expect_near3(si.ns, glm::normalize(vec3(0.3f, 0, 0.8f)));
    // flip_normals: both normals turn, uv and dp/du do not.
    scene = build_scene(load_scene(scene_with(d, shape("<boolean name=\"flip_normals\" value=\"true\"/>"))));
    si = hit_at(*scene, vec3(0.25f, 0.5f, 1), vec3(0, 0, -1));
    expect_near3(si.ng, vec3(0, 0, -1));
    expect_near3(si.ns, -vec3(0.6f, 0, 0.8f));
    expect_near2(si.uv, vec2(0.25f, 0.5f));
    expect_near3(si.dpdu, vec3(1, 0, 0));
}

TEST(MeshShapes, SerializedShapeAndObjTexcoords) {
    std::string d = temp_dir("mesh-ser-obj");
    SerMesh m;
    m.p = {vec3(0, 0, 0), vec3(1, 0, 0), vec3(1, 1, 0), vec3(0, 1, 0)};
    m.uv = {vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1)};
    m.c = {vec3(1), vec3(1), vec3(1), vec3(1)};
    m.t = {uvec3(0, 1, 2), uvec3(0, 2, 3)};
    SerMesh far = m;
    for (vec3& p : far.p) p += vec3(0, 0, -3);
    write_text(d + "/m.serialized", write_serialized({m, far}, 4));
    auto scene = build_scene(load_scene(scene_with(
        d, "<shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/>"
           "<integer name=\"shape_index\" value=\"1\"/></shape>\n")));
    SurfaceInteraction si = hit_at(*scene, vec3(0.75f, 0.25f, 1), vec3(0, 0, -1));
    EXPECT_NEAR(si.p.z, -3.f, 1e-6f);
    expect_near2(si.uv, vec2(0.75f, 0.25f));  // serialized: no flip_tex_coords (Mitsuba has none)
    EXPECT_TRUE(scene->shapes[0].smooth);      // no normals in the file: computed, as Mitsuba
    EXPECT_FALSE(scene->shapes[0].has_color());  // Mitsuba 3.9 reads past serialized colours
    // OBJ vt, flipped by default (Mitsuba's obj: flip_tex_coords true).
    write_text(d + "/q.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n");
    scene = build_scene(load_scene(scene_with(d, "<shape type=\"obj\"><string name=\"filename\" value=\"q.obj\"/></shape>\n")));
    si = hit_at(*scene, vec3(0.75f, 0.25f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.75f, 0.75f));
    scene = build_scene(load_scene(scene_with(d, "<shape type=\"obj\"><string name=\"filename\" value=\"q.obj\"/>"
                                                 "<boolean name=\"flip_tex_coords\" value=\"false\"/></shape>\n")));
    si = hit_at(*scene, vec3(0.75f, 0.25f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.75f, 0.25f));
    // Without uvs: Mitsuba's barycentric parameterisation.
    write_text(d + "/n.obj", "v 0 0 0\nv 2 0 0\nv 0 2 0\nf 1 2 3\n");
    scene = build_scene(load_scene(scene_with(d, "<shape type=\"obj\"><string name=\"filename\" value=\"n.obj\"/></shape>\n")));
    EXPECT_TRUE(scene->mesh.uvs.empty());
    si = hit_at(*scene, vec3(0.5f, 0.25f, 1), vec3(0, 0, -1));
    expect_near2(si.uv, vec2(0.25f, 0.125f));
    expect_near3(si.dpdu, vec3(2, 0, 0));
    expect_near3(si.dpdv, vec3(0, 2, 0));
}

TEST(MeshShapes, AttributesArePayPerUse) {
    // Shapes without uvs or colours add nothing to the mesh's attribute arrays.
    std::string d = temp_dir("mesh-pay");
    write_text(d + "/n.obj", "v 0 0 0\nv 2 0 0\nv 0 2 0\nf 1 2 3\n");
    write_text(d + "/u.obj", "v 0 0 0\nv 2 0 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    auto scene = build_scene(load_scene(scene_with(
        d, "<shape type=\"obj\"><string name=\"filename\" value=\"n.obj\"/></shape>\n"
           "<shape type=\"obj\"><string name=\"filename\" value=\"u.obj\"/></shape>\n"
           "<shape type=\"obj\"><string name=\"filename\" value=\"n.obj\"/></shape>\n")));
    EXPECT_EQ(scene->mesh.positions.size(), 9u);
    EXPECT_EQ(scene->mesh.uvs.size(), 3u);
    EXPECT_TRUE(scene->mesh.colors.empty());
    EXPECT_EQ(scene->shapes[1].uv_offset, 0u);
    EXPECT_FALSE(scene->shapes[0].has_uv() || scene->shapes[2].has_uv());
}

TEST(MeshShapes, EmitterWithoutBsdfIsBlackAsInMitsuba) {
    // Mitsuba 3.9.1: a shape with an area emitter and no BSDF gets diffuse 0, others diffuse 0.5.
    std::string d = temp_dir("mesh-emitter-bsdf");
    SceneDescription s = load_scene(scene_with(d, "<shape type=\"rectangle\"><emitter type=\"area\"/></shape>\n"
                                                  "<shape type=\"cube\"/>\n"));
    ASSERT_EQ(s.shapes.size(), 2u);
    EXPECT_EQ(std::get<DiffuseBsdf>(s.materials[s.shapes[0].material].bsdf).albedo, vec3(0.f));
    EXPECT_EQ(std::get<DiffuseBsdf>(s.materials[s.shapes[1].material].bsdf).albedo, vec3(0.5f));
}

TEST(MeshShapes, BadMeshFilesThroughTheProgram) {
    std::string d = temp_dir("mesh-bad");
    auto run = [&](const std::string& file, const std::string& type, const std::string& extra = "") {
        scene_with(d, "<shape type=\"" + type + "\">\n<string name=\"filename\" value=\"" + file + "\"/>" + extra + "</shape>\n");
        return run_candela(d + "/scene.xml --width 8 --height 8 --frames 1 --quiet --out " + d + "/out.exr");
    };
    auto expect_one_line = [&](const RunResult& r, std::initializer_list<std::string> needles) {
        EXPECT_EQ(r.exit_code, 1) << r.output;
        for (const std::string& n : needles) EXPECT_NE(r.output.find(n), std::string::npos) << n << " in " << r.output;
        size_t lines = 0;
        for (char c : r.output) lines += c == '\n';
        EXPECT_EQ(lines, 1u) << r.output;
    };
    expect_one_line(run("none.ply", "ply"), {d + "/scene.xml:3: ", "cannot open PLY file 'none.ply'"});
    write_text(d + "/bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    expect_one_line(run("bad.ply", "ply"), {d + "/bad.ply: triangle 0 has a vertex index out of range", "(shape at " + d + "/scene.xml:2)"});
    write_text(d + "/nan.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n");
    expect_one_line(run("nan.ply", "ply"), {d + "/nan.ply:12: vertex 2: 'y' is NaN"});
    write_text(d + "/z.serialized", std::string("\x1c\x04\x04\x00garbage-not-zlib", 20));
    expect_one_line(run("z.serialized", "serialized"), {d + "/z.serialized: byte ", "corrupt compressed data"});
    write_text(d + "/one.serialized", write_serialized({ser_from(make_reference(9), false)}, 4));
    expect_one_line(run("one.serialized", "serialized", "<integer name=\"shape_index\" value=\"4\"/>"),
                    {"shape_index 4 is out of range: the file holds 1 meshes"});
    expect_one_line(run("one.serialized", "serialized", "<integer name=\"shape_index\" value=\"-1\"/>"),
                    {d + "/scene.xml:3: ", "shape_index must be >= 0"});
    expect_one_line(run("one.serialized", "serialized", "<boolean name=\"flip_tex_coords\" value=\"true\"/>"),
                    {"unused parameter 'flip_tex_coords'"});
}

// ---- agreement with Mitsuba 3 ----------------------------------------------------------------
//
// tests/data/scenes/mesh_formats.xml (Mitsuba's teapot.ply, the matpreview serialized mesh, a PLY
// floor, a flipped rectangle light) against tests/data/mesh_formats64_{mean,var}.exr: the mean of 16
// Mitsuba 3.9.1 llvm_ad_rgb renders of 1024 spp at 64 x 64 and the variance of that mean, made by
//   $PY tests/data/make_reference.py tests/data/scenes/mesh_formats.xml --res 64 --batches 16
//       --spp 1024 --out tests/data/mesh_formats64
// candela renders 8 batches of 64 spp; a block z-test (8 x 8 blocks, Sidak-corrected) and a
// whole-image z-test per channel must pass. Controls that must fail: 3% darker albedos, and the
// teapot and matpreview shaded with face normals (what dropping the normals would give).

#include "film/image_io.h"
#include "render/renderer.h"
#include "support/stats.h"

namespace {

stats::ImageEstimate load_estimate(const std::string& prefix) { return stats::ImageEstimate::from_reference_files(prefix); }

stats::ImageEstimate render_mesh_scene(const std::function<void(SceneDescription&)>& edit) {
    SceneDescription desc = load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/mesh_formats.xml",
                                       {{"res", "64"}});
    edit(desc);
    const std::shared_ptr<const Scene> built = build_scene(std::move(desc));
    std::vector<std::unique_ptr<Film>> films;
    std::vector<const Film*> ptrs;
    for (int b = 0; b < 8; ++b) {
        films.push_back(std::make_unique<Film>(64, 64));
        SceneParams p = built->params();
        p.settings.seed = uint64_t(b + 1);
        Renderer::render_pass(*built->with_params(p), *films.back(), 0, 64, 0);
        ptrs.push_back(films.back().get());
    }
    return stats::ImageEstimate::from_batches(ptrs);
}

}  // namespace

TEST(MeshFormatsRender, PlyAndSerializedMatchMitsuba) {
    stats::ImageEstimate ref = load_estimate(std::string(CANDELA_TEST_DATA) + "/mesh_formats64");
    ASSERT_EQ(ref.width, 64);
    stats::ImageEstimate test = render_mesh_scene([](SceneDescription&) {});
    stats::BlockTestResult r = stats::block_z_test(test, ref, 8, 0.01);
    double p = whole_image_p(test, ref);
    std::printf("  blocks: %s\n  whole image: p = %.3g\n", r.describe().c_str(), p);
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
    EXPECT_GE(p, 0.01);
}

TEST(MeshFormatsRender, ControlsFail) {
    stats::ImageEstimate ref = load_estimate(std::string(CANDELA_TEST_DATA) + "/mesh_formats64");
    stats::ImageEstimate darker = render_mesh_scene([](SceneDescription& d) {
        for (Material& m : d.materials) std::get<DiffuseBsdf>(m.bsdf).albedo *= 0.97f;
    });
    stats::BlockTestResult r = stats::block_z_test(darker, ref, 8, 0.01);
    double p = whole_image_p(darker, ref);
    std::printf("  3%% darker: blocks %s, whole image p = %.3g\n", r.describe().c_str(), p);
    EXPECT_TRUE(!r.passed(0.01) || p < 0.01);
    EXPECT_LT(p, 0.01);
    // Face normals on the teapot and the matpreview mesh: the smooth normals (computed for the
    // teapot, read from the serialized file) matter to the image, and the test sees them.
    stats::ImageEstimate flat = render_mesh_scene([](SceneDescription& d) {
        d.shapes[0].smooth = false;
        d.shapes[1].smooth = false;
    });
    r = stats::block_z_test(flat, ref, 8, 0.01);
    p = whole_image_p(flat, ref);
    std::printf("  flat teapot and matpreview: blocks %s, whole image p = %.3g\n", r.describe().c_str(), p);
    EXPECT_TRUE(!r.passed(0.01) || p < 0.01);
}
