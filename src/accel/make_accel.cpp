#include "accel/accel.h"
#include "accel/brute.h"
#include "accel/grid.h"
#include "accel/kdtree.h"
#include "core/error.h"
#ifdef CANDELA_HAS_EMBREE
#include "accel/embree.h"
#endif

namespace candela {

std::unique_ptr<Accel> make_accel(const std::string& name, const Mesh& mesh) {
    if (name == "kdtree" || name == "auto") return std::make_unique<KdTreeAccel>(mesh);
    if (name == "hybrid") return std::make_unique<HybridGridAccel>(mesh);
    if (name == "brute") return std::make_unique<BruteForceAccel>(mesh);
#ifdef CANDELA_HAS_EMBREE
    if (name == "embree") return std::make_unique<EmbreeAccel>(mesh);
    throw Error("unknown accelerator '" + name + "' (expected: auto, kdtree, hybrid, brute, embree)");
#else
    throw Error("unknown accelerator '" + name + "' (expected: auto, kdtree, hybrid, brute)");
#endif
}

}  // namespace candela
