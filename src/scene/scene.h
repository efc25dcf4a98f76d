#pragma once
#include <memory>
#include <string>
#include <vector>
#include "accel/accel.h"
#include "bsdf/bsdf.h"
#include "geometry/mesh.h"
#include "light/area.h"
#include "scene/camera.h"

namespace candela {

enum class SamplingMode { Light, Bsdf, Mis };

// What the scene file says about rendering; the command line may override each field.
struct RenderSettings {
    int width = 512, height = 512;
    int spp = 64;            // sampler sample_count: the default number of passes x spp per pass
    uint64_t seed = 0;
    int max_depth = -1;      // scattering events; -1 = unbounded (Russian roulette ends paths)
    int rr_depth = 5;        // scattering events before Russian roulette starts
    SamplingMode sampling = SamplingMode::Mis;
};

// A loaded scene. Loaders fill the public data; finalize() derives the acceleration structure,
// the light set and the camera's film constants. After finalize() the scene is read-only during
// rendering and is shared by all render threads.
struct Scene {
    std::string source;                  // file it came from ("<built-in Cornell box>" otherwise)
    Mesh mesh;
    std::vector<Shape> shapes;
    std::vector<Material> materials;
    std::vector<AreaEmitter> emitters;
    Camera camera;
    RenderSettings settings;
    std::vector<std::string> warnings;   // non-fatal loader messages ("file: what") for the app to show

    std::unique_ptr<Accel> accel;
    LightSet lights;

    // Build the accelerator (by name, see make_accel) and lights; validates the geometry.
    void finalize(const std::string& accel_name = "auto");

    // Appends a shape made of the given triangles (world space). Returns its index.
    uint32_t add_shape(const std::string& name, const std::vector<vec3>& positions, const std::vector<vec3>& normals,
                       const std::vector<uvec3>& triangles, uint32_t material, int32_t emitter);

    // Surface data at a hit, with the error bound of the point.
    SurfaceInteraction interaction(const Hit& hit) const;

    // What the loaded scene holds in memory, by part. The mesh stores normals only where the file
    // gives them and the light maps only when there are emitters, so a scene pays for what it uses.
    struct Memory {
        size_t triangles = 0;
        size_t mesh = 0, accel = 0, lights = 0;  // bytes
        size_t total() const { return mesh + accel + lights; }
    };
    Memory memory() const;
};

// Loads a scene by its extension: .xml (Mitsuba 3 subset) or .obj (OBJ + MTL). `defines` are
// name=value pairs that override the XML's <default> values. Throws Error with file:line.
Scene load_scene(const std::string& path, const std::vector<std::pair<std::string, std::string>>& defines = {});

}  // namespace candela
