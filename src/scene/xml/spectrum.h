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

// A piecewise-linear spectrum (wavelengths in nm, strictly increasing, at least two) as linear
// sRGB, as Mitsuba's RGB variants convert a wavelength:value list:
//   values are scaled by 1 / ∫ȳ (MI_CIE_Y_NORMALIZATION) and integrated against the matching
//   functions with 1000 uniform steps over [360, 830] nm (the spectrum is zero outside its own
//   range), then XYZ -> linear sRGB (D65 white). No illuminant is multiplied in, for reflectances
//   and emitters alike: a constant spectrum of 1 gives (1, 1, 1) up to the table's rounding.
//   bounded (reflectances): the result is clamped to [0, 1]; unbounded (emitters, eta, k, int_ior,
//   ext_ior): negative components are clamped to 0.
vec3 spectrum_list_to_srgb(const std::vector<double>& wavelengths, const std::vector<double>& values, bool bounded);

}  // namespace xml
}  // namespace candela
