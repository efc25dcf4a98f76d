#pragma once
// The part of Intel Open Image Denoise's C API (OpenImageDenoise/oidn.h, version 2.x) that candela
// calls, declared here as the function-pointer types the loader (denoise/denoiser.cpp) looks up with
// dlsym: candela never includes OIDN's headers nor links against it, so a build needs nothing of
// it and a machine without it only loses denoising. The values of the enums are those of OIDN 2.x's
// documented API.
#include <cstddef>

namespace candela::oidn {

using Device = struct DeviceImpl*;  // OIDNDevice
using Filter = struct FilterImpl*;  // OIDNFilter

enum DeviceType : int { kDeviceDefault = 0, kDeviceCpu = 1 };        // OIDNDeviceType
enum ErrorCode : int { kErrorNone = 0 };                             // OIDNError
enum Format : int { kFormatFloat3 = 3 };                             // OIDNFormat
enum Quality : int { kQualityFast = 4, kQualityBalanced = 5, kQualityHigh = 6 };  // OIDNQuality

struct Api {
    Device (*NewDevice)(int type);
    void (*CommitDevice)(Device);
    void (*ReleaseDevice)(Device);
    void (*SetDeviceInt)(Device, const char* name, int value);
    int (*GetDeviceError)(Device, const char** message);  // the first unqueried error; clears it
    Filter (*NewFilter)(Device, const char* type);
    // An image the caller owns (host memory is device memory for the CPU device). Strides of 0:
    // packed pixels and rows.
    void (*SetSharedFilterImage)(Filter, const char* name, void* ptr, int format, size_t width, size_t height,
                                 size_t byte_offset, size_t pixel_byte_stride, size_t row_byte_stride);
    void (*SetFilterBool)(Filter, const char* name, bool value);
    void (*SetFilterInt)(Filter, const char* name, int value);
    void (*CommitFilter)(Filter);
    void (*ExecuteFilter)(Filter);
    void (*ReleaseFilter)(Filter);
};

}  // namespace candela::oidn
