#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace candela {

// Texels as an 8- or 16-bit file stores them, scaled to [0, 1]: row-major from the top-left,
// `channels` values per texel (1 for grey, 3 for colour), still in the file's encoding (sRGB
// values, not yet linear).
struct EncodedTexels {
    int width = 0, height = 0, channels = 0;
    std::vector<float> v;
};

// Refuses an image before decoding when its header's size is empty or over kMaxTexels ("image
// size WxH is not supported"), or when it claims more texels than `bytes` can code at most
// `texels_per_byte` (0: no such bound) ("<format> claims WxH texels, more than its N bytes can
// hold"): a truncated file is read as zeros by some decoders, and decoding hundreds of megatexels
// from a few bytes takes seconds and gigabytes. Throws Error naming `path`.
void check_image_size(const std::string& path, const char* format, long long w, long long h, size_t bytes,
                      double texels_per_byte);
// The same test without the message.
bool image_size_ok(long long w, long long h, size_t bytes, double texels_per_byte);

// Decodes a JPEG held in memory with libjpeg-turbo (the decoder Mitsuba 3 uses too, so a JPEG
// texture gives both renderers the same texels). Throws Error naming `path` on a corrupt, truncated
// or CMYK file, and before decoding one whose header claims more texels than its bytes can hold.
EncodedTexels decode_jpeg(const std::string& path, const std::vector<unsigned char>& file);

// The most texels a byte of a Huffman-coded JPEG can code: each 8 x 8 block of the fullest
// component costs at least one bit (its DC code, in a baseline or a progressive file). Arithmetic-
// coded files, rare, can spend less, and are bounded by kMaxTexels and the end of file only.
constexpr double kJpegTexelsPerByte = 512.0;

// Decodes a binary PGM (P5) or PPM (P6) held in memory: 1 or 2 bytes a sample (big-endian) by
// its maxval, values divided by maxval. Comments (#) are allowed in the header. Throws Error
// naming `path` on a bad header or a short raster.
EncodedTexels decode_pnm(const std::string& path, const std::vector<unsigned char>& file);

// Whether the bytes start as a binary PGM or PPM does ("P5" or "P6" and whitespace).
bool is_pnm(const std::vector<unsigned char>& file);

// Decodes a Radiance RGBE file (.hdr) held in memory, flat or run-length coded, "-Y height +X
// width" only, to linear RGB floats (3 a texel, from the top-left). Throws Error naming `path` on a
// bad header, a corrupt run or a short file.
std::vector<float> decode_rgbe(const std::string& path, const std::vector<unsigned char>& file, int& width, int& height);

// Whether the bytes start as a Radiance file does ("#?" and a program name, e.g. "#?RADIANCE").
bool is_rgbe(const std::vector<unsigned char>& file);

}  // namespace candela
