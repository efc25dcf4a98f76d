#pragma once
// The scanned meshes in ../shared/assets/meshes (bunny, dragon). A developer's checkout may not
// have ../shared, so a test that needs a mesh skips without it; CI has it, so under CI (the
// environment variable CI set to true or 1) a missing mesh fails the test instead: a skip there
// would let the meshes' coverage vanish unnoticed. CANDELA_SHARED_DIR in the environment overrides
// the directory the build was configured with (the tests of this rule point it elsewhere).
#include <gtest/gtest.h>
#include <cstdlib>
#include <fstream>
#include <string>

namespace candela::test {

inline std::string shared_dir() {
    const char* env = std::getenv("CANDELA_SHARED_DIR");
    return env && *env ? std::string(env) : std::string(CANDELA_SHARED_DIR);
}
inline std::string shared_mesh_path(const std::string& name) { return shared_dir() + "/assets/meshes/" + name; }
inline bool running_under_ci() {
    const char* ci = std::getenv("CI");
    return ci && (std::string(ci) == "true" || std::string(ci) == "1");
}

}  // namespace candela::test

// In a test body: returns from it, failing under CI and skipping elsewhere, when `path` (a shared
// mesh) cannot be opened.
#define CANDELA_REQUIRE_SHARED_MESH(path)                                                                  \
    do {                                                                                                   \
        const std::string candela_path_ = (path);                                                          \
        if (!std::ifstream(candela_path_)) {                                                               \
            if (candela::test::running_under_ci())                                                         \
                FAIL() << candela_path_ << " is absent, and CI=true: CI must run the scanned-mesh tests"; \
            GTEST_SKIP() << candela_path_ << " is absent";                                                 \
        }                                                                                                  \
    } while (0)
