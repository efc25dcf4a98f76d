#include "integrator/desc.h"

namespace candela {

int aov_channel_count(AovType t) { return t == AovType::Depth ? 1 : 3; }

int aov_channel_count(const std::vector<AovSpec>& aovs) {
    int n = 0;
    for (const AovSpec& a : aovs) n += aov_channel_count(a.type);
    return n;
}

std::vector<std::string> aov_channel_names(const std::vector<AovSpec>& aovs) {
    std::vector<std::string> names;
    for (const AovSpec& a : aovs) {
        // Mitsuba's aov.cpp suffixes.
        const char* const* sfx;
        static const char* const t[] = {".T"}, *xyz[] = {".X", ".Y", ".Z"}, *rgb[] = {".R", ".G", ".B"};
        sfx = a.type == AovType::Depth ? t : a.type == AovType::Albedo ? rgb : xyz;
        for (int k = 0; k < aov_channel_count(a.type); ++k) names.push_back(a.name + sfx[k]);
    }
    return names;
}

bool parse_aov_type(const std::string& s, AovType& out) {
    if (s == "depth") out = AovType::Depth;
    else if (s == "position") out = AovType::Position;
    else if (s == "geo_normal") out = AovType::GeoNormal;
    else if (s == "sh_normal") out = AovType::ShNormal;
    else if (s == "albedo") out = AovType::Albedo;
    else return false;
    return true;
}

}  // namespace candela
