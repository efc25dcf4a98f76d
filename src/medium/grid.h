#pragma once
// Mitsuba's volume grids (`gridvolume`, the binary .vol format of Mitsuba 0.6 and 3) and their
// lookup with Mitsuba 3's filtering.
//
// .vol: "VOL", version byte 3, int32 encoding (1: float32, the one Mitsuba 3 reads), int32 xres,
// yres, zres, int32 channels, 6 float32 (the grid's bounding box: xmin ymin zmin xmax ymax zmax),
// then xres yres zres channels float32 values, x fastest: value(x, y, z, c) at
// ((z yres + y) xres + x) channels + c. Little-endian.
//
// Lookup: a point p of the unit cube [0, 1]^3 (the grid's local space); voxel (x, y, z) is centred at
// ((x, y, z) + 0.5) / res. Trilinear: between the 8 nearest centres, the coordinates clamped to the
// grid at its faces (Mitsuba's clamp wrap mode); nearest: the voxel containing p.
#include <cstdint>
#include <string>
#include <vector>
#include "core/aabb.h"
#include "core/math.h"

namespace candela {

struct VolumeGrid {
    glm::ivec3 res{0};
    int channels = 0;   // 1 or 3
    AABB bbox;          // the file's bounding box (gridvolume's use_grid_bbox)
    std::vector<float> data;
    float max_value = 0.f;  // over every voxel and channel
    bool nearest = false;   // filter_type "nearest" (else trilinear)

    // The value at p (unit-cube coordinates) as RGB: a one-channel grid is grey.
    vec3 eval(vec3 p) const;
    float eval_1(vec3 p) const { return eval(p).x; }  // one-channel grids
};

// Parses .vol bytes. Throws Error(name, 0, why) for a bad magic or version, an encoding other than
// float32, a resolution or channel count out of range, a grid larger than kMaxVoxels values, data
// shorter or longer than the header says, a value that is NaN or infinite.
VolumeGrid parse_vol(const std::string& name, const std::string& bytes);
VolumeGrid read_vol(const std::string& path);

constexpr uint64_t kMaxVolValues = uint64_t(1) << 28;  // 1 GiB of float32: larger is refused

}  // namespace candela
