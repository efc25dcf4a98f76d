#include "sampling/sampler_desc.h"

namespace candela {

namespace {
constexpr const char* kNames[kSamplerTypeCount] = {"independent", "stratified", "multijitter",
                                                   "ldsampler",   "sobol",      "zsobol",
                                                   "orthogonal"};
}

const char* sampler_type_name(SamplerType t) { return kNames[int(t)]; }

bool parse_sampler_type(const std::string& s, SamplerType& out) {
    for (int i = 0; i < kSamplerTypeCount; ++i)
        if (s == kNames[i]) {
            out = SamplerType(i);
            return true;
        }
    return false;
}

uint32_t sampler_sample_count(SamplerType t, uint32_t n) {
    n = n < 1 ? 1 : n;
    switch (t) {
        case SamplerType::Stratified: {
            uint32_t r = 1;
            while (r * r < n) ++r;
            return r * r;
        }
        case SamplerType::Multijitter: {
            uint32_t a = 1;
            while ((a + 1) * (a + 1) <= n) ++a;
            return a * ((n + a - 1) / a);
        }
        case SamplerType::LdSampler:
        case SamplerType::ZSobol: {
            uint32_t p = 1;
            while (p < n) p <<= 1;
            return p;
        }
        case SamplerType::Orthogonal: {
            auto prime = [](uint32_t x) {
                for (uint32_t d = 2; d * d <= x; ++d)
                    if (x % d == 0) return false;
                return true;
            };
            uint32_t p = 2;
            while (p * p < n || !prime(p)) ++p;
            return p * p;
        }
        default: return n;
    }
}

}  // namespace candela
