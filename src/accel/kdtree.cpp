#include "accel/kdtree.h"
#include <omp.h>
#include <algorithm>
#include <cmath>
#include <memory>
#include <unordered_map>
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

}  // namespace

// ---- KdTree ---------------------------------------------------------------------------------

void KdTree::interrupted_build() {
    nodes_.clear();
    blocks_.clear();
    root_leaf_ = false;
    bounds_ = AABB();
    stats_ = {};
}

void KdTree::build(const Mesh& mesh, const std::vector<uint32_t>* tris, const AABB* clip, const KdBuildOptions& opt) {
    nodes_.clear();
    blocks_.clear();
    root_leaf_ = false;
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
        // Never hit: left out, so that the traversal's SIMD test need not check for it.
        if (zero_area_triangle(v[0], v[1], v[2])) continue;
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

    // Layout: the binary tree collapsed into nodes of up to eight children (KdTree::WideNode),
    // depth first, each leaf's triangles as blocks of eight right after the node that reaches it.
    // First the box of every subtree: the cells split top down, each leaf's cell clipped to the
    // part of its triangles inside it; a subtree's box is the union of its leaves'. Then each node
    // takes its non-empty children and opens the interior child with the largest box while the
    // children still fit in eight lanes (a k-d tree collapsed as Embree collapses a binary BVH).
    struct Collapse {
        KdTree& t;
        const Mesh& mesh;
        const std::vector<uint32_t>& list;
        std::unordered_map<const BuildNode*, AABB> box;
        // Per leaf that may be split into lanes (see boxes()), the parts of its triangles in its
        // cell (in prims' order), for the split without clipping again.
        std::unordered_map<const BuildNode*, std::vector<AABB>> leaf_parts;
        // A lane of a wide node being made: an interior child, or a group of a leaf's triangles.
        struct Lane {
            const BuildNode* node;  // the interior child, or null for a group
            std::vector<uint32_t> prims;
            std::vector<AABB> parts;  // of a group that may be split: its triangles' parts in the cell
            AABB box;
        };
        float node_blocks = 1.25f;  // a node step's cost in block tests, from the SAH's constants

        // The part of triangle p inside `cell`. Where the clipping finds nothing (a triangle only
        // touching the cell), the cell clipped to the triangle's bounds: still around the touching part.
        AABB part_in(uint32_t p, const AABB& cell) const {
            vec3 v[3];
            mesh.vertices(list[p], v[0], v[1], v[2]);
            AABB c = clipped_bounds(v, cell);
            if (c.empty()) {
                for (const vec3& q : v) c.expand(q);
                c.min = glm::max(c.min, cell.min);
                c.max = glm::min(c.max, cell.max);
            }
            return c;
        }

        AABB boxes(const BuildNode* n, const AABB& cell, int depth) {
            t.stats_.max_depth = std::max(t.stats_.max_depth, depth);
            ++t.stats_.nodes;
            AABB b;
            if (n->axis < 0) {
                ++t.stats_.leaves;
                t.stats_.references += n->prims.size();
                if (n->prims.empty()) ++t.stats_.empty_leaves;
                // The parts of the triangles of a leaf that may be split into lanes: one of more
                // than a block, or a tree that is one leaf (split_root_leaf), for the split.
                const bool large = n->prims.size() > (depth == 0 ? size_t(1) : size_t(KdTree::kBlockLanes));
                std::vector<AABB> parts;
                for (uint32_t p : n->prims) {
                    const AABB c = part_in(p, cell);
                    b.expand(c);
                    if (large) parts.push_back(c);
                }
                if (large) leaf_parts[n] = std::move(parts);
            } else {
                AABB lo = cell, hi = cell;
                lo.max[n->axis] = n->split;
                hi.min[n->axis] = n->split;
                b = boxes(n->child[0].get(), lo, depth + 1);
                b.expand(boxes(n->child[1].get(), hi, depth + 1));
            }
            box[n] = b;
            return b;
        }
        bool holds(const BuildNode* n) const { return n->axis < 0 ? !n->prims.empty() : !box.at(n).empty(); }
        // Appends a leaf's triangles as blocks of kBlockLanes (the last triangle repeated to fill
        // the last block).
        uint32_t add_blocks(const std::vector<uint32_t>& prims) {
            constexpr size_t kLanes = KdTree::kBlockLanes;
            const uint32_t first = uint32_t(t.blocks_.size());
            for (size_t i = 0; i < prims.size(); i += kLanes) {
                TriBlock b;
                for (size_t k = 0; k < kLanes; ++k) {
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
        uint32_t make(const BuildNode* n) {
            constexpr size_t kLanes = KdTree::kBlockLanes;
            if (t.nodes_.size() >= KdTree::kMaxNodes || t.blocks_.size() >= KdTree::kMaxNodes)
                throw Error("k-d tree: more than 2^31 nodes or triangle blocks");
            const uint32_t idx = uint32_t(t.nodes_.size());
            t.nodes_.emplace_back();
            std::vector<const BuildNode*> kids;
            if (n->axis < 0) {
                if (holds(n)) kids.push_back(n);
            } else {
                for (const auto& c : n->child)
                    if (holds(c.get())) kids.push_back(c.get());
            }
            for (;;) {
                int best = -1;
                float best_area = -1.f;
                for (size_t i = 0; i < kids.size(); ++i) {
                    const BuildNode* c = kids[i];
                    if (c->axis < 0) continue;
                    const size_t grow = size_t(holds(c->child[0].get())) + size_t(holds(c->child[1].get()));
                    if (kids.size() - 1 + grow > kLanes) continue;
                    const float area = box.at(c).surface_area();
                    if (area > best_area) {
                        best_area = area;
                        best = int(i);
                    }
                }
                if (best < 0) break;
                const BuildNode* c = kids[size_t(best)];
                kids.erase(kids.begin() + best);
                for (const auto& g : c->child)
                    if (holds(g.get())) kids.push_back(g.get());
            }
            // The lanes: the interior children, and the leaves' triangles in groups. A leaf of more
            // than eight triangles is split into groups, each in a lane of its own with the box of
            // its part of the cell, while lanes are free (the largest group first): a ray then tests
            // only the blocks whose box it crosses, at no extra node step. A tree that is one leaf
            // is split otherwise (split_root_leaf).
            std::vector<Lane> lanes;
            for (const BuildNode* k : kids) {
                if (k->axis >= 0) {
                    lanes.push_back({k, {}, {}, box.at(k)});
                } else {
                    auto it = leaf_parts.find(k);
                    lanes.push_back({nullptr, k->prims, it == leaf_parts.end() ? std::vector<AABB>() : std::move(it->second),
                                     box.at(k)});
                }
            }
            if (n->axis >= 0) {
                while (lanes.size() < kLanes) {
                    int widest = -1;
                    for (size_t i = 0; i < lanes.size(); ++i)
                        if (!lanes[i].node && lanes[i].prims.size() > kLanes &&
                            (widest < 0 || lanes[i].prims.size() > lanes[size_t(widest)].prims.size()))
                            widest = int(i);
                    if (widest < 0) break;
                    Lane& split = lanes[size_t(widest)];
                    Lane second = split_group(split, split_plan(split, SplitBy::KeptBlocks));
                    lanes.push_back(std::move(second));
                }
            } else if (lanes.size() == 1) {
                split_root_leaf(lanes);
            }
            WideNode w;
            for (int a = 0; a < 3; ++a)
                for (size_t k = 0; k < kLanes; ++k) {
                    w.lo[a][k] = kInfinity;
                    w.hi[a][k] = -kInfinity;
                }
            for (size_t k = 0; k < kLanes; ++k) w.child[k] = w.count[k] = 0;
            for (size_t k = 0; k < lanes.size(); ++k) {
                const AABB& b = lanes[k].box;
                for (int a = 0; a < 3; ++a) {
                    w.lo[a][k] = b.min[a];
                    w.hi[a][k] = b.max[a];
                }
                if (!lanes[k].node) {
                    ++t.stats_.leaf_lanes;
                    w.child[k] = add_blocks(lanes[k].prims);
                    w.count[k] = uint32_t(lanes[k].prims.size());
                } else {
                    w.child[k] = make(lanes[k].node);
                    w.count[k] = kWideInterior;
                }
            }
            t.nodes_[idx] = w;  // by index: make() above may have moved the vector
            return idx;
        }

        static size_t blocks(size_t m) { return (m + KdTree::kBlockLanes - 1) / KdTree::kBlockLanes; }

        // KeptBlocks: area times blocks, each side, among the splits with no more blocks in total
        // than the group (memory unchanged). Triangles: area times triangles, each side, as a BVH
        // build weighs them (blocks would hide the gain of splits that a further split completes:
        // two walls of a room fill a block, as each one alone does).
        enum class SplitBy { KeptBlocks, Triangles };

        // The best split of a group of leaf triangles in two: the least surface area heuristic cost
        // (`by`) among the orders of the triangles' part centroids along each axis (centroid_order).
        // The first `at` triangles of that axis' order go to one side; no split: infinite cost,
        // axis -1.
        struct SplitPlan {
            float cost = kInfinity;
            int axis = -1;
            size_t at = 0;
        };
        static std::vector<size_t> centroid_order(const Lane& g, int a) {
            std::vector<size_t> order(g.prims.size());
            for (size_t i = 0; i < order.size(); ++i) order[i] = i;
            const std::vector<AABB>& part = g.parts;
            std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) {
                return part[x].min[a] + part[x].max[a] < part[y].min[a] + part[y].max[a];
            });
            return order;
        }
        SplitPlan split_plan(const Lane& g, SplitBy by) const {
            const size_t n = g.prims.size();
            const std::vector<AABB>& part = g.parts;
            std::vector<float> right_area(n + 1);
            SplitPlan best;
            for (int a = 0; a < 3; ++a) {
                const std::vector<size_t> order = centroid_order(g, a);
                AABB r;
                for (size_t i = n; i-- > 0;) {
                    r.expand(part[order[i]]);
                    right_area[i] = r.surface_area();
                }
                AABB l;
                for (size_t i = 1; i < n; ++i) {
                    l.expand(part[order[i - 1]]);
                    float cost;
                    if (by == SplitBy::Triangles) {
                        cost = l.surface_area() * float(i) + right_area[i] * float(n - i);
                    } else {
                        if (blocks(i) + blocks(n - i) != blocks(n)) continue;
                        cost = l.surface_area() * float(blocks(i)) + right_area[i] * float(blocks(n - i));
                    }
                    if (cost < best.cost) best = SplitPlan{cost, a, i};
                }
            }
            return best;
        }

        // Splits a group in two as `plan` (split_plan() of it) says, in place, returning the second
        // half.
        static Lane split_group(Lane& g, const SplitPlan& plan) {
            std::vector<size_t> order;
            size_t at = plan.at;
            if (plan.axis >= 0) {
                order = centroid_order(g, plan.axis);
            } else {  // NaN areas: halves in order
                order.resize(g.prims.size());
                for (size_t i = 0; i < order.size(); ++i) order[i] = i;
                at = KdTree::kBlockLanes * (blocks(order.size()) / 2);
            }
            Lane first{nullptr, {}, {}, AABB()}, second{nullptr, {}, {}, AABB()};
            for (size_t i = 0; i < order.size(); ++i) {
                const size_t j = order[i];
                Lane& side = i < at ? first : second;
                side.prims.push_back(g.prims[j]);
                side.parts.push_back(g.parts[j]);
                side.box.expand(g.parts[j]);
            }
            g = std::move(first);
            return second;
        }

        // A tree that is one leaf (a small scene: the Cornell box is 32 triangles) has no node step:
        // a ray tests the root box, then every block. Its triangles may instead go into up to eight
        // groups under boxes of their own, grouped as a BVH would group them (split by triangle
        // count, the group that gains most first): a ray then pays one node step and tests the
        // groups whose box it crosses. In a room, a wall's group has a flat box that a ray crosses
        // only where it hits the wall. Kept when the SAH in block tests says it pays: the groups'
        // area x blocks plus a node step over the root box, against the leaf's area x blocks. The
        // groups are partly filled blocks: more memory, for a small scene.
        void split_root_leaf(std::vector<Lane>& lanes) const {
            const std::vector<Lane> leaf = lanes;
            // One plan per lane (a group of fewer than two triangles has no parts, and no split).
            auto plan = [&](const Lane& l) { return l.prims.size() < 2 ? SplitPlan{} : split_plan(l, SplitBy::Triangles); };
            std::vector<SplitPlan> plans{plan(lanes[0])};
            while (lanes.size() < KdTree::kBlockLanes) {
                int best = -1;
                float best_gain = 0.f;
                for (size_t i = 0; i < lanes.size(); ++i) {
                    const Lane& l = lanes[i];
                    const float gain = l.box.surface_area() * float(l.prims.size()) - plans[i].cost;
                    if (gain > best_gain) {
                        best_gain = gain;
                        best = int(i);
                    }
                }
                if (best < 0) break;
                Lane& split = lanes[size_t(best)];
                Lane second = split_group(split, plans[size_t(best)]);
                plans[size_t(best)] = plan(split);
                plans.push_back(plan(second));
                lanes.push_back(std::move(second));
            }
            const float root_area = leaf[0].box.surface_area();
            float split = root_area * node_blocks;
            for (const Lane& l : lanes) split += l.box.surface_area() * float(blocks(l.prims.size()));
            if (!(split < root_area * float(blocks(leaf[0].prims.size())))) lanes = leaf;
        }
    };
    Collapse c{*this, mesh, list, {}, {}};
    c.node_blocks = opt.traversal_cost / (opt.intersection_cost * float(kBlockLanes));
    c.boxes(root.get(), bounds_, 0);
    c.make(root.get());
    // One lane in the root, a leaf: its box test is the root box's (a leaf split into lanes is not).
    root_leaf_ = root->axis < 0 && nodes_[0].count[1] == 0;
    nodes_.shrink_to_fit();
    blocks_.shrink_to_fit();
    stats_.wide_nodes = nodes_.size();
}

size_t KdTree::memory_bytes() const {
    return nodes_.capacity() * sizeof(WideNode) + blocks_.capacity() * sizeof(TriBlock);
}

KdTraceCounters& kd_trace_counters() {
    static thread_local KdTraceCounters c;
    return c;
}

// Traversal (KdTree::intersect, KdTree::occluded): kdtree_trace.cpp.

}  // namespace candela
