#pragma once
// The GL entry points the display code uses, as one table of function pointers per context.
//
// Nothing in candela calls a gl* symbol directly: OSMesa and GLFW/GLX hand out function pointers
// differently (and linking libGL next to libOSMesa would bind GL 3.3 calls to whichever library
// came first), so the table is filled through the one get-proc-address function of the context
// that will run it: load_gl_api(OSMesaGetProcAddress) for headless, load_gl_api(glfwGetProcAddress)
// in the viewer window. Load it after the context is current; use it only with that context.
//
// Members drop the "gl" prefix (gl.CreateShader) so that they never collide with the prototypes
// of <GL/gl.h> or with the macros of other loaders included in the same file.
#include <GL/glcorearb.h>

namespace candela {

#if defined(_WIN32)
#define CANDELA_GLAPIENTRY __stdcall
#else
#define CANDELA_GLAPIENTRY
#endif

// The entry points, as X(return type, name without "gl", parameter list). Signatures are spelled
// out here rather than taken from the PFNGL...PROC typedefs, because <GL/gl.h> (pulled in by
// <GL/osmesa.h> and GLFW) hides the GL 1.1 typedefs of <GL/glcorearb.h> when included first.
#define CANDELA_GL_FUNCTIONS(X) \
    X(GLenum, GetError, (void)) \
    X(const GLubyte*, GetString, (GLenum name)) \
    X(void, GetIntegerv, (GLenum pname, GLint* data)) \
    X(GLboolean, IsEnabled, (GLenum cap)) \
    X(void, Enable, (GLenum cap)) \
    X(void, Disable, (GLenum cap)) \
    X(void, Viewport, (GLint x, GLint y, GLsizei width, GLsizei height)) \
    X(void, ClearColor, (GLfloat r, GLfloat g, GLfloat b, GLfloat a)) \
    X(void, Clear, (GLbitfield mask)) \
    X(void, PixelStorei, (GLenum pname, GLint param)) \
    X(void, ReadPixels, (GLint x, GLint y, GLsizei width, GLsizei height, GLenum format, GLenum type, void* pixels)) \
    X(void, DrawArrays, (GLenum mode, GLint first, GLsizei count)) \
    X(GLuint, CreateShader, (GLenum type)) \
    X(void, ShaderSource, (GLuint shader, GLsizei count, const GLchar* const* string, const GLint* length)) \
    X(void, CompileShader, (GLuint shader)) \
    X(void, GetShaderiv, (GLuint shader, GLenum pname, GLint* params)) \
    X(void, GetShaderInfoLog, (GLuint shader, GLsizei size, GLsizei* length, GLchar* log)) \
    X(void, DeleteShader, (GLuint shader)) \
    X(GLuint, CreateProgram, (void)) \
    X(void, AttachShader, (GLuint program, GLuint shader)) \
    X(void, DetachShader, (GLuint program, GLuint shader)) \
    X(void, LinkProgram, (GLuint program)) \
    X(void, GetProgramiv, (GLuint program, GLenum pname, GLint* params)) \
    X(void, GetProgramInfoLog, (GLuint program, GLsizei size, GLsizei* length, GLchar* log)) \
    X(void, DeleteProgram, (GLuint program)) \
    X(void, UseProgram, (GLuint program)) \
    X(GLint, GetUniformLocation, (GLuint program, const GLchar* name)) \
    X(void, Uniform1i, (GLint location, GLint v0)) \
    X(void, Uniform1f, (GLint location, GLfloat v0)) \
    X(void, GenTextures, (GLsizei n, GLuint* textures)) \
    X(void, DeleteTextures, (GLsizei n, const GLuint* textures)) \
    X(void, BindTexture, (GLenum target, GLuint texture)) \
    X(void, ActiveTexture, (GLenum texture)) \
    X(void, TexImage2D, (GLenum target, GLint level, GLint internalformat, GLsizei width, GLsizei height, GLint border, GLenum format, GLenum type, const void* pixels)) \
    X(void, TexSubImage2D, (GLenum target, GLint level, GLint xoffset, GLint yoffset, GLsizei width, GLsizei height, GLenum format, GLenum type, const void* pixels)) \
    X(void, TexParameteri, (GLenum target, GLenum pname, GLint param)) \
    X(void, BindBuffer, (GLenum target, GLuint buffer)) \
    X(void, BindSampler, (GLuint unit, GLuint sampler)) \
    X(void, GenVertexArrays, (GLsizei n, GLuint* arrays)) \
    X(void, DeleteVertexArrays, (GLsizei n, const GLuint* arrays)) \
    X(void, BindVertexArray, (GLuint array)) \
    X(void, GenFramebuffers, (GLsizei n, GLuint* framebuffers)) \
    X(void, DeleteFramebuffers, (GLsizei n, const GLuint* framebuffers)) \
    X(void, BindFramebuffer, (GLenum target, GLuint framebuffer)) \
    X(void, FramebufferTexture2D, (GLenum target, GLenum attachment, GLenum textarget, GLuint texture, GLint level)) \
    X(GLenum, CheckFramebufferStatus, (GLenum target)) \
    X(void, BlitFramebuffer, (GLint srcX0, GLint srcY0, GLint srcX1, GLint srcY1, GLint dstX0, GLint dstY0, GLint dstX1, GLint dstY1, GLbitfield mask, GLenum filter))

struct GlApi {
#define CANDELA_GL_MEMBER(ret, name, params) ret(CANDELA_GLAPIENTRY* name) params = nullptr;
    CANDELA_GL_FUNCTIONS(CANDELA_GL_MEMBER)
#undef CANDELA_GL_MEMBER
};

// The signature shared by OSMesaGetProcAddress and glfwGetProcAddress.
using GlProc = void (*)();
using GlGetProcAddress = GlProc (*)(const char* name);

// Fills the table from `get_proc` for the current context. Throws Error listing the missing
// entry points, and Error when the context is older than GL 3.3.
GlApi load_gl_api(GlGetProcAddress get_proc);

// Throws Error("<what>: GL error 0x....") when glGetError reports anything (and drains the queue).
void check_gl_error(const GlApi& gl, const char* what);

}  // namespace candela
