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

void DiffuseStep(size_t n, const DiffuseStepBatch& b) {
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    using VF = hn::Vec<decltype(d)>;
    using VI = hn::Vec<decltype(di)>;
    using MF = hn::Mask<decltype(d)>;
    const size_t lanes = hn::Lanes(d);
    const VF zero = hn::Zero(d), one = hn::Set(d, 1.f), two = hn::Set(d, 2.f);
    const VF inv_pi = hn::Set(d, kInvPi), quarter_pi = hn::Set(d, kPi / 4.f);
    const VF inf = hn::Set(d, kInfinity), neg_zero = hn::Set(d, -0.f);
    const VI ione = hn::Set(di, 1);
    auto sel = [](MF m, VF a, VF c) { return hn::IfThenElse(m, a, c); };
    // next_float_up / next_float_down (core/math.h) per lane.
    auto up = [&](VF v) {
        const VF w = sel(hn::Eq(v, zero), zero, v);  // -0 -> +0 (and +0 stays)
        const VI bits = hn::BitCast(di, w);
        const VF r = hn::BitCast(d, sel(hn::Ge(w, zero), hn::BitCast(d, hn::Add(bits, ione)),
                                        hn::BitCast(d, hn::Sub(bits, ione))));
        return sel(hn::Eq(v, inf), v, r);
    };
    auto down = [&](VF v) {
        const VF w = sel(hn::Eq(v, zero), neg_zero, v);  // +0 -> -0
        const VI bits = hn::BitCast(di, w);
        const VF r = hn::BitCast(d, sel(hn::Gt(w, zero), hn::BitCast(d, hn::Sub(bits, ione)),
                                        hn::BitCast(d, hn::Add(bits, ione))));
        return sel(hn::Eq(v, hn::Neg(inf)), v, r);
    };
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
        // The next ray: to_world, then offset_ray_origin.
        VF w[3];
        for (int k = 0; k < 3; ++k)
            w[k] = hn::Add(hn::Add(hn::Mul(ld(b.s[k]), dx), hn::Mul(ld(b.t[k]), dy)), hn::Mul(ld(b.n[k]), z));
        VF ng[3];
        for (int k = 0; k < 3; ++k) ng[k] = ld(b.ng[k]);
        const VF dist = hn::Add(hn::Add(hn::Mul(hn::Abs(ng[0]), ld(b.p_error[0])), hn::Mul(hn::Abs(ng[1]), ld(b.p_error[1]))),
                                hn::Mul(hn::Abs(ng[2]), ld(b.p_error[2])));
        const MF below = hn::Lt(hn::Add(hn::Add(hn::Mul(w[0], ng[0]), hn::Mul(w[1], ng[1])), hn::Mul(w[2], ng[2])), zero);
        for (int k = 0; k < 3; ++k) {
            VF off = hn::Mul(dist, ng[k]);
            off = sel(below, hn::Neg(off), off);
            const VF po = hn::Add(ld(b.p[k]), off);
            const VF o = sel(hn::Gt(off, zero), up(po), sel(hn::Lt(off, zero), down(po), po));
            hn::StoreU(o, d, b.o[k] + i);
            hn::StoreU(w[k], d, b.d[k] + i);
        }
        // Russian roulette: q = min(max_component(beta) eta_scale, 0.95) as std::min and std::max.
        const VF m12 = sel(hn::Lt(beta[1], beta[2]), beta[2], beta[1]);
        const VF mx = sel(hn::Lt(beta[0], m12), m12, beta[0]);
        const VF qa = hn::Mul(mx, ld(b.eta_scale));
        const VF c95 = hn::Set(d, 0.95f);
        const VF q = sel(hn::Lt(c95, qa), c95, qa);
        const MF rr = hn::RebindMask(d, hn::Ne(hn::LoadU(di, b.rr + i), hn::Zero(di)));
        ok = hn::And(ok, hn::Not(hn::And(rr, hn::Ge(ld(b.u_rr), q))));
        for (int k = 0; k < 3; ++k) hn::StoreU(sel(rr, hn::Div(beta[k], q), beta[k]), d, b.beta[k] + i);
        hn::StoreU(pdf, d, b.pdf + i);
        hn::StoreU(hn::IfThenElseZero(hn::RebindMask(di, ok), hn::Set(di, 1)), di, b.alive + i);
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace candela
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace candela {

HWY_EXPORT(DiffuseStep);

void diffuse_step(size_t n, const DiffuseStepBatch& b) { HWY_DYNAMIC_DISPATCH(DiffuseStep)(n, b); }

}  // namespace candela
#endif  // HWY_ONCE
