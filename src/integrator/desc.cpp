#include "integrator/desc.h"

namespace candela {

const char* integrator_type_name(IntegratorType t) {
    switch (t) {
        case IntegratorType::Direct: return "direct";
        case IntegratorType::Ptracer: return "ptracer";
        case IntegratorType::Bdpt: return "bdpt";
        case IntegratorType::Pssmlt: return "pssmlt";
        case IntegratorType::Mmlt: return "mmlt";
        case IntegratorType::Volpath: return "volpath";
        default: return "path";
    }
}


int aov_channel_count(AovType t) {
    switch (t) {
        case AovType::Depth:
        case AovType::PrimIndex:
        case AovType::ShapeIndex: return 1;
        case AovType::Uv: return 2;
        case AovType::Moment: return 6;
        default: return 3;
    }
}

int aov_channel_count(const std::vector<AovSpec>& aovs) {
    int n = 0;
    for (const AovSpec& a : aovs) n += aov_channel_count(a.type);
    return n;
}

std::vector<std::string> aov_channel_names(const std::vector<AovSpec>& aovs) {
    std::vector<std::string> names;
    for (const AovSpec& a : aovs) {
        // Mitsuba's aov.cpp and moment.cpp suffixes.
        if (a.type == AovType::Moment) {
            for (const char* c : {".X", ".Y", ".Z"}) names.push_back(a.name + c);
            for (const char* c : {".X", ".Y", ".Z"}) names.push_back("m2_" + a.name + c);
            continue;
        }
        const char* const* sfx;
        static const char* const t[] = {".T"}, *i[] = {".I"}, *uv[] = {".U", ".V"}, *xyz[] = {".X", ".Y", ".Z"},
                                 *rgb[] = {".R", ".G", ".B"};
        switch (a.type) {
            case AovType::Depth: sfx = t; break;
            case AovType::PrimIndex:
            case AovType::ShapeIndex: sfx = i; break;
            case AovType::Uv: sfx = uv; break;
            case AovType::Albedo:
            case AovType::DenoiseAlbedo: sfx = rgb; break;
            default: sfx = xyz; break;
        }
        for (int k = 0; k < aov_channel_count(a.type); ++k) names.push_back(a.name + sfx[k]);
    }
    return names;
}

void add_denoise_aovs(std::vector<AovSpec>& aovs) {
    bool taken = false;
    for (const AovSpec& a : aovs) {
        if (a.type == AovType::DenoiseAlbedo || a.type == AovType::DenoiseNormal) return;
        taken = taken || a.name == "albedo" || a.name == "normal";
    }
    const std::string prefix = taken ? "denoise_" : "";
    auto at = aovs.end();
    if (!aovs.empty() && aovs.back().type == AovType::Moment) --at;  // the moment channels stay last
    aovs.insert(at, {{prefix + "albedo", AovType::DenoiseAlbedo}, {prefix + "normal", AovType::DenoiseNormal}});
}

bool parse_aov_type(const std::string& s, AovType& out) {
    if (s == "depth") out = AovType::Depth;
    else if (s == "position") out = AovType::Position;
    else if (s == "geo_normal") out = AovType::GeoNormal;
    else if (s == "sh_normal") out = AovType::ShNormal;
    else if (s == "albedo") out = AovType::Albedo;
    else if (s == "uv") out = AovType::Uv;
    else if (s == "dp_du") out = AovType::DpDu;
    else if (s == "dp_dv") out = AovType::DpDv;
    else if (s == "prim_index") out = AovType::PrimIndex;
    else if (s == "shape_index") out = AovType::ShapeIndex;
    else return false;
    return true;
}

}  // namespace candela
