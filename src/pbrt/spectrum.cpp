#include "pbrt/spectrum.hpp"

#include <cmath>

namespace mcrt::pbrt {
namespace {

// A piecewise Gaussian: different widths left and right of its centre.
double g(double x, double mu, double s1, double s2) {
  const double t = (x - mu) / (x < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}

constexpr double lambda_min = 360.0, lambda_max = 830.0, step = 1.0;

// Integral of f(l) (xbar, ybar, zbar)(l) dl by the midpoint rule, 1 nm steps.
template <class F>
glm::dvec3 integrate_xyz(F&& f) {
  glm::dvec3 sum(0.0);
  for (double l = lambda_min + 0.5 * step; l < lambda_max; l += step) sum += f(l) * cie_xyz_bar(l) * step;
  return sum;
}

// Planck's law, spectral radiance at l nm for T kelvin (any constant factor:
// it is normalised away).
double planck(double lambda_nm, double t) {
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  const double l = lambda_nm * 1e-9;
  return (2.0 * h * c * c) / (std::pow(l, 5) * (std::exp((h * c) / (l * kb * t)) - 1.0));
}

// Bradford adaptation from illuminant E to D65, in XYZ.
glm::dvec3 adapt_e_to_d65(const glm::dvec3& xyz) {
  // M_Bradford, and the white points: E (1, 1, 1), D65 (0.95047, 1, 1.08883).
  const glm::dmat3 m = glm::transpose(glm::dmat3(0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296));
  const glm::dvec3 e = m * glm::dvec3(1.0), d = m * glm::dvec3(0.95047, 1.0, 1.08883);
  const glm::dvec3 cone = m * xyz;
  return glm::inverse(m) * (cone * (d / e));
}

}  // namespace

glm::dvec3 cie_xyz_bar(double l) {
  const double x = 1.056 * g(l, 599.8, 37.9, 31.0) + 0.362 * g(l, 442.0, 16.0, 26.7) - 0.065 * g(l, 501.1, 20.4, 26.2);
  const double y = 0.821 * g(l, 568.8, 46.9, 40.5) + 0.286 * g(l, 530.9, 16.3, 31.1);
  const double z = 1.217 * g(l, 437.0, 11.8, 36.0) + 0.681 * g(l, 459.0, 26.0, 13.8);
  return {x, y, z};
}

color xyz_to_linear_srgb(const glm::dvec3& c) {
  return color(float(3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z),
               float(-0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z),
               float(0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z));
}

color blackbody_rgb(double kelvin) {
  const glm::dvec3 xyz = integrate_xyz([&](double l) { return planck(l, kelvin); });
  return xyz_to_linear_srgb(xyz / xyz.y);
}

std::optional<color> sampled_spectrum_rgb(const std::vector<double>& pairs, spectrum_use use, std::string& why) {
  if (pairs.size() < 4 || pairs.size() % 2 != 0) {
    why = "must be wavelength-value pairs, at least two";
    return std::nullopt;
  }
  for (std::size_t i = 2; i < pairs.size(); i += 2)
    if (!(pairs[i] > pairs[i - 2])) {
      why = "wavelengths must increase";
      return std::nullopt;
    }
  const auto at = [&](double l) {
    if (l <= pairs[0]) return pairs[1];
    if (l >= pairs[pairs.size() - 2]) return pairs.back();
    std::size_t i = 2;
    while (pairs[i] < l) i += 2;
    const double t = (l - pairs[i - 2]) / (pairs[i] - pairs[i - 2]);
    return (1 - t) * pairs[i - 1] + t * pairs[i + 1];
  };
  if (use == spectrum_use::unbounded) return color(float(at(630.0)), float(at(532.0)), float(at(465.0)));
  const glm::dvec3 xyz = integrate_xyz(at);
  if (use == spectrum_use::illuminant) {
    if (!(xyz.y > 0.0)) {
      why = "has no luminance";
      return std::nullopt;
    }
    return xyz_to_linear_srgb(xyz / xyz.y);
  }
  const glm::dvec3 white = integrate_xyz([](double) { return 1.0; });
  return xyz_to_linear_srgb(adapt_e_to_d65(xyz / white.y));
}

namespace {

// pbrt-v4's named spectra (its tabulated measurements, src/pbrt/util/
// spectrum.cpp) converted once by the method of this file: a metal's eta
// and k integrated as reflectance-like spectra (against the matching
// functions, illuminant E adapted to D65), as Mitsuba 3's RGB variants
// convert spectral data; a glass's IOR at 550 nm. Values below 0 that the
// conversion leaves for k ~ 0 are clamped to 0.
struct named_entry {
  const char* name;
  color rgb;
};
constexpr named_entry named_spectra[] = {
    {"glass-BK7", {1.51854f, 1.51854f, 1.51854f}},     {"glass-BAF10", {1.67305f, 1.67305f, 1.67305f}},
    {"glass-FK51A", {1.4878f, 1.4878f, 1.4878f}},      {"glass-LASF9", {1.85581f, 1.85581f, 1.85581f}},
    {"glass-F5", {1.67709f, 1.67709f, 1.67709f}},      {"glass-F10", {1.73357f, 1.73357f, 1.73357f}},
    {"glass-F11", {1.79112f, 1.79112f, 1.79112f}},     {"metal-Ag-eta", {0.128661f, 0.123346f, 0.151831f}},
    {"metal-Ag-k", {4.07651f, 3.30939f, 2.37055f}},    {"metal-Al-eta", {1.42089f, 0.937391f, 0.577384f}},
    {"metal-Al-k", {7.74914f, 6.6383f, 5.33153f}},     {"metal-Au-eta", {0.0771668f, 0.390458f, 1.57352f}},
    {"metal-Au-k", {3.38512f, 2.53215f, 1.77101f}},    {"metal-Cu-eta", {0.0664227f, 0.966261f, 1.20706f}},
    {"metal-Cu-k", {3.30469f, 2.60231f, 2.35849f}},    {"metal-CuZn-eta", {0.415342f, 0.513783f, 1.13897f}},
    {"metal-CuZn-k", {3.688f, 2.7056f, 1.7608f}},      {"metal-MgO-eta", {1.72586f, 1.74324f, 1.75283f}},
    {"metal-MgO-k", {0.0f, 0.0f, 0.0f}},               {"metal-TiO2-eta", {2.84447f, 2.95747f, 3.19054f}},
    {"metal-TiO2-k", {7.88159e-05f, 0.0f, 0.000693437f}},
};

}  // namespace

std::optional<color> named_spectrum_rgb(const std::string& name, spectrum_use use, std::string& why) {
  if (use == spectrum_use::unbounded)
    for (const named_entry& e : named_spectra)
      if (name == e.name) return e.rgb;
  std::string names;
  for (const named_entry& e : named_spectra) names += std::string(names.empty() ? "" : ", ") + e.name;
  if (use != spectrum_use::unbounded)
    why = "names the spectrum \"" + name + "\": named spectra are supported only for IORs (eta, k)";
  else
    why = "names the spectrum \"" + name + "\", which is not supported (supported: " + names + ")";
  return std::nullopt;
}

}  // namespace mcrt::pbrt
