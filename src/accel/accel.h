#pragma once
#include <memory>
#include <string>
#include "geometry/interaction.h"
#include "geometry/mesh.h"

namespace candela {

// Ray-scene queries over the triangles of one Mesh. One virtual call per ray; traversal inside
// is free of virtual dispatch. Implementations keep a pointer to the mesh they were built on.
class Accel {
public:
    virtual ~Accel() = default;
    // Closest hit with ray.tmin < t < ray.tmax. On a hit, fills `hit` and shrinks ray.tmax to t.
    virtual bool intersect(Ray& ray, Hit& hit) const = 0;
    // Any hit in (tmin, tmax): for shadow rays; may stop at the first one found.
    virtual bool occluded(const Ray& ray) const = 0;
    virtual std::string name() const = 0;
    // Bytes held by the structure (not counting the mesh itself).
    virtual size_t memory_bytes() const = 0;
};

// Accelerator names accepted by --accel. "auto" lets the scene choose.
std::unique_ptr<Accel> make_accel(const std::string& name, const Mesh& mesh);

}  // namespace candela
