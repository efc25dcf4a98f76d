#include "display/display_program.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <utility>

#include "core/error.h"
#include "display/embedded_shaders.h"  // generated into the build tree by CMake
#include "display/gl_api.h"

namespace candela {

namespace {

// Runs a cleanup on scope exit, so that GL state is restored on the error paths too.
template <typename F>
struct ScopeExit {
    F f;
    ~ScopeExit() { f(); }
};
template <typename F>
ScopeExit<F> on_exit(F f) { return ScopeExit<F>{std::move(f)}; }

// GL info logs span several lines; Error messages are one line.
std::string one_line(std::string log) {
    while (!log.empty() && (log.back() == '\n' || log.back() == '\r' || log.back() == ' ' || log.back() == '\0'))
        log.pop_back();
    std::string out;
    for (char c : log) {
        if (c == '\n') out += " | ";
        else if (c != '\r') out += c;
    }
    return out.empty() ? "(no info log)" : out;
}

GLuint compile_shader(const GlApi& gl, GLenum type, const ShaderSource& src) {
    GLuint s = gl.CreateShader(type);
    if (!s) throw Error(src.origin, 0, "glCreateShader failed");
    const char* text = src.text.c_str();
    GLint length = GLint(src.text.size());
    gl.ShaderSource(s, 1, &text, &length);
    gl.CompileShader(s);
    GLint ok = 0;
    gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint n = 0;
        gl.GetShaderiv(s, GL_INFO_LOG_LENGTH, &n);
        std::string log(size_t(n > 0 ? n : 1), '\0');
        gl.GetShaderInfoLog(s, GLsizei(log.size()), nullptr, log.data());
        gl.DeleteShader(s);
        throw Error(src.origin, 0, "shader compilation failed: " + one_line(log));
    }
    return s;
}

// The state draw() touches and puts back. Everything ImGui's OpenGL3 backend relies on between
// its own backup and restore is in here, plus the enables that would corrupt our output.
struct SavedDrawState {
    GLint program, vao, active_texture, texture, sampler, viewport[4];
    static constexpr GLenum kCaps[] = {GL_BLEND, GL_DEPTH_TEST, GL_CULL_FACE, GL_SCISSOR_TEST,
                                       GL_STENCIL_TEST, GL_FRAMEBUFFER_SRGB, GL_DITHER};
    GLboolean enabled[std::size(kCaps)];

    explicit SavedDrawState(const GlApi& gl) {
        gl.GetIntegerv(GL_CURRENT_PROGRAM, &program);
        gl.GetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao);
        gl.GetIntegerv(GL_ACTIVE_TEXTURE, &active_texture);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.GetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
        gl.GetIntegerv(GL_SAMPLER_BINDING, &sampler);
        gl.GetIntegerv(GL_VIEWPORT, viewport);
        for (size_t i = 0; i < std::size(kCaps); ++i) enabled[i] = gl.IsEnabled(kCaps[i]);
    }
    void restore(const GlApi& gl) const {
        for (size_t i = 0; i < std::size(kCaps); ++i)
            enabled[i] ? gl.Enable(kCaps[i]) : gl.Disable(kCaps[i]);
        gl.Viewport(viewport[0], viewport[1], viewport[2], viewport[3]);
        gl.BindSampler(0, GLuint(sampler));
        gl.BindTexture(GL_TEXTURE_2D, GLuint(texture));
        gl.ActiveTexture(GLenum(active_texture));
        gl.BindVertexArray(GLuint(vao));
        gl.UseProgram(GLuint(program));
    }
};

// Pixel transfer state for one direction (pack = read back, unpack = upload), set to tightly
// packed rows from client memory and restored afterwards. Alignment 1 matters for widths whose
// rows are not a multiple of 4 bytes; a bound pixel buffer would turn our pointer into an offset.
struct PixelStoreScope {
    const GlApi& gl;
    GLenum buffer_target;
    GLenum names[4];
    GLint saved[4];
    GLint saved_buffer;
    PixelStoreScope(const GlApi& g, bool pack) : gl(g) {
        buffer_target = pack ? GL_PIXEL_PACK_BUFFER : GL_PIXEL_UNPACK_BUFFER;
        const GLenum p[4] = {GL_PACK_ALIGNMENT, GL_PACK_ROW_LENGTH, GL_PACK_SKIP_ROWS, GL_PACK_SKIP_PIXELS};
        const GLenum u[4] = {GL_UNPACK_ALIGNMENT, GL_UNPACK_ROW_LENGTH, GL_UNPACK_SKIP_ROWS, GL_UNPACK_SKIP_PIXELS};
        std::memcpy(names, pack ? p : u, sizeof(names));
        for (int i = 0; i < 4; ++i) gl.GetIntegerv(names[i], &saved[i]);
        gl.GetIntegerv(pack ? GL_PIXEL_PACK_BUFFER_BINDING : GL_PIXEL_UNPACK_BUFFER_BINDING, &saved_buffer);
        gl.PixelStorei(names[0], 1);
        for (int i = 1; i < 4; ++i) gl.PixelStorei(names[i], 0);
        gl.BindBuffer(buffer_target, 0);
    }
    ~PixelStoreScope() {
        for (int i = 0; i < 4; ++i) gl.PixelStorei(names[i], saved[i]);
        gl.BindBuffer(buffer_target, GLuint(saved_buffer));
    }
};

}  // namespace

const char* default_shader_dir() { return CANDELA_SHADER_DIR; }

ShaderSource load_display_shader(const std::string& shader_dir, const std::string& name) {
    if (!shader_dir.empty()) {
        std::string path = shader_dir + "/" + name;
        std::ifstream in(path, std::ios::binary);
        if (in) {
            std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            if (!in.bad()) return {path, text};
        }
    }
    if (name == "display.vert") return {"<embedded>/display.vert", embedded::kDisplayVert};
    if (name == "display.frag") return {"<embedded>/display.frag", embedded::kDisplayFrag};
    throw Error(name, 0, "no such display shader");
}

DisplayProgram::DisplayProgram(const GlApi& gl_table, const std::string& shader_dir)
    : gl_(std::make_unique<GlApi>(gl_table)) {
    const GlApi& gl = *gl_;
    const ShaderSource vs_src = load_display_shader(shader_dir, "display.vert");
    const ShaderSource fs_src = load_display_shader(shader_dir, "display.frag");
    origin_ = vs_src.origin + ", " + fs_src.origin;

    GLuint vs = compile_shader(gl, GL_VERTEX_SHADER, vs_src);
    GLuint fs = 0;
    try {
        fs = compile_shader(gl, GL_FRAGMENT_SHADER, fs_src);
    } catch (...) {
        gl.DeleteShader(vs);
        throw;
    }
    program_ = gl.CreateProgram();
    gl.AttachShader(program_, vs);
    gl.AttachShader(program_, fs);
    gl.LinkProgram(program_);
    // The shaders are not needed once linked (or once linking failed).
    gl.DetachShader(program_, vs);
    gl.DetachShader(program_, fs);
    gl.DeleteShader(vs);
    gl.DeleteShader(fs);
    GLint ok = 0;
    gl.GetProgramiv(program_, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint n = 0;
        gl.GetProgramiv(program_, GL_INFO_LOG_LENGTH, &n);
        std::string log(size_t(n > 0 ? n : 1), '\0');
        gl.GetProgramInfoLog(program_, GLsizei(log.size()), nullptr, log.data());
        gl.DeleteProgram(program_);
        throw Error(fs_src.origin, 0, "display program link failed: " + one_line(log));
    }
    loc_image_ = gl.GetUniformLocation(program_, "u_image");
    loc_exposure_ = gl.GetUniformLocation(program_, "u_exposure");
    loc_linear_ = gl.GetUniformLocation(program_, "u_linear");
    if (loc_image_ < 0 || loc_exposure_ < 0 || loc_linear_ < 0) {
        gl.DeleteProgram(program_);
        throw Error(fs_src.origin, 0, "display shader lacks a uniform (u_image, u_exposure, u_linear)");
    }
    // Core profile draws need a bound VAO even without vertex attributes.
    gl.GenVertexArrays(1, &vao_);
    try {
        check_gl_error(gl, "display program setup");
    } catch (...) {
        gl.DeleteVertexArrays(1, &vao_);
        gl.DeleteProgram(program_);
        throw;
    }
}

DisplayProgram::~DisplayProgram() {
    const GlApi& gl = *gl_;
    if (texture_) gl.DeleteTextures(1, &texture_);
    if (vao_) gl.DeleteVertexArrays(1, &vao_);
    if (program_) gl.DeleteProgram(program_);
}

void DisplayProgram::upload(int width, int height, const float* rgb) {
    const GlApi& gl = *gl_;
    if (width <= 0 || height <= 0 || !rgb)
        throw Error("display: cannot upload an empty image (" + std::to_string(width) + "x" +
                    std::to_string(height) + ")");
    GLint max_size = 0;
    gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (width > max_size || height > max_size)
        throw Error("display: image " + std::to_string(width) + "x" + std::to_string(height) +
                    " exceeds the GL texture size limit " + std::to_string(max_size));

    GLint active = 0, bound = 0;
    gl.GetIntegerv(GL_ACTIVE_TEXTURE, &active);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.GetIntegerv(GL_TEXTURE_BINDING_2D, &bound);
    auto restore = on_exit([&] {
        gl.BindTexture(GL_TEXTURE_2D, GLuint(bound));
        gl.ActiveTexture(GLenum(active));
    });
    PixelStoreScope store(gl, /*pack=*/false);

    if (!texture_) {
        gl.GenTextures(1, &texture_);
        gl.BindTexture(GL_TEXTURE_2D, texture_);
        // The shader fetches texels itself; these only keep the texture complete without mipmaps.
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    }
    gl.BindTexture(GL_TEXTURE_2D, texture_);
    if (width != width_ || height != height_) {
        gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, width, height, 0, GL_RGB, GL_FLOAT, rgb);
        check_gl_error(gl, "display: texture upload");
        width_ = width;
        height_ = height;
    } else {
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGB, GL_FLOAT, rgb);
    }
}

void DisplayProgram::draw(const DisplayRect& rect, const DisplaySettings& ds, DisplayFilter filter) const {
    if (!texture_ || rect.width <= 0 || rect.height <= 0) return;
    const GlApi& gl = *gl_;
    const SavedDrawState saved(gl);
    auto restore = on_exit([&] { saved.restore(gl); });

    for (GLenum cap : SavedDrawState::kCaps) gl.Disable(cap);
    gl.Viewport(rect.x, rect.y, rect.width, rect.height);
    gl.UseProgram(program_);
    gl.Uniform1i(loc_image_, 0);
    // A non-finite exposure would turn every pixel into NaN (shown as black): treat it as 0.
    gl.Uniform1f(loc_exposure_, std::isfinite(ds.exposure) ? ds.exposure : 0.f);
    gl.Uniform1i(loc_linear_, filter == DisplayFilter::Linear ? 1 : 0);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, texture_);
    gl.BindSampler(0, 0);  // a sampler object with mipmap filtering would make the texture incomplete
    gl.BindVertexArray(vao_);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
}

std::vector<unsigned char> DisplayProgram::read_srgb8(const DisplaySettings& ds) const {
    const GlApi& gl = *gl_;
    if (!texture_) throw Error("display: read_srgb8 before any image was uploaded");
    const int w = width_, h = height_;
    GLint max_viewport[2] = {0, 0};
    gl.GetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
    if (w > max_viewport[0] || h > max_viewport[1])
        throw Error("display: image " + std::to_string(w) + "x" + std::to_string(h) +
                    " exceeds the GL viewport limit " + std::to_string(max_viewport[0]) + "x" +
                    std::to_string(max_viewport[1]));

    GLint draw_fb = 0, read_fb = 0, active = 0, bound = 0;
    gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fb);
    gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_fb);
    gl.GetIntegerv(GL_ACTIVE_TEXTURE, &active);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.GetIntegerv(GL_TEXTURE_BINDING_2D, &bound);
    GLuint target = 0, fbo = 0;
    auto restore = on_exit([&] {
        gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(draw_fb));
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(read_fb));
        gl.BindTexture(GL_TEXTURE_2D, GLuint(bound));
        gl.ActiveTexture(GLenum(active));
        if (fbo) gl.DeleteFramebuffers(1, &fbo);
        if (target) gl.DeleteTextures(1, &target);
    });

    gl.GenTextures(1, &target);
    gl.BindTexture(GL_TEXTURE_2D, target);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    gl.GenFramebuffers(1, &fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target, 0);
    GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw Error("display: off-screen framebuffer incomplete (status " + std::to_string(status) + ")");

    draw({0, 0, w, h}, ds, DisplayFilter::Nearest);

    std::vector<unsigned char> bottom_up(size_t(w) * size_t(h) * 4);
    {
        PixelStoreScope store(gl, /*pack=*/true);
        gl.ReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
    }
    check_gl_error(gl, "display: off-screen render");

    // GL rows run bottom to top; images here are top row first.
    std::vector<unsigned char> out(bottom_up.size());
    const size_t row = size_t(w) * 4;
    for (int y = 0; y < h; ++y)
        std::memcpy(out.data() + size_t(y) * row, bottom_up.data() + size_t(h - 1 - y) * row, row);
    return out;
}

}  // namespace candela
