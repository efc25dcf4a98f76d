#include "accel/embree.h"
#include <embree3/rtcore.h>
#include <atomic>
#include <cstdio>
#include <cstring>
#include "core/error.h"

namespace candela {
namespace {

// Called from inside Embree (C code): report only; the constructor checks rtcGetDeviceError.
void embree_error(void*, RTCError code, const char* str) {
    std::fprintf(stderr, "Embree error %d: %s\n", int(code), str ? str : "");
}

// Counts the bytes Embree allocates while this device builds (the memory monitor sees them all).
std::atomic<ptrdiff_t> g_embree_bytes{0};
bool embree_memory(void*, ssize_t bytes, bool) {
    g_embree_bytes += ptrdiff_t(bytes);
    return true;
}

}  // namespace

EmbreeAccel::EmbreeAccel(const Mesh& mesh) : mesh_(&mesh) {
    RTCDevice dev = rtcNewDevice(nullptr);
    if (!dev) throw Error("rtcNewDevice failed");
    device_ = dev;
    rtcSetDeviceErrorFunction(dev, embree_error, nullptr);
    rtcSetDeviceMemoryMonitorFunction(dev, embree_memory, nullptr);

    RTCScene scene = rtcNewScene(dev);
    scene_ = scene;
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    const size_t nv = mesh.positions.size(), nt = mesh.triangles.size();
    if (nt > 0) {
        RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
        // Embree may read 16 bytes at the last vertex: its buffers are padded by the API.
        auto* vb = static_cast<float*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
        for (size_t i = 0; i < nv; ++i) std::memcpy(vb + 3 * i, &mesh.positions[i], 3 * sizeof(float));
        auto* ib = static_cast<uint32_t*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
        for (size_t i = 0; i < nt; ++i) std::memcpy(ib + 3 * i, &mesh.triangles[i], 3 * sizeof(uint32_t));
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene, geom);
        rtcReleaseGeometry(geom);
    }
    const ptrdiff_t before = g_embree_bytes.load();
    rtcCommitScene(scene);
    bvh_bytes_ = size_t(std::max<ptrdiff_t>(0, g_embree_bytes.load() - before));
    if (rtcGetDeviceError(dev) != RTC_ERROR_NONE) {
        rtcReleaseScene(scene);
        rtcReleaseDevice(dev);
        throw Error("Embree failed to build the scene");
    }
}

EmbreeAccel::~EmbreeAccel() {
    if (scene_) rtcReleaseScene(static_cast<RTCScene>(scene_));
    if (device_) rtcReleaseDevice(static_cast<RTCDevice>(device_));
}

bool EmbreeAccel::intersect(Ray& ray, Hit& hit) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = ray.o.x; rh.ray.org_y = ray.o.y; rh.ray.org_z = ray.o.z;
    rh.ray.dir_x = ray.d.x; rh.ray.dir_y = ray.d.y; rh.ray.dir_z = ray.d.z;
    rh.ray.tnear = ray.tmin;
    rh.ray.tfar = ray.tmax;
    rh.ray.time = 0.f;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(static_cast<RTCScene>(scene_), &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    ray.tmax = rh.ray.tfar;
    hit.t = rh.ray.tfar;
    hit.b1 = rh.hit.u;  // Embree's u, v weight vertices 1 and 2, as candela's b1, b2 do
    hit.b2 = rh.hit.v;
    hit.prim = rh.hit.primID;
    return true;
}

bool EmbreeAccel::occluded(const Ray& ray) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    r.org_x = ray.o.x; r.org_y = ray.o.y; r.org_z = ray.o.z;
    r.dir_x = ray.d.x; r.dir_y = ray.d.y; r.dir_z = ray.d.z;
    r.tnear = ray.tmin;
    r.tfar = ray.tmax;
    r.time = 0.f;
    r.mask = ~0u;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(static_cast<RTCScene>(scene_), &ctx, &r);
    return r.tfar < 0.f;  // Embree sets tfar to -inf on a hit
}

}  // namespace candela
