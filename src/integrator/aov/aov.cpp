#include "integrator/aov/aov.h"
#include "integrator/shading.h"

namespace candela {

namespace {

// Mitsuba's BSDF::eval_diffuse_reflectance: the diffuse BSDF returns its reflectance; the others
// return eval(wi, normal) * pi, i.e. f * cos * pi towards the shading normal, which is 0 for delta
// lobes; principled overrides it with its base colour, as Mitsuba's does.
vec3 diffuse_reflectance(const Bsdf& bsdf, vec3 wo_local) {
    if (const DiffuseBsdf* d = std::get_if<DiffuseBsdf>(&bsdf)) return d->albedo;
    if (const PrincipledBsdf* p = std::get_if<PrincipledBsdf>(&bsdf)) return p->base_color;
    return eval(bsdf, wo_local, vec3(0.f, 0.f, 1.f)) * kPi;
}

}  // namespace

void eval_aovs(const Scene& scene, const std::vector<AovSpec>& aovs, vec3 eye, const Ray& camera_ray, float* out,
               uint64_t* rays) {
    Ray ray = camera_ray;
    Hit hit;
    ++*rays;
    const bool found = scene.accel->intersect(ray, hit);
    float* o = out;
    if (!found) {
        for (const AovSpec& a : aovs)
            for (int k = 0; k < aov_channel_count(a.type); ++k) *o++ = 0.f;
        return;
    }
    const SurfaceInteraction si = scene.interaction(hit);
    const vec3 d = glm::normalize(ray.d);
    for (const AovSpec& a : aovs) {
        switch (a.type) {
            case AovType::Depth: *o++ = glm::dot(si.p - eye, d); break;
            case AovType::Position:
                for (int k = 0; k < 3; ++k) *o++ = si.p[k];
                break;
            case AovType::GeoNormal:
                for (int k = 0; k < 3; ++k) *o++ = si.ng[k];
                break;
            case AovType::ShNormal:
                for (int k = 0; k < 3; ++k) *o++ = si.ns[k];
                break;
            case AovType::Uv:
                *o++ = si.uv.x;
                *o++ = si.uv.y;
                break;
            case AovType::DpDu:
                for (int k = 0; k < 3; ++k) *o++ = si.dpdu[k];
                break;
            case AovType::DpDv:
                for (int k = 0; k < 3; ++k) *o++ = si.dpdv[k];
                break;
            case AovType::PrimIndex: {
                // Mitsuba's prim_index: the triangle within its mesh, the segment within its curve; the
                // other analytic shapes are one primitive. (A group's shape counts its first_triangle
                // in the group's mesh, as hit.prim does.)
                const Shape& shape = scene.shapes[si.shape];
                *o++ = hit.kind == PrimKind::Triangle ? float(hit.prim - shape.first_triangle)
                       : hit.kind == PrimKind::Curve  ? float(hit.prim - uint32_t(shape.analytic))
                                                      : 0.f;
                break;
            }
            case AovType::ShapeIndex: *o++ = float(si.shape); break;
            case AovType::Moment: o += aov_channel_count(AovType::Moment); break;  // write_moment's
            case AovType::Albedo: {
                // Mitsuba's blendbsdf returns the blend of its children's values, the other
                // wrappers their nested BSDF's: the mixture of the leaves, unperturbed.
                SurfaceInteraction s = si;
                ShadingT<false> sh;
                shade<false>(scene, hit, s, -d, sh);
                vec3 rho(0.f);
                if (!sh.is_wrapped) rho = diffuse_reflectance(*sh.bsdf, sh.wo);
                else
                    for (int k = 0; k < sh.wrapped.n; ++k) rho += sh.wrapped.w[size_t(k)] * diffuse_reflectance(*sh.wrapped.leaf[size_t(k)], sh.wo);
                for (int k = 0; k < 3; ++k) *o++ = rho[k];
                break;
            }
        }
    }
}

}  // namespace candela
