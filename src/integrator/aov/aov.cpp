#include "integrator/aov/aov.h"
#include <cstring>
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

vec3 shading_reflectance(const ShadingT<false>& sh) {
    // Mitsuba's blendbsdf returns the blend of its children's values, the other wrappers their
    // nested BSDF's: the mixture of the leaves, unperturbed.
    if (!sh.is_wrapped) return diffuse_reflectance(*sh.bsdf, sh.wo);
    vec3 rho(0.f);
    for (int k = 0; k < sh.wrapped.n; ++k) rho += sh.wrapped.w[size_t(k)] * diffuse_reflectance(*sh.wrapped.leaf[size_t(k)], sh.wo);
    return rho;
}

// A well-mixed 64-bit value from a ray's bits (splitmix64's finaliser over each word).
uint64_t hash_ray(const Ray& r) {
    uint32_t w[6];
    std::memcpy(w, &r.o, sizeof(float) * 3);
    std::memcpy(w + 3, &r.d, sizeof(float) * 3);
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (uint32_t v : w) {
        h ^= v;
        h += 0x9e3779b97f4a7c15ull;
        h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
        h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
        h ^= h >> 31;
    }
    return h;
}

// At most this many delta bounces before the denoiser's features give up and take the surface
// they are on (a hall of mirrors).
constexpr int kMaxDeltaBounces = 16;

// The denoiser's features: the camera ray followed through surfaces whose BSDF is all delta
// lobes (mirrors, smooth glass, thin panes) to the first surface with a non-delta component, its
// albedo (clamped to [0, 1], as OIDN requires) and shading normal. Which way glass sends the ray
// (reflected or refracted, with the Fresnel probabilities of its own sampling) is drawn from a
// hash of the ray, not from the sampler, so that the nested integrator's samples and image stay
// the same; averaged over a pixel's samples this is the Fresnel blend OIDN's documentation asks
// for. Zero albedo and normal where the ray leaves the scene.
void denoise_features(const Scene& scene, Ray ray, Hit hit, vec3& albedo, vec3& normal, uint64_t* rays) {
    albedo = normal = vec3(0.f);
    ShadingT<false> sh;
    for (int bounce = 0;; ++bounce) {
        SurfaceInteraction si = scene.interaction(hit);
        const vec3 d = glm::normalize(ray.d);
        shade<false>(scene, hit, si, -d, sh);
        if (sh.has_smooth_component() || bounce == kMaxDeltaBounces) {
            albedo = glm::clamp(shading_reflectance(sh), vec3(0.f), vec3(1.f));
            normal = sh.frame.n;
            return;
        }
        const uint64_t h = hash_ray(ray);
        const float u1 = float(h >> 40) * 0x1p-24f;
        const vec2 u2(float((h >> 16) & 0xffffffu) * 0x1p-24f, float(h & 0xffffu) * 0x1p-16f);
        const std::optional<BsdfSample> s = sh.sample(u1, u2);
        if (!s) {  // a delta surface seen from a side where it reflects nothing
            normal = sh.frame.n;
            return;
        }
        ray = spawn_ray(si, sh.frame.to_world(s->wi));
        ++*rays;
        if (!scene.accel->intersect(ray, hit)) return;
    }
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
    vec3 feature_albedo, feature_normal;
    bool features = false;  // computed once for both denoiser layers
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
                SurfaceInteraction s = si;
                ShadingT<false> sh;
                shade<false>(scene, hit, s, -d, sh);
                const vec3 rho = shading_reflectance(sh);
                for (int k = 0; k < 3; ++k) *o++ = rho[k];
                break;
            }
            case AovType::DenoiseAlbedo:
            case AovType::DenoiseNormal: {
                if (!features) denoise_features(scene, ray, hit, feature_albedo, feature_normal, rays);
                features = true;
                const vec3 v = a.type == AovType::DenoiseAlbedo ? feature_albedo : feature_normal;
                for (int k = 0; k < 3; ++k) *o++ = v[k];
                break;
            }
        }
    }
}

}  // namespace candela
