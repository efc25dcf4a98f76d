#include "scene/params.h"
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

namespace candela {

const char* param_type_name(ParamType t) {
    switch (t) {
        case ParamType::Integer: return "integer";
        case ParamType::Float: return "float";
        case ParamType::Boolean: return "boolean";
        case ParamType::String: return "string";
        case ParamType::Rgb: return "rgb";
        case ParamType::Spectrum: return "spectrum";
        case ParamType::Point: return "point";
        case ParamType::Vector: return "vector";
        case ParamType::Transform: return "transform";
    }
    return "?";
}

float parse_float_strict(const std::string& text) {
    const char* s = text.c_str();
    char* end = nullptr;
    errno = 0;
    float v = std::strtof(s, &end);
    while (end && (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r')) ++end;
    if (end == s || *end != '\0' || text.empty()) throw std::invalid_argument("not a number");
    // strtof accepts "nan" and "inf"; a scene value that is not finite is always a mistake.
    if (!std::isfinite(v)) throw std::invalid_argument("not a finite number");
    return v;
}

long long parse_int_strict(const std::string& text) {
    const char* s = text.c_str();
    char* end = nullptr;
    errno = 0;
    long long v = std::strtoll(s, &end, 10);
    while (end && (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r')) ++end;
    if (end == s || *end != '\0' || errno == ERANGE) throw std::invalid_argument("not an integer");
    return v;
}

std::vector<float> parse_float_list(const std::string& text) {
    std::vector<float> out;
    size_t i = 0;
    while (i < text.size()) {
        char c = text[i];
        if (c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r') {
            ++i;
            continue;
        }
        size_t j = text.find_first_of(", \t\n\r", i);
        if (j == std::string::npos) j = text.size();
        out.push_back(parse_float_strict(text.substr(i, j - i)));
        i = j;
    }
    return out;
}

void ParamSet::add(Param p) {
    if (const Param* old = find(p.name))
        throw Error(file_, p.line, "parameter '" + p.name + "' of " + object_ + " is given twice (first at line " +
                                       std::to_string(old->line) + ")");
    params_.push_back(std::move(p));
}

const Param* ParamSet::find(const std::string& name) const {
    for (const Param& p : params_)
        if (p.name == name) return &p;
    return nullptr;
}

int ParamSet::line_of(const std::string& name) const {
    const Param* p = find(name);
    return p ? p->line : 0;
}

Error ParamSet::error(const std::string& name, const std::string& what) const {
    return Error(file_, line_of(name), what);
}

const Param* ParamSet::fetch(const std::string& name, ParamType want, ParamType alt, ParamType alt2) const {
    const Param* p = find(name);
    if (!p) return nullptr;
    p->used = true;
    if (p->type != want && p->type != alt && p->type != alt2)
        throw Error(file_, p->line, "parameter '" + name + "' of " + object_ + " must be <" + param_type_name(want) +
                                        ">, not <" + param_type_name(p->type) + ">");
    return p;
}

int ParamSet::get_int(const std::string& name, int def) const {
    const Param* p = fetch(name, ParamType::Integer, ParamType::Integer);
    if (!p) return def;
    try {
        long long v = parse_int_strict(p->value);
        if (v < INT32_MIN || v > INT32_MAX) throw std::invalid_argument("range");
        return int(v);
    } catch (const std::invalid_argument&) {
        throw Error(file_, p->line, "could not parse integer '" + p->value + "' for parameter '" + name + "'");
    }
}

float ParamSet::get_float(const std::string& name, float def) const {
    const Param* p = fetch(name, ParamType::Float, ParamType::Integer);
    if (!p) return def;
    try {
        return parse_float_strict(p->value);
    } catch (const std::invalid_argument&) {
        throw Error(file_, p->line, "could not parse float '" + p->value + "' for parameter '" + name + "'");
    }
}

bool ParamSet::get_bool(const std::string& name, bool def) const {
    const Param* p = fetch(name, ParamType::Boolean, ParamType::Boolean);
    if (!p) return def;
    std::string v = p->value;
    for (char& c : v) c = char(std::tolower((unsigned char)c));  // Mitsuba accepts "True"
    if (v == "true") return true;
    if (v == "false") return false;
    throw Error(file_, p->line, "could not parse boolean '" + p->value + "' for parameter '" + name +
                                    "' (expected true or false)");
}

std::string ParamSet::get_string(const std::string& name, const std::string& def) const {
    const Param* p = fetch(name, ParamType::String, ParamType::String);
    return p ? p->value : def;
}

vec3 ParamSet::get_rgb(const std::string& name, vec3 def) const {
    const Param* p = fetch(name, ParamType::Rgb, ParamType::Float, ParamType::Spectrum);
    if (!p) return def;
    std::vector<float> v;
    try {
        v = parse_float_list(p->value);
    } catch (const std::invalid_argument&) {
        v.clear();
    }
    if (v.size() == 1) return vec3(v[0]);
    if (v.size() == 3 && p->type != ParamType::Float) return vec3(v[0], v[1], v[2]);
    throw Error(file_, p->line, "could not parse " + std::string(param_type_name(p->type)) + " value '" + p->value +
                                    "' for parameter '" + name + "'" +
                                    (p->type == ParamType::Rgb ? " (expected 1 or 3 numbers)" : ""));
}

// The three numbers of a <point> or <vector> (`what`), or an error naming the parameter.
static vec3 parse_triple(const std::string& file, const Param& p, const char* what, const std::string& name) {
    std::vector<float> v;
    try {
        v = parse_float_list(p.value);
    } catch (const std::invalid_argument&) {
        v.clear();
    }
    if (v.size() != 3)
        throw Error(file, p.line, std::string("could not parse ") + what + " '" + p.value + "' for parameter '" + name + "'");
    return vec3(v[0], v[1], v[2]);
}

vec3 ParamSet::get_point(const std::string& name, vec3 def) const {
    const Param* p = fetch(name, ParamType::Point, ParamType::Point);
    return p ? parse_triple(file_, *p, "point", name) : def;
}

vec3 ParamSet::get_vector(const std::string& name, vec3 def) const {
    const Param* p = fetch(name, ParamType::Vector, ParamType::Vector);
    return p ? parse_triple(file_, *p, "vector", name) : def;
}

mat4 ParamSet::get_transform(const std::string& name, const mat4& def) const {
    const Param* p = fetch(name, ParamType::Transform, ParamType::Transform);
    return p ? p->transform : def;
}

void ParamSet::report_unused() const {
    for (const Param& p : params_)
        if (!p.used)
            throw Error(file_, p.line, "unused parameter '" + p.name + "' in " + object_);
}

}  // namespace candela
