#include "integrator/aov/aov.h"

namespace candela {

namespace {

// Mitsuba's BSDF::eval_diffuse_reflectance: the diffuse BSDF returns its reflectance; the others
// (no override among the plugins candela has) return eval(wi, normal) * pi, i.e. f * cos * pi
// towards the shading normal, which is 0 for delta lobes.
vec3 diffuse_reflectance(const Bsdf& bsdf, vec3 wo_local) {
    if (const DiffuseBsdf* d = std::get_if<DiffuseBsdf>(&bsdf)) return d->albedo;
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
                // Mitsuba's prim_index: the triangle within its mesh; an analytic shape is one primitive.
                // (A group's shape counts its first_triangle in the group's mesh, as hit.prim does.)
                const Shape& shape = scene.shapes[si.shape];
                *o++ = hit.kind == PrimKind::Triangle ? float(hit.prim - shape.first_triangle) : 0.f;
                break;
            }
            case AovType::ShapeIndex: *o++ = float(si.shape); break;
            case AovType::Moment: o += aov_channel_count(AovType::Moment); break;  // write_moment's
            case AovType::Albedo: {
                const Material& mat = scene.materials[scene.shapes[si.shape].material];
                vec3 n = si.ns;
                if (mat.two_sided && glm::dot(d, n) > 0.f) n = -n;  // seen from the side the ray comes from
                Bsdf textured;
                const Bsdf& bsdf = mat.textured() ? bsdf_at(mat, scene.texture_query(si, hit), textured) : mat.bsdf;
                vec3 rho = diffuse_reflectance(bsdf, Frame(n).to_local(-d));
                for (int k = 0; k < 3; ++k) *o++ = rho[k];
                break;
            }
        }
    }
}

}  // namespace candela
