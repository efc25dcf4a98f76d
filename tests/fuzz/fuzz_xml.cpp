// libFuzzer target: the Mitsuba XML scene loader, then build_scene (geometry checks, accelerator and
// lights), as the program does before rendering. Any input must load or throw candela::Error; a
// crash, a sanitizer report, another exception, a leak or a hang is a finding.
#include <cstdint>
#include "core/error.h"
#include "fuzz_common.h"
#include "scene/loaders.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string path = candela::fuzz::write_input("scene.xml", data, size);
    try {
        candela::build_scene(candela::load_mitsuba_xml(path, {}));
    } catch (const candela::Error&) {
        // the expected outcome for bad input
    }
    return 0;
}
