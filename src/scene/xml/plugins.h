#pragma once
// The plugin families of the XML reader (see parser.h). Each family file defines its factories,
// its table and the entry point the parser core calls for a top-level (or nested) element of its
// tag. Adding a plugin: write its factory in the family's file and add one row to its table.
#include "scene/xml/parser.h"

namespace candela {
namespace xml {

// ---- bsdfs.cpp: <bsdf> -> Material (the name is set by the caller) ----
using BsdfFactory = Material (*)(XmlLoader&, Object&);
const PluginTable<BsdfFactory>& bsdf_plugins();
// bsdf_wrappers.cpp: blendbsdf, mask, null, bumpmap, normalmap (rows of bsdf_plugins()).
BsdfFactory blendbsdf_factory();
BsdfFactory mask_factory();
BsdfFactory null_factory();
BsdfFactory bumpmap_factory();
BsdfFactory normalmap_factory();

// ---- shapes.cpp: <shape> -> triangles in object space, then placed by the common code ----
struct ShapeGeometry {
    std::vector<vec3> positions, normals;  // object space; normals empty or per vertex
    std::vector<uvec3> triangles;
    std::vector<vec2> uvs;     // per vertex or empty; unchanged by to_world
    std::vector<vec3> colors;  // per vertex or empty
    // Mitsuba's rectangle and cube: under a mirroring to_world their geometric normal follows the
    // transformed winding but their shading normal is to_world^-T n_local, so the two disagree
    // (Mitsuba 3.9 checked). `normals` then become vertex normals, and are dropped otherwise.
    bool analytic = false;
    bool recompute_normals = false;  // obj without normals, face_normals false (Mitsuba's default)
};
using ShapeFactory = ShapeGeometry (*)(XmlLoader&, Object&);
const PluginTable<ShapeFactory>& shape_plugins();
void load_shape(XmlLoader& L, pugi::xml_node n);
// shapegroup and instance (src/scene/xml/instancing.cpp), called by load_shape.
void load_shapegroup(XmlLoader& L, Object& o);
void load_instance(XmlLoader& L, Object& o);

// ---- emitters.cpp: <emitter> nested in a shape (area), and top-level emitters ----
using EmitterModel = std::variant<AreaEmitter, PointLight, SpotLight, ProjectorLight, DirectionalLight, ConstantLight, EnvmapLight>;
using EmitterFactory = EmitterModel (*)(XmlLoader&, Object&);
const PluginTable<EmitterFactory>& emitter_plugins();
// The emitter nested in a shape: its index in scene().emitters.
int32_t load_shape_emitter(XmlLoader& L, pugi::xml_node n);
void load_emitter(XmlLoader& L, pugi::xml_node n);  // top level: appends to scene().lights

// ---- sensors.cpp: <sensor> with its <film> (and <rfilter>) and <sampler> ----
using SensorFactory = Camera (*)(XmlLoader&, Object&);
using FilmFactory = void (*)(XmlLoader&, Object&, RenderSettings&);
using SamplerFactory = void (*)(XmlLoader&, Object&, RenderSettings&);
const PluginTable<SensorFactory>& sensor_plugins();
const PluginTable<FilmFactory>& film_plugins();
const PluginTable<SamplerFactory>& sampler_plugins();
void load_sensor(XmlLoader& L, pugi::xml_node n);
// A film's nested <rfilter> (at most one; gaussian without one), for film factories. The filter
// factories are read_rfilter (scene/plugins/render_factories.h).
void load_rfilters(XmlLoader& L, Object& film, RenderSettings& s);

// ---- textures.cpp: <texture> -> Texture, and texture-valued parameters of other plugins ----
using TextureFactory = Texture (*)(XmlLoader&, Object&);
const PluginTable<TextureFactory>& texture_plugins();
// The texture a <texture> element (or a <ref> to one) stands for, built once.
std::shared_ptr<const Texture> load_texture(XmlLoader& L, pugi::xml_node n);
// The nested <texture> or <ref> to one with name="name" in `o`, marked used; null when none.
std::shared_ptr<const Texture> nested_texture(XmlLoader& L, Object& o, const std::string& name);
// A colour parameter given as a value or as a texture: the texture (a constant one for a value).
std::shared_ptr<const Texture> rgb_or_texture(XmlLoader& L, Object& o, const std::string& name, vec3 def);

// ---- media.cpp: <medium> (homogeneous, with its <phase>) -> SceneDescription::media ----
// The index of the medium element (built once, whether nested or referenced).
int32_t load_medium(XmlLoader& L, pugi::xml_node n);
// Whether a nested object is a <medium> or a <ref> to one.
bool is_medium_child(XmlLoader& L, const Nested& c);
// The medium a nested <medium> or <ref> stands for, marked used.
int32_t nested_medium(XmlLoader& L, Nested& c);
// A shape's media named "interior" and "exterior" (left as they are when not given).
void load_shape_media(XmlLoader& L, Object& shape, int32_t& interior, int32_t& exterior);

// ---- integrators.cpp: <integrator> -> RenderSettings (factories: read_integrator,
// scene/plugins/render_factories.h; this walks the moment/aov wrappers) ----
void load_integrator(XmlLoader& L, pugi::xml_node n);

}  // namespace xml
}  // namespace candela
