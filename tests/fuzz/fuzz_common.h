#pragma once
// Shared by the fuzz targets: the loaders take file paths, so each input is written to a file in a
// per-process scratch directory (with a small valid OBJ and MTL beside it, so that XML <shape
// type="obj"> and OBJ mtllib statements can reach real files as well as missing ones).
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace candela::fuzz {

inline const std::string& scratch_dir() {
    static const std::string dir = [] {
        char tmpl[] = "/tmp/candela-fuzz-XXXXXX";
        const char* d = mkdtemp(tmpl);
        if (!d) std::abort();
        std::string s(d);
        auto put = [&](const char* name, const char* text) {
            FILE* f = std::fopen((s + "/" + name).c_str(), "wb");
            if (!f) std::abort();
            std::fputs(text, f);
            std::fclose(f);
        };
        put("mesh.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n");
        put("m.mtl", "newmtl white\nKd 0.7 0.7 0.7\nnewmtl light\nKd 0 0 0\nKe 5 5 5\n");
        return s;
    }();
    return dir;
}

inline std::string write_input(const char* name, const uint8_t* data, size_t size) {
    std::string path = scratch_dir() + "/" + name;
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    return path;
}

}  // namespace candela::fuzz
