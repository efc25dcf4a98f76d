#include "texture/decode.h"
#include <csetjmp>
#include <cstdio>
#include <new>
#include <jpeglib.h>
#include <jerror.h>
#include "core/error.h"

namespace candela {

namespace {

// libjpeg reports a fatal error by calling error_exit, which must not return: it jumps back to
// decode_into with the message. Warnings are recoverable (libjpeg fills damaged data in) except
// a premature end of file: a truncated texture is an error here, as a truncated PNG is, and ending
// at once bounds the work a tiny file that claims a large image can cause.
struct ErrorManager {
    jpeg_error_mgr mgr;
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void error_exit(j_common_ptr cinfo) {
    auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, e->message);
    std::longjmp(e->jump, 1);
}

void emit_message(j_common_ptr cinfo, int level) {
    if (level == -1 && cinfo->err->msg_code == JWRN_JPEG_EOF) error_exit(cinfo);
}

// Progressive files can repeat scans over the whole coefficient buffer; real encoders write a
// dozen or so. libjpeg-turbo's own tools cap them at 500 for the same reason.
constexpr int kMaxScans = 500;

void progress(j_common_ptr cinfo) {
    auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
    if (d->is_decompressor && d->input_scan_number > kMaxScans) {
        auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
        std::snprintf(e->message, sizeof e->message, "more than %d scans", kMaxScans);
        std::longjmp(e->jump, 1);
    }
}

enum class Outcome { Ok, LibjpegError, Size, Cmyk, NoMemory };

// No object with a destructor lives in this frame, so libjpeg's longjmp back to it is well
// defined; `out` belongs to the caller and is only resized between libjpeg calls.
Outcome decode_into(const std::vector<unsigned char>& file, ErrorManager& err, EncodedTexels& out,
                    std::vector<unsigned char>& rowbuf, double& per_byte) {
    jpeg_decompress_struct cinfo;
    jpeg_progress_mgr monitor;
    cinfo.err = jpeg_std_error(&err.mgr);
    err.mgr.error_exit = error_exit;
    err.mgr.emit_message = emit_message;
    err.message[0] = '\0';
    if (setjmp(err.jump)) {
        jpeg_destroy_decompress(&cinfo);
        return Outcome::LibjpegError;
    }
    jpeg_create_decompress(&cinfo);
    monitor.progress_monitor = progress;
    cinfo.progress = &monitor;
    jpeg_mem_src(&cinfo, file.data(), static_cast<unsigned long>(file.size()));
    jpeg_read_header(&cinfo, TRUE);
    Outcome refused = Outcome::Ok;
    if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) refused = Outcome::Cmyk;
    // Arithmetic coding can spend less than a bit on a block, so only Huffman files are bounded.
    per_byte = cinfo.arith_code ? 0.0 : kJpegTexelsPerByte;
    if (!image_size_ok(cinfo.image_width, cinfo.image_height, file.size(), per_byte)) refused = Outcome::Size;
    out.width = int(cinfo.image_width);
    out.height = int(cinfo.image_height);
    if (refused != Outcome::Ok) {
        jpeg_destroy_decompress(&cinfo);
        return refused;
    }
    cinfo.out_color_space = cinfo.num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_start_decompress(&cinfo);
    out.channels = cinfo.output_components;
    const size_t row = size_t(cinfo.output_width) * size_t(out.channels);
    try {
        out.v.resize(row * size_t(cinfo.output_height));
        rowbuf.resize(row);
    } catch (const std::bad_alloc&) {
        jpeg_destroy_decompress(&cinfo);
        return Outcome::NoMemory;
    }
    while (cinfo.output_scanline < cinfo.output_height) {
        float* dst = out.v.data() + row * cinfo.output_scanline;
        JSAMPROW line = rowbuf.data();
        jpeg_read_scanlines(&cinfo, &line, 1);
        for (size_t i = 0; i < row; ++i) dst[i] = float(rowbuf[i]) * (1.f / 255.f);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    return Outcome::Ok;
}

}  // namespace

EncodedTexels decode_jpeg(const std::string& path, const std::vector<unsigned char>& file) {
    ErrorManager err;
    EncodedTexels out;
    std::vector<unsigned char> rowbuf;
    double per_byte = 0.0;
    switch (decode_into(file, err, out, rowbuf, per_byte)) {
        case Outcome::Ok: return out;
        case Outcome::LibjpegError: throw Error(path, 0, std::string("cannot decode JPEG: ") + err.message);
        case Outcome::Cmyk: throw Error(path, 0, "CMYK JPEG images are not supported (save it as RGB)");
        case Outcome::NoMemory:
            throw Error(path, 0, "out of memory decoding a " + std::to_string(out.width) + "x" +
                                     std::to_string(out.height) + " JPEG");
        case Outcome::Size: break;
    }
    check_image_size(path, "JPEG", out.width, out.height, file.size(), per_byte);
    throw Error(path, 0, "internal error: JPEG size refused without a reason");
}

}  // namespace candela
