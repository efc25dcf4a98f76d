#pragma once
// Named, typed parameters of one scene object (a sensor, a bsdf, a shape...), as read from the
// scene file. The object's factory reads what it understands with the typed getters, each of which
// marks the parameter as used; report_unused() then rejects whatever is left (a misspelled or
// unsupported parameter), naming the file and line, like pbrt-v4's ParameterDictionary::ReportUnused
// and Mitsuba 3's "unreferenced property" check. Values are kept as text and parsed on use, so a
// wrong type is reported against the parameter's own line.
#include <string>
#include <vector>
#include "core/error.h"
#include "core/math.h"

namespace candela {

enum class ParamType { Integer, Float, Boolean, String, Rgb, Spectrum, Point, Vector, Transform };

const char* param_type_name(ParamType t);  // the XML tag: "integer", "float", ...

struct Param {
    std::string name;
    ParamType type = ParamType::Float;
    std::string value;      // attribute text after $name substitution (unused for transforms); a
                            // <spectrum>: one number (constant) or its linear sRGB "r g b"
    mat4 transform{1.f};    // Transform only: already composed by the XML reader
    int line = 0;
    mutable bool used = false;
};

class ParamSet {
public:
    // `object` names the owner in messages, e.g. "sensor 'perspective'".
    ParamSet(std::string file, std::string object) : file_(std::move(file)), object_(std::move(object)) {}

    // Throws when the name is already present (Mitsuba rejects duplicates too).
    void add(Param p);

    bool has(const std::string& name) const { return find(name) != nullptr; }

    // Typed getters: the default when absent, an Error when present with another type or bad text.
    // get_float also takes an <integer> (exact); get_rgb also takes a <float> (grey) and a <spectrum>
    // (converted to linear sRGB by the XML reader).
    int get_int(const std::string& name, int def) const;
    float get_float(const std::string& name, float def) const;
    bool get_bool(const std::string& name, bool def) const;
    std::string get_string(const std::string& name, const std::string& def) const;
    vec3 get_rgb(const std::string& name, vec3 def) const;
    vec3 get_point(const std::string& name, vec3 def) const;  // a <point> (3 numbers)
    vec3 get_vector(const std::string& name, vec3 def) const;  // a <vector> (3 numbers)
    mat4 get_transform(const std::string& name, const mat4& def) const;

    // The line of a parameter (0 when absent), for messages about its value.
    int line_of(const std::string& name) const;
    // An Error located at the parameter (or at the object when absent).
    Error error(const std::string& name, const std::string& what) const;

    // Throws for the first parameter that no getter consumed.
    void report_unused() const;

    const std::string& file() const { return file_; }
    const std::string& object() const { return object_; }

private:
    const Param* find(const std::string& name) const;
    const Param* fetch(const std::string& name, ParamType want, ParamType alt, ParamType alt2) const;
    const Param* fetch(const std::string& name, ParamType want, ParamType alt) const { return fetch(name, want, alt, alt); }

    std::string file_, object_;
    std::vector<Param> params_;
};

// Text helpers shared by the XML reader: numbers separated by commas and/or white space.
// Throw std::invalid_argument on malformed text (callers attach the location).
std::vector<float> parse_float_list(const std::string& text);
float parse_float_strict(const std::string& text);
long long parse_int_strict(const std::string& text);

}  // namespace candela
