#pragma once
// pbrt-v4's spectral values as the linear sRGB (Rec. 709 primaries) mcrt
// renders in. pbrt-v4 renders spectrally and its RGB film integrates against
// the CIE 1931 matching functions; here a spectrum s becomes
//   XYZ = integral s(l) (xbar, ybar, zbar)(l) dl over 360-830 nm,
// converted to linear sRGB by the standard XYZ -> sRGB matrix (IEC
// 61966-2-1), with the matching functions of Wyman, Sloan & Shirley 2013
// ("Simple Analytic Approximations to the CIE XYZ Color Matching
// Functions", JCGT 2(2), the multi-lobe fit, within about 1 % of the
// tabulated functions).
//   - blackbody T: Planck's law, normalised to luminance Y = 1 (pbrt-v4
//     divides an area light's scale by its spectrum's luminance);
//   - sampled spectra ("spectrum" [l0 v0 l1 v1 ...], piecewise linear):
//     as reflectances, XYZ against the CIE illuminant E normalised so that
//     s = 1 gives white (1, 1, 1) (the sRGB white point, D65, is reached by
//     a von Kries adaptation in XYZ (Bradford) from E);
//     as illuminants, normalised to luminance 1; as IORs (unbounded), the
//     value at the three wavelengths 630, 532 and 465 nm;
//   - named spectra (IORs only: metal-Cu-eta, glass-BK7, ...): pbrt-v4's
//     tables converted once, see spectrum.cpp.
#include <optional>
#include <string>
#include <vector>

#include "mcrt/core/math.hpp"

namespace mcrt::pbrt {

enum class spectrum_use { albedo, illuminant, unbounded };

// The CIE 1931 2-degree matching functions at wavelength l (nm), by
// Wyman et al.'s multi-lobe fit.
glm::dvec3 cie_xyz_bar(double lambda_nm);

// Linear sRGB of XYZ (D65 white).
color xyz_to_linear_srgb(const glm::dvec3& xyz);

// A blackbody at T kelvin, normalised to luminance 1.
color blackbody_rgb(double kelvin);

// A piecewise-linear spectrum given as wavelength-value pairs; nullopt (and
// why) where the pairs are malformed.
std::optional<color> sampled_spectrum_rgb(const std::vector<double>& pairs, spectrum_use use, std::string& why);

// A named spectrum of pbrt-v4; nullopt (and why) for the names not supported.
std::optional<color> named_spectrum_rgb(const std::string& name, spectrum_use use, std::string& why);

}  // namespace mcrt::pbrt
