#pragma once
// Scalar and vector basics shared by the whole library: GLM float vectors,
// constants and the guarded elementary functions used wherever rounding can
// push an argument out of its domain.
#include <glm/glm.hpp>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numbers>

namespace mcrt {

using vec2 = glm::vec2;
using vec3 = glm::vec3;
using dvec2 = glm::dvec2;
using dvec3 = glm::dvec3;
using color = glm::vec3;

inline constexpr float pi = std::numbers::pi_v<float>;
inline constexpr float two_pi = 2.0f * std::numbers::pi_v<float>;
inline constexpr float inv_pi = std::numbers::inv_pi_v<float>;
inline constexpr float infinity = std::numeric_limits<float>::infinity();

template <class T>
constexpr T sqr(T x) { return x * x; }

// sqrt of a quantity that is mathematically >= 0 but may round to a tiny
// negative value (1 - cos^2, discriminants): clamp instead of returning NaN.
template <class T>
inline T safe_sqrt(T x) { return std::sqrt(std::max(x, T(0))); }

// asin / acos of a cosine or sine that may round just outside [-1, 1].
template <class T>
inline T safe_asin(T x) { return std::asin(std::clamp(x, T(-1), T(1))); }
template <class T>
inline T safe_acos(T x) { return std::acos(std::clamp(x, T(-1), T(1))); }

// Bound on the relative error of n successive float roundings, n u / (1 - n u)
// with u = 2^-24 the unit roundoff (Higham 2002, sec. 3.1; pbrt-v4's Gamma):
// the factor of the conservative error bounds of computed hit points.
constexpr float rounding_gamma(int n) {
  constexpr float u = 0x1p-24f;
  return (static_cast<float>(n) * u) / (1.0f - static_cast<float>(n) * u);
}

// The next float above / below v (pbrt-v4's NextFloatUp / NextFloatDown):
// a ray origin moved off a surface is rounded away from it, so that the
// rounding of the move cannot bring it back inside the error bound. Both
// zeros step to the smallest denormal; infinities stay.
inline float next_float_up(float v) {
  if (std::isinf(v) && v > 0.0f) return v;
  if (v == -0.0f) v = 0.0f;
  std::uint32_t ui = std::bit_cast<std::uint32_t>(v);
  ui = v >= 0.0f ? ui + 1 : ui - 1;
  return std::bit_cast<float>(ui);
}
inline float next_float_down(float v) {
  if (std::isinf(v) && v < 0.0f) return v;
  if (v == 0.0f) v = -0.0f;
  std::uint32_t ui = std::bit_cast<std::uint32_t>(v);
  ui = v > 0.0f ? ui - 1 : ui + 1;
  return std::bit_cast<float>(ui);
}

inline bool all_finite(const vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace mcrt
