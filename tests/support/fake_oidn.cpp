// A stand-in for libOpenImageDenoise.so.2 that fails inside the library, as a real one does when it
// runs out of memory or meets a device it cannot use: every call succeeds until the first filter
// executes, which records an error that oidnGetDeviceError then reports (OIDN's own error model).
// The tests point CANDELA_OIDN_LIBRARY at it (test_denoise.cpp, Denoise.FailureInsideTheLibrary...):
// a real library cannot be made to fail on demand.
#include <cstddef>

namespace {
struct Device {
    int error = 0;
    const char* message = nullptr;
};
Device g_device;
int g_filter;  // filters are opaque handles; one address serves for all
}  // namespace

extern "C" {
void* oidnNewDevice(int) { return &g_device; }
void oidnCommitDevice(void*) {}
void oidnReleaseDevice(void*) {}
void oidnSetDeviceInt(void*, const char*, int) {}
int oidnGetDeviceError(void* device, const char** message) {
    Device* d = device ? static_cast<Device*>(device) : &g_device;
    const int e = d->error;
    if (message) *message = e ? d->message : nullptr;
    d->error = 0;  // the first unqueried error, then cleared
    return e;
}
void* oidnNewFilter(void*, const char*) { return &g_filter; }
void oidnSetSharedFilterImage(void*, const char*, void*, int, size_t, size_t, size_t, size_t, size_t) {}
void oidnSetFilterBool(void*, const char*, bool) {}
void oidnSetFilterInt(void*, const char*, int) {}
void oidnCommitFilter(void*) {}
void oidnExecuteFilter(void*) {
    if (!g_device.error) {
        g_device.error = 5;  // OIDN_ERROR_OUT_OF_MEMORY
        g_device.message = "out of memory\n(fake library for tests)";
    }
}
void oidnReleaseFilter(void*) {}
}
