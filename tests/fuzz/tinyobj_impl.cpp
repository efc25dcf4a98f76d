// tinyobjloader's implementation compiled into the fuzz build (Debian's is a prebuilt library),
// so that ASan and the coverage instrumentation see inside it too.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
