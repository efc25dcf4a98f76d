// The emitter family of the XML reader, one table for every emitter plugin: `area` (nested in a
// shape, or referenced by one) and the top-level `point`, `spot`, `projector`, `directional`,
// `constant` and `envmap` (light/emitter.h). As Mitsuba's Scene, a scene takes at most one environment emitter
// (an infinite light that is not a delta: constant or envmap).
#include "scene/sensors.h"
#include "scene/xml/plugins.h"

namespace candela {
namespace xml {

namespace {

// The value of a nested constant texture (srgb, d65, uniform, rawconstant) given for `name`: not
// also given as a value, finite and not negative. Null when the texture varies.
const vec3* constant_strength(XmlLoader& L, Object& e, const char* name, const Texture& t) {
    if (e.params.has(name)) throw e.params.error(name, std::string("'") + name + "' is given both as a value and as a texture");
    const ConstantTexture* c = std::get_if<ConstantTexture>(&t.v);
    if (c && (!all_finite(c->value) || !(min_component(c->value) >= 0.f)))
        throw L.error(e.node, std::string(name) + " must be finite and not negative");
    return c ? &c->value : nullptr;
}

// A value, or a nested texture that is a constant: folded into the value, since these emitters take
// no spatially varying strength.
vec3 strength(XmlLoader& L, Object& e, const char* name) {
    if (std::shared_ptr<const Texture> t = nested_texture(L, e, name)) {
        if (const vec3* c = constant_strength(L, e, name, *t)) return *c;
        throw L.error(e.node, std::string("a varying texture for '") + name + "' is not supported by " + e.what());
    }
    vec3 v = e.params.get_rgb(name, vec3(1.f));
    if (!all_finite(v) || !(min_component(v) >= 0.f))
        throw e.params.error(name, std::string(name) + " must be finite and not negative");
    return v;
}

// A direction-valued to_world: its +z, normalised.
vec3 transformed_z(Object& e, const mat4& m) {
    vec3 d = glm::mat3(m) * vec3(0.f, 0.f, 1.f);
    float len = glm::length(d);
    if (!(len > 0.f) || !std::isfinite(len)) throw e.params.error("to_world", "to_world maps +z to a zero direction");
    return d / len;
}

EmitterModel make_area(XmlLoader& L, Object& e) {
    // A textured radiance (bitmap, checkerboard): evaluated at the uv of each emitting point.
    std::shared_ptr<const Texture> t = nested_texture(L, e, "radiance");
    if (!t) return AreaEmitter{strength(L, e, "radiance"), nullptr};
    if (const vec3* c = constant_strength(L, e, "radiance", *t)) return AreaEmitter{*c, nullptr};  // d65, srgb...
    if (t->uses_vertex_colors())
        throw L.error(e.node, "a radiance texture that reads vertex colours (mesh_attribute) is not supported");
    return AreaEmitter{vec3(0.f), t};
}

EmitterModel make_point(XmlLoader& L, Object& e) {
    PointLight l;
    l.intensity = strength(L, e, "intensity");
    if (e.params.has("position") && e.params.has("to_world"))
        throw L.error(e.node, "point: only one of 'position' and 'to_world' may be given");
    l.position = e.params.get_point("position", vec3(0.f));
    if (e.params.has("to_world")) l.position = vec3(e.params.get_transform("to_world", mat4(1.f))[3]);
    if (!all_finite(l.position)) throw L.error(e.node, "point: the position is not finite");
    return l;
}

EmitterModel make_spot(XmlLoader& L, Object& e) {
    SpotLight l;
    l.intensity = strength(L, e, "intensity");
    l.to_world = e.params.get_transform("to_world", mat4(1.f));
    l.cutoff_angle = e.params.get_float("cutoff_angle", 20.f);
    if (!(l.cutoff_angle > 0.f && l.cutoff_angle <= 90.f))
        throw e.params.error("cutoff_angle", "cutoff_angle must be in (0, 90] degrees");
    l.beam_width = e.params.get_float("beam_width", l.cutoff_angle * 3.f / 4.f);
    if (!(l.beam_width >= 0.f && l.beam_width <= l.cutoff_angle))
        throw e.params.error("beam_width", "beam_width must be in [0, cutoff_angle] degrees");
    if (glm::determinant(glm::mat3(l.to_world)) == 0.f || !std::isfinite(glm::determinant(glm::mat3(l.to_world))))
        throw e.params.error("to_world", "spot: to_world is singular");
    l.texture = nested_texture(L, e, "texture");
    if (l.texture && l.texture->is_constant())
        throw L.error(e.node, "spot: 'texture' must vary over the cone (e.g. a bitmap), as in Mitsuba");
    return l;
}

EmitterModel make_projector(XmlLoader& L, Object& e) {
    ProjectorLight l;
    if (std::shared_ptr<const Texture> t = nested_texture(L, e, "irradiance")) {
        if (!constant_strength(L, e, "irradiance", *t) && t->uses_vertex_colors())  // a constant is checked there
            throw L.error(e.node, "projector: an irradiance texture that reads vertex colours (mesh_attribute) is not supported");
        l.irradiance = t;
    } else if (e.params.has("irradiance")) {
        l.irradiance = std::make_shared<const Texture>(constant_texture(strength(L, e, "irradiance")));
    } else {
        throw L.error(e.node, "projector needs an 'irradiance' (a texture or a value), as in Mitsuba");
    }
    const float scale = e.params.get_float("scale", 1.f);
    if (!std::isfinite(scale) || !(scale >= 0.f)) throw e.params.error("scale", "scale must be finite and not negative");
    l.scale = vec3(scale);
    l.to_world = e.params.get_transform("to_world", mat4(1.f));
    // A rotation and a translation: a scale would change the projected irradiance in a way Mitsuba's
    // own emission sampling does not follow (its sample_direction and sample_ray disagree then).
    const glm::mat3 r(l.to_world);
    const glm::mat3 rtr = glm::transpose(r) * r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (!(std::abs(rtr[i][j] - (i == j ? 1.f : 0.f)) < 1e-4f))
                throw e.params.error("to_world", "projector: to_world must be a rotation and a translation (no scale or shear)");
    if (!all_finite(l.position())) throw e.params.error("to_world", "projector: the position is not finite");
    // The image's aspect ratio is the texture's (a bitmap's resolution; 1 for anything else, as
    // Mitsuba's Texture::resolution), and the fov is read as a perspective camera's.
    float aspect = 1.f;
    if (const BitmapTexture* b = std::get_if<BitmapTexture>(&l.irradiance->v))
        aspect = float(b->texels->width) / float(b->texels->height);
    Camera cam;
    read_fov(e.params, cam);
    const double x_fov = horizontal_fov(cam.fov_deg, cam.fov_axis, aspect);
    l.tan_x = float(std::tan(0.5 * x_fov * M_PI / 180.0));
    l.tan_y = l.tan_x / aspect;
    if (!(l.tan_x > 0.f) || !std::isfinite(l.tan_x) || !(l.tan_y > 0.f) || !std::isfinite(l.tan_y))
        throw L.error(e.node, "projector: the field of view gives no image (fov too close to 0 or 180 degrees)");
    l.build_density();
    return l;
}

EmitterModel make_directional(XmlLoader& L, Object& e) {
    DirectionalLight l;
    l.irradiance = strength(L, e, "irradiance");
    if (e.params.has("direction") && e.params.has("to_world"))
        throw L.error(e.node, "directional: only one of 'direction' and 'to_world' may be given");
    if (e.params.has("direction")) {
        vec3 d = e.params.get_vector("direction", vec3(0.f, 0.f, 1.f));
        float len = glm::length(d);
        if (!(len > 0.f) || !std::isfinite(len)) throw e.params.error("direction", "direction must not be zero");
        l.direction = d / len;
    } else if (e.params.has("to_world")) {
        l.direction = transformed_z(e, e.params.get_transform("to_world", mat4(1.f)));
    }
    return l;
}

EmitterModel make_constant(XmlLoader& L, Object& e) {
    return ConstantLight{strength(L, e, "radiance")};
}

EmitterModel make_envmap(XmlLoader& L, Object& e) {
    EnvmapLight l;
    if (e.params.has("bitmap")) throw e.params.error("bitmap", "envmap: a 'bitmap' object is not supported; give 'filename'");
    const std::string file = e.params.get_string("filename", "");
    if (file.empty()) throw L.error(e.node, "envmap needs a filename");
    const std::string path = L.resolve(e.node, file);
    try {
        l.map = EnvironmentMap::load(path);
    } catch (const Error& err) {
        // The image's problem, at the scene's line.
        throw e.params.error("filename", std::string("envmap: ") + err.what());
    }
    const float scale = e.params.get_float("scale", 1.f);
    if (!std::isfinite(scale) || !(scale >= 0.f)) throw e.params.error("scale", "scale must be finite and not negative");
    l.scale = vec3(scale);
    // mis_compensation changes only how Mitsuba samples the map (not the image): accepted, unused.
    (void)e.params.get_bool("mis_compensation", false);
    const mat4 m = e.params.get_transform("to_world", mat4(1.f));
    l.to_world = glm::mat3(m);
    const float det = glm::determinant(l.to_world);
    if (!(det != 0.f) || !std::isfinite(det)) throw e.params.error("to_world", "envmap: to_world is singular");
    l.update();
    return l;
}

}  // namespace

const PluginTable<EmitterFactory>& emitter_plugins() {
    static const PluginTable<EmitterFactory> table = {
        {"area", make_area},           {"point", make_point},       {"spot", make_spot},
        {"projector", make_projector}, {"directional", make_directional}, {"constant", make_constant},
        {"envmap", make_envmap},
    };
    return table;
}

namespace {
EmitterFactory find_emitter(XmlLoader& L, const Object& e) {
    for (const auto& p : emitter_plugins())
        if (e.type == p.type) return p.make;
    std::string known;
    for (const auto& p : emitter_plugins())
        known += (known.empty() ? "" : ", ") + std::string(p.type);
    throw L.error(e.node, "unsupported emitter type '" + e.type + "' (candela supports: " + known + ")");
}
}  // namespace

int32_t load_shape_emitter(XmlLoader& L, pugi::xml_node n) {
    Object e = L.read_object(n, "emitter");
    if (e.type != "area") throw L.error(n, "unsupported emitter type '" + e.type + "' inside a shape (area)");
    EmitterModel m = find_emitter(L, e)(L, e);
    L.finish(e);
    L.scene().emitters.push_back(std::get<AreaEmitter>(m));
    return int32_t(L.scene().emitters.size() - 1);
}

void load_emitter(XmlLoader& L, pugi::xml_node n) {
    if (L.attr(n, "type") == "area" && n.attribute("id")) return;  // built by the shapes that <ref> it
    Object e = L.read_object(n, "emitter");
    if (e.type == "area") throw L.error(n, "an area emitter must be nested inside a <shape> or referenced by one");
    EmitterModel m = find_emitter(L, e)(L, e);
    L.finish(e);
    Light l;
    l.model = std::visit([](auto&& v) -> LightModel {
        if constexpr (std::is_same_v<std::decay_t<decltype(v)>, AreaEmitter>) return ConstantLight{};  // not reached
        else return v;
    }, m);
    std::vector<Light>& lights = L.scene().lights;
    auto environment = [](const Light& x) {
        return (light_flags(x.model) & (kLightInfinite | kLightDeltaDirection)) == kLightInfinite;
    };
    if (environment(l))
        for (const Light& o : lights)
            if (environment(o)) throw L.error(n, "only one environment emitter (constant or envmap) can be specified per scene, as in Mitsuba");
    l.name = n.attribute("id") ? std::string(n.attribute("id").value())
                               : std::string(light_type_name(l.model)) + " " + std::to_string(lights.size());
    lights.push_back(std::move(l));
}

}  // namespace xml
}  // namespace candela
