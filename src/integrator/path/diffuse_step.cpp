// See diffuse_step.h. Exactness: Mul then Add, never MulAdd (-ffp-contract=off holds); std::max
// and std::min written as the selects they are; next_float_up/down as integer steps on the bits.
#include "integrator/path/diffuse_step.h"
#include "core/math.h"

#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_AVX3 | HWY_AVX3_DL)
#endif
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "integrator/path/diffuse_step.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace candela {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// The operations path_rules (path/rules.h) applies, on a vector of lanes: the per-path bounce's
// rules, lane by lane.
template <class D>
struct LaneOps {
    using VF = hn::Vec<D>;
    using MF = hn::Mask<D>;
    D d;
    VF set(float x) const { return hn::Set(d, x); }
    static VF mul(VF a, VF b) { return hn::Mul(a, b); }
    static VF add(VF a, VF b) { return hn::Add(a, b); }
    static VF div(VF a, VF b) { return hn::Div(a, b); }
    static MF lt(VF a, VF b) { return hn::Lt(a, b); }
    static MF gt(VF a, VF b) { return hn::Gt(a, b); }
    static MF is_inf(VF a) { return hn::IsInf(a); }
    static VF select(MF m, VF a, VF b) { return hn::IfThenElse(m, a, b); }
};

// The per-path bounce's rules compiled for this target (see rules.inc).
namespace path_rules {
#include "integrator/path/rules.inc"
}  // namespace path_rules

// offset_ray_origin (geometry/interaction.h) per lane: p offset along n by the error bound, on the
// side of w, then rounded away from the surface (next_float_up/down as integer steps).
template <class D, class VF>
HWY_INLINE void OffsetRayOrigin(D d, const VF p[3], const VF err[3], const VF n[3], const VF w[3], VF out[3]) {
    const hn::RebindToSigned<D> di;
    using VI = hn::Vec<decltype(di)>;
    const VF zero = hn::Zero(d), inf = hn::Set(d, kInfinity), neg_zero = hn::Set(d, -0.f);
    const VI ione = hn::Set(di, 1);
    auto up = [&](VF v) {
        const VF x = hn::IfThenElse(hn::Eq(v, zero), zero, v);  // -0 -> +0 (and +0 stays)
        const VI bits = hn::BitCast(di, x);
        const VF r = hn::IfThenElse(hn::Ge(x, zero), hn::BitCast(d, hn::Add(bits, ione)), hn::BitCast(d, hn::Sub(bits, ione)));
        return hn::IfThenElse(hn::Eq(v, inf), v, r);
    };
    auto down = [&](VF v) {
        const VF x = hn::IfThenElse(hn::Eq(v, zero), neg_zero, v);  // +0 -> -0
        const VI bits = hn::BitCast(di, x);
        const VF r = hn::IfThenElse(hn::Gt(x, zero), hn::BitCast(d, hn::Sub(bits, ione)), hn::BitCast(d, hn::Add(bits, ione)));
        return hn::IfThenElse(hn::Eq(v, hn::Neg(inf)), v, r);
    };
    const VF dist = hn::Add(hn::Add(hn::Mul(hn::Abs(n[0]), err[0]), hn::Mul(hn::Abs(n[1]), err[1])), hn::Mul(hn::Abs(n[2]), err[2]));
    const auto below = hn::Lt(hn::Add(hn::Add(hn::Mul(w[0], n[0]), hn::Mul(w[1], n[1])), hn::Mul(w[2], n[2])), zero);
    for (int k = 0; k < 3; ++k) {
        VF off = hn::Mul(dist, n[k]);
        off = hn::IfThenElse(below, hn::Neg(off), off);
        const VF po = hn::Add(p[k], off);
        out[k] = hn::IfThenElse(hn::Gt(off, zero), up(po), hn::IfThenElse(hn::Lt(off, zero), down(po), po));
    }
}

void ShadeDiffuse(size_t n, const float* albedo, const int32_t* two_sided, const ShadeDiffuseBatch& b) {
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    using VF = hn::Vec<decltype(d)>;
    const size_t lanes = hn::Lanes(d);
    const VF one = hn::Set(d, 1.f), zero = hn::Zero(d);
    const hn::Vec<decltype(di)> three = hn::Set(di, 3);
    auto dot3 = [](const VF a[3], const VF c[3]) {
        return hn::Add(hn::Add(hn::Mul(a[0], c[0]), hn::Mul(a[1], c[1])), hn::Mul(a[2], c[2]));
    };
    for (size_t i = 0; i < n; i += lanes) {
        auto ld = [&](const float* a) { return hn::LoadU(d, a + i); };
        // wo = -normalize(d), as glm: d * (1 / sqrt(dot(d, d))).
        VF rd[3], ns[3], wo[3];
        for (int k = 0; k < 3; ++k) rd[k] = ld(b.ray_d[k]), ns[k] = ld(b.ns[k]);
        const VF inv = hn::Div(one, hn::Sqrt(dot3(rd, rd)));
        for (int k = 0; k < 3; ++k) wo[k] = hn::Neg(hn::Mul(rd[k], inv));
        const hn::Vec<decltype(di)> shape = hn::BitCast(di, hn::LoadU(hn::RebindToUnsigned<decltype(d)>(), b.shape + i));
        const auto ts = hn::RebindMask(d, hn::Ne(hn::GatherIndex(di, two_sided, shape), hn::Zero(di)));
        const auto flipped = hn::And(ts, hn::Lt(dot3(wo, ns), zero));
        VF nv[3];
        for (int k = 0; k < 3; ++k) {
            nv[k] = hn::IfThenElse(flipped, hn::Neg(ns[k]), ns[k]);
            hn::StoreU(nv[k], d, b.n[k] + i);
            const VF g = ld(b.ng[k]);
            hn::StoreU(hn::IfThenElse(flipped, hn::Neg(g), g), d, b.ng_out[k] + i);
        }
        hn::StoreU(dot3(wo, nv), d, b.wo_z + i);  // Frame(n).to_local(wo).z
        const auto s3 = hn::Mul(shape, three);
        for (int k = 0; k < 3; ++k) hn::StoreU(hn::GatherIndex(d, albedo + k, s3), d, b.albedo[k] + i);
    }
}

void DiffuseStep(size_t n, const DiffuseStepBatch& b) {
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    using VF = hn::Vec<decltype(d)>;
    using MF = hn::Mask<decltype(d)>;
    const size_t lanes = hn::Lanes(d);
    const VF zero = hn::Zero(d), one = hn::Set(d, 1.f), two = hn::Set(d, 2.f);
    const VF inv_pi = hn::Set(d, kInvPi), quarter_pi = hn::Set(d, kPi / 4.f);
    auto sel = [](MF m, VF a, VF c) { return hn::IfThenElse(m, a, c); };
    for (size_t i = 0; i < n; i += lanes) {
        auto ld = [&](const float* a) { return hn::LoadU(d, a + i); };
        // DiffuseBsdf::sample: none when wo is below the surface.
        MF ok = hn::Gt(ld(b.wo_z), zero);
        // square_to_uniform_disk_concentric, then the cosine hemisphere.
        const VF ox = hn::Sub(hn::Mul(two, ld(b.u[0])), one), oy = hn::Sub(hn::Mul(two, ld(b.u[1])), one);
        const MF centre = hn::And(hn::Eq(ox, zero), hn::Eq(oy, zero));
        const MF xm = hn::Gt(hn::Abs(ox), hn::Abs(oy));
        const VF r = sel(xm, ox, oy);
        const VF a = hn::Mul(quarter_pi, hn::Div(sel(xm, oy, ox), r));
        const VF a2 = hn::Mul(a, a);
        const VF sn = hn::Add(
            a, hn::Mul(hn::Mul(a, a2),
                       hn::Add(hn::Set(d, -1.6666654611e-1f),
                               hn::Mul(a2, hn::Add(hn::Set(d, 8.3321608736e-3f), hn::Mul(a2, hn::Set(d, -1.9515295891e-4f)))))));
        const VF cs = hn::Add(
            hn::Sub(one, hn::Mul(hn::Set(d, 0.5f), a2)),
            hn::Mul(hn::Mul(a2, a2),
                    hn::Add(hn::Set(d, 4.166664568298827e-2f),
                            hn::Mul(a2, hn::Add(hn::Set(d, -1.388731625493765e-3f),
                                                hn::Mul(a2, hn::Set(d, 2.443315711809948e-5f)))))));
        const VF dx = sel(centre, zero, hn::Mul(r, sel(xm, cs, sn)));
        const VF dy = sel(centre, zero, hn::Mul(r, sel(xm, sn, cs)));
        const VF z2 = hn::Sub(hn::Sub(one, hn::Mul(dx, dx)), hn::Mul(dy, dy));
        const VF z = hn::Sqrt(sel(hn::Lt(z2, zero), zero, z2));  // safe_sqrt: std::max(x, 0)
        ok = hn::And(ok, hn::Gt(z, zero));
        const VF pdf = hn::Mul(z, inv_pi);
        ok = hn::And(ok, hn::Gt(pdf, zero));
        // f = albedo (1/pi z); weight f / pdf; beta *= weight.
        const VF fz = hn::Mul(inv_pi, z);
        VF beta[3];
        for (int k = 0; k < 3; ++k)
            beta[k] = hn::Mul(hn::LoadU(d, b.beta[k] + i), hn::Div(hn::Mul(ld(b.albedo[k]), fz), pdf));
        ok = hn::And(ok, hn::Not(hn::And(hn::And(hn::Eq(beta[0], zero), hn::Eq(beta[1], zero)), hn::Eq(beta[2], zero))));
        // The next ray: Frame(n).to_world (Duff et al.'s basis, as frame.h builds it), then
        // offset_ray_origin.
        const VF nv[3] = {ld(b.n[0]), ld(b.n[1]), ld(b.n[2])};
        const VF sign = hn::CopySign(one, nv[2]);
        const VF fa = hn::Div(hn::Set(d, -1.f), hn::Add(sign, nv[2]));
        const VF fb = hn::Mul(hn::Mul(nv[0], nv[1]), fa);
        const VF s[3] = {hn::Add(one, hn::Mul(hn::Mul(hn::Mul(sign, nv[0]), nv[0]), fa)), hn::Mul(sign, fb),
                         hn::Mul(hn::Neg(sign), nv[0])};
        const VF t[3] = {fb, hn::Add(sign, hn::Mul(hn::Mul(nv[1], nv[1]), fa)), hn::Neg(nv[1])};
        VF w[3];
        for (int k = 0; k < 3; ++k) w[k] = hn::Add(hn::Add(hn::Mul(s[k], dx), hn::Mul(t[k], dy)), hn::Mul(nv[k], z));
        VF pv[3], ev[3], ng[3], o[3];
        for (int k = 0; k < 3; ++k) pv[k] = ld(b.p[k]), ev[k] = ld(b.p_error[k]), ng[k] = ld(b.ng[k]);
        OffsetRayOrigin(d, pv, ev, ng, w, o);
        for (int k = 0; k < 3; ++k) {
            hn::StoreU(o[k], d, b.o[k] + i);
            hn::StoreU(w[k], d, b.d[k] + i);
        }
        // Russian roulette, by the per-path bounce's rule.
        const VF q = path_rules::roulette_survival(LaneOps<decltype(d)>{d}, beta[0], beta[1], beta[2], ld(b.eta_scale));
        if (b.rr) {
            ok = hn::And(ok, hn::Not(hn::Ge(ld(b.u_rr), q)));
            for (int k = 0; k < 3; ++k) beta[k] = hn::Div(beta[k], q);
        }
        for (int k = 0; k < 3; ++k) hn::StoreU(beta[k], d, b.beta[k] + i);
        hn::StoreU(pdf, d, b.pdf + i);
        hn::StoreU(hn::IfThenElseZero(hn::RebindMask(di, ok), hn::Set(di, 1)), di, b.alive + i);
    }
}

void AreaLightStep(size_t n, const float* cdf, const float* tri, const float* radiance, size_t entries, bool mis,
                   const AreaLightStepBatch& b) {
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    using VF = hn::Vec<decltype(d)>;
    using VI = hn::Vec<decltype(di)>;
    using MF = hn::Mask<decltype(d)>;
    const size_t lanes = hn::Lanes(d);
    const VF zero = hn::Zero(d), one = hn::Set(d, 1.f), half_v = hn::Set(d, 2.f);
    const VF inv_pi = hn::Set(d, kInvPi), gamma6 = hn::Set(d, gamma_bound(6));
    auto sel = [](MF m, VF a, VF c) { return hn::IfThenElse(m, a, c); };
    auto dot3 = [](const VF a[3], const VF c[3]) {
        return hn::Add(hn::Add(hn::Mul(a[0], c[0]), hn::Mul(a[1], c[1])), hn::Mul(a[2], c[2]));
    };
    const VI last = hn::Set(di, int32_t(entries) - 1);
    for (size_t i = 0; i < n; i += lanes) {
        auto ld = [&](const float* a) { return hn::LoadU(d, a + i); };
        // DiscreteDistribution::sample: the last CDF entry u is not below (cdf[0] = 0 is never
        // compared); no zero-pmf entries (area_triangle_tables), so no stepping over them.
        const VF ul = ld(b.u_l);
        VI base = hn::Zero(di);
        for (size_t m = entries + 1; m > 1;) {
            const size_t h = m / 2;
            const VI cand = hn::Add(base, hn::Set(di, int32_t(h)));
            base = hn::IfThenElse(hn::RebindMask(di, hn::Lt(ul, hn::GatherIndex(d, cdf, cand))), base, cand);
            m -= h;
        }
        const VI e = hn::Min(base, last);
        const VI e14 = hn::Mul(e, hn::Set(di, 14)), e3 = hn::Mul(e, hn::Set(di, 3));
        // square_to_uniform_triangle, interpolate_point (b0 = b.x, b1 = b.y, b2 = 1 - b.x - b.y).
        const VF ux = ld(b.u[0]), uy = ld(b.u[1]);
        const VF hx = hn::Div(ux, half_v), hy = hn::Div(uy, half_v);
        const MF lower = hn::Lt(ux, uy);
        const VF bx = sel(lower, hx, hn::Sub(ux, hy)), by = sel(lower, hn::Sub(uy, hx), hy);
        const VF bz = hn::Sub(hn::Sub(one, bx), by);
        VF lp[3], lerr[3], lng[3], P[3], dv[3];
        for (int k = 0; k < 3; ++k) {
            const VF a = hn::Mul(bx, hn::GatherIndex(d, tri + k, e14));
            const VF c = hn::Mul(by, hn::GatherIndex(d, tri + 3 + k, e14));
            const VF f = hn::Mul(bz, hn::GatherIndex(d, tri + 6 + k, e14));
            lp[k] = hn::Add(hn::Add(a, c), f);
            lerr[k] = hn::Mul(gamma6, hn::Add(hn::Add(hn::Abs(a), hn::Abs(c)), hn::Abs(f)));
            lng[k] = hn::GatherIndex(d, tri + 9 + k, e14);
            P[k] = ld(b.p[k]);
            dv[k] = hn::Sub(lp[k], P[k]);
        }
        const VF dist2 = dot3(dv, dv);
        MF ok = hn::Gt(dist2, zero);
        const VF dist = hn::Sqrt(dist2);
        VF wi[3];
        for (int k = 0; k < 3; ++k) wi[k] = hn::Div(dv[k], dist);
        const VF wn = dot3(wi, lng);
        const VF cos_light = hn::Neg(wn);
        ok = hn::And(ok, hn::Not(hn::Or(hn::Ge(wn, zero), hn::Eq(cos_light, zero))));
        const VF pmf_area = hn::GatherIndex(d, tri + 12, e14);
        const VF lpdf = hn::Div(hn::Mul(pmf_area, dist2), hn::Abs(cos_light));
        ok = hn::And(ok, hn::And(hn::IsFinite(lpdf), hn::Gt(lpdf, zero)));
        // The BSDF there: DiffuseBsdf::eval_pdf.
        VF fn[3];
        for (int k = 0; k < 3; ++k) fn[k] = ld(b.n[k]);
        const VF wz = dot3(wi, fn);  // to_local(wi).z; its x and y do not enter the diffuse BSDF
        ok = hn::And(ok, hn::And(hn::Gt(ld(b.wo_z), zero), hn::Gt(wz, zero)));
        const VF fz = hn::Mul(inv_pi, wz);
        const VF bpdf = hn::Mul(wz, inv_pi);
        VF f[3];
        for (int k = 0; k < 3; ++k) f[k] = hn::Mul(ld(b.albedo[k]), fz);
        ok = hn::And(ok, hn::Not(hn::And(hn::And(hn::Eq(f[0], zero), hn::Eq(f[1], zero)), hn::Eq(f[2], zero))));
        // The per-path bounce's weight and scale with transmittance 1 (ShadowRequest::contribution
        // in path/bounce.h): the MIS weight in MIS mode, else 1; the contribution beta f Le (1 w / pdf).
        const LaneOps<decltype(d)> ops{d};
        const VF w = mis ? path_rules::light_mis_weight(ops, lpdf, bpdf, one) : one;
        const VF scale = path_rules::light_scale(ops, one, w, lpdf);
        for (int k = 0; k < 3; ++k) {
            const VF Le = hn::GatherIndex(d, radiance + k, e3);
            hn::StoreU(hn::Mul(hn::Mul(hn::Mul(ld(b.beta[k]), f[k]), Le), scale), d, b.L[k] + i);
        }
        // spawn_ray_to(si, light point, its error, its normal).
        VF err[3], ng[3], o[3], pt[3], back[3];
        for (int k = 0; k < 3; ++k) err[k] = ld(b.p_error[k]), ng[k] = ld(b.ng[k]);
        OffsetRayOrigin(d, P, err, ng, dv, o);
        for (int k = 0; k < 3; ++k) back[k] = hn::Sub(o[k], lp[k]);
        OffsetRayOrigin(d, lp, lerr, lng, back, pt);
        for (int k = 0; k < 3; ++k) {
            hn::StoreU(o[k], d, b.o[k] + i);
            hn::StoreU(hn::Sub(pt[k], o[k]), d, b.d[k] + i);
        }
        hn::StoreU(hn::IfThenElseZero(hn::RebindMask(di, ok), hn::Set(di, 1)), di, b.shadow + i);
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace candela
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace candela {

HWY_EXPORT(ShadeDiffuse);
HWY_EXPORT(DiffuseStep);
HWY_EXPORT(AreaLightStep);

void shade_diffuse(size_t n, const float* albedo, const int32_t* two_sided, const ShadeDiffuseBatch& b) {
    HWY_DYNAMIC_DISPATCH(ShadeDiffuse)(n, albedo, two_sided, b);
}
void diffuse_step(size_t n, const DiffuseStepBatch& b) { HWY_DYNAMIC_DISPATCH(DiffuseStep)(n, b); }
void area_light_step(size_t n, const float* cdf, const float* tri, const float* radiance, size_t entries, bool mis,
                     const AreaLightStepBatch& b) {
    HWY_DYNAMIC_DISPATCH(AreaLightStep)(n, cdf, tri, radiance, entries, mis, b);
}

}  // namespace candela
#endif  // HWY_ONCE
