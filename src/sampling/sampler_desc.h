#pragma once
// Which sampler renders a scene (the scene's <sampler type=...>, --sampler): plain data that the
// render settings carry; sampling/samplers.h turns it into the sampler a pass runs with.
// docs/samplers.md describes each, its parameters and its dimension budget.
#include <cstdint>
#include <string>

namespace candela {

enum class SamplerType {
    Independent,  // independent uniform numbers (PCG32): Mitsuba's `independent`
    Stratified,   // jittered strata, per-dimension permuted: Mitsuba's `stratified`
    Multijitter,  // correlated multi-jittered (Kensler 2013): Mitsuba's `multijitter`
    LdSampler,    // (0,2)-sequence per dimension pair, randomly shifted and shuffled: Mitsuba's `ldsampler`
    Sobol,        // candela's: Sobol points per pixel, Owen-scrambled (Burley 2020)
    ZSobol,       // candela's: Sobol points over pixels in Z order, blue noise (Ahmed and Wonka 2020)
    Orthogonal,   // orthogonal-array Latin hypercubes, strength 2 (Jarosz et al. 2019): Mitsuba's `orthogonal`
};

struct SamplerDesc {
    SamplerType type = SamplerType::Independent;
    bool jitter = true;  // stratified, multijitter, orthogonal: a random point in the stratum (false: its centre)
    bool operator==(const SamplerDesc& o) const { return type == o.type && jitter == o.jitter; }
    bool operator!=(const SamplerDesc& o) const { return !(*this == o); }
};

// The names of --sampler and the XML plugins, in SamplerType order; kSamplerTypeCount of them.
constexpr int kSamplerTypeCount = 7;
const char* sampler_type_name(SamplerType t);
// False when `s` names no sampler candela has.
bool parse_sampler_type(const std::string& s, SamplerType& out);

// The sample count a sampler stratifies over, given the scene's sample_count n: n rounded up to a
// square (stratified), to a x b with a = floor(sqrt(n)) (multijitter), to a power of two
// (ldsampler, zsobol), to p^2 with p the smallest prime with p^2 >= n (orthogonal, so at least 4);
// n for the others. The loaders round the scene's sample_count to it, as
// Mitsuba does, so that a default render completes whole stratified sets.
uint32_t sampler_sample_count(SamplerType t, uint32_t n);

}  // namespace candela
