// candela-bench: builds accelerators on a mesh and measures build time, memory per triangle and
// ray throughput (closest hit and any hit) on primary camera rays and diffuse bounce rays, on one
// thread and on all threads. See bench/RESULTS.md for the figures and the commands.
//
//   candela-bench MESH.obj|SCENE.xml [--accel NAME]... [--threads N] [--width W] [--height H]
//                 [--repeat R] [--seed S] [--view x,y,z] [--stadium] [--bisect K]
//   candela-bench MESH.obj --rays FILE [--accel NAME]... [--threads N]
//   candela-bench MESH.obj --build-scaling K [--accel NAME]... [--threads N]
//
// The camera and the bounce rays follow ../shared/tools/embree_bench (same framing, same hash for
// the random numbers), so that the two programs trace comparable ray sets; for bit-identical sets
// use its --dump-rays files with --rays here.
// A scene file (.xml) without --view takes its primary rays from the scene's own camera.
#include <omp.h>
#include <tiny_obj_loader.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>
#include "accel/accel.h"
#include "accel/kdtree.h"
#include "core/error.h"
#include "scene/scene.h"

using namespace candela;

namespace {

// CPU time of the calling thread: with --threads 1 the rays are traced on it, and on a shared
// machine this figure does not count the time other processes held the core.
double thread_cpu_now() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double now() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// The ray-file record: origin, direction, tmax (tmin = 0).
struct RayRecord {
    float o[3], d[3], tmax;
};
static_assert(sizeof(RayRecord) == 28, "ray record must be 7 floats");

Ray to_ray(const RayRecord& r) {
    Ray ray;
    ray.o = vec3(r.o[0], r.o[1], r.o[2]);
    ray.d = vec3(r.d[0], r.d[1], r.d[2]);
    ray.tmin = 0.f;
    ray.tmax = r.tmax;
    return ray;
}

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// OBJ straight into a Mesh (all shapes, positions only); a scene file through load_scene(), whose
// camera then makes the primary rays (a camera framing the bounds from outside would see, say, the
// Cornell box from behind, and its bounce rays would leave the box).
Mesh load_mesh(const std::string& path, std::optional<Camera>* camera = nullptr) {
    if (ends_with(path, ".xml")) {
        SceneDescription scene = load_scene(path);
        if (camera) *camera = scene.camera;
        return std::move(scene.mesh);
    }
    tinyobj::ObjReaderConfig cfg;
    cfg.triangulate = true;
    cfg.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, cfg)) throw Error(path + ": " + reader.Error());
    Mesh mesh;
    const auto& v = reader.GetAttrib().vertices;
    for (size_t i = 0; i + 2 < v.size(); i += 3) mesh.positions.emplace_back(v[i], v[i + 1], v[i + 2]);
    for (const auto& shape : reader.GetShapes()) {
        const auto& idx = shape.mesh.indices;
        for (size_t i = 0; i + 2 < idx.size(); i += 3)
            mesh.triangles.emplace_back(idx[i].vertex_index, idx[i + 1].vertex_index, idx[i + 2].vertex_index);
    }
    mesh.tri_shape.assign(mesh.triangles.size(), 0);
    for (const vec3& p : mesh.positions)
        if (!all_finite(p)) throw Error(path + ": a vertex has a NaN or infinite coordinate");
    return mesh;
}

uint32_t hash_u32(uint32_t v) {  // the same PCG-style hash as embree_bench
    uint32_t state = v * 747796405u + 2891336453u;
    uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
float u01(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }

// Splits every triangle in two at the midpoint of its longest edge, lifting the new vertex along
// the face normal by a small hashed amount (so the surface stays curved, not flat halves). Exactly
// doubles the triangle count: N, 2N, 4N, 8N for the build-scaling figure.
void bisect(Mesh& m, uint32_t round) {
    std::vector<uvec3> out;
    out.reserve(m.triangles.size() * 2);
    std::unordered_map<uint64_t, uint32_t> mid;  // shared edges share their midpoint
    for (size_t t = 0; t < m.triangles.size(); ++t) {
        uvec3 tri = m.triangles[t];
        vec3 p[3] = {m.positions[tri.x], m.positions[tri.y], m.positions[tri.z]};
        int e = 0;
        float best = -1.f;
        for (int k = 0; k < 3; ++k) {
            float l = glm::length(p[(k + 1) % 3] - p[k]);
            if (l > best) { best = l; e = k; }
        }
        uint32_t a = tri[e], b = tri[(e + 1) % 3], c = tri[(e + 2) % 3];
        uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
        auto it = mid.find(key);
        uint32_t mv;
        if (it != mid.end()) {
            mv = it->second;
        } else {
            vec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
            float len = glm::length(n);
            n = len > 0.f ? n / len : vec3(0.f);
            float h = (u01(hash_u32(uint32_t(key) ^ hash_u32(uint32_t(key >> 32) + round))) - 0.5f) * 0.02f * best;
            mv = uint32_t(m.positions.size());
            m.positions.push_back(0.5f * (m.positions[a] + m.positions[b]) + h * n);
            mid.emplace(key, mv);
        }
        out.emplace_back(a, mv, c);
        out.emplace_back(mv, b, c);
    }
    m.triangles = std::move(out);
    m.tri_shape.assign(m.triangles.size(), 0);
}

// An axis-aligned box as 12 triangles; `open_top` leaves out the +y face.
void add_box(Mesh& m, vec3 lo, vec3 hi, bool open_top = false) {
    uint32_t base = uint32_t(m.positions.size());
    for (int k = 0; k < 8; ++k) m.positions.emplace_back(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
    const uint32_t f[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (int i = 0; i < 6; ++i) {
        if (open_top && i == 3) continue;
        const auto& q = f[i];
        m.triangles.emplace_back(base + q[0], base + q[1], base + q[2]);
        m.triangles.emplace_back(base + q[0], base + q[2], base + q[3]);
    }
}

// "Teapot in a stadium": the mesh stays where it is; around it goes an arena 100x its size (a
// floor and walls, open to the sky so that the camera sees in) with 200 sparse pillars: a few
// thousand big triangles around one dense core.
void add_stadium(Mesh& m) {
    AABB b = m.bounds();
    float diag = glm::length(b.extent());
    vec3 c = b.center();
    float half = 50.f * diag;
    add_box(m, vec3(c.x - half, b.min.y, c.z - half), vec3(c.x + half, b.min.y + 10.f * diag, c.z + half), true);
    for (uint32_t i = 0; i < 200; ++i) {
        float x = c.x + (u01(hash_u32(2 * i + 1)) * 2.f - 1.f) * 0.9f * half;
        float z = c.z + (u01(hash_u32(2 * i + 2)) * 2.f - 1.f) * 0.9f * half;
        if (std::fabs(x - c.x) < 3.f * diag && std::fabs(z - c.z) < 3.f * diag) continue;
        add_box(m, vec3(x, b.min.y, z), vec3(x + diag, b.min.y + 5.f * diag, z + diag));
    }
    m.tri_shape.assign(m.triangles.size(), 0);
}

// Pinhole camera framing the mesh bounds, rays in scanline order (as embree_bench).
std::vector<RayRecord> primary_rays(const Mesh& mesh, int W, int H, vec3 view) {
    AABB box = mesh.bounds();
    const vec3 c = box.center();
    const float fovy = 40.f * kPi / 180.f, aspect = float(W) / float(H);
    const vec3 back = glm::normalize(view), fwd = -back;
    const vec3 upref = std::fabs(fwd.y) > 0.99f ? vec3(0, 0, 1) : vec3(0, 1, 0);
    const vec3 right = glm::normalize(glm::cross(fwd, upref)), up = glm::cross(right, fwd);
    const float th = std::tan(0.5f * fovy), tw = th * aspect;
    const float radius = 0.5f * glm::length(box.extent());
    float dist = 0.f;
    for (int k = 0; k < 8; ++k) {
        vec3 p(k & 1 ? box.max.x : box.min.x, k & 2 ? box.max.y : box.min.y, k & 4 ? box.max.z : box.min.z);
        vec3 q = p - c;
        float z = glm::dot(q, fwd);
        dist = std::max({dist, std::fabs(glm::dot(q, right)) / tw - z, std::fabs(glm::dot(q, up)) / th - z,
                         1e-3f * radius - z});
    }
    const vec3 eye = c + back * dist;
    std::vector<RayRecord> rays(size_t(W) * H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float sx = (2.f * (x + 0.5f) / W - 1.f) * tw, sy = (1.f - 2.f * (y + 0.5f) / H) * th;
            vec3 d = glm::normalize(fwd + right * sx + up * sy);
            rays[size_t(y) * W + x] = {{eye.x, eye.y, eye.z}, {d.x, d.y, d.z}, kInfinity};
        }
    return rays;
}

// One cosine-distributed bounce per primary hit, leaving the hit point by 1e-4 of the diagonal
// along the normal facing the incoming ray (as embree_bench).
std::vector<RayRecord> bounce_rays(const Mesh& mesh, const Accel& accel, const std::vector<RayRecord>& primary,
                                   uint32_t seed) {
    const float eps = 1e-4f * glm::length(mesh.bounds().extent());
    std::vector<RayRecord> out;
    for (size_t i = 0; i < primary.size(); ++i) {
        Ray r = to_ray(primary[i]);
        Hit hit;
        if (!accel.intersect(r, hit)) continue;
        vec3 p0, p1, p2;
        mesh.vertices(hit.prim, p0, p1, p2);
        vec3 n = glm::cross(p1 - p0, p2 - p0);
        float len = glm::length(n);
        if (!(len > 0.f)) continue;
        n /= len;
        if (glm::dot(n, r.d) > 0.f) n = -n;
        float s = std::copysign(1.f, n.z), a = -1.f / (s + n.z), b = n.x * n.y * a;
        vec3 t1(1.f + s * n.x * n.x * a, s * b, -s * n.x), t2(b, s + n.y * n.y * a, -n.y);
        uint32_t h1 = hash_u32(uint32_t(i) ^ hash_u32(seed)), h2 = hash_u32(h1);
        float u1 = u01(h1), u2 = u01(h2);
        float rr = std::sqrt(u1), phi = 2.f * kPi * u2;
        vec3 dir = glm::normalize(t1 * (rr * std::cos(phi)) + t2 * (rr * std::sin(phi)) + n * std::sqrt(std::max(0.f, 1.f - u1)));
        vec3 o = r.at(hit.t) + n * eps;
        out.push_back({{o.x, o.y, o.z}, {dir.x, dir.y, dir.z}, kInfinity});
    }
    return out;
}

struct Result {
    double mrays = 0.0;
    double cpu_mrays = 0.0;  // one thread: per second of this thread's CPU time (see trace())
    uint64_t hits = 0;
    double sum_t = 0.0;
};

// Best of `repeat` runs; the checksum (hits, sum of t in ray order) is taken from the last.
Result trace(const Accel& accel, const std::vector<RayRecord>& rays, bool any_hit, int threads, int repeat) {
    const int64_t n = int64_t(rays.size());
    std::vector<float> t(rays.size());
    double best = 1e30, best_cpu = 1e30;
    for (int rep = 0; rep < repeat; ++rep) {
        double t0 = now(), c0 = thread_cpu_now();
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
        for (int64_t i = 0; i < n; ++i) {
            Ray r = to_ray(rays[size_t(i)]);
            if (any_hit) {
                t[size_t(i)] = accel.occluded(r) ? 1.f : -1.f;
            } else {
                Hit h;
                t[size_t(i)] = accel.intersect(r, h) ? h.t : -1.f;
            }
        }
        best = std::min(best, now() - t0);
        best_cpu = std::min(best_cpu, thread_cpu_now() - c0);
    }
    Result res;
    res.mrays = double(n) / best / 1e6;
    if (threads == 1) res.cpu_mrays = double(n) / best_cpu / 1e6;
    for (float x : t)
        if (x >= 0.f) {
            ++res.hits;
            res.sum_t += double(x);
        }
    return res;
}

struct Built {
    std::unique_ptr<Accel> accel;
    double build_s = 0.0;
};

// "kdtree:KT,KI,EB[,STALLS[,MAXDEPTH]]" builds a k-d tree with those SAH constants (traversal, intersection, empty
// bonus): for tuning. Any other name goes to make_accel().
Built build(const std::string& name, const Mesh& mesh) {
    Built b;
    double t0 = now();
    if (name.rfind("kdtree:", 0) == 0) {
        KdBuildOptions opt;
        if (std::sscanf(name.c_str() + 7, "%f,%f,%f,%d,%d", &opt.traversal_cost, &opt.intersection_cost, &opt.empty_bonus,
                        &opt.max_stalls, &opt.max_depth) < 3)
            throw Error("expected kdtree:KT,KI,EB[,STALLS[,MAXDEPTH]], got " + name);
        b.accel = std::make_unique<KdTreeAccel>(mesh, opt);
    } else {
        b.accel = make_accel(name, mesh);
    }
    b.build_s = now() - t0;
    if (auto* kd = dynamic_cast<const KdTreeAccel*>(b.accel.get())) {
        const KdTreeStats& s = kd->tree().stats();
        std::fprintf(stderr, "[%s] nodes %zu (%zu wide) leaves %zu (empty %zu, in %zu lanes) refs/tri %.2f refs/leaf %.2f depth %d\n",
                     name.c_str(), s.nodes, s.wide_nodes, s.leaves, s.empty_leaves, s.leaf_lanes, double(s.references) / double(std::max<size_t>(1, mesh.triangles.size())),
                     double(s.references) / double(std::max<size_t>(1, s.leaves - s.empty_leaves)), s.max_depth);
    }
    return b;
}

std::vector<RayRecord> read_rays(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error("cannot open " + path);
    uint64_t n = 0;
    f.read(reinterpret_cast<char*>(&n), 8);
    std::vector<RayRecord> rays(n);
    f.read(reinterpret_cast<char*>(rays.data()), std::streamsize(n * sizeof(RayRecord)));
    if (!f) throw Error(path + ": truncated ray file");
    return rays;
}

[[noreturn]] void usage() {
    std::fprintf(stderr,
                 "usage: candela-bench MESH.obj|SCENE.xml [--accel NAME]... [--threads N] [--width W] [--height H]\n"
                 "                     [--repeat R] [--seed S] [--view x,y,z] [--stadium] [--bisect K]\n"
                 "       candela-bench MESH.obj --rays FILE [--accel NAME]... [--threads N] [--repeat R]\n"
                 "       candela-bench MESH.obj --build-scaling K [--accel NAME]... [--threads N]\n"
                 "accelerators: kdtree hybrid brute"
#ifdef CANDELA_HAS_EMBREE
                 " embree"
#endif
                 " (default: kdtree hybrid"
#ifdef CANDELA_HAS_EMBREE
                 " embree"
#endif
                 ")\n");
    std::exit(2);
}

}  // namespace

int main(int argc, char** argv) try {
    std::vector<std::string> inputs, accels;
    std::string rays_path;
    int W = 1024, H = 1024, repeat = 3, threads = 0, bisect_rounds = 0, scaling = -1;
    uint32_t seed = 1;
    vec3 view(0.3f, 0.4f, 1.f);
    bool stadium = false, view_given = false;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) usage();
            return argv[++i];
        };
        if (a == "--accel") accels.push_back(next());
        else if (a == "--threads") threads = std::atoi(next().c_str());
        else if (a == "--rays") rays_path = next();
        else if (a == "--width") W = std::atoi(next().c_str());
        else if (a == "--height") H = std::atoi(next().c_str());
        else if (a == "--repeat") repeat = std::max(1, std::atoi(next().c_str()));
        else if (a == "--seed") seed = uint32_t(std::strtoul(next().c_str(), nullptr, 10));
        else if (a == "--bisect") bisect_rounds = std::atoi(next().c_str());
        else if (a == "--build-scaling") scaling = std::atoi(next().c_str());
        else if (a == "--stadium") stadium = true;
        else if (a == "--view") {
            view_given = true;
            if (std::sscanf(next().c_str(), "%f,%f,%f", &view.x, &view.y, &view.z) != 3) usage();
        } else if (a == "-h" || a == "--help" || (!a.empty() && a[0] == '-')) usage();
        else inputs.push_back(a);
    }
    if (inputs.size() != 1) usage();
    if (accels.empty()) {
        accels = {"kdtree", "hybrid"};
#ifdef CANDELA_HAS_EMBREE
        accels.push_back("embree");
#endif
    }
    const int nthreads = threads > 0 ? threads : omp_get_max_threads();
    if (threads > 0) omp_set_num_threads(threads);

    std::optional<Camera> scene_camera;
    Mesh mesh = load_mesh(inputs[0], &scene_camera);
    for (int k = 0; k < bisect_rounds; ++k) bisect(mesh, uint32_t(k));
    if (stadium) add_stadium(mesh);
    const size_t ntris = mesh.triangles.size();

    // ---- the exact, comparable form: one line per accelerator
    if (!rays_path.empty()) {
        std::vector<RayRecord> rays = read_rays(rays_path);
        // All accelerators are built first and then timed in turn, one pass each per round, so
        // that the machine's slow spells (it is shared) fall on all of them alike; each keeps its
        // best round.
        std::vector<Built> built;
        for (const std::string& name : accels) built.push_back(build(name, mesh));
        std::vector<Result> best(accels.size());
        std::vector<KdTraceCounters> counters(accels.size());
        for (int rep = 0; rep < std::max(repeat, 1); ++rep)
            for (size_t k = 0; k < accels.size(); ++k) {
                kd_trace_counters() = {};
                const Result r = trace(*built[k].accel, rays, false, nthreads, 1);
                if (rep == 0) {
                    best[k] = r;  // hits and sum_t are the same in every pass
                    counters[k] = kd_trace_counters();
                }
                best[k].mrays = std::max(best[k].mrays, r.mrays);
                best[k].cpu_mrays = std::max(best[k].cpu_mrays, r.cpu_mrays);
            }
        for (size_t k = 0; k < accels.size(); ++k) {
            const std::string& name = accels[k];
            const Result& r = best[k];
            if (r.cpu_mrays > 0.0)
                std::fprintf(stderr, "[%s] %.3f Mrays/s per second of thread CPU time\n", name.c_str(), r.cpu_mrays);
#ifdef CANDELA_KD_COUNTERS
            if (const KdTraceCounters& c = counters[k]; c.rays > 0)
                std::fprintf(stderr, "[%s] per ray: %.2f nodes, %.2f leaves, %.2f triangle tests (1 thread only)\n",
                             name.c_str(), double(c.nodes) / double(c.rays), double(c.leaves) / double(c.rays),
                             double(c.tris) / double(c.rays));
#endif
            std::printf("accel=%s rays=%zu hits=%llu sum_t=%.9e build_s=%.4f mrays_per_s=%.3f\n", name.c_str(),
                        rays.size(), (unsigned long long)r.hits, r.sum_t, built[k].build_s, r.mrays);
            std::fflush(stdout);
        }
        return 0;
    }

    // ---- build time against N log N
    if (scaling >= 0) {
        std::printf("build scaling: %s, %d threads (N doubled by longest-edge bisection)\n", inputs[0].c_str(), nthreads);
        std::printf("%-8s %10s %10s %14s %12s\n", "accel", "triangles", "build_s", "us/(N log2 N)", "bytes/tri");
        for (int k = 0; k <= scaling; ++k) {
            if (k > 0) bisect(mesh, uint32_t(100 + k));
            const double n = double(mesh.triangles.size());
            for (const std::string& name : accels) {
                Built b = build(name, mesh);
                std::printf("%-8s %10zu %10.3f %14.4f %12.1f\n", name.c_str(), mesh.triangles.size(), b.build_s,
                            1e6 * b.build_s / (n * std::log2(n)), double(b.accel->memory_bytes()) / n);
                std::fflush(stdout);
            }
        }
        return 0;
    }

    // ---- the full table
    std::printf("mesh: %s%s%s, %zu triangles; rays %dx%d; threads 1 and %d; best of %d\n", inputs[0].c_str(),
                stadium ? " + stadium" : "", bisect_rounds ? (" bisected x" + std::to_string(bisect_rounds)).c_str() : "",
                ntris, W, H, nthreads, repeat);
    std::vector<RayRecord> primary;
    if (scene_camera && !stadium && !view_given) {
        // Through pixel centres, in scanline order, like primary_rays(); tmax from the far clip.
        scene_camera->set_film_size(W, H);
        primary.reserve(size_t(W) * H);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                Ray r = scene_camera->generate_ray(vec2(float(x) + 0.5f, float(y) + 0.5f));
                primary.push_back({{r.o.x, r.o.y, r.o.z}, {r.d.x, r.d.y, r.d.z}, r.tmax});
            }
        std::printf("primary rays from the scene's camera\n");
    } else {
        primary = primary_rays(mesh, W, H, view);
    }
    std::vector<RayRecord> bounce;
    {
        KdTreeAccel ref(mesh);  // rays are generated once, with the k-d tree, for every accelerator
        bounce = bounce_rays(mesh, ref, primary, seed);
    }
    std::printf("primary rays %zu, bounce rays %zu\n\n", primary.size(), bounce.size());
    std::printf("%-8s %8s %9s | %-7s %10s %10s %10s %10s | %9s %16s\n", "accel", "build_s", "bytes/tri", "rays",
                "closest 1T", ("closest " + std::to_string(nthreads) + "T").c_str(), "any 1T",
                ("any " + std::to_string(nthreads) + "T").c_str(), "hits", "sum_t");
    for (const std::string& name : accels) {
        Built b = build(name, mesh);
        const double bpt = ntris ? double(b.accel->memory_bytes()) / double(ntris) : 0.0;
        for (int set = 0; set < 2; ++set) {
            const auto& rays = set == 0 ? primary : bounce;
            kd_trace_counters() = {};
            Result c1 = trace(*b.accel, rays, false, 1, repeat);
#ifdef CANDELA_KD_COUNTERS
            if (const KdTraceCounters& c = kd_trace_counters(); c.rays > 0)
                std::fprintf(stderr, "[%s %s closest] per ray: %.2f nodes, %.2f leaves, %.2f triangle tests\n",
                             name.c_str(), set == 0 ? "primary" : "bounce", double(c.nodes) / double(c.rays),
                             double(c.leaves) / double(c.rays), double(c.tris) / double(c.rays));
#endif
            Result cn = trace(*b.accel, rays, false, nthreads, repeat);
            Result a1 = trace(*b.accel, rays, true, 1, repeat);
            Result an = trace(*b.accel, rays, true, nthreads, repeat);
            std::printf("%-8s %8.3f %9.1f | %-7s %10.2f %10.2f %10.2f %10.2f | %9llu %16.9e\n", name.c_str(), b.build_s,
                        bpt, set == 0 ? "primary" : "bounce", c1.mrays, cn.mrays, a1.mrays, an.mrays,
                        (unsigned long long)c1.hits, c1.sum_t);
            if (a1.hits != c1.hits) std::printf("  (any-hit count %llu differs from closest-hit count)\n", (unsigned long long)a1.hits);
            std::fflush(stdout);
        }
    }
    std::printf("\n(Mrays/s; T = threads; hits and sum_t: closest-hit checksum, sum in ray order)\n");
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "candela-bench: %s\n", e.what());
    return 1;
}
