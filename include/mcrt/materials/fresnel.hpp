#pragma once
// Exact Fresnel reflectance of unpolarized light at a smooth interface and
// the law of reflection and refraction, after pbrt-v4 (4th ed., sec. 9.3,
// util/scattering.h: Reflect, Refract, FrDielectric, FrComplex).
//
// Conventions of pbrt-v4: eta is the RELATIVE index of refraction, the
// index of the side the normal points away from (inside) over the index of
// the side it points to (outside); directions point away from the surface.
#include <algorithm>
#include <cmath>
#include <complex>

#include "mcrt/core/math.hpp"

namespace mcrt {

// Mirror direction of wo about n (pbrt-v4 sec. 9.3, Reflect): -wo + 2 (wo . n) n.
inline vec3 reflect(const vec3& wo, const vec3& n) { return -wo + 2.0f * glm::dot(wo, n) * n; }

// Refracted direction wt of wi through the interface with normal n and
// relative IOR eta by Snell's law in vector form (pbrt-v4 sec. 9.3, Refract).
// If wi is on the side n points away from (cos theta_i < 0), the interface is
// flipped: eta -> 1/eta, n -> -n. Returns false on total internal reflection;
// otherwise wt (unit if wi and n are) and etap, the relative IOR along the
// ray: the index on wt's side over the index on wi's side.
inline bool refract(const vec3& wi, vec3 n, float eta, float& etap, vec3& wt) {
  float cos_theta_i = glm::dot(n, wi);
  // Potentially flip interface orientation for Snell's law.
  if (cos_theta_i < 0.0f) {
    eta = 1.0f / eta;
    cos_theta_i = -cos_theta_i;
    n = -n;
  }
  // cos theta_t by Snell's law, sin^2 t = sin^2 i / eta^2. The max guards
  // against cos_theta_i rounding a little above 1 for unit inputs.
  const float sin2_theta_i = std::max(0.0f, 1.0f - sqr(cos_theta_i));
  const float sin2_theta_t = sin2_theta_i / sqr(eta);
  if (sin2_theta_t >= 1.0f) return false;  // total internal reflection
  const float cos_theta_t = std::sqrt(1.0f - sin2_theta_t);
  wt = -wi / eta + (cos_theta_i / eta - cos_theta_t) * n;
  etap = eta;
  return true;
}

// Fresnel reflectance of a dielectric interface for unpolarized light
// (pbrt-v4 sec. 9.3, the Fresnel equations; FrDielectric): the mean of the
// squared amplitude coefficients r_parallel (p) and r_perpendicular (s).
// cos_theta_i < 0 means the light arrives from the inside: eta -> 1/eta.
// Returns 1 under total internal reflection.
inline float fresnel_dielectric(float cos_theta_i, float eta) {
  // A cosine rounded just past +-1 would make sin^2 negative.
  cos_theta_i = std::clamp(cos_theta_i, -1.0f, 1.0f);
  // Potentially flip interface orientation for the Fresnel equations.
  if (cos_theta_i < 0.0f) {
    eta = 1.0f / eta;
    cos_theta_i = -cos_theta_i;
  }
  const float sin2_theta_i = 1.0f - sqr(cos_theta_i);
  const float sin2_theta_t = sin2_theta_i / sqr(eta);
  if (sin2_theta_t >= 1.0f) return 1.0f;  // total internal reflection
  const float cos_theta_t = safe_sqrt(1.0f - sin2_theta_t);
  const float r_parl = (eta * cos_theta_i - cos_theta_t) / (eta * cos_theta_i + cos_theta_t);
  const float r_perp = (cos_theta_i - eta * cos_theta_t) / (cos_theta_i + eta * cos_theta_t);
  return 0.5f * (sqr(r_parl) + sqr(r_perp));
}

// Fresnel reflectance of a conductor with complex relative IOR eta + i k
// (pbrt-v4 sec. 9.3, Fresnel equations for conductors; FrComplex): the same
// equations as the dielectric's, with complex Snell's law. The incident
// side is always the outside: cos_theta_i is clamped to [0, 1].
inline float fresnel_complex(float cos_theta_i, std::complex<float> eta) {
  using complex = std::complex<float>;
  // |eta| -> 0 and |eta| -> infinity both make a perfect mirror (R -> 1 at
  // every angle); where |eta|^2 underflows or overflows single precision the
  // equations below would divide 0 by 0 or infinity by infinity.
  const float modulus2 = std::norm(eta);
  if (!(modulus2 > 1e-30f && modulus2 < 1e30f)) return 1.0f;
  cos_theta_i = std::clamp(cos_theta_i, 0.0f, 1.0f);
  const float sin2_theta_i = 1.0f - sqr(cos_theta_i);
  const complex sin2_theta_t = sin2_theta_i / (eta * eta);
  const complex cos_theta_t = std::sqrt(complex(1.0f) - sin2_theta_t);  // principal branch, as pstd::sqrt
  const complex r_parl = (eta * cos_theta_i - cos_theta_t) / (eta * cos_theta_i + cos_theta_t);
  const complex r_perp = (cos_theta_i - eta * cos_theta_t) / (cos_theta_i + eta * cos_theta_t);
  return 0.5f * (std::norm(r_parl) + std::norm(r_perp));
}

// Per RGB channel: eta and k are the real and imaginary parts of the
// conductor's relative IOR in each channel (pbrt-v4's SampledSpectrum
// overload of FrComplex, with RGB in place of wavelengths).
inline color fresnel_complex(float cos_theta_i, const color& eta, const color& k) {
  return {fresnel_complex(cos_theta_i, std::complex<float>(eta.x, k.x)),
          fresnel_complex(cos_theta_i, std::complex<float>(eta.y, k.y)),
          fresnel_complex(cos_theta_i, std::complex<float>(eta.z, k.z))};
}

}  // namespace mcrt
