#include "light/area.h"
#include "sampling/warp.h"

namespace candela {

namespace {

// The radiance a textured emitter stands for in light selection: its mean over a 64 x 64 grid of
// uv, floored at a small fraction of the largest value seen so that no part of a texture that
// emits somewhere gets a zero pmf (any positive weight keeps the estimate unbiased; the mean only
// makes it efficient).
vec3 textured_weight_radiance(const Texture& t) {
    constexpr int kN = 64;
    dvec3 sum(0.0);
    float peak = 0.f;
    TextureQuery q;
    for (int j = 0; j < kN; ++j)
        for (int i = 0; i < kN; ++i) {
            q.uv = vec2((float(i) + 0.5f) / kN, (float(j) + 0.5f) / kN);
            vec3 v = t.eval(q);
            sum += dvec3(v);
            peak = std::max(peak, luminance(v));
        }
    vec3 mean = vec3(sum / double(kN * kN));
    const float floor = std::max(1e-3f * peak, 1e-6f);
    return luminance(mean) >= floor ? mean : vec3(floor);
}

}  // namespace

vec3 LightSet::triangle_radiance(uint32_t tri, int32_t e, float b1, float b2) const {
    const Texture* tex = emitter_texture_[size_t(e)];
    if (!tex) return emitter_radiance_[size_t(e)];
    TextureQuery q;
    const Shape& shape = (*shapes_)[mesh_->tri_shape[tri]];
    if (shape.has_uv()) {
        const uvec3& t = mesh_->triangles[tri];
        const vec2* uv = mesh_->uvs.data() + shape.uv_offset - shape.first_vertex;
        q.uv = (1.f - b1 - b2) * uv[t.x] + b1 * uv[t.y] + b2 * uv[t.z];
    } else {
        q.uv = vec2(b1, b2);
    }
    return tex->eval(q);
}

void LightSet::build(const Mesh& mesh, const std::vector<Shape>& shapes, const std::vector<AreaEmitter>& emitters,
                     const std::vector<AnalyticShape>* analytic, const std::vector<Light>* lights,
                     const AABB& bounds) {
    mesh_ = &mesh;
    shapes_ = &shapes;
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
    emitter_texture_.clear();
    for (const AreaEmitter& e : emitters) {
        emitter_radiance_.push_back(e.texture ? textured_weight_radiance(*e.texture) : e.radiance);
        emitter_texture_.push_back(e.texture.get());
    }
    for (const Shape& s : shapes) {
        if (s.emitter < 0) continue;
        vec3 L = emitter_radiance_[size_t(s.emitter)];
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

    lights_.clear();
    infinite_.clear();
    if (lights) lights_ = *lights;
    for (size_t i = 0; i < lights_.size(); ++i)
        if ((light_flags(lights_[i].model) & (kLightInfinite | kLightDeltaDirection)) == kLightInfinite)
            infinite_.push_back(uint32_t(i));
    // Mitsuba's bounding sphere of the scene's box, its radius enlarged by a relative epsilon.
    if (bounds.empty()) {
        sphere_ = SceneSphere{vec3(0.f), 1e-4f};
    } else {
        sphere_.center = bounds.center();
        sphere_.radius = std::max(1e-4f, 0.5f * glm::length(bounds.extent()) * (1.f + 1e-4f));
    }
    choices_ = uint32_t(lights_.size()) + (has_area() ? 1u : 0u);
    choice_pmf_ = choices_ > 0 ? 1.f / float(choices_) : 0.f;
    area_pmf_ = has_area() ? choice_pmf_ : 0.f;

    etris_.clear();
    etris_.reserve(tris_.size());
    for (size_t i = 0; i < tris_.size(); ++i) {
        EmissiveTriangle et;
        mesh.vertices(tris_[i], et.p0, et.p1, et.p2);
        // Its area is > 0 (zero-weight triangles are not in tris_): never face_normal's +z fallback.
        et.ng = face_normal(et.p0, et.p1, et.p2);
        et.pmf_area = dist_.pmf(i) / area_[i];
        et.pdf_area = area_pmf_ * dist_.pmf(i) / area_[i];
        etris_.push_back(et);
    }
}

// Exact point and its error bound from barycentrics (pbrt-v4 uses gamma(6) for this sum).
static inline void interpolate_point(vec3 p0, vec3 p1, vec3 p2, float b0, float b1, float b2, vec3& p, vec3& err) {
    p = b0 * p0 + b1 * p1 + b2 * p2;
    err = gamma_bound(6) * (abs3(b0 * p0) + abs3(b1 * p1) + abs3(b2 * p2));
}

bool LightSet::sample_li(vec3 ref_p, float u1, vec2 u2, LightSample& out) const {
    if (__builtin_expect(lights_.empty(), 1)) return has_area() && sample_area_li(ref_p, u1, u2, out);
    // Uniform choice among (the area lights, light 0, light 1, ...); u1 is reused inside it.
    const float x = u1 * float(choices_);
    uint32_t k = std::min(uint32_t(x), choices_ - 1);
    const float u1r = std::min(x - float(k), 0x1.fffffep-1f);
    if (has_area()) {
        if (k == 0) {
            if (!sample_area_li(ref_p, u1r, u2, out)) return false;
            out.pdf *= choice_pmf_;
            out.light = -1;
            return true;
        }
        --k;
    }
    if (!candela::sample_li(lights_[k].model, sphere_, ref_p, u2, out)) return false;
    out.pdf *= choice_pmf_;
    out.light = int32_t(k);
    return !is_black(out.Le) && out.pdf > 0.f;
}

bool LightSet::sample_area_li(vec3 ref_p, float u1, vec2 u2, LightSample& out) const {
    out.delta = false;
    out.infinite = false;
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
        out.n = out.ns = as.n;
        out.Le = emitter_radiance_[size_t(analytic_emitter_[alights_[i - tris_.size()]])];
        out.pdf = pmf * as.pdf;
        return std::isfinite(out.pdf) && out.pdf > 0.f;
    }
    const uint32_t tri = tris_[i];
    const EmissiveTriangle& et = etris_[i];
    vec2 b = square_to_uniform_triangle(u2);
    interpolate_point(et.p0, et.p1, et.p2, b.x, b.y, 1.f - b.x - b.y, out.p, out.p_error);
    const vec3 ng = et.ng;
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
    out.ns = ns;
    // interpolate_point weighs p0, p1, p2 by (b.x, b.y, 1 - b.x - b.y).
    out.Le = emitter_texture_[size_t(tri_emitter_[tri])] ? triangle_radiance(tri, tri_emitter_[tri], b.y, 1.f - b.x - b.y)
                                                         : radiance_[i];
    out.pdf = et.pmf_area * dist2 / std::abs(cos_light);
    return std::isfinite(out.pdf) && out.pdf > 0.f;
}

float LightSet::pdf_li(vec3 ref_p, const SurfaceInteraction& on_light) const {
    if (on_light.kind != PrimKind::Triangle) {
        if (analytic_light_.empty()) return 0.f;
        int32_t li = analytic_light_[on_light.prim];
        if (li < 0) return 0.f;
        return area_pmf_ * dist_.pmf(size_t(li)) * pdf_analytic((*analytic_)[on_light.prim], ref_p, on_light.p, on_light.ng);
    }
    if (prim_light_.empty()) return 0.f;
    int32_t li = prim_light_[on_light.prim];
    if (li < 0) return 0.f;
    vec3 d = on_light.p - ref_p;
    float dist2 = glm::dot(d, d);
    float cos_light = std::abs(glm::dot(d, on_light.ng)) / std::sqrt(dist2);
    if (!(cos_light > 0.f)) return 0.f;
    return etris_[size_t(li)].pdf_area * dist2 / cos_light;
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
    if (const Texture* tex = emitter_texture_[size_t(e)]) {
        TextureQuery q;
        q.uv = on_light.uv;
        return tex->eval(q);
    }
    return emitter_radiance_[size_t(e)];
}

bool LightSet::sample_position(float u_sel, vec2 u_pos, PositionSample& out) const {
    if (choices_ == 0) return false;
    const float x = u_sel * float(choices_);
    uint32_t k = std::min(uint32_t(x), choices_ - 1);
    const float u1 = std::min(x - float(k), 0x1.fffffep-1f);
    if (!has_area() || k > 0) {
        if (has_area()) --k;
        if (light_flags(lights_[k].model) & (kLightDeltaPosition | kLightDeltaDirection)) return false;
        out.light = int32_t(k);
        out.pdf = choice_pmf_;
        return true;
    }
    float pmf;
    size_t i = dist_.sample(u1, &pmf);
    out.light = -1;
    SurfaceInteraction& si = out.si;
    float area;
    if (i >= tris_.size()) {
        const uint32_t ai = alights_[i - tris_.size()];
        const AnalyticShape& a = (*analytic_)[ai];
        // Seen from inside a sphere, and from anywhere for a disk or cylinder, sample_analytic draws
        // uniformly by area (only its point is used here): from the centre, from a point on the
        // disk's axis, from the middle of the cylinder's axis.
        vec3 ref = a.center;
        if (a.kind == PrimKind::Disk) ref = vec3(a.to_world[3]) + a.normal * std::sqrt(a.area);
        if (a.kind == PrimKind::Cylinder) ref = vec3(a.to_world * glm::vec4(0.f, 0.f, 0.5f * a.length, 1.f));
        AnalyticSample as;
        if (!sample_analytic(a, ref, u_pos, as)) return false;
        si.p = as.p;
        si.p_error = as.p_error;
        si.ng = si.ns = as.n;
        si.kind = a.kind;
        si.prim = ai;
        area = a.area;
        out.Le = emitter_radiance_[size_t(analytic_emitter_[ai])];
    } else {
        const uint32_t tri = tris_[i];
        const EmissiveTriangle& et = etris_[i];
        vec2 b = square_to_uniform_triangle(u_pos);
        interpolate_point(et.p0, et.p1, et.p2, b.x, b.y, 1.f - b.x - b.y, si.p, si.p_error);
        si.ng = si.ns = et.ng;
        if (!mesh_->normals.empty()) {
            const uvec3& t = mesh_->triangles[tri];
            vec3 n = b.x * mesh_->normals[t.x] + b.y * mesh_->normals[t.y] + (1.f - b.x - b.y) * mesh_->normals[t.z];
            if (glm::dot(n, n) > 0.f) si.ns = glm::normalize(n);
        }
        si.kind = PrimKind::Triangle;
        si.prim = tri;
        area = area_[i];
        out.Le = emitter_texture_[size_t(tri_emitter_[tri])] ? triangle_radiance(tri, tri_emitter_[tri], b.y, 1.f - b.x - b.y)
                                                             : radiance_[i];
    }
    out.pdf = area_pmf_ * pmf / area;
    return true;
}

std::optional<EmissionSample> LightSet::sample_le(float u_sel, vec2 u_pos, vec2 u_dir, SurfaceInteraction* on_light,
                                                 int32_t* light) const {
    if (choices_ == 0) return std::nullopt;
    const float x = u_sel * float(choices_);
    const uint32_t k = std::min(uint32_t(x), choices_ - 1);
    if (!has_area() || k > 0) {
        const uint32_t j = has_area() ? k - 1 : k;
        std::optional<EmissionSample> es = candela::sample_le(lights_[j].model, sphere_, u_pos, u_dir);
        if (es) es->pdf_pos *= choice_pmf_;
        if (light) *light = int32_t(j);
        return es;
    }
    PositionSample ps;
    if (!sample_position(u_sel, u_pos, ps)) return std::nullopt;
    EmissionSample es;
    es.flags = kLightArea;
    es.Le = ps.Le;
    // Cosine-distributed about the emitting side (the shading normal's, as emitted()).
    vec3 local = square_to_cosine_hemisphere(u_dir);
    Frame f(ps.si.ns);
    vec3 d = f.to_world(local);
    if (!(local.z > 0.f)) return std::nullopt;
    es.ray = spawn_ray(ps.si, d);
    es.n = ps.si.ng;  // the estimate's |cos| is the geometric one (emitter.h)
    es.pdf_pos = ps.pdf;
    es.pdf_dir = square_to_cosine_hemisphere_pdf(local);
    if (on_light) *on_light = ps.si;
    if (light) *light = -1;
    return es;
}

void LightSet::pdf_le(const SurfaceInteraction& on_light, vec3 w, float& pdf_pos, float& pdf_dir) const {
    pdf_pos = pdf_dir = 0.f;
    int32_t li = -1;
    float area = 0.f;
    if (on_light.kind != PrimKind::Triangle) {
        if (!analytic_light_.empty()) li = analytic_light_[on_light.prim];
        if (li >= 0) area = (*analytic_)[on_light.prim].area;
    } else if (!prim_light_.empty()) {
        li = prim_light_[on_light.prim];
        if (li >= 0) area = area_[size_t(li)];
    }
    if (li < 0) return;
    pdf_pos = area_pmf_ * dist_.pmf(size_t(li)) / area;
    pdf_dir = std::max(glm::dot(w, on_light.ns), 0.f) * kInvPi;
}

void LightSet::pdf_le(size_t i, vec3 d, float& pdf_pos, float& pdf_dir) const {
    candela::pdf_le(lights_[i].model, sphere_, d, pdf_pos, pdf_dir);
    pdf_pos *= choice_pmf_;
}

}  // namespace candela
