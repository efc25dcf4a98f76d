#pragma once
// <spectrum> values as Mitsuba 3's RGB variants read them (src/core/xml.cpp,
// create_texture_from_spectrum; src/core/spectrum.cpp, spectrum_list_to_srgb).
#include <vector>
#include "core/math.h"

namespace candela {
namespace xml {

// The CIE 1931 2-degree colour matching functions (x̄, ȳ, z̄), linearly interpolated between the
// published 5 nm samples over [360, 830] nm; zero outside.
vec3 cie1931_xyz(double lambda_nm);

// The CIE D65 illuminant, linearly interpolated between its 5 nm samples, scaled by Mitsuba's
// MI_CIE_D65_NORMALIZATION (so that a unit reflectance under it integrates to Y = 1); zero outside
// [360, 830] nm.
double cie_d65(double lambda_nm);

// CIE XYZ -> linear sRGB (D65 white), Mitsuba's xyz_to_srgb matrix.
vec3 xyz_to_linear_srgb(double x, double y, double z);

// A piecewise-linear spectrum (wavelengths in nm, strictly increasing, at least two) as linear
// sRGB, as Mitsuba 3.9's RGB variants convert a wavelength:value list (spectrum_list_to_srgb):
//   XYZ = MI_CIE_Y_NORMALIZATION * Σ_i xyz̄(λ_i) s(λ_i) [D65(λ_i)] Δλ, 1000 uniform steps λ_i over
//   [360, 830] nm, Δλ = 470/1000 nm, s = 0 outside its own range; then XYZ -> linear sRGB.
//   d65: multiply by the normalised D65 illuminant. Mitsuba does so for every spectrum that is not
//   an emitter's (reflectances, eta, k...), so that a flat reflectance of 1 is white (1, 1, 1),
//   and not for emitters (a flat emission spectrum is then the purple-ish xyz_to_srgb(1, 1, 1)).
//   bounded (reflectances): clamped to [0, 1]; otherwise negative components are clamped to 0.
vec3 spectrum_list_to_srgb(const std::vector<double>& wavelengths, const std::vector<double>& values, bool bounded,
                           bool d65);

}  // namespace xml
}  // namespace candela
