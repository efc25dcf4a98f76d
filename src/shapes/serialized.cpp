// Mitsuba's serialized mesh format (Mitsuba 3 src/shapes/serialized.cpp), decompressed with
// Debian's zlib. The compressed stream is inflated on demand, so a corrupt or truncated stream, or
// counts that promise more than it holds, fail with the byte offset before anything large is
// allocated.
#include <zlib.h>
#include <cmath>
#include <cstring>
#include "core/error.h"
#include "shapes/mesh_file.h"

namespace candela {

namespace {

constexpr uint16_t kMagic = 0x041C;
enum : uint32_t {
    kHasNormals = 0x0001,
    kHasTexcoords = 0x0002,
    kHasColors = 0x0008,
    kFaceNormals = 0x0010,
    kDoublePrecision = 0x2000,
};

template <typename T>
T load_le(const unsigned char* p) {  // the format is little-endian, as is every host candela runs on
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
}

// Inflates a zlib stream that starts at `offset` of `data`, handing out bytes as they are asked for.
class Inflater {
public:
    Inflater(const std::string& name, const std::string& data, size_t offset) : name_(name), start_(offset) {
        std::memset(&z_, 0, sizeof(z_));
        if (inflateInit(&z_) != Z_OK) throw Error(name_, 0, "zlib initialisation failed");
        z_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data() + offset));
        // zlib counts in uInt: feed at most 1 GiB at a time.
        in_left_ = data.size() - offset;
        feed();
    }
    ~Inflater() { inflateEnd(&z_); }
    Inflater(const Inflater&) = delete;
    Inflater& operator=(const Inflater&) = delete;

    // Exactly n bytes of the decompressed stream into dst, or an Error saying what was cut short.
    void read(void* dst, size_t n, const char* what) {
        unsigned char* out = static_cast<unsigned char*>(dst);
        while (n > 0) {
            if (ended_) throw error(std::string("the compressed stream ends before ") + what);
            size_t chunk = std::min<size_t>(n, 1u << 30);
            z_.next_out = out;
            z_.avail_out = uInt(chunk);
            int rc = inflate(&z_, Z_NO_FLUSH);
            size_t got = chunk - z_.avail_out;
            out += got;
            n -= got;
            produced_ += got;
            if (rc == Z_STREAM_END) {
                ended_ = true;
            } else if (rc != Z_OK && rc != Z_BUF_ERROR) {  // Z_DATA_ERROR, Z_NEED_DICT, Z_MEM_ERROR...
                throw error(std::string("corrupt compressed data (zlib: ") + (z_.msg ? z_.msg : "error") + ") in " + what);
            } else if (n > 0 && z_.avail_in == 0) {
                // Output space is left, so zlib has used all its input: more must come, or the file is cut.
                if (in_left_ == 0) throw error(std::string("the file ends inside the compressed stream, before ") + what);
                feed();
            } else if (got == 0) {
                throw error(std::string("the compressed stream makes no progress in ") + what);
            }
        }
    }
    // The stream must end here, its checksum intact: a cut or corrupt end is an error too.
    void finish() {
        if (ended_) return;
        unsigned char extra;
        z_.next_out = &extra;
        z_.avail_out = 1;
        int rc = inflate(&z_, Z_FINISH);
        if (rc == Z_STREAM_END && z_.avail_out == 1) return;
        if (z_.avail_out == 0) throw error("the compressed stream holds more data than its counts describe");
        if (rc == Z_DATA_ERROR) throw error(std::string("corrupt compressed data (zlib: ") + (z_.msg ? z_.msg : "error") + ") at its end");
        throw error("the file ends inside the compressed stream (its end and checksum are missing)");
    }
    template <typename T>
    T get(const char* what) {
        unsigned char b[sizeof(T)];
        read(b, sizeof(T), what);
        return load_le<T>(b);
    }
    size_t produced() const { return produced_; }

    Error error(const std::string& what) const {
        return Error(name_, 0, "byte " + std::to_string(start_ + z_.total_in) + " (" + std::to_string(produced_) +
                                   " bytes into the mesh's decompressed data): " + what);
    }

private:
    void feed() {
        size_t n = std::min<size_t>(in_left_, 1u << 30);
        z_.avail_in = uInt(n);
        in_left_ -= n;
    }
    std::string name_;
    size_t start_;
    z_stream z_;
    size_t in_left_ = 0, produced_ = 0;
    bool ended_ = false;
};

// n vectors of D floats or doubles, read in blocks so that memory grows only with data that exists.
template <typename Vec, int D>
std::vector<Vec> read_array(Inflater& z, uint64_t n, bool dbl, const char* what) {
    std::vector<Vec> out;
    out.reserve(size_t(std::min<uint64_t>(n, 1u << 16)));
    const size_t block = 4096;
    std::vector<unsigned char> buf(block * D * (dbl ? 8 : 4));
    for (uint64_t done = 0; done < n;) {
        size_t m = size_t(std::min<uint64_t>(block, n - done));
        z.read(buf.data(), m * D * (dbl ? 8 : 4), what);
        for (size_t i = 0; i < m; ++i) {
            Vec v;
            for (int k = 0; k < D; ++k)
                v[k] = dbl ? float(load_le<double>(&buf[(i * D + size_t(k)) * 8])) : load_le<float>(&buf[(i * D + size_t(k)) * 4]);
            out.push_back(v);
        }
        done += m;
    }
    return out;
}

}  // namespace

MeshFile parse_serialized(const std::string& name, const std::string& data, int shape_index) {
    auto at = [&](size_t b, const std::string& what) { return Error(name, 0, "byte " + std::to_string(b) + ": " + what); };
    const unsigned char* d = reinterpret_cast<const unsigned char*>(data.data());
    if (data.size() < 4) throw at(0, "too short for a serialized mesh header");
    if (load_le<uint16_t>(d) != kMagic) throw at(0, "not a Mitsuba serialized file (wrong magic number)");
    uint16_t version = load_le<uint16_t>(d + 2);
    if (version != 3 && version != 4)
        throw at(2, "serialized format version " + std::to_string(version) + " is not supported (3 or 4)");
    if (shape_index < 0) throw Error(name, 0, "shape_index must be >= 0");

    size_t offset = 0;
    if (shape_index > 0) {
        // The end-of-file dictionary: one offset per mesh (uint64 in v4, uint32 in v3), then the count.
        if (data.size() < 8) throw at(0, "too short for the end-of-file dictionary");
        uint32_t count = load_le<uint32_t>(d + data.size() - 4);
        if (uint32_t(shape_index) >= count)
            throw at(data.size() - 4, "shape_index " + std::to_string(shape_index) + " is out of range: the file holds " +
                                          std::to_string(count) + " meshes");
        size_t entry = version == 4 ? 8 : 4;
        uint64_t back = uint64_t(count - uint32_t(shape_index)) * entry + 4;
        if (back > data.size()) throw at(data.size() - 4, "the dictionary of " + std::to_string(count) + " meshes is larger than the file");
        size_t pos = data.size() - size_t(back);
        uint64_t off = version == 4 ? load_le<uint64_t>(d + pos) : load_le<uint32_t>(d + pos);
        if (off >= data.size() || data.size() - off <= 4)  // (not off + 4: it may wrap around)
            throw at(pos, "mesh " + std::to_string(shape_index) + " starts at byte " + std::to_string(off) + ", beyond the file");
        offset = size_t(off);
        if (load_le<uint16_t>(d + offset) != kMagic || load_le<uint16_t>(d + offset + 2) != version)
            throw at(offset, "mesh " + std::to_string(shape_index) + " does not start with a serialized header");
    }

    Inflater z(name, data, offset + 4);
    uint32_t flags = z.get<uint32_t>("the flags");
    MeshFile m;
    if (version == 4) {
        for (;;) {
            char c = z.get<char>("the end of the mesh name");
            if (c == 0) break;
            if (m.name.size() >= 4096) throw z.error("the mesh name is longer than 4096 bytes (no terminating zero)");
            m.name += c;
        }
    }
    uint64_t nv = z.get<uint64_t>("the vertex count"), nf = z.get<uint64_t>("the triangle count");
    if (nv > 0xffffffffull) throw z.error("more than 2^32 - 1 vertices (" + std::to_string(nv) + ")");
    if (nf > 0xffffffffull) throw z.error("more than 2^32 - 1 triangles (" + std::to_string(nf) + ")");
    if (nf == 0) throw z.error("the mesh has no triangles");
    bool dbl = (flags & kDoublePrecision) != 0;
    m.face_normals = (flags & kFaceNormals) != 0;
    m.positions = read_array<vec3, 3>(z, nv, dbl, "the vertex positions");
    if (flags & kHasNormals) m.normals = read_array<vec3, 3>(z, nv, dbl, "the vertex normals");
    if (flags & kHasTexcoords) m.uvs = read_array<vec2, 2>(z, nv, dbl, "the texture coordinates");
    if (flags & kHasColors) m.colors = read_array<vec3, 3>(z, nv, dbl, "the vertex colours");
    m.triangles.reserve(size_t(std::min<uint64_t>(nf, 1u << 16)));
    std::vector<uint32_t> buf(3 * 4096);
    for (uint64_t done = 0; done < nf;) {
        size_t k = size_t(std::min<uint64_t>(4096, nf - done));
        z.read(buf.data(), k * 12, "the triangles");
        for (size_t i = 0; i < k; ++i) {
            uvec3 t(buf[3 * i], buf[3 * i + 1], buf[3 * i + 2]);
            if (t.x >= nv || t.y >= nv || t.z >= nv)
                throw Error(name, 0, "triangle " + std::to_string(done + i) + " has a vertex index out of range (" +
                                         std::to_string(nv) + " vertices)");
            m.triangles.push_back(t);
        }
        done += k;
    }
    z.finish();
    auto finite = [&](const auto& v, const char* what) {
        for (size_t i = 0; i < v.size(); ++i)
            for (int k = 0; k < int(v[i].length()); ++k)
                if (!std::isfinite(v[i][k]))
                    throw Error(name, 0, "vertex " + std::to_string(i) + " has a NaN or infinite " + what);
    };
    finite(m.positions, "position");
    finite(m.normals, "normal");
    finite(m.uvs, "texture coordinate");
    finite(m.colors, "colour");
    return m;
}

MeshFile read_serialized(const std::string& path, int shape_index) {
    std::string bytes = read_file_bytes(path);
    return parse_serialized(path, bytes, shape_index);
}

}  // namespace candela
