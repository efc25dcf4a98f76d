#include "app/checkpoint.h"
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <atomic>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include "bsdf/bsdf.h"
#include "core/error.h"

namespace candela {

namespace {

// ---- hashing -------------------------------------------------------------------------------------
// A streaming 64-bit hash, a word at a time (one multiply-rotate lane in the style of xxHash64):
// fast enough to checksum a 4K film's 230 MB in a fraction of a second, and it sees every bit.
class Hasher {
public:
    void bytes(const void* data, size_t n) {
        if (n == 0) return;  // an empty vector's data() may be null, which memcpy must not see
        const unsigned char* p = static_cast<const unsigned char*>(data);
        length_ += n;
        if (fill_ > 0) {  // complete the word left over from the last call
            size_t take = std::min<size_t>(n, 8 - fill_);
            std::memcpy(pending_ + fill_, p, take);
            fill_ += take;
            p += take;
            n -= take;
            if (fill_ < 8) return;
            word(load(pending_));
            fill_ = 0;
        }
        for (; n >= 8; n -= 8, p += 8) word(load(p));
        std::memcpy(pending_, p, n);
        fill_ = n;
    }
    void u64(uint64_t v) { bytes(&v, 8); }
    void i64(int64_t v) { bytes(&v, 8); }
    void f32(float v) { bytes(&v, 4); }  // by bit pattern: -0 and NaN payloads count
    void v3(vec3 v) { bytes(&v, sizeof v); }
    void str(const std::string& s) {
        u64(s.size());
        bytes(s.data(), s.size());
    }
    uint64_t digest() const {
        uint64_t h = h_;
        for (size_t i = 0; i < fill_; ++i) h = mix_bits(h ^ (uint64_t(pending_[i]) << (8 * i)) ^ (uint64_t(i) << 60));
        return mix_bits(h ^ length_);
    }

private:
    static uint64_t load(const unsigned char* p) {
        uint64_t w;
        std::memcpy(&w, p, 8);
        return w;
    }
    void word(uint64_t w) {
        h_ ^= w * 0xC2B2AE3D27D4EB4FULL;
        h_ = (h_ << 31) | (h_ >> 33);
        h_ = h_ * 0x9E3779B97F4A7C15ULL + 0x165667B19E3779F9ULL;
    }
    uint64_t h_ = 0x27D4EB2F165667C5ULL, length_ = 0;
    unsigned char pending_[8] = {};
    size_t fill_ = 0;
};

static_assert(sizeof(vec3) == 12 && sizeof(uvec3) == 12 && sizeof(dvec3) == 24, "tightly packed GLM vectors");

// ---- the file format -----------------------------------------------------------------------------
// Native byte order (x86-64 and ARM64 are both little-endian; a marker catches any other):
//   0  char[8]  magic "CNDLCKPT"      8  u32 version          12 u32 header size (64)
//   16 i32 width                      20 i32 height           24 u32 spp        28 u32 flags (1: alpha, 2: weighted)
//   32 u64 non-finite samples         40 u64 fingerprint      48 u64 pixels     56 u64 byte-order marker
//   64 pixels x 3 f64 sums, then pixels x u32 counts, then (flag alpha) pixels x f64 alpha sums, then
//   (flag weighted: tent, gaussian filters) pixels x f64 weight sums, then (flag 4, splats: light
//   tracing) u64 light paths and pixels x 3 f64 splat sums, then u64 hash of everything before it.
//   Files without splats are those of before (and still load).
constexpr char kMagic[8] = {'C', 'N', 'D', 'L', 'C', 'K', 'P', 'T'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderSize = 64;
constexpr uint64_t kByteOrderMarker = 0x0102030405060708ULL;
constexpr uint64_t kBytesPerPixel = sizeof(dvec3) + sizeof(uint32_t);

template <class T>
void put(unsigned char* h, size_t at, T v) { std::memcpy(h + at, &v, sizeof v); }
template <class T>
T get(const unsigned char* h, size_t at) {
    T v;
    std::memcpy(&v, h + at, sizeof v);
    return v;
}

std::string errno_text(int err) { return std::strerror(err); }

// A file written under a temporary name beside the target and renamed over it on commit(), so a
// kill at any moment leaves either the old checkpoint or the new one, never a torn one. Streams
// (unlike write_file_atomic, which takes one buffer) so that the film is never copied.
class AtomicWriter {
public:
    explicit AtomicWriter(const std::string& path) : path_(path) {
        static std::atomic<unsigned> counter{0};
        for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
            tmp_ = path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1));
            fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
            if (fd_ < 0 && errno != EEXIST) break;
        }
        if (fd_ < 0) throw Error(path, 0, "cannot create temporary file for the checkpoint: " + errno_text(errno));
    }
    ~AtomicWriter() {
        if (fd_ >= 0) ::close(fd_);
        if (!committed_) ::unlink(tmp_.c_str());
    }
    AtomicWriter(const AtomicWriter&) = delete;
    AtomicWriter& operator=(const AtomicWriter&) = delete;

    void write(const void* data, size_t size) {
        hash_.bytes(data, size);
        const char* p = static_cast<const char*>(data);
        while (size > 0) {
            ssize_t n = ::write(fd_, p, size);
            if (n < 0) {
                if (errno == EINTR) continue;  // a signal (SIGINT asking for a stop) is not an error
                fail("write failed");
            }
            p += n;
            size -= size_t(n);
        }
    }
    uint64_t hash() const { return hash_.digest(); }
    void commit() {
        // fsync before rename, or a crash may leave the new name on an empty file.
        if (::fsync(fd_) != 0) fail("fsync failed");
        int rc = ::close(fd_);
        fd_ = -1;
        if (rc != 0) fail("close failed");
        if (::rename(tmp_.c_str(), path_.c_str()) != 0) fail("cannot rename the temporary file into place");
        committed_ = true;
        std::string dir = std::filesystem::path(path_).parent_path().string();
        int dfd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (dfd >= 0) {
            ::fsync(dfd);  // persists the rename; the file is complete either way
            ::close(dfd);
        }
    }

private:
    [[noreturn]] void fail(const std::string& what) { throw Error(path_, 0, what + ": " + errno_text(errno)); }
    std::string path_, tmp_;
    int fd_ = -1;
    bool committed_ = false;
    Hasher hash_;
};

// Reads exactly `size` bytes or throws.
void read_exact(FILE* f, void* data, size_t size, const std::string& path) {
    if (size > 0 && std::fread(data, 1, size, f) != size)
        throw Error(path, 0, std::ferror(f) ? "cannot read checkpoint: " + errno_text(errno) : "truncated checkpoint");
}

std::string hex(uint64_t v) {
    char buf[24];
    std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
    return buf;
}

}  // namespace

// A curve segment's other end and place (nothing for the other kinds: their fingerprints stay).
void hash_curve(Hasher& h, const AnalyticShape& a) {
    if (a.kind != PrimKind::Curve) return;
    h.v3(a.p1);
    h.f32(a.radius1);
    h.u64(a.segment);
    h.u64(a.segments);
    h.u64(a.start_cap);
}

uint64_t scene_fingerprint(const Scene& scene) {
    Hasher h;
    h.str("candela scene fingerprint 1");
    const RenderSettings& st = scene.settings;
    h.i64(st.width);
    h.i64(st.height);
    h.u64(st.seed);
    h.u64(st.alpha);
    h.i64(st.max_depth);
    h.i64(st.rr_depth);
    h.i64(int(st.sampling));
    // The integrator and the filter (a default-constructed description adds nothing, so that
    // checkpoints of box-filtered path tracing made before they existed stay valid).
    const IntegratorDesc& in = st.integrator;
    if (in.type != IntegratorType::Path || in.hide_emitters) {
        h.str("integrator");
        h.i64(int(in.type));
        h.u64(in.hide_emitters);
        h.i64(in.emitter_samples);
        h.i64(in.bsdf_samples);
    }
    // The sampler, and the sample count its stratified sets are made of (the independent sampler
    // adds nothing, so that checkpoints made before the other samplers stay valid).
    if (st.sampler != SamplerDesc()) {
        h.str("sampler");
        h.i64(int(st.sampler.type));
        h.u64(st.sampler.jitter);
        h.i64(st.spp);
    }
    if (st.filter != FilterDesc()) {
        h.str("filter");
        h.i64(int(st.filter.type));
        h.f32(st.filter.radius);
        h.f32(st.filter.stddev);
        if (st.filter.type == FilterType::Mitchell) {  // the other types keep their fingerprints
            h.f32(st.filter.b);
            h.f32(st.filter.c);
        }
    }
    h.str(scene.accel ? scene.accel->name() : std::string());

    const Mesh& m = scene.mesh;
    h.u64(m.positions.size());
    h.bytes(m.positions.data(), m.positions.size() * sizeof(vec3));
    h.u64(m.normals.size());
    h.bytes(m.normals.data(), m.normals.size() * sizeof(vec3));
    // uvs and colours only when present, so that scenes without them keep their fingerprint.
    if (!m.uvs.empty()) {
        h.str("uvs");
        h.bytes(m.uvs.data(), m.uvs.size() * sizeof(vec2));
    }
    if (!m.colors.empty()) {
        h.str("colors");
        h.bytes(m.colors.data(), m.colors.size() * sizeof(vec3));
    }
    h.u64(m.triangles.size());
    h.bytes(m.triangles.data(), m.triangles.size() * sizeof(uvec3));
    h.bytes(m.tri_shape.data(), m.tri_shape.size() * sizeof(uint32_t));
    h.u64(scene.shapes.size());
    for (const Shape& s : scene.shapes) {
        h.u64(s.material);
        h.i64(s.emitter);
        h.u64(s.smooth);
        h.u64(s.first_triangle);
        h.u64(s.triangle_count);
        if (s.has_uv() || s.has_color()) {  // only then, so that other scenes keep their fingerprint
            h.u64(s.first_vertex);
            h.u64(s.uv_offset);
            h.u64(s.color_offset);
        }
    }
    // Analytic shapes (only when there are some: a scene of triangles keeps its fingerprint).
    if (!scene.analytic.empty()) {
        h.str("analytic");
        h.u64(scene.analytic.size());
        for (const AnalyticShape& a : scene.analytic) {
            h.u64(uint64_t(a.kind));
            h.u64(a.shape);
            h.u64(a.flip);
            h.v3(a.center);
            h.f32(a.radius);
            h.f32(a.length);
            h.bytes(&a.to_world, sizeof(a.to_world));
            h.v3(a.normal);
            h.f32(a.area);
            hash_curve(h, a);
        }
        for (const Shape& s : scene.shapes) h.i64(s.analytic);
    }
    // Shapegroups and instances (only when there are some, as above).
    if (!scene.instances.empty() || !scene.groups.empty()) {
        h.str("instances");
        h.u64(scene.groups.size());
        for (const ShapeGroup& g : scene.groups) {
            const Mesh& gm = g.mesh;
            h.u64(gm.positions.size());
            h.bytes(gm.positions.data(), gm.positions.size() * sizeof(vec3));
            h.u64(gm.normals.size());
            h.bytes(gm.normals.data(), gm.normals.size() * sizeof(vec3));
            h.u64(gm.triangles.size());
            h.bytes(gm.triangles.data(), gm.triangles.size() * sizeof(uvec3));
            h.bytes(gm.tri_shape.data(), gm.tri_shape.size() * sizeof(uint32_t));
            h.u64(gm.uvs.size());
            h.bytes(gm.uvs.data(), gm.uvs.size() * sizeof(vec2));
            h.u64(gm.colors.size());
            h.bytes(gm.colors.data(), gm.colors.size() * sizeof(vec3));
            h.u64(g.analytic.size());
            for (const AnalyticShape& a : g.analytic) {
                h.u64(uint64_t(a.kind));
                h.u64(a.shape);
                h.u64(a.flip);
                h.v3(a.center);
                h.f32(a.radius);
                h.f32(a.length);
                h.bytes(&a.to_world, sizeof(a.to_world));
                hash_curve(h, a);
            }
        }
        h.u64(scene.instances.size());
        for (const Instance& in : scene.instances) {
            h.u64(in.group);
            h.bytes(&in.to_world, sizeof(in.to_world));
        }
        for (const Shape& s : scene.shapes) h.i64(s.group);
    }
    h.u64(scene.emitters.size());
    for (const AreaEmitter& e : scene.emitters) h.v3(e.radiance);
    // The other lights: probed through their sampling routines, which read every parameter.
    h.u64(scene.light_params.size());
    for (const Light& l : scene.light_params) {
        h.u64(l.model.index());
        h.v3(light_strength(l.model));
        for (const vec3& ref : {vec3(0.31f, 0.77f, -0.52f), vec3(-2.f, 3.f, 1.f)}) {
            LightSample s;
            const bool ok = sample_li(l.model, scene.lights.scene_sphere(), ref, vec2(0.37f, 0.61f), s);
            h.u64(ok);
            if (ok) {
                h.v3(s.wi);
                h.v3(s.Le);
            }
        }
    }

    // Materials are a closed variant whose members keep changing; probing each one through the
    // BSDF interface covers every parameter that can change an image without naming any of them.
    const vec3 dirs[] = {glm::normalize(vec3(0.3f, -0.2f, 0.93f)), glm::normalize(vec3(-0.6f, 0.1f, 0.4f)),
                         glm::normalize(vec3(0.05f, 0.9f, 0.1f)), vec3(0.f, 0.f, 1.f),
                         glm::normalize(vec3(0.2f, 0.3f, -0.8f))};
    const float us[] = {0.1f, 0.45f, 0.8f, 0.97f};
    h.u64(scene.materials.size());
    for (const Material& mat : scene.materials) {
        h.u64(mat.two_sided);
        h.u64(mat.bsdf.index());
        for (vec3 wo : dirs) {
            for (vec3 wi : dirs) {
                h.v3(eval(mat.bsdf, wo, wi));
                h.f32(pdf(mat.bsdf, wo, wi));
            }
            for (float u : us) {
                std::optional<BsdfSample> s = sample(mat.bsdf, wo, u, vec2(1.f - u, 0.5f * u));
                h.u64(s.has_value());
                if (!s) continue;
                h.v3(s->f);
                h.v3(s->wi);
                h.f32(s->pdf);
                h.u64(s->delta);
            }
        }
    }

    // The camera is probed by its rays, which depend on every camera parameter (type, fov, clip
    // planes, principal point, aperture through off-centre lens samples, focus distance, full
    // film and crop window) and the image size; the crop offset also moves the sampler's pixels.
    const Camera& cam = scene.camera;
    h.u64(uint64_t(cam.type));
    h.u64(cam.needs_lens_sample());
    const ivec2 seed_px = cam.sampler_pixel(ivec2(0));
    h.u64(uint64_t(uint32_t(seed_px.x)) << 32 | uint32_t(seed_px.y));
    const float fx[] = {0.f, 0.31f, 0.5f, 1.f}, fy[] = {0.f, 0.77f, 0.5f, 1.f};
    const vec2 lens[] = {vec2(0.5f), vec2(0.13f, 0.71f), vec2(0.9f, 0.35f)};
    for (float x : fx)
        for (float y : fy)
            for (vec2 l : lens) {
                Ray r = cam.generate_ray(ivec2(0), vec2(x * float(st.width), y * float(st.height)), l);
                h.v3(r.o);
                h.v3(r.d);
                h.f32(r.tmin);
                h.f32(r.tmax);
            }
    return h.digest();
}

void save_checkpoint(const std::string& path, const Film& film, uint32_t spp, uint64_t fingerprint) {
    const std::vector<dvec3>& sums = film.sums();
    const std::vector<uint32_t>& counts = film.counts();
    for (uint32_t c : counts)
        if (c != spp) throw Error(path, 0, "internal error: checkpoint of a film with a partial pass");

    unsigned char header[kHeaderSize] = {};
    std::memcpy(header, kMagic, 8);
    put<uint32_t>(header, 8, kVersion);
    put<uint32_t>(header, 12, uint32_t(kHeaderSize));
    put<int32_t>(header, 16, film.width());
    put<int32_t>(header, 20, film.height());
    put<uint32_t>(header, 24, spp);
    const bool splats = film.has_splats();
    put<uint32_t>(header, 28, (film.has_alpha() ? 1u : 0u) | (film.weighted() ? 2u : 0u) | (splats ? 4u : 0u));
    put<uint64_t>(header, 32, film.nonfinite_count());
    put<uint64_t>(header, 40, fingerprint);
    put<uint64_t>(header, 48, uint64_t(sums.size()));
    put<uint64_t>(header, 56, kByteOrderMarker);

    AtomicWriter w(path);
    w.write(header, kHeaderSize);
    w.write(sums.data(), sums.size() * sizeof(dvec3));
    w.write(counts.data(), counts.size() * sizeof(uint32_t));
    if (film.has_alpha()) w.write(film.alpha_sums().data(), film.alpha_sums().size() * sizeof(double));
    if (film.weighted()) w.write(film.weights().data(), film.weights().size() * sizeof(double));
    if (splats) {
        const uint64_t paths = film.splat_paths();
        w.write(&paths, sizeof paths);
        std::vector<dvec3> zero;
        const std::vector<dvec3>* ss = &film.splat_sums();
        if (ss->empty()) {  // light paths traced, none landed: store zeros (one layout for all)
            zero.assign(sums.size(), dvec3(0.0));
            ss = &zero;
        }
        w.write(ss->data(), ss->size() * sizeof(dvec3));
    }
    uint64_t check = w.hash();
    w.write(&check, sizeof check);
    w.commit();
}

CheckpointInfo load_checkpoint(const std::string& path, Film& film, uint64_t fingerprint) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) throw Error(path, 0, "cannot open checkpoint: " + errno_text(errno));
    if (!S_ISREG(st.st_mode)) throw Error(path, 0, "checkpoint is not a regular file");
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), std::fclose);
    if (!f) throw Error(path, 0, "cannot open checkpoint: " + errno_text(errno));
    const uint64_t file_size = uint64_t(st.st_size);

    unsigned char header[kHeaderSize];
    if (file_size < 8 || std::fread(header, 1, 8, f.get()) != 8 || std::memcmp(header, kMagic, 8) != 0)
        throw Error(path, 0, "not a candela checkpoint");
    if (file_size < kHeaderSize + 8) throw Error(path, 0, "truncated checkpoint");
    read_exact(f.get(), header + 8, kHeaderSize - 8, path);
    if (get<uint64_t>(header, 56) != kByteOrderMarker)
        throw Error(path, 0, "checkpoint written on a machine of another byte order");
    if (get<uint32_t>(header, 8) != kVersion || get<uint32_t>(header, 12) != kHeaderSize)
        throw Error(path, 0, "unsupported checkpoint version " + std::to_string(get<uint32_t>(header, 8)));

    CheckpointInfo info;
    info.width = get<int32_t>(header, 16);
    info.height = get<int32_t>(header, 20);
    info.spp = get<uint32_t>(header, 24);
    info.nonfinite = get<uint64_t>(header, 32);
    info.fingerprint = get<uint64_t>(header, 40);
    const uint64_t pixels = get<uint64_t>(header, 48);
    // All sizes are checked against the file's length before the film's buffers are allocated.
    if (info.width <= 0 || info.height <= 0 || info.width > (1 << 20) || info.height > (1 << 20) ||
        pixels != uint64_t(info.width) * uint64_t(info.height))
        throw Error(path, 0, "corrupt checkpoint (bad image size)");
    const uint32_t flags = get<uint32_t>(header, 28);
    if (flags > 7) throw Error(path, 0, "corrupt checkpoint (unknown flags)");
    const bool alpha = (flags & 1u) != 0, weighted = (flags & 2u) != 0, splats = (flags & 4u) != 0;
    if (alpha != film.has_alpha())
        throw Error(path, 0, std::string("checkpoint ") + (alpha ? "has" : "has no") + " alpha channel, this render " +
                                 (film.has_alpha() ? "has one" : "has none") + "; refusing to resume");
    const uint64_t expected =
        kHeaderSize + pixels * (kBytesPerPixel + (alpha ? sizeof(double) : 0) + (weighted ? sizeof(double) : 0) +
                                (splats ? sizeof(dvec3) : 0)) +
        (splats ? 8 : 0) + 8;
    if (file_size != expected)
        throw Error(path, 0, "truncated or corrupt checkpoint (" + std::to_string(file_size) + " bytes, expected " +
                                 std::to_string(expected) + ")");
    if (info.width != film.width() || info.height != film.height())
        throw Error(path, 0, "checkpoint is of a " + std::to_string(info.width) + "x" + std::to_string(info.height) +
                                 " image, this render is " + std::to_string(film.width()) + "x" +
                                 std::to_string(film.height()));
    if (info.fingerprint != fingerprint)
        throw Error(path, 0, "checkpoint was made for another scene or other settings (fingerprint " +
                                 hex(info.fingerprint) + ", this render " + hex(fingerprint) + "); refusing to resume");

    if (weighted != film.weighted())
        throw Error(path, 0, std::string("checkpoint was made with ") + (weighted ? "a wide" : "the box") +
                                 " pixel filter, this render uses " + (film.weighted() ? "a wide one" : "the box"));
    std::vector<dvec3> sums(static_cast<size_t>(pixels));
    std::vector<double> weights(weighted ? static_cast<size_t>(pixels) : 0);
    std::vector<uint32_t> counts(static_cast<size_t>(pixels));
    read_exact(f.get(), sums.data(), sums.size() * sizeof(dvec3), path);
    read_exact(f.get(), counts.data(), counts.size() * sizeof(uint32_t), path);
    std::vector<double> alpha_sums(alpha ? static_cast<size_t>(pixels) : 0);
    if (alpha) read_exact(f.get(), alpha_sums.data(), alpha_sums.size() * sizeof(double), path);
    read_exact(f.get(), weights.data(), weights.size() * sizeof(double), path);
    uint64_t splat_paths = 0;
    std::vector<dvec3> splat_sums(splats ? static_cast<size_t>(pixels) : 0);
    if (splats) {
        read_exact(f.get(), &splat_paths, sizeof splat_paths, path);
        read_exact(f.get(), splat_sums.data(), splat_sums.size() * sizeof(dvec3), path);
    }
    uint64_t stored = 0;
    read_exact(f.get(), &stored, sizeof stored, path);
    Hasher h;
    h.bytes(header, kHeaderSize);
    h.bytes(sums.data(), sums.size() * sizeof(dvec3));
    h.bytes(counts.data(), counts.size() * sizeof(uint32_t));
    if (alpha) h.bytes(alpha_sums.data(), alpha_sums.size() * sizeof(double));
    h.bytes(weights.data(), weights.size() * sizeof(double));
    if (splats) {
        h.bytes(&splat_paths, sizeof splat_paths);
        h.bytes(splat_sums.data(), splat_sums.size() * sizeof(dvec3));
    }
    if (h.digest() != stored) throw Error(path, 0, "corrupt checkpoint (checksum mismatch)");
    // Whole passes only, and sums the film could have made (non-finite samples never enter them).
    for (uint32_t c : counts)
        if (c != info.spp) throw Error(path, 0, "corrupt checkpoint (pixels with different sample counts)");
    for (const dvec3& s : sums)
        if (!std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.z))
            throw Error(path, 0, "corrupt checkpoint (non-finite sum)");
    if (info.nonfinite > pixels * uint64_t(info.spp)) throw Error(path, 0, "corrupt checkpoint (non-finite count)");
    for (double w : weights)
        if (!(w >= 0.0) || !std::isfinite(w)) throw Error(path, 0, "corrupt checkpoint (bad filter weight)");
    // Alpha sums are coverage x (1 per sample, or the filter weight): at most the count or weight sum.
    for (size_t i = 0; i < alpha_sums.size(); ++i) {
        const double limit = weighted ? weights[i] * (1.0 + 1e-9) : double(info.spp);
        if (!(alpha_sums[i] >= 0.0 && alpha_sums[i] <= limit)) throw Error(path, 0, "corrupt checkpoint (alpha out of range)");
    }
    for (const dvec3& s : splat_sums)
        if (!std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.z))
            throw Error(path, 0, "corrupt checkpoint (non-finite splat sum)");
    if (splats && splat_paths != pixels * uint64_t(info.spp))
        throw Error(path, 0, "corrupt checkpoint (light paths do not match the samples)");
    film.restore(std::move(sums), std::move(counts), info.nonfinite, std::move(weights));
    if (splats) film.restore_splats(std::move(splat_sums), splat_paths);
    if (alpha) film.restore_alpha(std::move(alpha_sums));
    return info;
}

}  // namespace candela
