#include "accel/kdtree.h"
#include <omp.h>
#include <immintrin.h>
#include <algorithm>
#include <cmath>
#include <memory>
#include "core/error.h"
#include "core/interrupt.h"
#include "geometry/triangle.h"

namespace candela {
namespace {

// ---- build ----------------------------------------------------------------------------------

// Wald-Havran event types; the order end < planar < start is the sweep's tie order at one position.
enum : uint8_t { kEnd = 0, kPlanar = 1, kStart = 2 };

struct Event {
    float pos;
    uint32_t tri;  // index into the builder's triangle list (not the mesh's)
    uint8_t dim, type;
    bool operator<(const Event& o) const {
        if (pos != o.pos) return pos < o.pos;
        if (dim != o.dim) return dim < o.dim;
        return type < o.type;
    }
};

enum : uint8_t { kBoth = 0, kLeftOnly = 1, kRightOnly = 2 };

// Sorts the events as std::stable_sort would (equal events keep their triangle order), as a merge
// sort of 2^18-event runs, so that an interrupt is noticed within one run or merge of a
// multi-second sort. Returns false when interrupted (the order is then unspecified).
bool sort_events(std::vector<Event>& ev) {
    constexpr size_t kRun = size_t(1) << 18;
    const size_t n = ev.size();
    for (size_t i = 0; i < n; i += kRun) {
        if (interrupt_requested()) return false;
        std::stable_sort(ev.begin() + std::ptrdiff_t(i), ev.begin() + std::ptrdiff_t(std::min(n, i + kRun)));
    }
    for (size_t width = kRun; width < n; width *= 2)
        for (size_t i = 0; i + width < n; i += 2 * width) {
            if (interrupt_requested()) return false;
            auto first = ev.begin() + std::ptrdiff_t(i);
            std::inplace_merge(first, first + std::ptrdiff_t(width), ev.begin() + std::ptrdiff_t(std::min(n, i + 2 * width)));
        }
    return true;
}

// Bounds of the part of triangle v inside `box` (Sutherland-Hodgman in double), rounded outwards
// and never larger than the box or the triangle's own bounds. Empty when the triangle misses it.
AABB clipped_bounds(const vec3 v[3], const AABB& box) {
    AABB tb(v[0], v[0]);
    tb.expand(v[1]);
    tb.expand(v[2]);
    bool inside = true;
    for (int i = 0; i < 3; ++i) inside &= tb.min[i] >= box.min[i] && tb.max[i] <= box.max[i];
    if (inside) return tb;

    dvec3 poly[2][9];
    int n = 3;
    for (int i = 0; i < 3; ++i) poly[0][i] = dvec3(v[i]);
    int cur = 0;
    for (int a = 0; a < 3 && n > 0; ++a) {
        for (int side = 0; side < 2 && n > 0; ++side) {
            const double c = side == 0 ? box.min[a] : box.max[a];
            const double sign = side == 0 ? 1.0 : -1.0;  // inside: sign * (p[a] - c) >= 0
            const dvec3* in = poly[cur];
            dvec3* out = poly[cur ^ 1];
            int m = 0;
            for (int i = 0; i < n; ++i) {
                const dvec3& p = in[i];
                const dvec3& q = in[(i + 1) % n];
                const bool pin = sign * (p[a] - c) >= 0.0, qin = sign * (q[a] - c) >= 0.0;
                if (pin) out[m++] = p;
                if (pin != qin) {
                    dvec3 x = p + (q - p) * ((c - p[a]) / (q[a] - p[a]));
                    x[a] = c;
                    out[m++] = x;
                }
            }
            n = m;
            cur ^= 1;
        }
    }
    if (n == 0) return AABB();
    dvec3 lo(poly[cur][0]), hi(poly[cur][0]);
    for (int i = 1; i < n; ++i) {
        lo = glm::min(lo, poly[cur][i]);
        hi = glm::max(hi, poly[cur][i]);
    }
    AABB out;
    for (int i = 0; i < 3; ++i) {
        out.min[i] = std::max({box.min[i], tb.min[i], next_float_down(float(lo[i]))});
        out.max[i] = std::min({box.max[i], tb.max[i], next_float_up(float(hi[i]))});
        if (out.min[i] > out.max[i]) {  // a sliver at the rounding limit: keep it, flat
            float x = std::clamp(float(lo[i]), box.min[i], box.max[i]);
            out.min[i] = out.max[i] = x;
        }
    }
    return out;
}

void add_events(std::vector<Event>& out, uint32_t tri, const AABB& b) {
    for (uint8_t d = 0; d < 3; ++d) {
        if (b.min[d] == b.max[d]) {
            out.push_back({b.min[d], tri, d, kPlanar});
        } else {
            out.push_back({b.min[d], tri, d, kStart});
            out.push_back({b.max[d], tri, d, kEnd});
        }
    }
}

struct BuildNode {
    std::unique_ptr<BuildNode> child[2];
    std::vector<uint32_t> prims;  // leaves only; builder-local triangle indices
    float split = 0.f;
    int axis = -1;  // -1: leaf
};

class Builder {
public:
    Builder(const Mesh& mesh, const std::vector<uint32_t>& tris, const KdBuildOptions& opt, size_t n)
        : mesh_(mesh), tris_(tris), opt_(opt) {
        int md = opt.max_depth >= 0 ? opt.max_depth : int(8 + 1.3 * std::log2(double(std::max<size_t>(n, 1))));
        max_depth_ = std::min(md, KdTree::kMaxDepth);
        flags_.resize(size_t(omp_get_max_threads()));
        for (auto& f : flags_) f.resize(tris.size());
    }

    // `stalls`: consecutive ancestors whose split left one child with all of their triangles.
    std::unique_ptr<BuildNode> build(std::vector<Event>& events, size_t n, const AABB& box, int depth, int stalls) {
        auto node = std::make_unique<BuildNode>();
        // An exception must not leave an OpenMP task: an interrupted build unwinds as empty
        // leaves, and the tree's owner throws outside the parallel region.
        if (interrupt_requested()) return node;
        const float leaf_cost = opt_.intersection_cost * float(n);
        const float sa = box.surface_area();
        float best_cost = kInfinity;
        float best_pos = 0.f;
        int best_dim = -1;
        bool planar_left = false;
        if (n > 0 && depth < max_depth_ && sa > 0.f)
            sweep(events, n, box, sa, stalls < opt_.max_stalls, best_cost, best_pos, best_dim, planar_left);

        if (best_dim < 0 || !(best_cost < leaf_cost)) {
            make_leaf(*node, events, n);
            return node;
        }

        // Classify (Wald-Havran section 5.1): a triangle is on one side when its extent along the
        // split axis ends at or before the plane (left) or starts at or after it (right).
        std::vector<uint8_t>& flag = flags_[size_t(omp_get_thread_num())];
        for (const Event& e : events) flag[e.tri] = kBoth;
        for (const Event& e : events) {
            if (e.dim != best_dim) continue;
            if (e.type == kEnd && e.pos <= best_pos) flag[e.tri] = kLeftOnly;
            else if (e.type == kStart && e.pos >= best_pos) flag[e.tri] = kRightOnly;
            else if (e.type == kPlanar) {
                if (e.pos < best_pos || (e.pos == best_pos && planar_left)) flag[e.tri] = kLeftOnly;
                else if (e.pos > best_pos || (e.pos == best_pos && !planar_left)) flag[e.tri] = kRightOnly;
            }
        }

        AABB lbox = box, rbox = box;
        lbox.max[best_dim] = best_pos;
        rbox.min[best_dim] = best_pos;

        // Split the sorted list in one pass; the lists stay sorted. Straddling triangles are clipped
        // to each child and their new events sorted and merged in.
        std::vector<Event> el, er, nl_ev, nr_ev;
        el.reserve(events.size() / 2 + 16);
        er.reserve(events.size() / 2 + 16);
        std::vector<uint32_t> straddle;
        size_t nl = 0, nr = 0;
        for (const Event& e : events) {
            const uint8_t f = flag[e.tri];
            if (f == kLeftOnly) el.push_back(e);
            else if (f == kRightOnly) er.push_back(e);
            if (e.dim == 0 && e.type != kEnd) {  // once per triangle
                if (f == kLeftOnly) ++nl;
                else if (f == kRightOnly) ++nr;
                else straddle.push_back(e.tri);
            }
        }
        for (uint32_t t : straddle) {
            vec3 v[3];
            mesh_.vertices(tris_[t], v[0], v[1], v[2]);
            AABB lb = clipped_bounds(v, lbox), rb = clipped_bounds(v, rbox);
            if (!lb.empty()) { add_events(nl_ev, t, lb); ++nl; }
            if (!rb.empty()) { add_events(nr_ev, t, rb); ++nr; }
        }
        std::vector<Event>().swap(events);  // the parent's list is no longer needed
        merge_into(el, nl_ev);
        merge_into(er, nr_ev);

        node->axis = best_dim;
        node->split = best_pos;
        // With perfect splits the SAH never stops zooming in on a shared vertex: every box around
        // it holds all the triangles of its fan, and there is always empty space to cut off. A
        // split that leaves a child with all of the node's triangles counts as a stall; after
        // max_stalls of them in a row only splits that reduce both sides are considered.
        const int lstall = nl >= n ? stalls + 1 : 0, rstall = nr >= n ? stalls + 1 : 0;
        const bool spawn = parallel_ && el.size() + er.size() > 20000 && depth < 12;
        if (spawn) {
#pragma omp task default(shared)
            node->child[0] = build(el, nl, lbox, depth + 1, lstall);
            node->child[1] = build(er, nr, rbox, depth + 1, rstall);
#pragma omp taskwait
        } else {
            node->child[0] = build(el, nl, lbox, depth + 1, lstall);
            node->child[1] = build(er, nr, rbox, depth + 1, rstall);
        }
        return node;
    }

    bool parallel_ = false;

private:
    float cost(float pl, float pr, size_t nl, size_t nr) const {
        float c = opt_.traversal_cost + opt_.intersection_cost * (pl * float(nl) + pr * float(nr));
        if (nl == 0 || nr == 0) c *= 1.f - opt_.empty_bonus;
        return c;
    }

    // Sweeps the sorted events once, keeping per-axis counts left / planar / right of the plane.
    // Without `allow_stall`, only splits that leave each child fewer triangles than the node count.
    void sweep(const std::vector<Event>& ev, size_t n, const AABB& box, float sa, bool allow_stall, float& best_cost,
               float& best_pos, int& best_dim, bool& planar_left) const {
        size_t nl[3] = {0, 0, 0}, nr[3] = {n, n, n};
        const float inv_sa = 1.f / sa;
        const vec3 ext = box.extent();
        size_t i = 0;
        const size_t m = ev.size();
        for (size_t poll = 0; i < m; ++poll) {
            // A big node's sweep takes a while; on an interrupt no split is chosen (a leaf).
            if (poll % 65536 == 0 && interrupt_requested()) {
                best_dim = -1;
                return;
            }
            const float pos = ev[i].pos;
            const int d = ev[i].dim;
            size_t pe = 0, pp = 0, ps = 0;
            while (i < m && ev[i].dim == d && ev[i].pos == pos && ev[i].type == kEnd) { ++pe; ++i; }
            while (i < m && ev[i].dim == d && ev[i].pos == pos && ev[i].type == kPlanar) { ++pp; ++i; }
            while (i < m && ev[i].dim == d && ev[i].pos == pos && ev[i].type == kStart) { ++ps; ++i; }
            nr[d] -= pp + pe;
            // Planes on the node's faces are skipped: they would give a child equal to the node.
            if (pos > box.min[d] && pos < box.max[d]) {
                const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
                const float cross = ext[d1] * ext[d2];
                const float span = ext[d1] + ext[d2];
                const float pl = 2.f * (cross + (pos - box.min[d]) * span) * inv_sa;
                const float pr = 2.f * (cross + (box.max[d] - pos) * span) * inv_sa;
                const float cl = cost(pl, pr, nl[d] + pp, nr[d]);
                const float cr = cost(pl, pr, nl[d], nr[d] + pp);
                const bool ok_l = allow_stall || (nl[d] + pp < n && nr[d] < n);
                const bool ok_r = allow_stall || (nl[d] < n && nr[d] + pp < n);
                if (cl < best_cost && ok_l) { best_cost = cl; best_pos = pos; best_dim = d; planar_left = true; }
                if (cr < best_cost && ok_r) { best_cost = cr; best_pos = pos; best_dim = d; planar_left = false; }
            }
            nl[d] += ps + pp;
        }
    }

    static void merge_into(std::vector<Event>& list, std::vector<Event>& extra) {
        if (extra.empty()) return;
        std::sort(extra.begin(), extra.end());
        const size_t mid = list.size();
        list.insert(list.end(), extra.begin(), extra.end());
        std::inplace_merge(list.begin(), list.begin() + std::ptrdiff_t(mid), list.end());
    }

    static void make_leaf(BuildNode& node, const std::vector<Event>& events, size_t n) {
        node.prims.reserve(n);
        for (const Event& e : events)
            if (e.dim == 0 && e.type != kEnd) node.prims.push_back(e.tri);
    }

    const Mesh& mesh_;
    const std::vector<uint32_t>& tris_;
    KdBuildOptions opt_;
    int max_depth_ = 0;
    std::vector<std::vector<uint8_t>> flags_;  // per thread: side of each triangle at the current node
};

// Widening of a ray parameter by 2^-16 of its size: room for the rounding of split-plane
// distances and of triangle hit distances (both a few ulps) so that the traversal never culls a
// node that brute force would find a hit in. The traversal keeps every parameter >= 0 (hits have
// t > 0), so a single multiplication widens.
constexpr float kWidenUp = 1.f + 1.f / 65536.f;
constexpr float kWidenDown = 1.f - 1.f / 65536.f;

}  // namespace

// ---- KdTree ---------------------------------------------------------------------------------

void KdTree::interrupted_build() {
    nodes_.clear();
    blocks_.clear();
    bounds_ = AABB();
    stats_ = {};
}

void KdTree::build(const Mesh& mesh, const std::vector<uint32_t>* tris, const AABB* clip, const KdBuildOptions& opt) {
    nodes_.clear();
    blocks_.clear();
    bounds_ = AABB();
    stats_ = {};

    std::vector<uint32_t> all;
    if (!tris) {
        all.resize(mesh.triangles.size());
        for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
        tris = &all;
    }
    const std::vector<uint32_t>& list = *tris;
    if (list.empty()) return;
    if (interrupt_requested()) return interrupted_build();

    std::vector<Event> events;
    events.reserve(list.size() * 6);
    size_t n = 0;
    for (uint32_t i = 0; i < list.size(); ++i) {
        if (i % 4096 == 0 && interrupt_requested()) return interrupted_build();
        vec3 v[3];
        mesh.vertices(list[i], v[0], v[1], v[2]);
        AABB b;
        if (clip) {
            b = clipped_bounds(v, *clip);
            if (b.empty()) continue;
        } else {
            b = AABB(v[0], v[0]);
            b.expand(v[1]);
            b.expand(v[2]);
        }
        add_events(events, i, b);
        bounds_.expand(b);
        ++n;
    }
    if (n == 0) return;
    if (!sort_events(events)) return interrupted_build();

    Builder builder(mesh, list, opt, n);
    std::unique_ptr<BuildNode> root;
    if (opt.parallel && !omp_in_parallel() && omp_get_max_threads() > 1) {
        builder.parallel_ = true;
#pragma omp parallel
#pragma omp single
        root = builder.build(events, n, bounds_, 0, 0);
    } else {
        root = builder.build(events, n, bounds_, 0, 0);
    }
    if (interrupt_requested()) return interrupted_build();

    // Layout: the two children of a node are adjacent (a sibling pair), so an interior node stores
    // one index. Pairs are packed in treelets of up to 4 pairs (8 nodes, 64 bytes), filled breadth
    // first: a pair, its children's pairs, one more. A ray descending through a treelet's 2-3
    // levels then touches one or two cache lines instead of one per level, which is what
    // incoherent rays pay for: the deep levels are never in cache. Treelets follow each other in
    // depth-first order, and so do the leaves' triangle blocks.
    struct Flatten {
        KdTree& t;
        const Mesh& mesh;
        const std::vector<uint32_t>& list;
        // Appends the leaf's triangles as blocks of four (the last lane repeated to fill a block).
        uint32_t add_blocks(const std::vector<uint32_t>& prims) {
            const uint32_t first = uint32_t(t.blocks_.size());
            for (size_t i = 0; i < prims.size(); i += 4) {
                TriBlock b;
                for (size_t k = 0; k < 4; ++k) {
                    const uint32_t prim = list[prims[std::min(i + k, prims.size() - 1)]];
                    vec3 v[3];
                    mesh.vertices(prim, v[0], v[1], v[2]);
                    for (int j = 0; j < 3; ++j)
                        for (int a = 0; a < 3; ++a) b.v[j][a][k] = v[j][a];
                    b.prim[k] = prim;
                }
                t.blocks_.push_back(b);
            }
            return first;
        }
        // Writes a leaf, or an interior node whose children index is patched when its pair is placed.
        void write(uint32_t idx, const BuildNode* bn, int depth) {
            t.stats_.max_depth = std::max(t.stats_.max_depth, depth);
            Node& nd = t.nodes_[idx];
            if (bn->axis >= 0) {
                nd.split = bn->split;
                nd.bits = uint32_t(bn->axis);
                return;
            }
            const size_t n = bn->prims.size();
            const uint32_t first = n > 0 ? add_blocks(bn->prims) : 0;
            t.nodes_[idx].first = first;
            t.nodes_[idx].bits = (uint32_t(n) << 2) | 3u;
            ++t.stats_.leaves;
            t.stats_.references += n;
            if (n == 0) ++t.stats_.empty_leaves;
        }
        struct Pair {
            const BuildNode* parent;  // its two children form the pair
            uint32_t parent_idx;
            int depth;                // of the children
        };
        void run(const BuildNode& root) {
            t.nodes_.emplace_back();
            write(0, &root, 0);
            if (root.axis < 0) return;
            std::vector<Pair> work{{&root, 0, 1}};
            Pair q[8];
            while (!work.empty()) {
                int qn = 0, qi = 0, placed = 0;
                q[qn++] = work.back();
                work.pop_back();
                const size_t mark = work.size();
                while (qi < qn) {
                    const Pair p = q[qi++];
                    if (placed == 4) {  // the treelet is full: the rest starts treelets of its own
                        work.push_back(p);
                        continue;
                    }
                    ++placed;
                    const uint32_t c = uint32_t(t.nodes_.size());
                    if (c + 2 > KdTree::kMaxNodes) throw Error("k-d tree: more than 2^28 nodes");
                    t.nodes_.emplace_back();
                    t.nodes_.emplace_back();
                    t.nodes_[p.parent_idx].bits |= c << 4;
                    for (int k = 0; k < 2; ++k) {
                        const BuildNode* ch = p.parent->child[k].get();
                        if (ch->axis < 0 && ch->prims.empty()) t.nodes_[p.parent_idx].bits |= 4u << k;
                        write(c + uint32_t(k), ch, p.depth);
                        if (ch->axis >= 0 && qn < 8) q[qn++] = {ch, c + uint32_t(k), p.depth + 1};
                        else if (ch->axis >= 0) work.push_back({ch, c + uint32_t(k), p.depth + 1});
                    }
                }
                // Depth first between treelets: the pairs just deferred are taken first, in order.
                std::reverse(work.begin() + ptrdiff_t(mark), work.end());
            }
        }
    };
    Flatten{*this, mesh, list}.run(*root);
    nodes_.shrink_to_fit();
    blocks_.shrink_to_fit();
    stats_.nodes = nodes_.size();
}

size_t KdTree::memory_bytes() const {
    return nodes_.capacity() * sizeof(Node) + blocks_.capacity() * sizeof(TriBlock);
}

KdTraceCounters& kd_trace_counters() {
    static thread_local KdTraceCounters c;
    return c;
}

#ifdef CANDELA_KD_COUNTERS
#define KD_COUNT(field, n) (kd_trace_counters().field += (n))
#else
#define KD_COUNT(field, n) ((void)0)
#endif

namespace {

// Per-ray constants in plain arrays: glm's operator[] is a switch, slow in the node loop.
struct RayData {
    float o[3], inv_d[3];
    bool d_nonpos[3];  // d <= 0: a ray starting on a split plane goes below first
    // The origin as compared with split planes: o_above[a] > split exactly when the origin lies
    // above the plane, or on it moving up (o rounded up to the next float when d > 0).
    float o_above[3];
    int kx, ky, kz;  // the shear of intersect_triangle (RayShear), for the 4-wide filter
    float sx, sy, sz;
    RayData(const Ray& ray, const RayShear& sh) {
        kx = sh.kx;
        ky = sh.ky;
        kz = sh.kz;
        sx = sh.sx;
        sy = sh.sy;
        sz = sh.sz;
        for (int i = 0; i < 3; ++i) {
            o[i] = ray.o[i];
            inv_d[i] = 1.f / ray.d[i];
            d_nonpos[i] = ray.d[i] <= 0.f;
            o_above[i] = d_nonpos[i] ? o[i] : next_float_up(o[i]);
        }
    }
};

// intersect_triangle() (geometry/triangle.h) on four triangles at once: the translation, the
// shear, the edge functions, the degenerate-triangle check, the determinant, the scaled distance
// and its interval check, the division, and the error bound on t, with the same float operations
// in the same order (no FMA at -march=x86-64-v2; max and abs written to give what std::max and
// glm::abs give), so each lane's result is the scalar test's, bit for bit. Lanes with an edge
// function exactly 0 are left to the scalar test itself (it redoes them in double): they come back
// in `scalar`. The hits come back in the return value, with t, b1 and b2 in `out`.
struct Hits4 {
    alignas(16) float t[4], b1[4], b2[4];
};
inline unsigned triangle_hits4(const RayData& r, const KdTree::TriBlock& b, float tmin, float tmax, unsigned lanes,
                               unsigned& scalar, Hits4& out) {
    const __m128 sx = _mm_set1_ps(r.sx), sy = _mm_set1_ps(r.sy), sz = _mm_set1_ps(r.sz);
    __m128 x[3], y[3], z[3];
    for (int v = 0; v < 3; ++v) {
        // a = p - o, then a[kx] + sx * a[kz], a[ky] + sy * a[kz] and sz * a[kz].
        const __m128 ax = _mm_sub_ps(_mm_load_ps(b.v[v][r.kx]), _mm_set1_ps(r.o[r.kx]));
        const __m128 ay = _mm_sub_ps(_mm_load_ps(b.v[v][r.ky]), _mm_set1_ps(r.o[r.ky]));
        const __m128 az = _mm_sub_ps(_mm_load_ps(b.v[v][r.kz]), _mm_set1_ps(r.o[r.kz]));
        x[v] = _mm_add_ps(ax, _mm_mul_ps(sx, az));
        y[v] = _mm_add_ps(ay, _mm_mul_ps(sy, az));
        z[v] = _mm_mul_ps(sz, az);
    }
    const __m128 e0 = _mm_sub_ps(_mm_mul_ps(x[1], y[2]), _mm_mul_ps(y[1], x[2]));
    const __m128 e1 = _mm_sub_ps(_mm_mul_ps(x[2], y[0]), _mm_mul_ps(y[2], x[0]));
    const __m128 e2 = _mm_sub_ps(_mm_mul_ps(x[0], y[1]), _mm_mul_ps(y[0], x[1]));
    // Edge test. With no edge exactly 0, "some edge negative and some positive" is "the sign bits
    // differ". A NaN edge may go either way: the scalar test rejects NaN lanes too (at t).
    const __m128 zero = _mm_setzero_ps();
    const __m128 any_zero = _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(e0, zero), _mm_cmpeq_ps(e1, zero)), _mm_cmpeq_ps(e2, zero));
    const unsigned zero_edge = unsigned(_mm_movemask_ps(any_zero)) & lanes;
    const unsigned edge_out = unsigned(_mm_movemask_ps(_mm_or_ps(_mm_xor_ps(e0, e1), _mm_xor_ps(e0, e2))));
    scalar = zero_edge;
    unsigned live = ~edge_out & lanes & ~zero_edge;
    if (!live) return 0;  // the usual case: the ray misses all four
    // Degenerate (collinear) triangles: n = cross(p1 - p0, p2 - p0) == 0, as glm::cross computes it.
    __m128 u[3], w[3];
    for (int a = 0; a < 3; ++a) {
        const __m128 p0 = _mm_load_ps(b.v[0][a]);
        u[a] = _mm_sub_ps(_mm_load_ps(b.v[1][a]), p0);
        w[a] = _mm_sub_ps(_mm_load_ps(b.v[2][a]), p0);
    }
    const __m128 nx = _mm_sub_ps(_mm_mul_ps(u[1], w[2]), _mm_mul_ps(w[1], u[2]));
    const __m128 ny = _mm_sub_ps(_mm_mul_ps(u[2], w[0]), _mm_mul_ps(w[2], u[0]));
    const __m128 nz = _mm_sub_ps(_mm_mul_ps(u[0], w[1]), _mm_mul_ps(w[0], u[1]));
    const __m128 degenerate = _mm_and_ps(_mm_and_ps(_mm_cmpeq_ps(nx, zero), _mm_cmpeq_ps(ny, zero)), _mm_cmpeq_ps(nz, zero));
    // det = e0 + e1 + e2 and t_scaled = e0 z0 + e1 z1 + e2 z2, left to right as in the scalar test;
    // then its comparisons with tmin det and tmax det, whose sense follows det's sign.
    const __m128 det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
    const __m128 ts = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e0, z[0]), _mm_mul_ps(e1, z[1])), _mm_mul_ps(e2, z[2]));
    const __m128 lo = _mm_mul_ps(_mm_set1_ps(tmin), det), hi = _mm_mul_ps(_mm_set1_ps(tmax), det);
    const __m128 out_neg = _mm_and_ps(_mm_cmplt_ps(det, zero), _mm_or_ps(_mm_cmpge_ps(ts, lo), _mm_cmple_ps(ts, hi)));
    const __m128 out_pos = _mm_and_ps(_mm_cmpgt_ps(det, zero), _mm_or_ps(_mm_cmple_ps(ts, lo), _mm_cmpge_ps(ts, hi)));
    __m128 rejected = _mm_or_ps(_mm_or_ps(degenerate, _mm_cmpeq_ps(det, zero)), _mm_or_ps(out_neg, out_pos));
    live &= ~unsigned(_mm_movemask_ps(rejected));
    if (!live) return 0;
    const __m128 inv_det = _mm_div_ps(_mm_set1_ps(1.f), det);
    const __m128 t = _mm_mul_ps(ts, inv_det);
    // !(t > tmin && t < tmax): rounding, and NaN from degenerate input.
    rejected = _mm_or_ps(_mm_cmpngt_ps(t, _mm_set1_ps(tmin)), _mm_cmpnlt_ps(t, _mm_set1_ps(tmax)));
    // t must exceed its rounding error bound (pbrt-v4); max(a, max(b, c)) as std::max nests it.
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    auto vabs = [&](__m128 v) { return _mm_and_ps(v, abs_mask); };
    auto vmax3 = [&](__m128 a, __m128 b2, __m128 c) { return _mm_max_ps(_mm_max_ps(c, b2), a); };
    const __m128 max_zt = vmax3(vabs(z[0]), vabs(z[1]), vabs(z[2]));
    const __m128 max_xt = vmax3(vabs(x[0]), vabs(x[1]), vabs(x[2]));
    const __m128 max_yt = vmax3(vabs(y[0]), vabs(y[1]), vabs(y[2]));
    const __m128 delta_z = _mm_mul_ps(_mm_set1_ps(gamma_bound(3)), max_zt);
    const __m128 delta_x = _mm_mul_ps(_mm_set1_ps(gamma_bound(5)), _mm_add_ps(max_xt, max_zt));
    const __m128 delta_y = _mm_mul_ps(_mm_set1_ps(gamma_bound(5)), _mm_add_ps(max_yt, max_zt));
    const __m128 delta_e = _mm_mul_ps(
        _mm_set1_ps(2.f), _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(gamma_bound(2)), max_xt), max_yt),
                                                _mm_mul_ps(delta_y, max_xt)),
                                     _mm_mul_ps(delta_x, max_yt)));
    const __m128 max_e = vmax3(vabs(e0), vabs(e1), vabs(e2));
    const __m128 delta_t = _mm_mul_ps(
        _mm_mul_ps(_mm_set1_ps(3.f),
                   _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(gamma_bound(3)), max_e), max_zt),
                                         _mm_mul_ps(delta_e, max_zt)),
                              _mm_mul_ps(delta_z, max_e))),
        vabs(inv_det));
    rejected = _mm_or_ps(rejected, _mm_cmple_ps(t, delta_t));
    live &= ~unsigned(_mm_movemask_ps(rejected));
    _mm_store_ps(out.t, t);
    _mm_store_ps(out.b1, _mm_mul_ps(e1, inv_det));
    _mm_store_ps(out.b2, _mm_mul_ps(e2, inv_det));
    return live;
}

}  // namespace

template <bool Shadow>
bool KdTree::trace(Ray& ray, Hit* hit) const {
    if (nodes_.empty()) return false;
    KD_COUNT(rays, 1);
    const RayShear sh(ray.d);
    const RayData r(ray, sh);
    float t0, t1;
    if (!bounds_.intersect(ray, vec3(r.inv_d[0], r.inv_d[1], r.inv_d[2]), t0, t1)) return false;
    t0 = std::max(t0, 0.f);  // no hit has t <= 0 (intersect_triangle's error bound)
    if (!(t0 <= t1)) return false;

    // The stack of nodes still to visit with their intervals, as three arrays: single stores.
    const Node* st_node[kMaxDepth + 4];
    float st_t0[kMaxDepth + 4], st_t1[kMaxDepth + 4];
    int sp = 0;
    const Node* nodes = nodes_.data();
    const Node* node = nodes;
    float tmax = ray.tmax;
    bool found = false;
    if (t0 == 0.f) {
        // The segment starts at the origin (inside the root box): every node on the way down
        // holds the origin, so the next node is always the child on the origin's side (the exact
        // test of the general step below), and the other child is pushed when the ray reaches the
        // plane inside the segment. The general step visits the same nodes with the same
        // intervals, but its branches on tp mispredict here, so this walk (half of a bounce or
        // shadow ray's node visits) uses masks instead (docs/accel.md has the measurements).
        const __m128 zero = _mm_setzero_ps(), up = _mm_set_ss(kWidenUp), down = _mm_set_ss(kWidenDown);
        const __m128 inf = _mm_set_ss(kInfinity);
        while (!node->leaf()) {
            KD_COUNT(nodes, 1);
            const int a = node->axis();
            const float split = node->split;
            const float oa = r.o[a];
            const int above = int(r.o_above[a] > split);
            const Node* below = nodes + node->children();
            // Pushed unless the plane is behind (tp <= 0) or beyond the segment; a NaN tp (the
            // ray lies in the plane) pushes over the whole segment (max_ss returns its second
            // operand for a NaN). The segment's end is a running minimum over the planes ahead
            // (min(t1, tp) when tp > 0, which leaves t1 alone where nothing was pushed), so its
            // update does not wait for the push decision.
            const __m128 tp = _mm_set_ss((split - oa) * r.inv_d[a]), vt1 = _mm_set_ss(t1);
            const __m128 ahead = _mm_cmpgt_ss(tp, zero);
            const __m128 push = _mm_and_ps(_mm_cmpnle_ss(tp, zero), _mm_cmpngt_ss(tp, _mm_mul_ss(vt1, up)));
            st_node[sp] = below + (1 - above);
            st_t0[sp] = _mm_cvtss_f32(_mm_max_ss(_mm_mul_ss(tp, down), zero));
            st_t1[sp] = t1;
            sp += _mm_movemask_ps(push) & int(node->empty_child(1 - above) ^ 1u);
            t1 = _mm_cvtss_f32(_mm_min_ss(vt1, _mm_blendv_ps(inf, _mm_mul_ss(tp, up), ahead)));
            node = below + above;
        }
    }
    for (;;) {
        KD_COUNT(nodes, 1);
        if (!node->leaf()) {
            const int a = node->axis();
            const float split = node->split;
            const float oa = r.o[a];
            const float tp = (split - oa) * r.inv_d[a];
            // The sign of split - o is exact, so the child holding the origin is found without
            // rounding; a ray starting on the plane goes first to the side it moves into.
            const bool below_first = oa < split || (oa == split && r.d_nonpos[a]);
            const Node* below = nodes + node->children();
            const Node* above = below + 1;
            const Node* first = below_first ? below : above;
            const Node* second = below_first ? above : below;
            // tp <= 0: the plane is behind (or the origin is on it, moving away); tp is NaN only
            // for a ray lying in the plane, which then visits both children over the whole interval
            // (std::max / std::min return their first argument for a NaN second). Branches, not
            // selects: they predict well here, and a branch-free step makes every step wait for
            // its comparisons (docs/accel.md has the measurements).
            // An empty child is never entered nor stacked: the walk goes on with the other one
            // (its interval trimmed as if the empty one had been visited), or with the stack.
            const uint32_t first_empty = node->empty_child(!below_first), second_empty = node->empty_child(below_first);
            if (tp > t1 * kWidenUp || tp <= 0.f) {
                node = first;
                if (!first_empty) continue;
            } else if (tp < t0 * kWidenDown) {
                node = second;
                if (!second_empty) continue;
            } else if (first_empty) {
                node = second;
                t0 = std::max(t0, tp * kWidenDown);
                if (!second_empty) continue;
            } else {
                if (!second_empty) {
                    st_node[sp] = second;
                    st_t0[sp] = std::max(t0, tp * kWidenDown);
                    st_t1[sp++] = t1;
                }
                node = first;
                t1 = std::min(t1, tp * kWidenUp);
                continue;
            }
        } else {
            const uint32_t count = node->count();
            KD_COUNT(leaves, 1);
            KD_COUNT(tris, count);
            auto record = [&](float t, float b1, float b2, uint32_t prim) {
                tmax = t;
                ray.tmax = t;
                hit->t = t;
                hit->b1 = b1;
                hit->b2 = b2;
                hit->prim = prim;
                found = true;
            };
            const TriBlock* b = blocks_.data() + node->first;
            for (uint32_t i = 0; i < count; i += 4, ++b) {
                const uint32_t n4 = std::min(count - i, 4u);
                unsigned scalar;
                Hits4 h4;
                const unsigned hits = triangle_hits4(r, *b, ray.tmin, ray.tmax, (1u << n4) - 1u, scalar, h4);
                if (Shadow && hits) return true;
                // In lane order, as the scalar test would meet them: a later lane replaces an
                // earlier hit only when strictly closer. Lanes with an edge function exactly 0 go
                // to the shared scalar test (its double fallback), so every hit is bit-identical
                // to brute force.
                for (unsigned m = hits | scalar; m; m &= m - 1) {
                    const int k = __builtin_ctz(m);
                    if (scalar >> k & 1u) {
                        TriangleHit th;
                        const vec3 p0(b->v[0][0][k], b->v[0][1][k], b->v[0][2][k]);
                        const vec3 p1(b->v[1][0][k], b->v[1][1][k], b->v[1][2][k]);
                        const vec3 p2(b->v[2][0][k], b->v[2][1][k], b->v[2][2][k]);
                        if (!intersect_triangle(ray, sh, p0, p1, p2, th)) continue;
                        if constexpr (Shadow) return true;
                        record(th.t, th.b1, th.b2, b->prim[k]);
                    } else if constexpr (!Shadow) {
                        if (h4.t[k] < ray.tmax) record(h4.t[k], h4.b1[k], h4.b2[k], b->prim[k]);
                    }
                }
            }
        }
        // Next node in ray order, skipping those that start beyond the closest hit (with slack, so
        // that a hit within rounding of a boundary still meets the triangles beyond it). Entries
        // are skipped, not the walk ended: a ray lying in a split plane pushes a node whose
        // interval starts before those pushed after it.
        for (;;) {
            if (sp == 0) return found;
            --sp;
            if (Shadow || !(tmax < st_t0[sp] * kWidenDown)) {
                node = st_node[sp];
                t0 = st_t0[sp];
                t1 = st_t1[sp];
                break;
            }
        }
    }
}

bool KdTree::intersect(Ray& ray, Hit& hit) const { return trace<false>(ray, &hit); }

bool KdTree::occluded(const Ray& ray) const {
    Ray r = ray;
    return trace<true>(r, nullptr);
}

template bool KdTree::trace<false>(Ray&, Hit*) const;
template bool KdTree::trace<true>(Ray&, Hit*) const;

}  // namespace candela
