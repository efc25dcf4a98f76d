#pragma once
// Intel Embree 3 behind the Accel interface: the yardstick the k-d tree is measured against.
// Compiled only with -DCANDELA_EMBREE=ON (then CANDELA_HAS_EMBREE is defined). Embree's own
// triangle test is not watertight in the same way, so its hits can differ from brute force in the
// last bits; it is for benchmarks, not the renderer's default.
#include "accel/accel.h"

namespace candela {

class EmbreeAccel final : public Accel {
public:
    // Builds with RTC_BUILD_QUALITY_HIGH (as the reference embree_bench does).
    explicit EmbreeAccel(const Mesh& mesh);
    ~EmbreeAccel() override;
    EmbreeAccel(const EmbreeAccel&) = delete;
    EmbreeAccel& operator=(const EmbreeAccel&) = delete;

    bool intersect(Ray& ray, Hit& hit) const override;   // rtcIntersect1
    bool occluded(const Ray& ray) const override;        // rtcOccluded1
    std::string name() const override { return "embree"; }
    // Bytes Embree allocated for the scene (its memory monitor callback), our vertex/index copies
    // excluded.
    size_t memory_bytes() const override { return bvh_bytes_; }

private:
    const Mesh* mesh_;
    void* device_ = nullptr;  // RTCDevice, kept opaque so that users need no Embree headers
    void* scene_ = nullptr;   // RTCScene
    size_t bvh_bytes_ = 0;
};

}  // namespace candela
