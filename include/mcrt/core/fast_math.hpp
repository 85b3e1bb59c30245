#pragma once
// Elementary functions in double without libm calls or data-dependent
// branches, for the set-ups of the solid-angle samplers, which run once per
// shading point and are chains of dependent operations: atan2 on the upper
// half-plane, sin and cos on [0, pi/2], and square roots packed four at a
// time. Each is accurate to a few ulp (stated per function), so the
// samplers keep the accuracy their comments claim.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#if defined(__AVX__) || defined(__SSE2__)
#include <immintrin.h>
#endif

namespace mcrt {

namespace fast_math {

// atan2(y, x) for y >= 0, in [0, pi], to 5e-15 relative (the fit's bound;
// under 10 ulp measured, tests/test_fast_math.cpp),
// without a branch or a libm call: the reductions of Cephes' atan (S. L.
// Moshier, "Methods and Programs for Mathematical Functions", 1989), t =
// a / b -> 1/t and t -> (t - 1)/(t + 1) down to |t| <= tan(pi/8), selected
// by signs (copysign), not by branches, which would be mispredicted from one
// observer to the next; then atan(t) = t + t z P(z), z = t^2, with P of
// degree 8 a Chebyshev fit of (atan(t) / t - 1) / z on [0, tan^2(pi/8)]
// (mpmath.chebyfit, 40 digits; relative error of atan below 5e-15),
// evaluated by Estrin's scheme. One division. Small angles keep their
// relative precision.
inline double atan2_upper(double y, double x) {
  const double ax = std::abs(x);
  const double a = std::min(y, ax), b = std::max(y, ax);  // t = a / b in [0, 1]
  const double mid = 0.5 - std::copysign(0.5, 0.41421356237309503 * b - a);  // 1 iff atan(t) > pi / 8
  const double t = (a - mid * b) / (b + mid * a);
  // The result is off + scale * atan(t): atan(a / b) = mid pi / 4 + atan(t);
  // y > |x| (keep = -1) takes pi / 2 minus it, x < 0 (sx = -1) pi minus
  // that. Formed in parallel with the division.
  const double keep = std::copysign(1.0, ax - y), sx = std::copysign(1.0, x);
  const double scale = sx * keep;
  const double off = scale * mid * (std::numbers::pi / 4.0) + sx * (0.5 - 0.5 * keep) * (std::numbers::pi / 2.0) +
                     (0.5 - 0.5 * sx) * std::numbers::pi;
  const double z = t * t, z2 = z * z, z4 = z2 * z2;
  const double p01 = -0.33333333333330926096 + 0.199999999977248869 * z;
  const double p23 = -0.1428571393037856691 + 0.1111108964921105538 * z;
  const double p45 = -0.090902559526906562104 + 0.076810452027429472637 * z;
  const double p67 = -0.065509073075630907133 + 0.051688349359193618931 * z;
  const double p = (p01 + z2 * p23) + z4 * ((p45 + z2 * p67) + z4 * -0.027232884060574881754);
  const double st = scale * t;
  return off + (st + st * z * p);
}

// sin and cos of a in [0, pi/2] to a few ulp of double (relative; sin keeps
// its relative precision for small a), without a branch or a libm call:
// s = a + a z S(z), c = 1 + z C(z), z = a^2, S and C of degree 6 Chebyshev
// fits on [0, (pi/2)^2] (mpmath.chebyfit, 40 digits; relative errors below
// 5e-16 and 8e-15), evaluated by Estrin's scheme. Measured: sin within 1e-15
// relative, cos within 8e-15 absolute (tests/test_fast_math.cpp).
inline void sincos_quadrant(double a, double& s, double& c) {
  const double z = a * a, z2 = z * z, z4 = z2 * z2;
  const double s01 = -0.16666666666666648035 + 0.0083333333333259326765 * z;
  const double s23 = -0.00019841269836469024924 + 2.7557318055685784254e-6 * z;
  const double s45 = -2.5051972921545551591e-8 + 1.6050972244135634775e-10 * z;
  s = a + a * z * ((s01 + z2 * s23) + z4 * (s45 + z2 * -7.4080548895426098568e-13));
  const double c01 = -0.49999999999999684203 + 0.041666666666541228256 * z;
  const double c23 = -0.0013888888880751316294 + 0.000024801585321095496471 * z;
  const double c45 = -2.7557089550661794834e-7 + 2.086306804599395415e-9 * z;
  c = 1.0 + z * ((c01 + z2 * c23) + z4 * (c45 + z2 * -1.1064990517793409977e-11));
}

// Square roots, and their reciprocals, of four doubles: one packed square
// root (and one packed division) where AVX is available, four otherwise.
// Square roots and divisions share one slow unit; packed, four cost about
// as much as one. Built in registers (four scalar stores read back as one
// vector would stall store-to-load forwarding).
inline std::array<double, 4> sqrt4(double a, double b, double c, double d) {
  std::array<double, 4> y;
#if defined(__AVX__)
  _mm256_storeu_pd(y.data(), _mm256_sqrt_pd(_mm256_set_pd(d, c, b, a)));
#else
  y = {std::sqrt(a), std::sqrt(b), std::sqrt(c), std::sqrt(d)};
#endif
  return y;
}
inline std::array<double, 4> inverse_sqrt4(double a, double b, double c, double d) {
  std::array<double, 4> y;
#if defined(__AVX__)
  _mm256_storeu_pd(y.data(), _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_sqrt_pd(_mm256_set_pd(d, c, b, a))));
#else
  y = {1.0 / std::sqrt(a), 1.0 / std::sqrt(b), 1.0 / std::sqrt(c), 1.0 / std::sqrt(d)};
#endif
  return y;
}

// The same for four floats (one SSE square root), and four reciprocals of
// floats (one SSE division).
inline std::array<float, 4> sqrt4(float a, float b, float c, float d) {
  std::array<float, 4> y;
#if defined(__SSE2__)
  _mm_storeu_ps(y.data(), _mm_sqrt_ps(_mm_set_ps(d, c, b, a)));
#else
  y = {std::sqrt(a), std::sqrt(b), std::sqrt(c), std::sqrt(d)};
#endif
  return y;
}
inline std::array<float, 4> reciprocal4(float a, float b, float c, float d) {
  std::array<float, 4> y;
#if defined(__SSE2__)
  _mm_storeu_ps(y.data(), _mm_div_ps(_mm_set1_ps(1.0f), _mm_set_ps(d, c, b, a)));
#else
  y = {1.0f / a, 1.0f / b, 1.0f / c, 1.0f / d};
#endif
  return y;
}

}  // namespace fast_math

}  // namespace mcrt
