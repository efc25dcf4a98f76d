#pragma once
// The emitters that are not attached to a shape: Mitsuba 3.9's `point`, `spot`, `projector`,
// `directional`, `constant` and `envmap` (src/emitters/*.cpp), a closed set dispatched through std::variant. Area emitters live
// with their shapes in LightSet (light/area.h), which samples every light of the scene.
//
// Conventions (world space throughout, directions unit length):
//   wi        direction from the reference point towards the light
//   w (eval)  direction from the scene out to an infinite light (= the escaping ray's direction)
//   Li        what sample_li returns as LightSample::Le:
//               area, constant, envmap: radiance arriving along -wi (W m^-2 sr^-1)
//               point, spot, projector: intensity / dist^2 (the delta position is folded in)
//               directional:    irradiance at a surface facing it
//             so that the direct-light estimate is always f(wo, wi) |cos| Le / pdf.
//   pdf       area, constant, envmap: solid angle at the reference point; delta lights: 1 (a discrete
//             choice). LightSet multiplies in the pmf of choosing the light.
//   sample_le a ray leaving the light (for light tracing, BDPT, MLT) with Le the radiance it
//             carries (point, spot, projector: intensity; directional: irradiance), pdf_pos (area measure on
//             the light, or on the disk of the scene's bounding sphere for directional and
//             infinite lights, 1 for a delta position) and pdf_dir (solid angle, 1 for a delta
//             direction), as pbrt-v4's Light::SampleLe; the estimate of a light path's start is
//             Le |cos| / (pdf_pos pdf_dir), cos against EmissionSample::n.
//   Area lights with vertex normals: one convention everywhere. Their shading normal ns picks the
//   emitting side (emitted(), sample_li, sample_le) and is the axis of sample_le's cosine-weighted
//   direction (and of its pdf, pdf_le); every cosine of a measure (area to solid angle in
//   sample_li / pdf_li, the |cos| of sample_le's estimate) is the GEOMETRIC one, so that all the
//   strategies estimate what a ray hitting the light sees: radiance per unit of projected area of
//   the actual surface (as the path tracer's BSDF sampling does, the unbiased witness).
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include "core/frame.h"
#include "core/ray.h"
#include "light/envmap.h"
#include "sampling/distribution.h"
#include "texture/texture.h"

namespace candela {

enum LightFlags : uint32_t {
    kLightDeltaPosition = 1u,
    kLightDeltaDirection = 2u,
    kLightInfinite = 4u,
    kLightArea = 8u,
};

// Where the light sees the scene from: the bounding sphere of the scene's geometry (Mitsuba's
// bbox().bounding_sphere(), the radius enlarged by a relative epsilon).
struct SceneSphere {
    vec3 center{0.f};
    float radius = 1.f;
};

// A point chosen on a light for next-event estimation, seen from a reference point.
struct LightSample {
    vec3 p{0.f}, p_error{0.f};  // point on the light and its error bound (unused for infinite lights)
    vec3 n{0.f};                // geometric normal at p (zero for point and spot lights)
    vec3 ns{0.f};               // area lights: the shading normal at p, whose side emits (= n on flat
                                // shapes); unused by the other lights
    vec3 wi{0.f};               // unit direction from the reference point to p
    float dist = 0.f;           // distance from the reference point to p (infinity: infinite light)
    vec3 Le{0.f};               // see "Li" above
    float pdf = 0.f;            // see "pdf" above; includes the pmf of the light's choice
    bool delta = false;         // a delta light: no MIS with BSDF sampling (it cannot be hit)
    bool infinite = false;      // the shadow ray is unbounded
    int32_t light = -1;         // LightSet::sample_li: index into light(i), -1 for an area light
};

// A ray leaving a light (see "sample_le" above).
struct EmissionSample {
    Ray ray;
    // Normal at the ray's origin, for the |cos| of the estimate: area lights: the GEOMETRIC normal
    // (radiance is per unit of projected surface, as the rays that hit the light see it; the
    // direction is cosine-distributed about the shading normal, the emitting side);
    // directional/infinite: ray.d; else 0.
    vec3 n{0.f};
    vec3 Le{0.f};
    float pdf_pos = 0.f, pdf_dir = 0.f;  // include the pmf of the light's choice in pdf_pos
    uint32_t flags = 0;
};

// Mitsuba's `point`: intensity I (W/sr) radiated uniformly from `position`.
struct PointLight {
    vec3 position{0.f};
    vec3 intensity{1.f};
};

// Mitsuba's `spot`: at the origin of to_world, pointing along its +z. Intensity I inside beam_width,
// ramping linearly in angle to 0 at cutoff_angle (degrees, Mitsuba's defaults 20 and 3/4 of it);
// an optional texture projected over the cone (uv = 1/2 + 1/2 (x, y) / (z tan(cutoff))).
struct SpotLight {
    mat4 to_world{1.f};
    vec3 intensity{1.f};
    float cutoff_angle = 20.f, beam_width = 15.f;  // degrees
    std::shared_ptr<const Texture> texture;        // null: untextured

    // The falloff in [0, 1] times the texture in local direction d (unit, +z is the axis).
    vec3 profile(vec3 d) const;
    vec3 position() const { return vec3(to_world[3]); }
    vec3 axis() const { return glm::normalize(glm::mat3(to_world) * vec3(0.f, 0.f, 1.f)); }
    vec3 to_local(vec3 w) const { return glm::normalize(glm::inverse(glm::mat3(to_world)) * w); }
};

// Mitsuba's `projector`: a pinhole at the origin of to_world (a rotation and a translation) looking
// along its +z, which projects `irradiance` onto its image plane at z = 1 as the perspective camera
// maps its film: uv = (1/2 - x / (2 z tan_x), 1/2 - y / (2 z tan_y)) for a local direction (x, y, z),
// tan_x from the fov (along fov_axis, for the texture's aspect ratio) and tan_y = tan_x / aspect.
// The irradiance on that plane is pi * scale * irradiance(uv), so the intensity along a local unit
// direction d inside the frustum is pi * scale * irradiance(uv) / d.z^3 (and 0 outside), as
// Mitsuba's sample_direction gives it. Emission sampling picks uv from `density` (the texture's
// values plus a uniform part, so that every uv where bilinear filtering can give light is
// reachable) and maps it to a direction: pdf_dir = pdf_uv / (image area * d.z^3).
struct ProjectorLight {
    mat4 to_world{1.f};
    std::shared_ptr<const Texture> irradiance;
    vec3 scale{1.f};  // Mitsuba's float scale, per channel so that the viewer edits it as a strength
    float tan_x = 1.f, tan_y = 1.f;
    std::shared_ptr<const Distribution2D> density;  // over uv; see build_density()

    vec3 position() const { return vec3(to_world[3]); }
    vec3 to_local(vec3 w) const { return glm::transpose(glm::mat3(to_world)) * w; }  // rigid
    vec3 to_world_dir(vec3 d) const { return glm::mat3(to_world) * d; }
    // The image-plane coordinates of local direction d (any length); false outside the frustum.
    bool uv_of(vec3 d, vec2& uv) const;
    // The local unit direction through uv, and its z (the cosine to the axis).
    vec3 direction_of(vec2 uv) const;
    float image_area() const { return 4.f * tan_x * tan_y; }
    // Builds `density` from the texture (call after setting irradiance).
    void build_density();
};

// Mitsuba's `directional`: irradiance E (W/m^2) arriving along `direction` (the way the light
// travels, unit; Mitsuba's to_world +z).
struct DirectionalLight {
    vec3 direction{0.f, 0.f, 1.f};
    vec3 irradiance{1.f};
};

// Mitsuba's `constant`: radiance L from every direction. Sampled uniformly over the sphere, as
// Mitsuba does.
struct ConstantLight {
    vec3 radiance{1.f};
};

// Mitsuba's `envmap`: radiance scale * map(uv(to_local(w))) arriving from direction w, the map in
// Mitsuba's lat-long orientation (light/envmap.h), importance sampled by its luminance. `scale` is
// Mitsuba's float scale, per channel here so that the viewer edits it as it edits a radiance.
// `rotation` (degrees) turns the map about its own up axis (local +y) before to_world; the viewer
// edits it. Call update() after changing to_world or rotation.
struct EnvmapLight {
    std::shared_ptr<const EnvironmentMap> map;
    vec3 scale{1.f};
    glm::mat3 to_world{1.f};  // the linear part of the XML's to_world
    float rotation = 0.f;

    glm::mat3 frame{1.f}, frame_inv{1.f};  // local -> world and back, rotation included
    void update();
    vec3 to_local(vec3 w) const { return glm::normalize(frame_inv * w); }
    vec3 from_local(vec3 d) const { return glm::normalize(frame * d); }
};

using LightModel = std::variant<PointLight, SpotLight, ProjectorLight, DirectionalLight, ConstantLight, EnvmapLight>;

struct Light {
    std::string name;  // the XML id, or "<type> k"
    LightModel model;
};

uint32_t light_flags(const LightModel& m);
const char* light_type_name(const LightModel& m);  // Mitsuba's plugin name
// The parameter the viewer edits: intensity, irradiance, radiance or (envmap, projector) scale.
vec3& light_strength(LightModel& m);
vec3 light_strength(const LightModel& m);
const char* light_strength_name(const LightModel& m);
bool same_light(const Light& a, const Light& b);

// Next-event sampling of one light from ref_p (pdf without the light's pmf). False when it cannot
// light ref_p (outside a spot's cone or a projector's frustum, zero strength).
bool sample_li(const LightModel& m, const SceneSphere& sphere, vec3 ref_p, vec2 u, LightSample& out);
// Solid-angle density of sample_li choosing w (0 for delta lights).
float pdf_li(const LightModel& m, vec3 w);
// Radiance arriving along -w from an infinite light (w points out to it); 0 for the others.
vec3 eval_infinite(const LightModel& m, vec3 w);
// Emission sampling (pdfs without the light's pmf).
std::optional<EmissionSample> sample_le(const LightModel& m, const SceneSphere& sphere, vec2 u_pos, vec2 u_dir);
// The densities sample_le gives to a ray of direction d leaving point p (for an infinite light: d is
// the direction the light travels); a delta part reports 1, as sample_le.
void pdf_le(const LightModel& m, const SceneSphere& sphere, vec3 d, float& pdf_pos, float& pdf_dir);

}  // namespace candela
