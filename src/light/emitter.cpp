#include "light/emitter.h"
#include "sampling/warp.h"

namespace candela {

namespace {

template <class... F>
struct overloaded : F... {
    using F::operator()...;
};
template <class... F>
overloaded(F...) -> overloaded<F...>;

float radians(float deg) { return deg * (kPi / 180.f); }

// A point on the disk of the scene's bounding sphere that faces direction w, through its centre
// (pbrt-v4's infinite-light emission: every ray that reaches the scene crosses that disk).
vec3 disk_point(const SceneSphere& s, vec3 w, vec2 u) {
    vec2 d = square_to_uniform_disk_concentric(u);
    Frame f(w);
    return s.center + s.radius * (f.s * d.x + f.t * d.y);
}

// Solid-angle density of a direction of the envmap from its density in uv (light/envmap.h):
// dw = 2 pi^2 sin(theta) du dv. sin(theta) is floored as Mitsuba's pdf_direction does, so that
// the poles give a large finite density, never inf or NaN.
float envmap_pdf_sa(float pdf_uv, float sin_theta) {
    return pdf_uv / (2.f * kPi * kPi * std::max(sin_theta, 1e-7f));
}

float envmap_pdf_li(const EnvmapLight& l, vec3 w) {
    const vec3 d = l.to_local(w);
    const float sin_theta = std::sqrt(d.x * d.x + d.z * d.z);
    return envmap_pdf_sa(l.map->pdf(EnvironmentMap::direction_to_uv(d)), sin_theta);
}

}  // namespace

void EnvmapLight::update() {
    const float a = radians(rotation), c = std::cos(a), s = std::sin(a);
    // A turn by `rotation` about local +y (right-handed: +z towards +x).
    const glm::mat3 ry(vec3(c, 0.f, -s), vec3(0.f, 1.f, 0.f), vec3(s, 0.f, c));
    frame = to_world * ry;
    frame_inv = glm::inverse(frame);
}

vec3 SpotLight::profile(vec3 d) const {
    const float cutoff = radians(cutoff_angle), beam = radians(beam_width);
    const float cos_theta = d.z;
    if (!(cos_theta > std::cos(cutoff))) return vec3(0.f);
    // Linear in angle from 1 at beam_width to 0 at cutoff_angle (Mitsuba's falloff_curve).
    float falloff = cos_theta >= std::cos(beam) ? 1.f : (cutoff - std::acos(std::min(cos_theta, 1.f))) / (cutoff - beam);
    falloff = glm::clamp(falloff, 0.f, 1.f);
    vec3 v(falloff);
    if (texture) {
        const float uv_factor = std::tan(cutoff);
        TextureQuery q;
        q.uv = vec2(0.5f + 0.5f * d.x / (d.z * uv_factor), 0.5f + 0.5f * d.y / (d.z * uv_factor));
        v *= texture->eval(q);
    }
    return v;
}

bool ProjectorLight::uv_of(vec3 d, vec2& uv) const {
    if (!(d.z > 0.f)) return false;
    uv = vec2(0.5f - 0.5f * d.x / (d.z * tan_x), 0.5f - 0.5f * d.y / (d.z * tan_y));
    return uv.x >= 0.f && uv.x <= 1.f && uv.y >= 0.f && uv.y <= 1.f;  // closed, as Mitsuba's test
}

vec3 ProjectorLight::direction_of(vec2 uv) const {
    return glm::normalize(vec3((1.f - 2.f * uv.x) * tan_x, (1.f - 2.f * uv.y) * tan_y, 1.f));
}

// The texture's mean over a grid of cells (its texels when it is a plain bitmap, else 64 x 64),
// each cell given the largest value of its 3 x 3 neighbourhood (bilinear filtering spreads a texel
// into its neighbours' cells), mixed 9:1 with a uniform density so that no uv that can give light
// has density 0, whatever the texture (a checkerboard's edges, wrapped borders).
void ProjectorLight::build_density() {
    int nu = 64, nv = 64;
    if (const BitmapTexture* b = std::get_if<BitmapTexture>(&irradiance->v);
        b && b->to_uv.m == glm::mat3(1.f) && b->texels->width <= 2048 && b->texels->height <= 2048) {
        nu = b->texels->width;
        nv = b->texels->height;
    } else if (irradiance->is_constant()) {
        nu = nv = 1;
    }
    std::vector<float> f(size_t(nu) * size_t(nv));
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            TextureQuery q;
            q.uv = vec2((float(i) + 0.5f) / float(nu), (float(j) + 0.5f) / float(nv));
            const vec3 c = glm::max(irradiance->eval(q), vec3(0.f));
            const float m = (c.x + c.y + c.z) / 3.f;
            f[size_t(j) * size_t(nu) + size_t(i)] = std::isfinite(m) ? m : 0.f;
        }
    std::vector<float> w(f.size());
    double sum = 0.0;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            float m = 0.f;
            for (int y = std::max(j - 1, 0); y <= std::min(j + 1, nv - 1); ++y)
                for (int x = std::max(i - 1, 0); x <= std::min(i + 1, nu - 1); ++x)
                    m = std::max(m, f[size_t(y) * size_t(nu) + size_t(x)]);
            w[size_t(j) * size_t(nu) + size_t(i)] = m;
            sum += double(m);
        }
    const double mean = sum / double(w.size());
    for (float& x : w) x = mean > 0.0 ? float(0.9 * double(x) / mean + 0.1) : 1.f;
    density = std::make_shared<const Distribution2D>(w, nu, nv);
}

uint32_t light_flags(const LightModel& m) {
    return std::visit(overloaded{[](const PointLight&) { return uint32_t(kLightDeltaPosition); },
                                 [](const SpotLight&) { return uint32_t(kLightDeltaPosition); },
                                 [](const ProjectorLight&) { return uint32_t(kLightDeltaPosition); },
                                 [](const DirectionalLight&) { return uint32_t(kLightDeltaDirection | kLightInfinite); },
                                 [](const ConstantLight&) { return uint32_t(kLightInfinite); },
                                 [](const EnvmapLight&) { return uint32_t(kLightInfinite); }},
                      m);
}

const char* light_type_name(const LightModel& m) {
    return std::visit(overloaded{[](const PointLight&) { return "point"; }, [](const SpotLight&) { return "spot"; },
                                 [](const ProjectorLight&) { return "projector"; },
                                 [](const DirectionalLight&) { return "directional"; },
                                 [](const ConstantLight&) { return "constant"; },
                                 [](const EnvmapLight&) { return "envmap"; }},
                      m);
}

vec3& light_strength(LightModel& m) {
    return std::visit(overloaded{[](PointLight& l) -> vec3& { return l.intensity; },
                                 [](SpotLight& l) -> vec3& { return l.intensity; },
                                 [](ProjectorLight& l) -> vec3& { return l.scale; },
                                 [](DirectionalLight& l) -> vec3& { return l.irradiance; },
                                 [](ConstantLight& l) -> vec3& { return l.radiance; },
                                 [](EnvmapLight& l) -> vec3& { return l.scale; }},
                      m);
}
vec3 light_strength(const LightModel& m) { return light_strength(const_cast<LightModel&>(m)); }

const char* light_strength_name(const LightModel& m) {
    return std::visit(overloaded{[](const PointLight&) { return "intensity"; }, [](const SpotLight&) { return "intensity"; },
                                 [](const ProjectorLight&) { return "scale"; },
                                 [](const DirectionalLight&) { return "irradiance"; },
                                 [](const ConstantLight&) { return "radiance"; },
                                 [](const EnvmapLight&) { return "scale"; }},
                      m);
}

bool same_light(const Light& a, const Light& b) {
    if (a.model.index() != b.model.index() || light_strength(a.model) != light_strength(b.model)) return false;
    return std::visit(
        overloaded{[&](const PointLight& l) { return l.position == std::get<PointLight>(b.model).position; },
                   [&](const SpotLight& l) {
                       const SpotLight& o = std::get<SpotLight>(b.model);
                       return l.to_world == o.to_world && l.cutoff_angle == o.cutoff_angle &&
                              l.beam_width == o.beam_width && l.texture == o.texture;
                   },
                   [&](const ProjectorLight& l) {
                       const ProjectorLight& o = std::get<ProjectorLight>(b.model);
                       return l.to_world == o.to_world && l.irradiance == o.irradiance && l.tan_x == o.tan_x &&
                              l.tan_y == o.tan_y;
                   },
                   [&](const DirectionalLight& l) { return l.direction == std::get<DirectionalLight>(b.model).direction; },
                   [&](const ConstantLight&) { return true; },
                   [&](const EnvmapLight& l) {
                       const EnvmapLight& o = std::get<EnvmapLight>(b.model);
                       return l.map == o.map && l.to_world == o.to_world && l.rotation == o.rotation;
                   }},
        a.model);
}

bool sample_li(const LightModel& m, const SceneSphere& sphere, vec3 ref_p, vec2 u, LightSample& out) {
    (void)sphere;
    return std::visit(
        overloaded{
            [&](const PointLight& l) {
                vec3 d = l.position - ref_p;
                float d2 = glm::dot(d, d);
                if (!(d2 > 0.f)) return false;
                out.dist = std::sqrt(d2);
                out.wi = d / out.dist;
                out.p = l.position;
                out.p_error = vec3(0.f);
                out.n = vec3(0.f);
                out.Le = l.intensity / d2;
                out.pdf = 1.f;
                out.delta = true;
                out.infinite = false;
                return true;
            },
            [&](const SpotLight& l) {
                vec3 pos = l.position();
                vec3 d = pos - ref_p;
                float d2 = glm::dot(d, d);
                if (!(d2 > 0.f)) return false;
                out.dist = std::sqrt(d2);
                out.wi = d / out.dist;
                vec3 prof = l.profile(l.to_local(-out.wi));
                if (is_black(prof)) return false;
                out.p = pos;
                out.p_error = vec3(0.f);
                out.n = vec3(0.f);
                out.Le = l.intensity * prof / d2;
                out.pdf = 1.f;
                out.delta = true;
                out.infinite = false;
                return true;
            },
            [&](const ProjectorLight& l) {
                const vec3 pos = l.position();
                const vec3 d = pos - ref_p;
                const float d2 = glm::dot(d, d);
                if (!(d2 > 0.f)) return false;
                out.dist = std::sqrt(d2);
                out.wi = d / out.dist;
                const vec3 local = l.to_local(ref_p - pos);
                vec2 uv;
                if (!l.uv_of(local, uv)) return false;
                // Mitsuba's sample_direction: pi scale E(uv) / (z^2 cos), z the reference point's depth
                // along the axis and cos = z / dist the angle to it (= pi scale E / cos^3 / dist^2).
                const float cos_axis = local.z / out.dist;
                TextureQuery q;
                q.uv = uv;
                out.Le = kPi * l.scale * l.irradiance->eval(q) / (local.z * local.z * cos_axis);
                if (is_black(out.Le) || !all_finite(out.Le)) return false;
                out.p = pos;
                out.p_error = vec3(0.f);
                out.n = vec3(0.f);
                out.pdf = 1.f;
                out.delta = true;
                out.infinite = false;
                return true;
            },
            [&](const DirectionalLight& l) {
                out.wi = -l.direction;
                out.dist = kInfinity;
                out.p = ref_p;
                out.n = l.direction;
                out.Le = l.irradiance;
                out.pdf = 1.f;
                out.delta = true;
                out.infinite = true;
                return true;
            },
            [&](const ConstantLight& l) {
                out.wi = square_to_uniform_sphere(u);
                out.dist = kInfinity;
                out.p = ref_p;
                out.n = -out.wi;
                out.Le = l.radiance;
                out.pdf = kInv4Pi;
                out.delta = false;
                out.infinite = true;
                return true;
            },
            [&](const EnvmapLight& l) {
                vec2 uv;
                float pdf_uv, sin_theta;
                if (!l.map->sample(u, uv, pdf_uv)) return false;
                vec3 d = EnvironmentMap::uv_to_direction(uv, sin_theta);
                if (!(sin_theta > 0.f)) return false;  // a pole: measure zero
                out.wi = l.from_local(d);
                out.dist = kInfinity;
                out.p = ref_p;
                out.n = -out.wi;
                out.Le = l.scale * l.map->eval(uv);
                out.pdf = envmap_pdf_sa(pdf_uv, sin_theta);
                out.delta = false;
                out.infinite = true;
                return std::isfinite(out.pdf) && out.pdf > 0.f;
            }},
        m);
}

float pdf_li(const LightModel& m, vec3 w) {
    if (std::holds_alternative<ConstantLight>(m)) return kInv4Pi;
    if (const EnvmapLight* e = std::get_if<EnvmapLight>(&m)) return envmap_pdf_li(*e, w);
    return 0.f;
}

vec3 eval_infinite(const LightModel& m, vec3 w) {
    if (const ConstantLight* c = std::get_if<ConstantLight>(&m)) return c->radiance;
    if (const EnvmapLight* e = std::get_if<EnvmapLight>(&m))
        return e->scale * e->map->eval(EnvironmentMap::direction_to_uv(e->to_local(w)));
    return vec3(0.f);
}

std::optional<EmissionSample> sample_le(const LightModel& m, const SceneSphere& sphere, vec2 u_pos, vec2 u_dir) {
    EmissionSample es;
    es.flags = light_flags(m);
    bool ok = std::visit(
        overloaded{[&](const PointLight& l) {
                       es.ray.o = l.position;
                       es.ray.d = square_to_uniform_sphere(u_dir);
                       es.Le = l.intensity;
                       es.pdf_pos = 1.f;
                       es.pdf_dir = kInv4Pi;
                       return true;
                   },
                   [&](const SpotLight& l) {
                       const float cos_cutoff = std::cos(radians(l.cutoff_angle));
                       vec3 local = square_to_uniform_cone(u_dir, cos_cutoff);
                       es.ray.o = l.position();
                       es.ray.d = glm::normalize(glm::mat3(l.to_world) * local);
                       es.Le = l.intensity * l.profile(local);
                       es.pdf_pos = 1.f;
                       es.pdf_dir = square_to_uniform_cone_pdf(local, cos_cutoff);
                       return es.pdf_dir > 0.f;
                   },
                   [&](const ProjectorLight& l) {
                       vec2 uv;
                       float pdf_uv;
                       if (!l.density || !l.density->sample(u_dir, uv, pdf_uv)) return false;
                       const vec3 d = l.direction_of(uv);
                       const float c3 = d.z * d.z * d.z;
                       TextureQuery q;
                       q.uv = uv;
                       es.ray.o = l.position();
                       es.ray.d = glm::normalize(l.to_world_dir(d));
                       es.Le = kPi * l.scale * l.irradiance->eval(q) / c3;
                       es.pdf_pos = 1.f;
                       es.pdf_dir = pdf_uv / (l.image_area() * c3);
                       return std::isfinite(es.pdf_dir) && es.pdf_dir > 0.f && all_finite(es.Le);
                   },
                   [&](const DirectionalLight& l) {
                       // From the disk facing the light, one radius before the centre.
                       es.ray.o = disk_point(sphere, -l.direction, u_pos) - sphere.radius * l.direction;
                       es.ray.d = l.direction;
                       es.n = l.direction;
                       es.Le = l.irradiance;
                       es.pdf_pos = 1.f / (kPi * sphere.radius * sphere.radius);
                       es.pdf_dir = 1.f;
                       return true;
                   },
                   [&](const ConstantLight& l) {
                       vec3 w = square_to_uniform_sphere(u_dir);  // towards the light
                       es.ray.o = disk_point(sphere, w, u_pos) + sphere.radius * w;
                       es.ray.d = -w;
                       es.n = -w;
                       es.Le = l.radiance;
                       es.pdf_pos = 1.f / (kPi * sphere.radius * sphere.radius);
                       es.pdf_dir = kInv4Pi;
                       return true;
                   },
                   [&](const EnvmapLight& l) {
                       vec2 uv;
                       float pdf_uv, sin_theta;
                       if (!l.map->sample(u_dir, uv, pdf_uv)) return false;
                       vec3 d = EnvironmentMap::uv_to_direction(uv, sin_theta);
                       if (!(sin_theta > 0.f)) return false;
                       vec3 w = l.from_local(d);  // towards the light
                       es.ray.o = disk_point(sphere, w, u_pos) + sphere.radius * w;
                       es.ray.d = -w;
                       es.n = -w;
                       es.Le = l.scale * l.map->eval(uv);
                       es.pdf_pos = 1.f / (kPi * sphere.radius * sphere.radius);
                       es.pdf_dir = envmap_pdf_sa(pdf_uv, sin_theta);
                       return std::isfinite(es.pdf_dir) && es.pdf_dir > 0.f;
                   }},
        m);
    if (!ok) return std::nullopt;
    return es;
}

void pdf_le(const LightModel& m, const SceneSphere& sphere, vec3 d, float& pdf_pos, float& pdf_dir) {
    const float disk = 1.f / (kPi * sphere.radius * sphere.radius);
    std::visit(overloaded{[&](const PointLight&) {
                              pdf_pos = 1.f;
                              pdf_dir = kInv4Pi;
                          },
                          [&](const SpotLight& l) {
                              pdf_pos = 1.f;
                              pdf_dir = square_to_uniform_cone_pdf(l.to_local(d), std::cos(radians(l.cutoff_angle)));
                          },
                          [&](const ProjectorLight& l) {
                              pdf_pos = 1.f;
                              pdf_dir = 0.f;
                              const vec3 local = l.to_local(d);
                              vec2 uv;
                              if (!l.density || !l.uv_of(local, uv)) return;
                              const float z = local.z / glm::length(local);
                              pdf_dir = l.density->pdf(uv) / (l.image_area() * z * z * z);
                          },
                          [&](const DirectionalLight&) {
                              pdf_pos = disk;
                              pdf_dir = 1.f;
                          },
                          [&](const ConstantLight&) {
                              pdf_pos = disk;
                              pdf_dir = kInv4Pi;
                          },
                          [&](const EnvmapLight& l) {
                              pdf_pos = disk;
                              pdf_dir = envmap_pdf_li(l, -d);  // d travels away from the light
                          }},
               m);
}

}  // namespace candela
