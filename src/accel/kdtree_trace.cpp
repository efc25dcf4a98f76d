// K-d tree traversal (KdTree::intersect and KdTree::occluded): the collapsed tree's nodes of eight
// child boxes (KdTree::WideNode), each tested in one vector step, and the SIMD triangle test.
//
// The SIMD is Google Highway, compiled once per instruction set that the target architecture
// offers (foreach_target: SSSE3, SSE4, AVX2 on x86; NEON and SVE on aarch64; a scalar fallback
// everywhere) and chosen at run time for the CPU, once per ray (HWY_DYNAMIC_DISPATCH: one indirect
// call, like the Accel's virtual one). Runtime dispatch: static dispatch at the x86-64 baseline
// would get Highway 1.0.3's scalar fallback. A node holds 8 boxes and a leaf block 8 triangles
// (KdTree::TriBlock): AVX2 tests them in one step of 8 lanes, the 128-bit targets (SSSE3, SSE4, NEON, and SVE, whose
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
#include <cmath>
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
constexpr int kStep = int(hn::MaxLanes(DL()));
constexpr int kLanes = KdTree::kBlockLanes;
static_assert(kStep == kStepWanted && kLanes % kStep == 0, "a block is a whole number of vectors");
constexpr unsigned kStepMask = (1u << kStep) - 1u;

// Widening of a ray parameter by 2^-16 of its size: room for the rounding of box-plane distances
// and of triangle hit distances (both a few ulps) so that the traversal never culls a child that
// brute force would find a hit in. The traversal keeps every entry distance >= 0 (hits have
// t > 0), so a single multiplication widens.
constexpr float kWidenUp = 1.f + 1.f / 65536.f;
constexpr float kWidenDown = 1.f - 1.f / 65536.f;

// Per-ray constants in plain arrays: glm's operator[] is a switch, slow in the node loop.
struct RayData {
    float o[3], inv_d[3];
    // The sign bit of d (and so of inv_d: 1 / -0 = -inf): a box's near plane on that axis is its
    // upper one. Not d < 0, which would pair d = -0 with the lower plane and an inv_d of -inf.
    bool d_neg[3];
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
            d_neg[i] = std::signbit(ray.d[i]);
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
// contraction: see the top of the file; max and abs written to give what std::max and abs3
// give), so each lane's result is the scalar test's, bit for bit. Lanes with an edge function
// exactly 0 are left to the scalar test itself (it redoes them in double): they come back in
// `scalar`. The hits come back in the return value, with t, b1 and b2 in `out` (indexed by block
// lane). `lanes` holds the step's lanes in use; bit k of a mask is lane c + k of the block.
struct BlockHits {
    alignas(32) float t[kLanes], b1[kLanes], b2[kLanes];
};
// The ray's open interval (tmin, tmax) and the widened bounds of the check before the division
// (scaled_check_tmin/tmax), kept per ray rather than recomputed per block: tmin is fixed and tmax
// changes only at a closer hit (set_tmax).
struct Interval {
    float tmin, tmax, check_lo, check_hi;
    explicit Interval(const Ray& ray)
        : tmin(ray.tmin), tmax(ray.tmax), check_lo(scaled_check_tmin(ray.tmin)), check_hi(scaled_check_tmax(ray.tmax)) {}
    void set_tmax(float t) {
        tmax = t;
        check_hi = scaled_check_tmax(t);
    }
};
// Lanes c to c + kStep - 1 of the block (bit 0 is lane c).
inline unsigned hits_step(const RayData& r, const KdTree::TriBlock& b, int c, const Interval& iv, unsigned lanes,
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
    // then its comparisons with tmin det and tmax det (widened as intersect_triangle widens them),
    // whose sense follows det's sign.
    const VL det = hn::Add(hn::Add(e0, e1), e2);
    const VL ts = hn::Add(hn::Add(hn::Mul(e0, z0), hn::Mul(e1, z1)), hn::Mul(e2, z2));
    const VL vtmin = hn::Set(d, iv.tmin), vtmax = hn::Set(d, iv.tmax);
    const VL lo = hn::Mul(hn::Set(d, iv.check_lo), det), hi = hn::Mul(hn::Set(d, iv.check_hi), det);
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
inline unsigned triangle_hits(const RayData& r, const KdTree::TriBlock& b, const Interval& iv, unsigned lanes,
                              unsigned& scalar, BlockHits& out) {
    if constexpr (kStep == kLanes) return hits_step(r, b, 0, iv, lanes, scalar, out);
    unsigned hits = 0;
    scalar = 0;
    for (int c = 0; c < kLanes; c += kStep) {
        const unsigned step_lanes = lanes >> c & kStepMask;
        if (!step_lanes) break;  // the block's unused lanes are its last ones
        unsigned step_scalar;
        hits |= hits_step(r, b, c, iv, step_lanes, step_scalar, out) << c;
        scalar |= step_scalar << c;
    }
    return hits;
}

// The triangles of a leaf (`count` of them from block `b`) against the ray: records a closer hit
// in ray.tmax, `iv`, *hit and `found`; with Shadow, returns true at the first hit.
template <bool Shadow>
inline bool test_leaf(const RayData& r, const RayShear& sh, const KdTree::TriBlock* b, uint32_t count, Ray& ray, Hit* hit,
                      Interval& iv, bool& found) {
    KD_COUNT(tris, count);
    auto record = [&](float t, float b1, float b2, uint32_t prim) {
        iv.set_tmax(t);
        ray.tmax = t;
        hit->t = t;
        hit->b1 = b1;
        hit->b2 = b2;
        hit->prim = prim;
        found = true;
    };
    for (uint32_t i = 0; i < count; i += kLanes, ++b) {
        const uint32_t n = std::min(count - i, uint32_t(kLanes));
        unsigned scalar;
        BlockHits bh;
        const unsigned hits = triangle_hits(r, *b, iv, (1u << n) - 1u, scalar, bh);
        if (Shadow && hits) return true;
        // In lane order, as the scalar test would meet them: a later lane replaces an earlier hit
        // only when strictly closer. Lanes with an edge function exactly 0 go to the shared scalar
        // test (its double fallback), so every hit is bit-identical to brute force.
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
                if (bh.t[k] < iv.tmax) record(bh.t[k], bh.b1[k], bh.b2[k], b->prim[k]);
            }
        }
    }
    return false;
}

// Slab test of a ray against kStep boxes: narrows [tnear, tfar] by one axis. A NaN distance
// ((plane - o) * inf = 0 * inf, a ray lying in a box's plane) fails both comparisons and so never
// narrows the interval: the ray is then inside the slab, as it should be.
inline void slab(const DL d, const float* near_plane, const float* far_plane, VL o, VL inv, VL& tnear, VL& tfar) {
    const VL tn = hn::Mul(hn::Sub(hn::Load(d, near_plane), o), inv);
    const VL tf = hn::Mul(hn::Sub(hn::Load(d, far_plane), o), inv);
#if HWY_TARGET == HWY_AVX2
    // maxps / minps return their second operand when either is NaN: the same result in one
    // instruction instead of a compare and a blend.
    tnear.raw = _mm256_max_ps(tn.raw, tnear.raw);
    tfar.raw = _mm256_min_ps(tf.raw, tfar.raw);
#elif HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_SSSE3
    tnear.raw = _mm_max_ps(tn.raw, tnear.raw);
    tfar.raw = _mm_min_ps(tf.raw, tfar.raw);
#else
    tnear = hn::IfThenElse(hn::Gt(tn, tnear), tn, tnear);
    tfar = hn::IfThenElse(hn::Lt(tf, tfar), tf, tfar);
#endif
}

// Closest hit (any hit with Shadow) in the collapsed tree. A node's eight child boxes are tested
// in one vector step (two of four); the children hit are stacked with their entry distances,
// farthest first, so that the nearest is taken next, and a stacked child that starts beyond the
// closest hit found is skipped. With Shadow the order is the lanes': any hit ends the walk. When
// the whole tree is one leaf (`leaf_root`: its box), the root box's scalar test stands for the
// vector step.
template <bool Shadow>
bool trace(const KdTree::WideNode* nodes, const KdTree::TriBlock* blocks, const AABB* leaf_root, Ray& ray, Hit* hit) {
    KD_COUNT(rays, 1);
    const RayShear sh(ray.d);
    const RayData r(ray, sh);
    Interval iv(ray);
    bool found = false;
    if (leaf_root) {
        float t0, t1;
        if (!leaf_root->intersect(ray, vec3(r.inv_d[0], r.inv_d[1], r.inv_d[2]), t0, t1)) return false;
        KD_COUNT(leaves, 1);
        return test_leaf<Shadow>(r, sh, blocks + nodes[0].child[0], nodes[0].count[0], ray, hit, iv, found) ||
               found;
    }
    struct Entry {
        uint32_t child, count;
        float t;
    };
    // A step pops one entry and pushes at most eight, and the collapsed tree is no deeper than the
    // binary one (kMaxDepth): at most 7 kMaxDepth + 8 entries.
    Entry st[8 * (KdTree::kMaxDepth + 2)];
    int sp = 0;
    const DL d;
    // Per axis, the offsets (in floats from a node's start) of the near and far planes' lanes.
    int near_off[3], far_off[3];
    for (int a = 0; a < 3; ++a) {
        const int lo = a * kLanes, hi = (3 + a) * kLanes;
        near_off[a] = r.d_neg[a] ? hi : lo;
        far_off[a] = r.d_neg[a] ? lo : hi;
    }
    const VL ox = hn::Set(d, r.o[0]), oy = hn::Set(d, r.o[1]), oz = hn::Set(d, r.o[2]);
    const VL ix = hn::Set(d, r.inv_d[0]), iy = hn::Set(d, r.inv_d[1]), iz = hn::Set(d, r.inv_d[2]);
    const VL down = hn::Set(d, kWidenDown), up = hn::Set(d, kWidenUp);
    const VL tmin = hn::Set(d, std::max(ray.tmin, 0.f));
    uint32_t cur = 0;
    for (;;) {
        KD_COUNT(nodes, 1);
        const float* base = &nodes[cur].lo[0][0];
        alignas(32) float tn[kLanes];
        unsigned bits = 0;
        const VL tmax_v = hn::Set(d, iv.tmax);
        for (int c = 0; c < kLanes; c += kStep) {
            VL tnear = tmin, tfar = tmax_v;
            slab(d, base + near_off[0] + c, base + far_off[0] + c, ox, ix, tnear, tfar);
            slab(d, base + near_off[1] + c, base + far_off[1] + c, oy, iy, tnear, tfar);
            slab(d, base + near_off[2] + c, base + far_off[2] + c, oz, iz, tnear, tfar);
            tnear = hn::Mul(tnear, down);
            hn::Store(tnear, d, tn + c);
            bits |= lane_bits(hn::Le(tnear, hn::Mul(tfar, up))) << c;
        }
        // The nearest child hit is taken next, the others stacked farthest first.
        const KdTree::WideNode& n = nodes[cur];
        Entry next{0, 0, 0.f};
        bool have = false;
        if (bits) {
            have = true;
            int k = __builtin_ctz(bits);
            bits &= bits - 1;
            next = Entry{n.child[k], n.count[k], tn[k]};
            if (bits) {
                k = __builtin_ctz(bits);
                bits &= bits - 1;
                Entry other{n.child[k], n.count[k], tn[k]};
                if (!bits) {
                    // Two: one comparison, written as selects.
                    const bool swap = !Shadow && other.t < next.t;
                    const Entry near_e = swap ? other : next, far_e = swap ? next : other;
                    st[sp++] = far_e;
                    next = near_e;
                } else {
                    // More: insertion sort by entry distance (at most eight), stacked in reverse.
                    Entry e[kLanes];
                    e[0] = next;
                    e[1] = other;
                    int ne = 2;
                    if (!Shadow && e[1].t < e[0].t) std::swap(e[0], e[1]);
                    for (; bits; bits &= bits - 1) {
                        k = __builtin_ctz(bits);
                        const Entry x{n.child[k], n.count[k], tn[k]};
                        int j = ne++;
                        if constexpr (!Shadow) {
                            for (; j > 0 && e[j - 1].t > x.t; --j) e[j] = e[j - 1];
                        }
                        e[j] = x;
                    }
                    for (int j = ne - 1; j >= 1; --j) st[sp++] = e[j];
                    next = e[0];
                }
            }
        }
        // The next interior node; leaves on the way are tested as they come.
        for (;;) {
            if (!have) {
                if (sp == 0) return found;
                next = st[--sp];
                if (!Shadow && next.t > iv.tmax * kWidenUp) continue;
            }
            have = false;
            if (next.count == KdTree::kWideInterior) {
                cur = next.child;
                break;
            }
            KD_COUNT(leaves, 1);
            if (test_leaf<Shadow>(r, sh, blocks + next.child, next.count, ray, hit, iv, found)) return true;
        }
    }
}

}  // namespace

// The entry points of each target, for the dispatch table below.
bool KdIntersect(const KdTree::WideNode* nodes, const KdTree::TriBlock* blocks, const AABB* leaf_root, Ray& ray,
                 Hit& hit) {
    return trace<false>(nodes, blocks, leaf_root, ray, &hit);
}
bool KdOccluded(const KdTree::WideNode* nodes, const KdTree::TriBlock* blocks, const AABB* leaf_root, const Ray& ray) {
    Ray r = ray;
    return trace<true>(nodes, blocks, leaf_root, r, nullptr);
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
    return HWY_DYNAMIC_DISPATCH(KdIntersect)(nodes_.data(), blocks_.data(), root_leaf_ ? &bounds_ : nullptr, ray, hit);
}

bool KdTree::occluded(const Ray& ray) const {
    if (nodes_.empty()) return false;
    return HWY_DYNAMIC_DISPATCH(KdOccluded)(nodes_.data(), blocks_.data(), root_leaf_ ? &bounds_ : nullptr, ray);
}

}  // namespace candela
#endif  // HWY_ONCE
