#pragma once
// The sensor and film plugins of the Mitsuba XML reader, on an object's parameters alone (the XML
// structure stays in the reader): `perspective`, `thinlens`, `orthographic` and `hdrfilm`, with
// Mitsuba 3.9's parameter names, defaults and checks (src/render/sensor.cpp parse_fov and
// ProjectiveCamera, src/sensors/*.cpp, src/render/film.cpp). Every value a factory reads is marked
// used; errors name the parameter's line.
#include <string>
#include <vector>
#include "scene/camera.h"
#include "scene/params.h"

namespace candela {

// True for the sensor types make_sensor builds.
bool is_supported_sensor(const std::string& type);
// "perspective, thinlens, orthographic" for messages.
const char* supported_sensors();

// The field of view Mitsuba's parse_fov reads: `fov` (degrees, in (0, 180)) along `fov_axis`, or a
// 35 mm-equivalent `focal_length` ("<x>mm", default "50mm") on the diagonal; into cam.fov_deg and
// cam.fov_axis. Also read by the projector emitter, which takes a camera's parameters.
void read_fov(const ParamSet& p, Camera& cam);

// A camera of sensor type `type` (is_supported_sensor) from its parameters. The film geometry
// (film_size, crop) is left for apply_film.
Camera make_sensor(const std::string& type, const ParamSet& p);

// What an hdrfilm says: its size, the crop window and whether the output has alpha. Parameters
// that only shape Mitsuba's own output file (banner, file_format, component_format, a pixel_format
// other than rgb/rgba) are accepted as Mitsuba 3.9 accepts them, each with a one-line note.
struct FilmDesc {
    int width = 768, height = 576;
    ivec2 crop_offset{0}, crop_size{768, 576};  // the whole film: nothing cropped
    bool alpha = false;                  // pixel_format rgba (or luminance_alpha, xyza)
    std::vector<std::string> notes;      // "file:line: what", for SceneDescription::warnings
};
FilmDesc make_hdrfilm(const ParamSet& p);

// Gives the camera the film's geometry (full size and crop window) and returns the rendered image
// size: the crop window.
ivec2 apply_film(const FilmDesc& f, Camera& cam);

}  // namespace candela
