#include "support/paths.h"

namespace candela::test_paths {
const char* bin() { return CANDELA_PATH_BIN; }
const char* source_dir() { return CANDELA_PATH_SOURCE_DIR; }
const char* test_data() { return CANDELA_PATH_TEST_DATA; }
const char* assets_dir() { return CANDELA_PATH_ASSETS_DIR; }
const char* mpirun() {
#ifdef CANDELA_PATH_MPIRUN
    return CANDELA_PATH_MPIRUN;
#else
    return "mpiexec";
#endif
}
const char* fake_oidn() {
#ifdef CANDELA_PATH_FAKE_OIDN
    return CANDELA_PATH_FAKE_OIDN;
#else
    return "";
#endif
}
}  // namespace candela::test_paths
