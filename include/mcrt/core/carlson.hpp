#pragma once
// Carlson's symmetric elliptic integrals R_C, R_F and R_J in double
// precision by the duplication theorem (Carlson 1995, "Numerical computation
// of real or complex elliptic integrals", Numer. Algorithms 10, alg. 1-4;
// DLMF 19.36.i), and Legendre's incomplete integrals of the first and third
// kinds written through them (DLMF 19.25.5, 19.25.14):
//
//   F(phi | m)    = s R_F(c^2, 1 - m s^2, 1)
//   Pi(n; phi | m) = s R_F(c^2, 1 - m s^2, 1) + (n/3) s^3 R_J(c^2, 1 - m s^2, 1, 1 - n s^2)
//
// with s = sin(phi), c = cos(phi), |phi| <= pi/2. The library keeps its own
// implementation so that it depends on GLM only.
//
// Each duplication step takes the arguments 4 times closer to their mean;
// the loop stops when the scaled deviation is small enough for the
// fifth-order Taylor polynomial of Carlson's paper to leave a relative
// truncation error below `carlson_tolerance` (Carlson 1995, eq. 2.2-2.4:
// Q = (3 r)^(-1/6) max |A0 - x_i| for R_F, (r/4)^(-1/6) for R_J).
#include <algorithm>
#include <array>
#include <cmath>

#include "mcrt/core/fast_math.hpp"

namespace mcrt {

// Relative truncation error aimed at: far below float precision, so that
// the area equation of the spherical-ellipse sampler is evaluated well past
// the 1e-6 accuracy its Newton solver is held to.
inline constexpr double carlson_tolerance = 1e-12;

// The stopping factors of the duplication loops, evaluated once (std::pow is
// not constexpr): (3 r)^(-1/6) for R_F and (r/4)^(-1/6) for R_J, r =
// carlson_tolerance (Carlson 1995, eq. 2.2 and 2.4).
inline const double carlson_rf_stop = std::pow(3.0 * carlson_tolerance, -1.0 / 6.0);
inline const double carlson_rj_stop = std::pow(0.25 * carlson_tolerance, -1.0 / 6.0);

// R_C(x, y) = 1/2 int_0^inf (t + x)^(-1/2) (t + y)^(-1) dt, x >= 0, y > 0
// (DLMF 19.2.17-19.2.18): closed form in atan / atanh; a series near x = y,
// where both closed forms divide 0 by 0.
inline double carlson_rc(double x, double y) {
  const double e = (x - y) / y;  // R_C(x, y) = R_C(1 + e, 1) / sqrt(y)
  if (std::abs(e) < 1e-3) {
    // R_C(1 + e, 1) = 1 - e/6 + 3 e^2/40 - 5 e^3/112 + 35 e^4/1152 + O(e^5)
    const double r = 1.0 - e * (1.0 / 6.0 - e * (3.0 / 40.0 - e * (5.0 / 112.0 - e * (35.0 / 1152.0))));
    return r / std::sqrt(y);
  }
  if (x < y) {
    const double t = std::sqrt((y - x) / x);
    return std::atan(t) / std::sqrt(y - x);
  }
  const double t = std::sqrt((x - y) / x);  // in (0, 1): atanh is finite
  return std::atanh(t) / std::sqrt(x - y);
}

// R_C(1, 1 + e), e > -1, the form the R_J loops below need: for |e| < 1e-2
// the series atan(sqrt(e)) / sqrt(e) = sum_k (-e)^k / (2k + 1) to e^8
// (truncation below 1e-19), with neither division nor square root; the
// closed forms of carlson_rc otherwise.
inline double carlson_rc1(double e) {
  if (std::abs(e) < 1e-2) {
    double r = 1.0 / 17.0;
    for (int k = 7; k >= 0; --k) r = 1.0 / (2 * k + 1) - e * r;
    return r;
  }
  return carlson_rc(1.0, 1.0 + e);
}

namespace carlson_detail {

// The truncated Taylor series that end the duplication loops (Carlson 1995,
// eq. 2.2 and 2.4), from the scaled deviations X = (A0 - x0) / (4^n A_n),
// formed from the original arguments, free of cancellation.
// R_F: Z = -(X + Y); the series over sqrt(A_n).
inline double rf_series(double xx, double yy, double a) {
  const double zz = -(xx + yy);
  const double e2 = xx * yy - zz * zz, e3 = xx * yy * zz;
  return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / std::sqrt(a);
}
// R_J: P = -(X + Y + Z) / 2; 4^-m series / A_m^(3/2) plus 6 times the R_C sum.
inline double rj_series(double xx, double yy, double zz, double a, double scale, double sum) {
  const double pp = -0.5 * (xx + yy + zz);
  const double e2 = xx * yy + xx * zz + yy * zz - 3.0 * pp * pp;
  const double e3 = xx * yy * zz + 2.0 * e2 * pp + 4.0 * pp * pp * pp;
  const double e4 = (2.0 * xx * yy * zz + e2 * pp + 3.0 * pp * pp * pp) * pp;
  const double e5 = xx * yy * zz * pp * pp;
  const double series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0 -
                        9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0;
  return scale * series / (a * std::sqrt(a)) + 6.0 * sum;
}

// One duplication step of R_J (Carlson 1995, alg. 4): adds the step's R_C
// term 4^-m R_C(1, 1 + e_m) / d_m to sum, takes x, y, z, p 4 times closer to
// their mean and returns lambda (by which the caller moves its A_m). The four
// square roots are packed into one (each correctly rounded, as std::sqrt),
// and one division gives both 1/d_m and e_m = delta 4^-3m / d_m^2: the step
// is a chain of them.
inline double rj_step(double& x, double& y, double& z, double& p, double scale, double delta, double& sum) {
  const std::array<double, 4> r = fast_math::sqrt4(x, y, z, p);
  const double sx = r[0], sy = r[1], sz = r[2], sp = r[3];
  const double lambda = sx * (sy + sz) + sy * sz;
  const double d = (sp + sx) * (sp + sy) * (sp + sz), inv_d = 1.0 / d;
  const double e = delta * (scale * scale * scale) * (inv_d * inv_d);
  sum += scale * carlson_rc1(e) * inv_d;
  x = 0.25 * (x + lambda);
  y = 0.25 * (y + lambda);
  z = 0.25 * (z + lambda);
  p = 0.25 * (p + lambda);
  return lambda;
}

}  // namespace carlson_detail

// R_F(x, y, z) = 1/2 int_0^inf ((t + x)(t + y)(t + z))^(-1/2) dt; x, y, z >= 0,
// at most one of them 0 (Carlson 1995, alg. 1).
inline double carlson_rf(double x, double y, double z) {
  const double a0 = (x + y + z) / 3.0, x0 = x, y0 = y;
  double a = a0;
  const double q = carlson_rf_stop *
                   std::max({std::abs(a0 - x), std::abs(a0 - y), std::abs(a0 - z)});
  double scale = 1.0;  // 4^-n
  while (scale * q >= std::abs(a)) {
    const double sx = std::sqrt(x), sy = std::sqrt(y), sz = std::sqrt(z);
    const double lambda = sx * (sy + sz) + sy * sz;
    x = 0.25 * (x + lambda);
    y = 0.25 * (y + lambda);
    z = 0.25 * (z + lambda);
    a = 0.25 * (a + lambda);
    scale *= 0.25;
  }
  return carlson_detail::rf_series((a0 - x0) * scale / a, (a0 - y0) * scale / a, a);
}

// R_J(x, y, z, p) = 3/2 int_0^inf ((t + x)(t + y)(t + z))^(-1/2) (t + p)^(-1) dt;
// x, y, z >= 0 with at most one 0, p > 0 (Carlson 1995, alg. 4, with the
// d_m, e_m form of the R_C sum: DLMF 19.36.10-19.36.11).
inline double carlson_rj(double x, double y, double z, double p) {
  const double a0 = (x + y + z + 2.0 * p) / 5.0, x0 = x, y0 = y, z0 = z;
  double a = a0;
  const double delta = (p - x) * (p - y) * (p - z);
  const double q = carlson_rj_stop *
                   std::max({std::abs(a0 - x), std::abs(a0 - y), std::abs(a0 - z), std::abs(a0 - p)});
  double scale = 1.0;  // 4^-m
  double sum = 0.0;
  while (scale * q >= std::abs(a)) {
    a = 0.25 * (a + carlson_detail::rj_step(x, y, z, p, scale, delta, sum));
    scale *= 0.25;
  }
  return carlson_detail::rj_series((a0 - x0) * scale / a, (a0 - y0) * scale / a, (a0 - z0) * scale / a, a, scale,
                                   sum);
}

// R_F(x, y, z) and R_J(x, y, z, p) together: both duplicate x, y, z with the
// same lambda, so the square roots of one step serve both (the loop runs
// until the stricter of the two stopping rules holds).
inline void carlson_rf_rj(double x, double y, double z, double p, double& rf, double& rj) {
  const double af0 = (x + y + z) / 3.0, aj0 = (x + y + z + 2.0 * p) / 5.0;
  const double x0 = x, y0 = y, z0 = z;
  double af = af0, aj = aj0;
  const double delta = (p - x) * (p - y) * (p - z);
  const double qf = carlson_rf_stop *
                    std::max({std::abs(af0 - x), std::abs(af0 - y), std::abs(af0 - z)});
  const double qj = carlson_rj_stop *
                    std::max({std::abs(aj0 - x), std::abs(aj0 - y), std::abs(aj0 - z), std::abs(aj0 - p)});
  double scale = 1.0, sum = 0.0;
  while (scale * qf >= std::abs(af) || scale * qj >= std::abs(aj)) {
    const double lambda = carlson_detail::rj_step(x, y, z, p, scale, delta, sum);
    af = 0.25 * (af + lambda);
    aj = 0.25 * (aj + lambda);
    scale *= 0.25;
  }
  rf = carlson_detail::rf_series((af0 - x0) * scale / af, (af0 - y0) * scale / af, af);
  rj = carlson_detail::rj_series((aj0 - x0) * scale / aj, (aj0 - y0) * scale / aj, (aj0 - z0) * scale / aj, aj,
                                 scale, sum);
}

// Legendre's incomplete integral of the first kind F(phi | m), m = k^2 < 1,
// |phi| <= pi/2, given s = sin(phi), c = cos(phi) >= 0 (DLMF 19.25.5).
inline double ellint_f(double s, double c, double m) {
  return s * carlson_rf(c * c, 1.0 - m * s * s, 1.0);
}

// Legendre's incomplete integral of the third kind
// Pi(n; phi | m) = int_0^phi dt / ((1 - n sin^2 t) sqrt(1 - m sin^2 t)),
// n sin^2(phi) < 1 (DLMF 19.25.14; the sign convention of Boost's ellint_3).
inline double ellint_pi(double n, double s, double c, double m) {
  const double s2 = s * s, y = 1.0 - m * s2;
  return s * carlson_rf(c * c, y, 1.0) + (n / 3.0) * s * s2 * carlson_rj(c * c, y, 1.0, 1.0 - n * s2);
}

}  // namespace mcrt
