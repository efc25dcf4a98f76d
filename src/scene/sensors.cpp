#include "scene/sensors.h"
#include <cctype>
#include <cmath>

namespace candela {

namespace {

float finite_float(const ParamSet& p, const std::string& name, float def) {
    float v = p.get_float(name, def);
    if (!std::isfinite(v)) throw p.error(name, name + " must be a finite number");
    return v;
}

}  // namespace

// The field of view of the perspective and thin lens cameras: `fov` along `fov_axis`, or a
// 35 mm-equivalent `focal_length` (a string "<x>mm" or "<x>", default "50mm") on the diagonal.
void read_fov(const ParamSet& p, Camera& cam) {
    if (p.has("fov") && p.has("focal_length"))
        throw p.error("focal_length", "give either a focal length ('focal_length') or a field of view ('fov'), not both");
    if (p.has("fov")) {
        cam.fov_deg = finite_float(p, "fov", 0.f);
        if (!(cam.fov_deg > 0.f && cam.fov_deg < 180.f)) throw p.error("fov", "fov must be in (0, 180) degrees");
        std::string axis = p.get_string("fov_axis", "x");
        for (char& c : axis) c = char(std::tolower(static_cast<unsigned char>(c)));  // Mitsuba lower-cases it
        if (axis == "x") cam.fov_axis = FovAxis::X;
        else if (axis == "y") cam.fov_axis = FovAxis::Y;
        else if (axis == "diagonal") cam.fov_axis = FovAxis::Diagonal;
        else if (axis == "smaller") cam.fov_axis = FovAxis::Smaller;
        else if (axis == "larger") cam.fov_axis = FovAxis::Larger;
        else throw p.error("fov_axis", "unknown fov_axis '" + axis + "' (x, y, diagonal, smaller or larger)");
        return;
    }
    std::string f = p.get_string("focal_length", "50mm");
    if (f.size() > 2 && f.compare(f.size() - 2, 2, "mm") == 0) f.resize(f.size() - 2);
    double mm = 0.0;
    try {
        mm = double(parse_float_strict(f));
    } catch (const std::exception&) {
        throw p.error("focal_length", "focal_length must be of the form '<x>mm' (e.g. '50mm'), not '" +
                                          p.get_string("focal_length", "") + "'");
    }
    if (!(mm > 0.0) || !std::isfinite(mm)) throw p.error("focal_length", "focal_length must be positive");
    cam.fov_deg = float(focal_length_to_fov(mm));
    cam.fov_axis = FovAxis::Diagonal;
    // Mitsuba reads fov_axis only with fov: without one it is not an error, and does nothing.
    if (p.has("fov_axis")) p.get_string("fov_axis", "");
}

namespace {

// What every projective camera reads (Mitsuba's Sensor and ProjectiveCamera constructors).
void read_projective(const ParamSet& p, Camera& cam, bool rigid) {
    cam.near_clip = finite_float(p, "near_clip", 1e-2f);
    cam.far_clip = finite_float(p, "far_clip", 1e4f);
    if (!(cam.near_clip > 0.f)) throw p.error("near_clip", "near_clip must be positive");
    if (!(cam.far_clip > cam.near_clip)) throw p.error("far_clip", "far_clip must be greater than near_clip");
    // Every projective camera reads it; only the thin lens uses it.
    cam.focus_distance = finite_float(p, "focus_distance", cam.far_clip);
    // A shutter interval only matters for animated transforms, which candela has none of.
    float open = finite_float(p, "shutter_open", 0.f), close = finite_float(p, "shutter_close", 0.f);
    if (close < open) throw p.error("shutter_close", "shutter_close must not be before shutter_open");
    cam.to_world = p.get_transform("to_world", mat4(1.f));
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row)
            if (!std::isfinite(cam.to_world[col][row])) throw p.error("to_world", "the sensor's to_world is not finite");
    for (int col = 0; col < 3; ++col) {
        float len2 = glm::dot(vec3(cam.to_world[col]), vec3(cam.to_world[col]));
        if (rigid && std::abs(len2 - 1.f) > 1e-3f)
            throw p.error("to_world", "the sensor's to_world must not scale (Mitsuba rejects it too)");
        if (!rigid && !(len2 > 0.f)) throw p.error("to_world", "the sensor's to_world is singular");
    }
}

}  // namespace

bool is_supported_sensor(const std::string& type) {
    return type == "perspective" || type == "thinlens" || type == "orthographic";
}
const char* supported_sensors() { return "perspective, thinlens, orthographic"; }

Camera make_sensor(const std::string& type, const ParamSet& p) {
    Camera cam;
    if (type == "orthographic") {
        // The extent is to_world's: camera space [-1, 1] x [-1/aspect, 1/aspect] on the near plane.
        cam.type = CameraType::Orthographic;
        read_projective(p, cam, false);
        return cam;
    }
    read_fov(p, cam);
    read_projective(p, cam, true);
    if (type == "thinlens") {
        cam.type = CameraType::ThinLens;
        if (!p.has("aperture_radius")) throw p.error("aperture_radius", "thinlens needs an 'aperture_radius' (Mitsuba requires it)");
        cam.aperture_radius = finite_float(p, "aperture_radius", 0.f);
        if (cam.aperture_radius < 0.f) throw p.error("aperture_radius", "aperture_radius must not be negative");
        // Mitsuba renders a zero aperture as one of 6e-8: a pinhole, which candela renders exactly.
        if (!(cam.focus_distance > 0.f)) throw p.error("focus_distance", "focus_distance must be positive");
    } else {
        cam.principal_point_offset = vec2(finite_float(p, "principal_point_offset_x", 0.f),
                                          finite_float(p, "principal_point_offset_y", 0.f));
    }
    return cam;
}

FilmDesc make_hdrfilm(const ParamSet& p) {
    FilmDesc f;
    f.width = p.get_int("width", 768);
    f.height = p.get_int("height", 576);
    if (f.width <= 0) throw p.error("width", "film width must be positive");
    if (f.height <= 0) throw p.error("height", "film height must be positive");
    f.crop_offset = ivec2(p.get_int("crop_offset_x", 0), p.get_int("crop_offset_y", 0));
    f.crop_size = ivec2(p.get_int("crop_width", f.width), p.get_int("crop_height", f.height));
    if (f.crop_offset.x < 0) throw p.error("crop_offset_x", "crop_offset_x must not be negative");
    if (f.crop_offset.y < 0) throw p.error("crop_offset_y", "crop_offset_y must not be negative");
    if (f.crop_size.x <= 0) throw p.error("crop_width", "crop_width must be positive");
    if (f.crop_size.y <= 0) throw p.error("crop_height", "crop_height must be positive");
    // As Mitsuba: the window must lie inside the film (64-bit sums: no overflow on absurd values).
    if (int64_t(f.crop_offset.x) + f.crop_size.x > f.width)
        throw p.error(p.has("crop_width") ? "crop_width" : "crop_offset_x",
                      "the crop window (x " + std::to_string(f.crop_offset.x) + " + width " + std::to_string(f.crop_size.x) +
                          ") does not fit in the film's width " + std::to_string(f.width));
    if (int64_t(f.crop_offset.y) + f.crop_size.y > f.height)
        throw p.error(p.has("crop_height") ? "crop_height" : "crop_offset_y",
                      "the crop window (y " + std::to_string(f.crop_offset.y) + " + height " + std::to_string(f.crop_size.y) +
                          ") does not fit in the film's height " + std::to_string(f.height));
    // Mitsuba 3.9's hdrfilm (src/films/hdrfilm.cpp): the three formats are lower-cased, checked
    // against its lists, and shape only the file it writes; candela's output is chosen by --out.
    auto note = [&](const std::string& name, const std::string& what) {
        f.notes.push_back(p.file() + ":" + std::to_string(p.line_of(name)) + ": hdrfilm: " + what);
    };
    auto lower = [](std::string v) {
        for (char& c : v) c = char(std::tolower((unsigned char)c));
        return v;
    };
    const std::string pf = lower(p.get_string("pixel_format", "rgb"));
    if (pf != "rgb" && pf != "rgba" && pf != "luminance" && pf != "luminance_alpha" && pf != "xyz" && pf != "xyza")
        throw p.error("pixel_format", "unknown pixel_format '" + pf + "' (rgb, rgba, luminance, luminance_alpha, xyz or xyza)");
    f.alpha = pf == "rgba" || pf == "luminance_alpha" || pf == "xyza";
    if (pf != "rgb" && pf != "rgba")
        note("pixel_format", "pixel_format '" + pf + "' shapes Mitsuba's output file only: candela writes RGB" +
                                 (f.alpha ? "A" : ""));
    const std::string cf = lower(p.get_string("component_format", "float16"));
    if (cf != "float16" && cf != "float32" && cf != "uint32")
        throw p.error("component_format", "unknown component_format '" + cf + "' (float16, float32 or uint32)");
    if (cf == "uint32") note("component_format", "component_format 'uint32' ignored: candela writes 32-bit float EXR");
    const std::string ff = lower(p.get_string("file_format", "openexr"));
    if (ff != "openexr" && ff != "exr" && ff != "rgbe" && ff != "pfm")
        throw p.error("file_format", "unknown file_format '" + ff + "' (openexr, exr, rgbe or pfm)");
    if (ff == "rgbe" || ff == "pfm") note("file_format", "file_format '" + ff + "' ignored: the output format is --out's extension");
    // A Mitsuba 0.x parameter that Mitsuba 3 accepts and ignores (hdrfilm marks it queried).
    if (p.has("banner")) {
        p.get_bool("banner", false);
        note("banner", "banner ignored (a Mitsuba 0.x parameter; Mitsuba 3 ignores it too)");
    }
    return f;
}

ivec2 apply_film(const FilmDesc& f, Camera& cam) {
    const bool cropped = f.crop_offset != ivec2(0) || f.crop_size != ivec2(f.width, f.height);
    cam.film_size = cropped ? ivec2(f.width, f.height) : ivec2(0);
    cam.crop_offset = cropped ? f.crop_offset : ivec2(0);
    cam.crop_size = cropped ? f.crop_size : ivec2(0);
    return f.crop_size;
}

}  // namespace candela
