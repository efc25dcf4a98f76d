#pragma once
// Where the tests find the program, the source tree and their data. The values are compiled into
// one file (paths.cpp) rather than into every test's flags, so that an object file does not
// depend on where the checkout lives (ccache can share objects between clones and worktrees).
// Force-included into every test file by tests/CMakeLists.txt.
#include <string>

namespace candela::test_paths {
const char* bin();          // the candela program
const char* source_dir();   // the repository root
const char* test_data();    // tests/data
const char* assets_dir();   // assets/: the scanned meshes and public scenes (assets/SOURCES.md)
const char* mpirun();       // mpiexec, in a build with MPI
const char* fake_oidn();    // support/fake_oidn.cpp's library, in a build with CANDELA_OIDN ("" without)
// A file under assets/ ("meshes/bunny.obj", "scenes-public/..."). The assets are part of the
// repository: a test that cannot open one fails, it never skips.
inline std::string asset(const std::string& relative) { return std::string(assets_dir()) + "/" + relative; }
}  // namespace candela::test_paths

#define CANDELA_BIN (std::string(candela::test_paths::bin()))
#define CANDELA_SOURCE_DIR (candela::test_paths::source_dir())
#define CANDELA_TEST_DATA (candela::test_paths::test_data())
#define CANDELA_ASSETS_DIR (candela::test_paths::assets_dir())
#define CANDELA_MPIRUN (candela::test_paths::mpirun())
