#include "accel/accel.h"
#include "accel/brute.h"
#include "core/error.h"

namespace candela {

std::unique_ptr<Accel> make_accel(const std::string& name, const Mesh& mesh) {
    if (name == "brute" || name == "auto") return std::make_unique<BruteForceAccel>(mesh);
    throw Error("unknown accelerator '" + name + "' (expected: auto, brute)");
}

}  // namespace candela
