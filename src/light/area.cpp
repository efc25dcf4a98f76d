#include "light/area.h"
#include "sampling/warp.h"

namespace candela {

void LightSet::build(const Mesh& mesh, const std::vector<Shape>& shapes, const std::vector<AreaEmitter>& emitters,
                     const std::vector<AnalyticShape>* analytic) {
    mesh_ = &mesh;
    analytic_ = analytic;
    alights_.clear();
    analytic_light_.clear();
    analytic_emitter_.clear();
    tris_.clear();
    area_.clear();
    radiance_.clear();
    prim_light_.clear();
    tri_emitter_.clear();
    emitter_radiance_.clear();
    std::vector<float> weights;
    for (const AreaEmitter& e : emitters) emitter_radiance_.push_back(e.radiance);
    for (const Shape& s : shapes) {
        if (s.emitter < 0) continue;
        vec3 L = emitters[size_t(s.emitter)].radiance;
        if (prim_light_.empty()) {
            prim_light_.assign(mesh.triangles.size(), -1);
            tri_emitter_.assign(mesh.triangles.size(), -1);
        }
        for (uint32_t t = s.first_triangle; t < s.first_triangle + s.triangle_count; ++t) {
            tri_emitter_[t] = s.emitter;
            float a = mesh.triangle_area(t);
            float w = a * luminance(L);
            if (!(w > 0.f) || !std::isfinite(w)) continue;  // never sampled; still emits if hit
            prim_light_[t] = int32_t(tris_.size());
            tris_.push_back(t);
            area_.push_back(a);
            radiance_.push_back(L);
            weights.push_back(w);
        }
    }
    // Analytic emitters after all triangles, so that the triangles' entries keep their indices.
    for (const Shape& s : shapes) {
        if (s.emitter < 0 || s.analytic < 0 || !analytic) continue;
        if (analytic_emitter_.empty()) {
            analytic_light_.assign(analytic->size(), -1);
            analytic_emitter_.assign(analytic->size(), -1);
        }
        const AnalyticShape& a = (*analytic)[size_t(s.analytic)];
        analytic_emitter_[size_t(s.analytic)] = s.emitter;
        float w = a.area * luminance(emitters[size_t(s.emitter)].radiance);
        if (!(w > 0.f) || !std::isfinite(w)) continue;
        analytic_light_[size_t(s.analytic)] = int32_t(tris_.size() + alights_.size());
        alights_.push_back(uint32_t(s.analytic));
        weights.push_back(w);
    }
    dist_.build(weights);
}

// Exact point and its error bound from barycentrics (pbrt-v4 uses gamma(6) for this sum).
static inline void interpolate_point(vec3 p0, vec3 p1, vec3 p2, float b0, float b1, float b2, vec3& p, vec3& err) {
    p = b0 * p0 + b1 * p1 + b2 * p2;
    err = gamma_bound(6) * (glm::abs(b0 * p0) + glm::abs(b1 * p1) + glm::abs(b2 * p2));
}

bool LightSet::sample_li(vec3 ref_p, float u1, vec2 u2, LightSample& out) const {
    if (empty()) return false;
    float pmf;
    size_t i = dist_.sample(u1, &pmf);
    if (i >= tris_.size()) {
        const AnalyticShape& a = (*analytic_)[alights_[i - tris_.size()]];
        AnalyticSample as;
        if (!sample_analytic(a, ref_p, u2, as)) return false;
        vec3 d = as.p - ref_p;
        float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f)) return false;
        out.dist = std::sqrt(dist2);
        out.wi = d / out.dist;
        if (glm::dot(out.wi, as.n) >= 0.f) return false;  // we see its back (one-sided)
        out.p = as.p;
        out.p_error = as.p_error;
        out.n = as.n;
        out.Le = emitter_radiance_[size_t(analytic_emitter_[alights_[i - tris_.size()]])];
        out.pdf = pmf * as.pdf;
        return std::isfinite(out.pdf) && out.pdf > 0.f;
    }
    uint32_t tri = tris_[i];
    vec3 p0, p1, p2;
    mesh_->vertices(tri, p0, p1, p2);
    vec2 b = square_to_uniform_triangle(u2);
    interpolate_point(p0, p1, p2, b.x, b.y, 1.f - b.x - b.y, out.p, out.p_error);
    vec3 ng = glm::cross(p1 - p0, p2 - p0);
    float len = glm::length(ng);
    if (!(len > 0.f)) return false;
    ng /= len;
    vec3 ns = ng;
    if (!mesh_->normals.empty()) {
        // One-sidedness follows the shading normal, as for BSDFs.
        const uvec3& t = mesh_->triangles[tri];
        vec3 n = b.x * mesh_->normals[t.x] + b.y * mesh_->normals[t.y] + (1.f - b.x - b.y) * mesh_->normals[t.z];
        if (glm::dot(n, n) > 0.f) ns = glm::normalize(n);
    }
    vec3 d = out.p - ref_p;
    float dist2 = glm::dot(d, d);
    if (!(dist2 > 0.f)) return false;
    out.dist = std::sqrt(dist2);
    out.wi = d / out.dist;
    float cos_light = -glm::dot(out.wi, ng);
    if (glm::dot(out.wi, ns) >= 0.f || cos_light == 0.f) return false;  // we see its back
    out.n = ng;
    out.Le = radiance_[i];
    out.pdf = pmf / area_[i] * dist2 / std::abs(cos_light);
    return std::isfinite(out.pdf) && out.pdf > 0.f;
}

float LightSet::pdf_li(vec3 ref_p, const SurfaceInteraction& on_light) const {
    if (on_light.kind != PrimKind::Triangle) {
        if (analytic_light_.empty()) return 0.f;
        int32_t li = analytic_light_[on_light.prim];
        if (li < 0) return 0.f;
        return dist_.pmf(size_t(li)) * pdf_analytic((*analytic_)[on_light.prim], ref_p, on_light.p, on_light.ng);
    }
    if (prim_light_.empty()) return 0.f;
    int32_t li = prim_light_[on_light.prim];
    if (li < 0) return 0.f;
    vec3 d = on_light.p - ref_p;
    float dist2 = glm::dot(d, d);
    float cos_light = std::abs(glm::dot(d, on_light.ng)) / std::sqrt(dist2);
    if (!(cos_light > 0.f)) return 0.f;
    return dist_.pmf(size_t(li)) / area_[size_t(li)] * dist2 / cos_light;
}

vec3 LightSet::emitted(const SurfaceInteraction& on_light, vec3 w) const {
    if (on_light.kind != PrimKind::Triangle) {
        int32_t e = analytic_emitter_.empty() ? -1 : analytic_emitter_[on_light.prim];
        if (e < 0 || glm::dot(w, on_light.ns) <= 0.f) return vec3(0.f);
        return emitter_radiance_[size_t(e)];
    }
    if (tri_emitter_.empty()) return vec3(0.f);
    int32_t e = tri_emitter_[on_light.prim];
    if (e < 0 || glm::dot(w, on_light.ns) <= 0.f) return vec3(0.f);
    return emitter_radiance_[size_t(e)];
}

}  // namespace candela
