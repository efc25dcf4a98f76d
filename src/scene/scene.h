#pragma once
// A scene exists in two forms (pbrt-v4 keeps its BasicScene apart from the aggregate for the same
// reason):
//   SceneDescription  what a loader produces: plain, mutable, movable data, nothing derived.
//   Scene             the built scene the renderer reads: geometry, accelerator and light set,
//                     plus the parameters (camera, settings, materials, emitters). Immutable once
//                     built and reached only through shared_ptr<const Scene>, so any number of
//                     threads may read one at the same time; an edit builds a new Scene
//                     (with_params) that shares the unchanged parts with the old one.
// The parts that hold pointers into another part (the accelerator and the light set point into the
// mesh) are built together by build_scene and shared by pointer afterwards, never copied or moved.
#include <atomic>
#include <memory>
#include <string>
#include <vector>
#include "accel/accel.h"
#include "bsdf/bsdf.h"
#include "film/filter.h"
#include "geometry/analytic.h"
#include "geometry/instance.h"
#include "geometry/mesh.h"
#include "integrator/desc.h"
#include "light/area.h"
#include "medium/medium.h"
#include "sampling/sampler_desc.h"
#include "scene/camera.h"

namespace candela {

enum class SamplingMode { Light, Bsdf, Mis };

// What the scene file says about rendering; the command line may override each field.
struct RenderSettings {
    int width = 512, height = 512;  // the rendered image: the film, or its crop window (Camera)
    bool alpha = false;      // hdrfilm pixel_format rgba: the image gets an alpha channel
    int spp = 64;            // sampler sample_count: the default number of passes x spp per pass,
                             // and what the stratified samplers stratify over (docs/samplers.md)
    uint64_t seed = 0;
    SamplerDesc sampler;     // which sampler draws the random numbers (sampling/samplers.h)
    int max_depth = -1;      // scattering events; -1 = unbounded (Russian roulette ends paths)
    int rr_depth = 5;        // scattering events before Russian roulette starts
    SamplingMode sampling = SamplingMode::Mis;
    IntegratorDesc integrator;  // which integrator renders the passes (the scene's <integrator>)
    FilterDesc filter;          // the film's reconstruction filter (box unless the scene says)
};

// Everything the image depends on that can change without rebuilding the geometry: what the viewer
// edits. Materials and emitters are indexed by Shape::material and Shape::emitter, so an edit keeps
// their number.
struct SceneParams {
    Camera camera;
    RenderSettings settings;
    std::vector<Material> materials;
    std::vector<AreaEmitter> emitters;
    std::vector<Light> lights;  // the emitters not on shapes (point, spot, directional, constant)
    std::vector<Medium> media;  // participating media (Shape::interior/exterior and the camera index them)
};

// A scene as loaded, before anything is derived from it. Loaders fill it; build_scene consumes it.
struct SceneDescription {
    std::string source;                  // file it came from ("<built-in Cornell box>" otherwise)
    Mesh mesh;
    std::vector<Shape> shapes;
    std::vector<AnalyticShape> analytic;  // spheres, disks, cylinders (Shape::analytic indexes it)
    std::vector<ShapeGroup> groups;       // shapegroups (Shape::group indexes it), seen only through
    std::vector<Instance> instances;      // instances (Instance::group indexes groups)
    std::vector<Material> materials;
    std::vector<AreaEmitter> emitters;
    std::vector<Light> lights;            // top-level emitters (light/emitter.h)
    std::vector<Medium> media;            // participating media (Shape::interior/exterior index it)
    int32_t camera_medium = -1;           // the medium around the sensor, or -1
    int media_line = 0;                   // the line of the first medium element (for messages)
    Camera camera;
    RenderSettings settings;
    std::vector<std::string> warnings;   // non-fatal loader messages ("file: what") for the app to show

    // Appends a shape made of the given triangles (world space). Returns its index. `uvs` and
    // `colors` are per vertex or empty (then the mesh stores none for this shape).
    uint32_t add_shape(const std::string& name, const std::vector<vec3>& positions, const std::vector<vec3>& normals,
                       const std::vector<uvec3>& triangles, uint32_t material, int32_t emitter,
                       const std::vector<vec2>& uvs = {}, const std::vector<vec3>& colors = {});
    // Appends an analytic shape (world space, see geometry/analytic.h). Returns its shape index.
    uint32_t add_analytic_shape(const std::string& name, AnalyticShape a, uint32_t material, int32_t emitter);
    // Appends one shape made of several analytic primitives (a curve's segments), without emitter.
    uint32_t add_analytic_shapes(const std::string& name, std::vector<AnalyticShape> parts, uint32_t material);
};

// The immutable geometry, shared by every Scene built from one description.
struct Geometry {
    Mesh mesh;
    std::vector<Shape> shapes;
    std::vector<AnalyticShape> analytic;
    std::vector<ShapeGroup> groups;
    std::vector<Instance> instances;
    int32_t camera_medium = -1;   // the medium the camera rays start in, or -1 (Scene::media)
    AABB bounds;  // world: the scene's own primitives and every instance
};

class Scene {
public:
    // The shared parts come first: members are destroyed in reverse order, so the geometry outlives
    // the accelerator and the light set that point into it.
    const std::string source;
    const std::shared_ptr<const Geometry> geometry;
    const Mesh& mesh;                  // geometry->mesh
    const std::vector<Shape>& shapes;  // geometry->shapes
    const std::vector<AnalyticShape>& analytic;  // geometry->analytic
    const std::vector<ShapeGroup>& groups;       // geometry->groups
    const std::vector<Instance>& instances;      // geometry->instances
    const std::shared_ptr<const Accel> accel;
    const std::shared_ptr<const LightSet> light_set;
    const LightSet& lights;            // *light_set

    // The parameters this scene renders with (the camera set to the settings' film size, materials
    // prepared: their derived tables built).
    const Camera camera;
    const RenderSettings settings;
    const std::vector<Material> materials;
    const std::vector<AreaEmitter> emitters;
    const std::vector<Light> light_params;  // SceneParams::lights (the light set holds its copy)
    const std::vector<Medium> media;        // participating media (medium/medium.h); empty in most scenes
    const std::vector<std::string> warnings;

    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    // This scene with other parameters: shares the geometry and the accelerator, and the light set
    // when the emitters are unchanged (else rebuilds it, which caches their radiance). Prepares the
    // materials (e.g. the plastic coat tables) on the calling thread: call it where that may take
    // time, the render worker, not the window. Throws Error when `p` does not fit the geometry
    // (another number of materials or emitters, an impossible film size).
    std::shared_ptr<const Scene> with_params(const SceneParams& p) const;
    SceneParams params() const { return {camera, settings, materials, emitters, light_params, media}; }

    // Surface data at a hit (a triangle or an analytic shape, by hit.kind), with the error bound
    // of the point. In an instance (hit.instance set) the group-space interaction is taken to
    // world space: p by to_world with its error bound carried through the transform (pbrt-v4
    // Point3fi), ng and ns by the inverse transpose and renormalised (as Mitsuba's Instance: a
    // mirroring to_world does not turn them around), uv unchanged.
    SurfaceInteraction interaction(const Hit& hit) const;
    // The vertex colours interpolated at a hit (Mitsuba's mesh attribute "vertex_color", what a
    // mesh_attribute texture reads); zero on a shape without colours. Apart from interaction() so
    // that only shading that reads colours pays for them.
    vec3 vertex_color(const Hit& hit) const;
    // What a texture reads at a hit: the uv, and the vertex colour where the shape has colours.
    TextureQuery texture_query(const SurfaceInteraction& si, const Hit& hit) const {
        TextureQuery q;
        q.uv = si.uv;
        if (hit.kind == PrimKind::Triangle && shapes[si.shape].has_color()) q.vertex_color = vertex_color(hit);
        return q;
    }

    // What the scene holds in memory, by part. The mesh stores normals only where the file gives
    // them and the light maps only when there are emitters, so a scene pays for what it uses.
    struct Memory {
        size_t triangles = 0;   // stored: the scene's own plus each group's once
        size_t instances = 0;
        size_t mesh = 0, accel = 0, lights = 0;  // bytes (mesh: every stored mesh, plus the instances)
        size_t total() const { return mesh + accel + lights; }
    };
    Memory memory() const;

private:
    friend std::shared_ptr<const Scene> build_scene(SceneDescription desc, const std::string& accel_name);
    Scene(std::string source, std::shared_ptr<const Geometry> geometry, std::shared_ptr<const Accel> accel,
          std::shared_ptr<const LightSet> lights, const SceneParams& p, std::vector<std::string> warnings);
};

// Validates the description (finite vertices, indices in range, film size, material and emitter
// indices), builds the accelerator (by name, see make_accel) and the light set, and prepares the
// materials. Throws Error naming the source.
std::shared_ptr<const Scene> build_scene(SceneDescription desc, const std::string& accel_name = "auto");

// Loads a scene description by its extension: .xml (Mitsuba 3 subset) or .obj (OBJ + MTL).
// `defines` are name=value pairs that override the XML's <default> values. Throws Error with
// file:line.
SceneDescription load_scene(const std::string& path,
                            const std::vector<std::pair<std::string, std::string>>& defines = {});

}  // namespace candela
