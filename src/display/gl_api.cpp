#include "display/gl_api.h"

#include <cstdio>
#include <string>

#include "core/error.h"

namespace candela {

GlApi load_gl_api(GlGetProcAddress get_proc) {
    if (!get_proc) throw Error("GL loader: no get-proc-address function");
    GlApi gl;
    std::string missing;
    // The cast goes through the loader's generic pointer type to each typed entry point; that is
    // what the get-proc-address contract promises.
#define CANDELA_GL_LOAD(ret, name, params)                                   \
    gl.name = reinterpret_cast<decltype(gl.name)>(get_proc("gl" #name));       \
    if (!gl.name) missing += (missing.empty() ? "gl" : ", gl") + std::string(#name);
    CANDELA_GL_FUNCTIONS(CANDELA_GL_LOAD)
#undef CANDELA_GL_LOAD
    if (!missing.empty()) throw Error("GL loader: missing entry points: " + missing);

    GLint major = 0, minor = 0;
    gl.GetIntegerv(GL_MAJOR_VERSION, &major);
    gl.GetIntegerv(GL_MINOR_VERSION, &minor);
    gl.GetError();  // GL_MAJOR_VERSION is unknown before 3.0; the check below covers that case
    if (major < 3 || (major == 3 && minor < 3)) {
        const GLubyte* version = gl.GetString(GL_VERSION);
        throw Error(std::string("GL loader: need OpenGL 3.3 core, the context reports ") +
                    (version ? reinterpret_cast<const char*>(version) : "no version"));
    }
    return gl;
}

void check_gl_error(const GlApi& gl, const char* what) {
    GLenum first = gl.GetError();
    if (first == GL_NO_ERROR) return;
    // Drain the queue so that the next check reports only new errors.
    for (int i = 0; i < 16 && gl.GetError() != GL_NO_ERROR; ++i) {}
    char code[16];
    std::snprintf(code, sizeof(code), "0x%04x", unsigned(first));
    throw Error(std::string(what) + ": GL error " + code);
}

}  // namespace candela
