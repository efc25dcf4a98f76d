#include "shapes/curve_file.h"
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include "core/error.h"
#include "shapes/mesh_file.h"

namespace candela {

CurveFile parse_curve_file(const std::string& name, const std::string& text) {
    CurveFile f;
    bool new_curve = true;
    int line_no = 0, curve_line = 0;
    auto finish_curve = [&] {
        if (new_curve) return;
        const size_t n = f.points.size() - f.starts.back();
        if (n < 2) throw Error(name, curve_line, "a curve needs at least two control points (this one has " + std::to_string(n) + ")");
    };
    size_t at = 0;
    while (at < text.size()) {
        size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        std::string line = text.substr(at, end - at);
        at = end + 1;
        ++line_no;
        if (line.size() > 1024) throw Error(name, line_no, "line longer than 1024 characters");
        if (line.find_first_not_of(" \t\r") == std::string::npos) {
            finish_curve();
            new_curve = true;
            continue;
        }
        float v[4];
        const char* p = line.c_str();
        for (int i = 0; i < 4; ++i) {
            char* q = nullptr;
            errno = 0;
            v[i] = std::strtof(p, &q);
            if (q == p) throw Error(name, line_no, "expected 'x y z radius', got '" + line + "'");
            p = q;
        }
        const vec3 pt(v[0], v[1], v[2]);
        if (!all_finite(pt)) throw Error(name, line_no, "control point position is not finite");
        if (!std::isfinite(v[3]) || v[3] < 0.f) throw Error(name, line_no, "control point radius must be finite and >= 0");
        if (new_curve) {
            f.starts.push_back(uint32_t(f.points.size()));
            curve_line = line_no;
            new_curve = false;
        }
        f.points.push_back(pt);
        f.radii.push_back(v[3]);
        if (f.points.size() > (1u << 28)) throw Error(name, line_no, "more than 2^28 control points");
    }
    finish_curve();
    if (f.points.empty()) throw Error(name + ": no control points (an empty curve file)");
    return f;
}

CurveFile read_curve_file(const std::string& path) { return parse_curve_file(path, read_file_bytes(path)); }

}  // namespace candela
