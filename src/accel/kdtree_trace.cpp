// K-d tree traversal (KdTree::intersect and KdTree::occluded) with its SIMD triangle test.
//
// The SIMD is Google Highway, compiled once per instruction set that the target architecture
// offers (foreach_target: SSSE3, SSE4, AVX2 on x86; NEON and SVE on aarch64; a scalar fallback
// everywhere) and chosen at run time for the CPU, once per ray (HWY_DYNAMIC_DISPATCH: one indirect
// call, like the Accel's virtual one). Runtime dispatch: static dispatch at the x86-64 baseline
// would get Highway 1.0.3's scalar fallback. A leaf block holds 8 triangles (KdTree::TriBlock):
// AVX2 tests them in one step of 8 lanes, the 128-bit targets (SSSE3, SSE4, NEON, and SVE, whose
// vectors may be no wider) in two steps of 4, the scalar fallback in 8 steps of 1.
// docs/accel.md has the measurements.
//
// Exactness: each lane of triangle_hits() is intersect_triangle() (geometry/triangle.h) on that
// triangle, bit for bit. That holds only without fused multiply-add: the AVX2, AVX-512, NEON and
// SVE targets have FMA, and GCC fuses a Mul followed by an Add (intrinsics included) by default in
// C++. CMakeLists.txt therefore builds everything with -ffp-contract=off; the code below writes
// Mul then Add, never MulAdd.

#include "accel/kdtree.h"
#include <algorithm>
#include <cstdint>
#include "core/math.h"
#include "geometry/triangle.h"

// No AVX-512 code: with 8 lanes it only changes the encoding, and with the 4-lane blocks of
// 2026-12-05 it measured 0.83x on the Cornell box's camera rays (any hit) where AVX2 and SSE4
// matched the raw-SSE version (docs/accel.md). The dispatch then takes AVX2 on an AVX-512 CPU (the
// chosen target is masked per translation unit).
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_AVX3 | HWY_AVX3_DL)
#endif

// foreach_target re-includes this file once per target with HWY_TARGET set; everything between
// HWY_BEFORE_NAMESPACE and HWY_AFTER_NAMESPACE is compiled for each of them.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "accel/kdtree_trace.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#ifndef CANDELA_KDTREE_TRACE_ONCE
#define CANDELA_KDTREE_TRACE_ONCE
#ifdef CANDELA_KD_COUNTERS
#define KD_COUNT(field, n) (candela::kd_trace_counters().field += (n))
#else
#define KD_COUNT(field, n) ((void)0)
#endif
#endif

HWY_BEFORE_NAMESPACE();
namespace candela {
namespace HWY_NAMESPACE {
namespace {

namespace hn = hwy::HWY_NAMESPACE;
// One lane per triangle of a TriBlock, kStep triangles per step: 8 on the 256-bit x86 targets,
// 1 on HWY_SCALAR (the fallback target of GCC < 12.3, whose EMU128 Highway disables), and 4
// elsewhere (SVE included: its vectors may be 128 bits, and a capped tag's MaxLanes is the cap).
#if HWY_TARGET == HWY_SCALAR
constexpr int kStepWanted = 1;
#elif HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL
constexpr int kStepWanted = 8;
#else
constexpr int kStepWanted = 4;
#endif
using DL = hn::CappedTag<float, kStepWanted>;
using VL = hn::Vec<DL>;
using ML = hn::Mask<DL>;
using D1 = hn::CappedTag<float, 1>;  // one float, for branch-free selects in the walk from the origin
using V1 = hn::Vec<D1>;
constexpr int kStep = int(hn::MaxLanes(DL()));
constexpr int kLanes = KdTree::kBlockLanes;
static_assert(kStep == kStepWanted && kLanes % kStep == 0, "a block is a whole number of vectors");
constexpr unsigned kStepMask = (1u << kStep) - 1u;

// Widening of a ray parameter by 2^-16 of its size: room for the rounding of split-plane
// distances and of triangle hit distances (both a few ulps) so that the traversal never culls a
// node that brute force would find a hit in. The traversal keeps every parameter >= 0 (hits have
// t > 0), so a single multiplication widens.
constexpr float kWidenUp = 1.f + 1.f / 65536.f;
constexpr float kWidenDown = 1.f - 1.f / 65536.f;

// Per-ray constants in plain arrays: glm's operator[] is a switch, slow in the node loop.
struct RayData {
    float o[3], inv_d[3];
    bool d_nonpos[3];  // d <= 0: a ray starting on a split plane goes below first
    // The origin as compared with split planes: o_above[a] > split exactly when the origin lies
    // above the plane, or on it moving up (o rounded up to the next float when d > 0).
    float o_above[3];
    int kx, ky, kz;  // the shear of intersect_triangle (RayShear), for the SIMD filter
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

// Lane k of the mask as bit k (what movemask gives on x86); at most 8 lanes.
inline unsigned lane_bits(ML m) {
    uint8_t bits[8];  // StoreMaskBits may write up to 8 bytes
    hn::StoreMaskBits(DL(), m, bits);
    return bits[0];
}

// intersect_triangle() (geometry/triangle.h) on kStep triangles at once: the translation, the
// shear, the edge functions, the determinant, the scaled distance and its interval check, the
// division, and the error bound on t (the degenerate-triangle check is done once, at build; see
// below), with the same float operations in the same order (Mul then Add, never MulAdd, and no
// contraction: see the top of the file; max and abs written to give what std::max and glm::abs
// give), so each lane's result is the scalar test's, bit for bit. Lanes with an edge function
// exactly 0 are left to the scalar test itself (it redoes them in double): they come back in
// `scalar`. The hits come back in the return value, with t, b1 and b2 in `out` (indexed by block
// lane). `lanes` holds the step's lanes in use; bit k of a mask is lane c + k of the block.
struct BlockHits {
    alignas(32) float t[kLanes], b1[kLanes], b2[kLanes];
};
// Lanes c to c + kStep - 1 of the block (bit 0 is lane c).
inline unsigned hits_step(const RayData& r, const KdTree::TriBlock& b, int c, float tmin, float tmax, unsigned lanes,
                          unsigned& scalar, BlockHits& out) {
    const DL d;
    // Vectors one by one, not in arrays: SVE vectors are sizeless and cannot be array elements.
    auto load = [&](int v, int axis) { return hn::Load(d, b.v[v][axis] + c); };
    const VL sx = hn::Set(d, r.sx), sy = hn::Set(d, r.sy), sz = hn::Set(d, r.sz);
    const VL ox = hn::Set(d, r.o[r.kx]), oy = hn::Set(d, r.o[r.ky]), oz = hn::Set(d, r.o[r.kz]);
    // a = p - o, then a[kx] + sx * a[kz], a[ky] + sy * a[kz] and sz * a[kz], for p0, p1, p2.
    const VL az0 = hn::Sub(load(0, r.kz), oz), az1 = hn::Sub(load(1, r.kz), oz), az2 = hn::Sub(load(2, r.kz), oz);
    const VL x0 = hn::Add(hn::Sub(load(0, r.kx), ox), hn::Mul(sx, az0));
    const VL x1 = hn::Add(hn::Sub(load(1, r.kx), ox), hn::Mul(sx, az1));
    const VL x2 = hn::Add(hn::Sub(load(2, r.kx), ox), hn::Mul(sx, az2));
    const VL y0 = hn::Add(hn::Sub(load(0, r.ky), oy), hn::Mul(sy, az0));
    const VL y1 = hn::Add(hn::Sub(load(1, r.ky), oy), hn::Mul(sy, az1));
    const VL y2 = hn::Add(hn::Sub(load(2, r.ky), oy), hn::Mul(sy, az2));
    const VL z0 = hn::Mul(sz, az0), z1 = hn::Mul(sz, az1), z2 = hn::Mul(sz, az2);
    const VL e0 = hn::Sub(hn::Mul(x1, y2), hn::Mul(y1, x2));
    const VL e1 = hn::Sub(hn::Mul(x2, y0), hn::Mul(y2, x0));
    const VL e2 = hn::Sub(hn::Mul(x0, y1), hn::Mul(y0, x1));
    // Edge test. With no edge exactly 0, "some edge negative and some positive" is "the sign bits
    // differ", read as an integer sign (a float compare would miss -0 and NaN bit patterns). A NaN
    // edge may go either way: the scalar test rejects NaN lanes too (at t).
    const VL zero = hn::Zero(d);
    const ML any_zero = hn::Or(hn::Or(hn::Eq(e0, zero), hn::Eq(e1, zero)), hn::Eq(e2, zero));
    const unsigned zero_edge = lane_bits(any_zero) & lanes;
    const hn::RebindToSigned<DL> di;
    const auto sign_mix = hn::BitCast(di, hn::Or(hn::Xor(e0, e1), hn::Xor(e0, e2)));
    uint8_t out_bits[8];
    hn::StoreMaskBits(di, hn::Lt(sign_mix, hn::Zero(di)), out_bits);
    const unsigned edge_out = out_bits[0] & kStepMask;
    scalar = zero_edge;
    unsigned live = ~edge_out & lanes & ~zero_edge;
    if (!live) return 0;  // the usual case: the ray misses them all
    // Degenerate (collinear) triangles, which intersect_triangle() rejects after the edge test, are
    // not in the tree (KdTree::build leaves out zero_area_triangle()), so no lane needs that check.
    //
    // det = e0 + e1 + e2 and t_scaled = e0 z0 + e1 z1 + e2 z2, left to right as in the scalar test;
    // then its comparisons with tmin det and tmax det, whose sense follows det's sign.
    const VL det = hn::Add(hn::Add(e0, e1), e2);
    const VL ts = hn::Add(hn::Add(hn::Mul(e0, z0), hn::Mul(e1, z1)), hn::Mul(e2, z2));
    const VL vtmin = hn::Set(d, tmin), vtmax = hn::Set(d, tmax);
    const VL lo = hn::Mul(vtmin, det), hi = hn::Mul(vtmax, det);
    const ML out_neg = hn::And(hn::Lt(det, zero), hn::Or(hn::Ge(ts, lo), hn::Le(ts, hi)));
    const ML out_pos = hn::And(hn::Gt(det, zero), hn::Or(hn::Le(ts, lo), hn::Ge(ts, hi)));
    ML rejected = hn::Or(hn::Eq(det, zero), hn::Or(out_neg, out_pos));
    live &= ~lane_bits(rejected);
    if (!live) return 0;
    const VL inv_det = hn::Div(hn::Set(d, 1.f), det);
    const VL t = hn::Mul(ts, inv_det);
    // !(t > tmin && t < tmax): rounding, and NaN from degenerate input.
    rejected = hn::Or(hn::Not(hn::Gt(t, vtmin)), hn::Not(hn::Lt(t, vtmax)));
    // t must exceed its rounding error bound (pbrt-v4); max(a, max(b, c)) as std::max nests it.
    // Max's result for a NaN operand differs between targets, but a NaN here (a NaN coordinate or
    // edge) also makes t NaN, and the lane is rejected above whatever delta_t is.
    auto vmax3 = [](VL a, VL b2, VL c) { return hn::Max(hn::Max(c, b2), a); };
    const VL max_zt = vmax3(hn::Abs(z0), hn::Abs(z1), hn::Abs(z2));
    const VL max_xt = vmax3(hn::Abs(x0), hn::Abs(x1), hn::Abs(x2));
    const VL max_yt = vmax3(hn::Abs(y0), hn::Abs(y1), hn::Abs(y2));
    const VL delta_z = hn::Mul(hn::Set(d, gamma_bound(3)), max_zt);
    const VL delta_x = hn::Mul(hn::Set(d, gamma_bound(5)), hn::Add(max_xt, max_zt));
    const VL delta_y = hn::Mul(hn::Set(d, gamma_bound(5)), hn::Add(max_yt, max_zt));
    const VL delta_e =
        hn::Mul(hn::Set(d, 2.f), hn::Add(hn::Add(hn::Mul(hn::Mul(hn::Set(d, gamma_bound(2)), max_xt), max_yt),
                                                  hn::Mul(delta_y, max_xt)),
                                          hn::Mul(delta_x, max_yt)));
    const VL max_e = vmax3(hn::Abs(e0), hn::Abs(e1), hn::Abs(e2));
    const VL delta_t = hn::Mul(
        hn::Mul(hn::Set(d, 3.f), hn::Add(hn::Add(hn::Mul(hn::Mul(hn::Set(d, gamma_bound(3)), max_e), max_zt),
                                                 hn::Mul(delta_e, max_zt)),
                                         hn::Mul(delta_z, max_e))),
        hn::Abs(inv_det));
    rejected = hn::Or(rejected, hn::Le(t, delta_t));
    live &= ~lane_bits(rejected);
    hn::Store(t, d, out.t + c);
    hn::Store(hn::Mul(e1, inv_det), d, out.b1 + c);
    hn::Store(hn::Mul(e2, inv_det), d, out.b2 + c);
    return live;
}

// The whole block, a step at a time; `lanes` holds its lanes in use (bit k is lane k).
inline unsigned triangle_hits(const RayData& r, const KdTree::TriBlock& b, float tmin, float tmax, unsigned lanes,
                              unsigned& scalar, BlockHits& out) {
    if constexpr (kStep == kLanes) return hits_step(r, b, 0, tmin, tmax, lanes, scalar, out);
    unsigned hits = 0;
    scalar = 0;
    for (int c = 0; c < kLanes; c += kStep) {
        const unsigned step_lanes = lanes >> c & kStepMask;
        if (!step_lanes) break;  // the block's unused lanes are its last ones
        unsigned step_scalar;
        hits |= hits_step(r, b, c, tmin, tmax, step_lanes, step_scalar, out) << c;
        scalar |= step_scalar << c;
    }
    return hits;
}

template <bool Shadow>
bool trace(const KdTree::Node* nodes, const KdTree::TriBlock* blocks, const AABB& bounds, Ray& ray, Hit* hit) {
    constexpr int kMaxDepth = KdTree::kMaxDepth;
    using Node = KdTree::Node;
    using TriBlock = KdTree::TriBlock;
    KD_COUNT(rays, 1);
    const RayShear sh(ray.d);
    const RayData r(ray, sh);
    float t0, t1;
    if (!bounds.intersect(ray, vec3(r.inv_d[0], r.inv_d[1], r.inv_d[2]), t0, t1)) return false;
    t0 = std::max(t0, 0.f);  // no hit has t <= 0 (intersect_triangle's error bound)
    if (!(t0 <= t1)) return false;

    // The stack of nodes still to visit with their intervals, as three arrays: single stores.
    const Node* st_node[kMaxDepth + 4];
    float st_t0[kMaxDepth + 4], st_t1[kMaxDepth + 4];
    int sp = 0;
    const Node* node = nodes;
    float tmax = ray.tmax;
    bool found = false;
    if (t0 == 0.f) {
        // The segment starts at the origin (inside the root box): every node on the way down
        // holds the origin, so the next node is always the child on the origin's side (the exact
        // test of the general step below), and the other child is pushed when the ray reaches the
        // plane inside the segment. The general step visits the same nodes with the same
        // intervals, but its branches on tp mispredict here, so this walk (half of a bounce or
        // shadow ray's node visits) is written without branches on tp: flag arithmetic, a scalar
        // min (minss) and two one-lane vector selects (docs/accel.md has the measurements).
        const D1 d1;
        const V1 inf1 = hn::Set(d1, kInfinity), zero1 = hn::Zero(d1);
        const V1 up1 = hn::Set(d1, kWidenUp), down1 = hn::Set(d1, kWidenDown);
        while (!node->leaf()) {
            KD_COUNT(nodes, 1);
            const int a = node->axis();
            const float split = node->split;
            const float oa = r.o[a];
            const int above = int(r.o_above[a] > split);
            const Node* below = nodes + node->children();
            // Pushed unless the plane is behind (tp <= 0) or beyond the segment; a NaN tp (the
            // ray lies in the plane) fails both comparisons and so pushes, over the whole segment:
            // `x > 0 ? x : 0` (what maxss x, 0 computes) gives 0 for a NaN x. The segment's end
            // is a running minimum over the planes ahead (min(t1, tp) when tp > 0, which leaves
            // t1 alone where nothing was pushed, NaN included), so its update does not wait for
            // the push decision.
            // The two selects on tp are one-lane vector selects: GCC 12 compiles a scalar
            // `tp > 0 ? tp * up : inf` to a branch on tp however it is written (the product sinks
            // into its arm), and that branch mispredicts here (bounce rays 10% slower); without
            // SSE4.1 it branches on `x > 0 ? x : 0` too. IfThenElse, not Max: Max's result for a
            // NaN differs between targets (NEON returns the NaN).
            const float tp = (split - oa) * r.inv_d[a];
            const V1 vtp = hn::Set(d1, tp), tp_down = hn::Mul(vtp, down1);
            const float tp_ahead = hn::GetLane(hn::IfThenElse(hn::Gt(vtp, zero1), hn::Mul(vtp, up1), inf1));
            const int push = int(!(tp <= 0.f)) & int(!(tp > t1 * kWidenUp));
            st_node[sp] = below + (1 - above);
            st_t0[sp] = hn::GetLane(hn::IfThenElse(hn::Gt(tp_down, zero1), tp_down, zero1));
            st_t1[sp] = t1;
            sp += push & int(node->empty_child(1 - above) ^ 1u);
            t1 = t1 < tp_ahead ? t1 : tp_ahead;
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
            const TriBlock* b = blocks + node->first;
            for (uint32_t i = 0; i < count; i += kLanes, ++b) {
                const uint32_t n = std::min(count - i, uint32_t(kLanes));
                unsigned scalar;
                BlockHits bh;
                const unsigned hits = triangle_hits(r, *b, ray.tmin, ray.tmax, (1u << n) - 1u, scalar, bh);
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
                        if (bh.t[k] < ray.tmax) record(bh.t[k], bh.b1[k], bh.b2[k], b->prim[k]);
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

}  // namespace

// The entry points of each target, for the dispatch table below.
bool KdIntersect(const KdTree::Node* nodes, const KdTree::TriBlock* blocks, const AABB& bounds, Ray& ray, Hit& hit) {
    return trace<false>(nodes, blocks, bounds, ray, &hit);
}
bool KdOccluded(const KdTree::Node* nodes, const KdTree::TriBlock* blocks, const AABB& bounds, const Ray& ray) {
    Ray r = ray;
    return trace<true>(nodes, blocks, bounds, r, nullptr);
}

}  // namespace HWY_NAMESPACE
}  // namespace candela
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace candela {

HWY_EXPORT(KdIntersect);
HWY_EXPORT(KdOccluded);

bool KdTree::intersect(Ray& ray, Hit& hit) const {
    if (nodes_.empty()) return false;
    return HWY_DYNAMIC_DISPATCH(KdIntersect)(nodes_.data(), blocks_.data(), bounds_, ray, hit);
}

bool KdTree::occluded(const Ray& ray) const {
    if (nodes_.empty()) return false;
    return HWY_DYNAMIC_DISPATCH(KdOccluded)(nodes_.data(), blocks_.data(), bounds_, ray);
}

}  // namespace candela
#endif  // HWY_ONCE
