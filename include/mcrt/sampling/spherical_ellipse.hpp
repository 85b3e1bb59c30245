#pragma once
// Uniform sampling of the solid angle subtended by an ellipse (or disk):
// the area-preserving "parallel" (cylindrical) parametrization of the
// spherical ellipse of Guillen, Urena, King, Fajardo, Georgiev, Lopez-Moreno
// and Jarabo 2017, "Area-Preserving Parametrizations for Spherical Ellipses"
// (EGSR 2017), whose area equation Omega_p(phi) = u1 Omega is the paper's
// eq. 13 (so numbered in A. Checa Molina, "Visualizacion realista por
// Monte-Carlo", undergraduate thesis, Universidad de Granada, 2020, app. A.4,
// below [CM20]), with the reduction of an arbitrary
// planar ellipse to a canonical elliptic cone (Heitz 2017, "Analytical
// calculation of the solid angle subtended by an arbitrarily positioned
// ellipsoid to a point source", NIMA 2017: eigen-decomposition of the cone's
// quadratic form).
//
// Canonical spherical ellipse. In the cone's principal frame the ellipse
// is {X^2/a^2 + Y^2/b^2 <= Z^2, Z > 0}: a >= b are the tangents of the
// spherical semi-axes (alpha = atan a, beta = atan b). Planes through the X
// axis at angle theta in [-beta, beta] cut it in arcs |X| <= x_max(theta);
// on the sphere dA = dX dtheta (Archimedes), so the parallel map is
//   theta from Omega_p(theta) = u1 Omega,  Omega_p(theta) = int_{-beta}^{theta} 2 x_max   (eq. 13)
//   X uniform on [-x_max(theta), x_max(theta)] by u2
// Substituting tan(theta) = b sin(psi), psi in [-pi/2, pi/2], the integrand
// loses its square-root end singularities (the paper's closed form of
// Omega_p through incomplete elliptic integrals of the 1st and 3rd kinds):
//   dOmega_p/dpsi = 2 a b cos^2(psi) / ((1 + b^2 sin^2 psi) sqrt(1 + a^2 cos^2 psi + b^2 sin^2 psi))
//   Omega_p(psi)  = Omega/2 + c1 b J(psi),  c1 = 2 a / sqrt(1 + a^2),  m = (a^2 - b^2)/(1 + a^2)
//   J(psi)        = int_0^psi cos^2 / ((1 + b^2 sin^2) sqrt(1 - m sin^2))
// The paper writes J = (1 + p) Pi(-b^2; psi | m) - p F(psi | m) with p = 1/b^2;
// for small b the two terms are ~1/b^2 and cancel (8 digits lost at b = 1e-4,
// all of them at b = 1e-8). Carlson's forms of F and Pi (core/carlson.hpp)
// merge them exactly:
//   J = s R_F(c^2, D, 1) - ((1 + b^2)/3) s^3 R_J(c^2, D, 1, 1 + b^2 s^2),
//   D = 1 - m s^2 = (1 + a^2 c^2 + b^2 s^2)/(1 + a^2)  (a sum of positive terms),
// which loses at most a factor ~b to cancellation (b <= 1e6 here: 1e-10).
//
// Two solvers of the area equation Omega_p = u1 Omega are policies:
//   newton_carlson_solver      closed form above + safeguarded Newton in psi
//                              (bracket, bisection fallback, planar initial
//                              guess; later steps integrate the density over
//                              the step by local Gauss-Legendre instead of
//                              evaluating the closed form again), residual
//                              <= 1e-9 Omega;
//   bisection_simpson_solver   the method of [CM20] (sec. 4.2, app. A.4), a
//                              baseline for comparison: 10 bisection steps
//                              in theta, Omega_p by a 10-interval composite
//                              Simpson rule of 2 h_p.
//
// Fallback. Where the spherical map cannot be set up accurately the light
// is sampled by area (ellipse_area.hpp) and evaluated with the exact area
// pdf d^2 / (|cos| A). The choice is made by make_ellipse_cone() from the
// ellipse and the observer only, so sample() and pdf() always agree.
// Thresholds (see ellipse_cone_limits):
//   - observer behind or in the plane (float test of ellipse::faces): no
//     sample, pdf 0, as every one-sided strategy;
//   - min_height: h / dist < 1e-9, far below the float rounding of the
//     coordinates (6e-8 relative): the plane of the light is itself
//     uncertain by more than the observer's height and the spherical
//     ellipse is thinner than float directions resolve, where area sampling
//     gives the same directions (grazing observers at 1e-6 use the map);
//   - max_tangent: b > 1e6 (observer within 1e-6 of a light that fills the
//     hemisphere, Omega > 2 pi (1 - 1e-6)): J above loses ~b ulps;
//   - max_ratio: a / b > 1e8: the eigenvalues of the cone's form span
//     (a/b)^2 > 1/eps_double, so the minor axis is no longer separated from
//     the rounding of the others; such a sliver is also narrower than the
//     float resolution of a direction (b < 1e-8 for a < 1), where area
//     sampling gives the same directions;
//   - min_omega: Omega < 1e-30 sr: 1/Omega overflows float;
//   - any non-finite quantity of the set-up.
#include <array>
#include <cstdint>
#include <numbers>

#include "mcrt/core/carlson.hpp"
#include "mcrt/core/fast_math.hpp"
#include "mcrt/core/math.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

// Canonical spherical ellipse: tangents of the semi-axes, a >= b > 0.
struct spherical_ellipse {
  double a = 0.0, b = 0.0;
};

// A slicing plane of the parallel map, by the sine and cosine of psi in
// [-pi/2, pi/2] (tan theta = b sin psi, chord half-width on the tangent
// plane Z = 1: a cos psi). c >= 0.
struct spherical_ellipse_slice {
  double s = 0.0, c = 1.0;
};

// dOmega_p/dpsi (eq. 13's integrand after the substitution tan theta = b sin psi).
inline double spherical_ellipse_slice_density(const spherical_ellipse& se, spherical_ellipse_slice sl) {
  const double a2 = se.a * se.a, b2 = se.b * se.b, c2 = sl.c * sl.c, s2 = sl.s * sl.s;
  return 2.0 * se.a * se.b * c2 / ((1.0 + b2 * s2) * std::sqrt(1.0 + a2 * c2 + b2 * s2));
}

// Omega_p(psi) - Omega/2 = c1 b J(psi), odd in psi (see the header comment).
inline double spherical_ellipse_half_partial_area(const spherical_ellipse& se, spherical_ellipse_slice sl) {
  const double a2 = se.a * se.a, b2 = se.b * se.b, c2 = sl.c * sl.c, s2 = sl.s * sl.s;
  const double d = (1.0 + a2 * c2 + b2 * s2) / (1.0 + a2);  // 1 - m s^2 without cancellation
  double rf, rj;
  carlson_rf_rj(c2, d, 1.0, 1.0 + b2 * s2, rf, rj);
  const double j = sl.s * (rf - (1.0 + b2) / 3.0 * s2 * rj);
  return 2.0 * se.a * se.b / std::sqrt(1.0 + a2) * j;
}

// Solid angle of the canonical spherical ellipse: Omega_p at psi = pi/2,
// Omega = 2 c1 b J(pi/2), with the complete J by the arithmetic-geometric
// mean instead of the duplication loops. DLMF 19.8.6-19.8.8 give, for
// Pi(n, k) with a_0 = 1, g_0 = k', p_0^2 = 1 - n, Q_0 = 1,
//   p_{j+1} = (p_j^2 + a_j g_j) / (2 p_j),  eps_j = (p_j^2 - a_j g_j) / (p_j^2 + a_j g_j),
//   Q_{j+1} = Q_j eps_j / 2,   Pi(n, k) = pi / (4 M) (2 + n / (1 - n) sum_j Q_j),
// M = AGM(1, k'), and K = pi / (2 M). Here n = -b^2 and
// k'^2 = 1 - m = (1 + b^2) / (1 + a^2), so J = (1 + 1/b^2) Pi - K / b^2
// = pi / (4 M) (1 - sum_{j>=1} Q_j) exactly (the 1/b^2 terms cancel in
// closed form). 1 - sum Q_j is ~1/b for wide cones; written as
//   1 - sum_{j>=1} Q_j = sum_{j>=1} 2^-j R_j,  R_j = 1 - eps_0 ... eps_{j-1},
//   R_{j+1} = R_j eps_j + (1 - eps_j),  1 - eps_j = 2 a_j g_j / (p_j^2 + a_j g_j),
// it is a sum of positive terms, accurate to a few ulps for every b (the
// duplication form loses ~b ulps). eps_j in [0, 1) since p_0^2 >= 1 >= g_0.
inline double spherical_ellipse_area(const spherical_ellipse& se) {
  const double a2 = se.a * se.a, b2 = se.b * se.b;
  const double inv_sa = 1.0 / std::sqrt(1.0 + a2);
  double an = 1.0, pn = std::sqrt(1.0 + b2), gn = pn * inv_sa;
  double r = 0.0, prod = 1.0, w = 0.5, sum = 0.0;
  // The AGM converges quadratically; p_j halves per step while p_j >> 1,
  // so wide cones take ~log2(b) steps (b <= 1e6 in the sampler: ~25).
  // One division per step: inv = 1 / (den p_j) gives both 1 / den and
  // p_{j+1} = den / (2 p_j).
  for (int j = 0; j < 100; ++j) {
    const double ag = an * gn, pp = pn * pn, den = pp + ag;
    const double inv = 1.0 / (den * pn);
    if (prod > 0.0) {
      const double inv_den = pn * inv;
      const double eps = (pp - ag) * inv_den;
      r = r * eps + 2.0 * ag * inv_den;
      prod *= eps;
      sum += w * r;
      // Once eps_0 ... eps_j is below the rounding of R, R_k = 1 for all
      // later k: the rest of the series is sum_{k>j+1} 2^-k = w.
      if (prod < 1e-17) {
        sum += w;
        prod = 0.0;
      }
      w *= 0.5;
    }
    pn = 0.5 * den * den * inv;
    const double an1 = 0.5 * (an + gn);
    gn = std::sqrt(ag);
    an = an1;
    if (prod == 0.0 && std::abs(an - gn) <= 1e-15 * an) break;
  }
  const double j = 0.25 * std::numbers::pi / an * sum;
  return 4.0 * se.a * se.b * inv_sa * j;
}

// Closed form + safeguarded Newton (the paper's recommendation).
struct newton_carlson_solver {
  // Newton stops once |Omega_p(psi) - u1 Omega| <= tolerance * Omega.
  static constexpr double tolerance = 1e-9;
  static constexpr int max_iterations = 60;

  static double area(const spherical_ellipse& se) { return spherical_ellipse_area(se); }

  // Omega_p: the solid angle of the part of the spherical ellipse on the
  // -psi side of the slice.
  static double partial_area(const spherical_ellipse& se, double omega, spherical_ellipse_slice sl) {
    return 0.5 * omega + spherical_ellipse_half_partial_area(se, sl);
  }

  // The slice with Omega_p = u1 Omega; `iterations` (optional) reports the
  // number of residuals examined: the closed-form one at the start, then one
  // per Newton, Halley or bisection step (by closed form or by local
  // quadrature, see below).
  static spherical_ellipse_slice invert(const spherical_ellipse& se, double omega, double u1,
                                        int* iterations = nullptr) {
    using fast_math::sincos_quadrant;
    constexpr double half_pi = 0.5 * std::numbers::pi;
    // Omega_p - Omega/2 is odd in psi: solve for |psi| on [0, pi/2].
    const double target = (u1 - 0.5) * omega;
    const double sign = target < 0.0 ? -1.0 : 1.0, goal = std::abs(target), half = 0.5 * omega;
    if (iterations) *iterations = 0;
    if (!(goal < half)) return {sign, 0.0};
    // Initial guess: the same equation for a planar ellipse (a, b -> 0), where
    // J = (psi + sin psi cos psi)/2 and the area fraction v = goal/half
    // solves 2 psi + sin 2 psi = pi v. Start from its leading behaviour at
    // either end (4 psi = pi v; (4/3) (pi/2 - psi)^3 = pi (1 - v)), then two
    // Newton steps on that cheap equation.
    const double v = goal / half;
    double psi = v < 0.5 ? 0.25 * std::numbers::pi * v : half_pi - std::cbrt(0.75 * std::numbers::pi * (1.0 - v));
    spherical_ellipse_slice sl;
    for (int i = 0; i < 2; ++i) {
      sincos_quadrant(psi, sl.s, sl.c);
      const double fp = 4.0 * sl.c * sl.c;
      if (!(fp > 1e-12)) break;  // at the end of the interval: keep the end estimate
      psi = std::clamp(psi - (2.0 * psi + 2.0 * sl.s * sl.c - std::numbers::pi * v) / fp, 0.0, half_pi);
    }
    sincos_quadrant(psi, sl.s, sl.c);
    // Newton on f(psi) = Omega_p(psi) - Omega/2 - goal, increasing on
    // [0, pi/2]; the bracket [lo, hi] shrinks with the sign of f and a step
    // leaving it is replaced by bisection (f' -> 0 as cos^2 at the end).
    //
    // f is evaluated in closed form (Carlson) where the solver starts; after
    // a step from psi to psi + d it is updated as f + int_psi^{psi+d} f',
    // the integral by 4-point Gauss-Legendre, when |d| <= delta / 8.
    // delta = min(1 / sqrt(1 + b^2), sqrt((1 + b^2) / (1 + a^2))) is a lower
    // bound on the distance from the real axis of the singularities of f'
    // (the zeros of 1 + b^2 sin^2 t at Im t = +-asinh(1/b) >= 1/sqrt(1 + b^2),
    // and of 1 + a^2 cos^2 t + b^2 sin^2 t at Im t = +-acosh(1/sqrt(m)) >=
    // sqrt(1 - m)), so f' is analytic in the Bernstein ellipse of parameter
    // rho ~ 16 around the step, and the rule's relative error is below
    // (64/15) rho^-8 / (rho^2 - 1) ~ 4e-12 times the ratio of f' at distance
    // delta/2 to f' on the step (Trefethen, "Approximation Theory and
    // Approximation Practice", thm. 19.3): negligible against the
    // tolerance, for a quarter of the cost of a closed-form evaluation.
    // Larger steps (from a poor start, or bisection) evaluate the closed form.
    //
    // f' (the slice density) decreases on [0, pi/2]: its log-derivative is
    // -2 tan psi - 2 b^2 s c / (1 + b^2 s^2) + (a^2 - b^2) s c / (1 + a^2 c^2 + b^2 s^2)
    // and the last term is at most a^2 s c / (a^2 c^2) = tan psi. So after a
    // Newton step d = -f / f'(psi) the new residual is
    //   |f(psi + d)| = |int_psi^{psi+d} (f'(t) - f'(psi)) dt| <= |d| |f'(psi + d) - f'(psi)|,
    // a bound that costs one density instead of one closed-form area: a large
    // step whose bound is within the tolerance is accepted without evaluating f.
    const double local = 0.125 * std::min(1.0 / std::sqrt(1.0 + se.b * se.b),
                                          std::sqrt((1.0 + se.b * se.b) / (1.0 + se.a * se.a)));
    double lo = 0.0, hi = half_pi;
    double f = spherical_ellipse_half_partial_area(se, sl) - goal;
    for (int it = 1; it <= max_iterations; ++it) {
      if (iterations) *iterations = it;
      if (std::abs(f) <= tolerance * omega) break;
      (f < 0.0 ? lo : hi) = psi;
      const double fp = spherical_ellipse_slice_density(se, sl);
      double next = psi - f / fp;
      const bool halley = std::abs(next - psi) <= local && sl.c > 1e-3;
      if (halley) {
        // A local step: Halley's instead of Newton's (cubic convergence),
        // d = d_N / (1 + d_N L / 2) with L = f'' / f' the log-derivative of
        // the slice density (see below); its residual is integrated, not
        // bounded, so any step inside the bracket is safe. Not within 1e-3
        // of psi = pi/2 (c <= 1e-3), where L has its -2 s / c pole and
        // Newton's step is kept.
        const double a2 = se.a * se.a, b2 = se.b * se.b, s2 = sl.s * sl.s, c2 = sl.c * sl.c;
        const double lg = -2.0 * sl.s / sl.c - 2.0 * b2 * sl.s * sl.c / (1.0 + b2 * s2) +
                          (a2 - b2) * sl.s * sl.c / (1.0 + a2 * c2 + b2 * s2);
        const double dn = next - psi;
        next = psi + dn / (1.0 + 0.5 * dn * lg);
      }
      const bool newton = next > lo && next < hi;
      if (!newton) next = 0.5 * (lo + hi);
      if (next == psi) break;  // the bracket is down to one ulp
      const double step = next - psi;
      if (std::abs(step) <= local) {
        f += local_integral(se, sl, step);
        psi = next;
        sincos_quadrant(psi, sl.s, sl.c);
        continue;
      }
      psi = next;
      sincos_quadrant(psi, sl.s, sl.c);
      // The bound holds for Newton steps only (a Halley step that ended up
      // longer than `local` is checked by the closed form).
      if (newton && !halley &&
          std::abs(step) * std::abs(spherical_ellipse_slice_density(se, sl) - fp) <= tolerance * omega)
        break;
      f = spherical_ellipse_half_partial_area(se, sl) - goal;
    }
    return {sign * sl.s, sl.c};
  }

 private:
  // int_psi^{psi+d} of the slice density by 4-point Gauss-Legendre (see
  // invert), |d| <= pi/2. sin and cos at the nodes by the addition theorem
  // from sl; the four 1 / ((1 + b^2 s^2) sqrt(1 + a^2 c^2 + b^2 s^2)) by one
  // packed square root and division.
  static double local_integral(const spherical_ellipse& se, spherical_ellipse_slice sl, double d) {
    constexpr double x0 = 0.33998104358485626480, x1 = 0.86113631159405257522;  // nodes +-x0, +-x1
    constexpr double w0 = 0.65214515486254614263, w1 = 0.34785484513745385737;
    const double h = 0.5 * d, ah = std::abs(h);
    const double offs[4] = {(1.0 - x1) * ah, (1.0 - x0) * ah, (1.0 + x0) * ah, (1.0 + x1) * ah};
    const double sd = h < 0.0 ? -1.0 : 1.0;
    const double a2 = se.a * se.a, b2 = se.b * se.b;
    double c2[4], q[4];
    for (int i = 0; i < 4; ++i) {
      double sn, cs;
      fast_math::sincos_quadrant(offs[i], sn, cs);
      const double st = sl.s * cs + sd * sl.c * sn, ct = sl.c * cs - sd * sl.s * sn;
      const double k = 1.0 + b2 * st * st;
      c2[i] = ct * ct;
      q[i] = k * k * (1.0 + a2 * c2[i] + b2 * st * st);
    }
    const std::array<double, 4> r = fast_math::inverse_sqrt4(q[0], q[1], q[2], q[3]);
    const double sum = w1 * (c2[0] * r[0] + c2[3] * r[3]) + w0 * (c2[1] * r[1] + c2[2] * r[2]);
    return 2.0 * se.a * se.b * h * sum;
  }
};

// The solver of [CM20] (sec. 4.2 and app. A.4), a baseline for comparison:
// Omega_p(theta) by a composite Simpson rule of the paper's integrand
// 2 h_p(theta) (eq. 13) with 10 intervals on [0, beta] and [0, |theta|], and
// theta by 10 bisection steps on [-beta, beta]. The integrand has
// square-root zeros at +-beta, so the rule converges as n^-1.5 and its Omega
// is low by ~2e-3 relative; pdf() is 1 / that Omega, consistent with
// sample() but not with the true density. [CM20] also stops bisection once
// the bracket is narrower than 1e-3 rad; that absolute tolerance is not
// reproduced, since for lights under 1e-3 rad it puts every sample on
// theta = 0.
struct bisection_simpson_solver {
  static constexpr int simpson_intervals = 10;
  static constexpr int bisection_steps = 10;

  // 2 h_p(theta), h_p = x_max(theta) the chord half-width on the sphere
  // (eq. 13; [CM20] app. A.4).
  static double integrand(const spherical_ellipse& se, double theta) {
    const double a2 = se.a * se.a, b2 = se.b * se.b;
    const double ct = se.a / std::sqrt(1.0 + a2), p = 1.0 / b2, m = (a2 - b2) / (a2 + 1.0);
    const double sp = sqr(std::sin(theta));
    const double disc = (1.0 - (p + 1.0) * sp) / (1.0 - (m * p + 1.0) * sp);
    return 2.0 * ct * safe_sqrt(disc);  // disc rounds below 0 at theta = +-beta
  }
  static double simpson(const spherical_ellipse& se, double t0, double t1) {
    const int n = simpson_intervals;
    const double step = (t1 - t0) / n;
    double s1 = 0.0, s2 = 0.0;
    for (int i = 0; i < n; ++i) s1 += integrand(se, t0 + step * (i + 0.5));
    for (int i = 1; i < n; ++i) s2 += integrand(se, t0 + step * i);
    return step / 6.0 * (integrand(se, t0) + integrand(se, t1) + 4.0 * s1 + 2.0 * s2);
  }
  static double beta(const spherical_ellipse& se) { return std::atan(se.b); }
  static double partial_area_theta(const spherical_ellipse& se, double theta) {
    const double whole = simpson(se, 0.0, beta(se)), part = simpson(se, 0.0, std::abs(theta));
    return theta >= 0.0 ? whole + part : whole - part;
  }

  static double area(const spherical_ellipse& se) { return 2.0 * simpson(se, 0.0, beta(se)); }
  static double partial_area(const spherical_ellipse& se, double, spherical_ellipse_slice sl) {
    return partial_area_theta(se, std::atan(se.b * sl.s));
  }
  static spherical_ellipse_slice invert(const spherical_ellipse& se, double omega, double u1,
                                        int* iterations = nullptr) {
    double lo = -beta(se), hi = beta(se), mid = 0.0;
    const double goal = u1 * omega;
    for (int i = 0; i < bisection_steps; ++i) {
      mid = 0.5 * (lo + hi);
      (partial_area_theta(se, mid) < goal ? lo : hi) = mid;
    }
    if (iterations) *iterations = bisection_steps;
    const double s = std::clamp(std::tan(mid) / se.b, -1.0, 1.0);
    return {s, safe_sqrt(1.0 - s * s)};  // |s| <= 1 after the clamp; the guard is for rounding
  }
};

// --- the parallel map on the canonical spherical ellipse. Directions are
// returned as points (x, y) of the tangent plane Z = 1 of the cone frame,
// i.e. the direction normalize(x, y, 1), which keeps relative precision for
// spherical ellipses of any size.

// u in [0,1]^2 -> tangent-plane point (X uniform on the chord).
template <class Solver = newton_carlson_solver>
inline dvec2 square_to_spherical_ellipse(dvec2 u, const spherical_ellipse& se, double omega) {
  const spherical_ellipse_slice sl = Solver::invert(se, omega, u.x);
  const double w = 2.0 * u.y - 1.0;
  // On the sphere the chord spans |X| <= a c / L, L^2 = 1 + a^2 c^2 + b^2 s^2, in
  // the plane through (0, b s, 1); X = w a c / L mapped back to Z = 1:
  // x = X / Z = w a c sqrt(K / (K + (1 - w^2) a^2 c^2)), K = 1 + b^2 s^2.
  const double k = 1.0 + sqr(se.b * sl.s), ac = se.a * sl.c;
  const double x = w * ac * std::sqrt(k / (k + (1.0 - w * w) * ac * ac));
  return {x, se.b * sl.s};
}
// Density per unit SOLID ANGLE: 1 / Omega on the spherical ellipse.
inline double square_to_spherical_ellipse_pdf(double omega) { return 1.0 / omega; }
// Tangent-plane point (inside the ellipse) -> u in [0,1]^2.
template <class Solver = newton_carlson_solver>
inline dvec2 spherical_ellipse_to_square(dvec2 p, const spherical_ellipse& se, double omega) {
  const double s = std::clamp(p.y / se.b, -1.0, 1.0);
  const spherical_ellipse_slice sl{s, safe_sqrt(1.0 - s * s)};  // |s| <= 1; guard for rounding
  const double u1 = Solver::partial_area(se, omega, sl) / omega;
  const double k = 1.0 + sqr(se.b * s), ac = se.a * sl.c;
  // Inverse of x = w a c sqrt(K / (K + (1 - w^2) a^2 c^2)).
  const double w = ac > 0.0 ? p.x / ac * std::sqrt((k + ac * ac) / (k + p.x * p.x)) : 0.0;
  return {std::clamp(u1, 0.0, 1.0), std::clamp(0.5 * (w + 1.0), 0.0, 1.0)};
}

// --- an ellipse seen from an observer as a canonical elliptic cone.

struct ellipse_cone_limits {
  static constexpr double min_height = 1e-9;   // h / dist
  static constexpr double max_tangent = 1e6;   // b
  static constexpr double max_ratio = 1e8;     // a / b
  static constexpr double min_omega = 1e-30;   // sr
};

enum class ellipse_cone_mode : std::uint8_t { none, spherical, area };

struct ellipse_cone {
  ellipse_cone_mode mode = ellipse_cone_mode::none;
  spherical_ellipse se;
  double omega = 0.0;
  // Frame around the direction to the ellipse centre (world space).
  dvec3 t1{0.0}, t2{0.0}, cdir{0.0};
  // Cone frame in (t1, t2, cdir) coordinates: X (major), Y (minor), axis.
  dvec3 ex{0.0}, ey{0.0}, ez{0.0};
  // Tangent-plane -> ellipse coordinates: a direction v (frame coordinates)
  // hits the ellipse at centre + xi a1 + eta a2 with
  // (xi, eta) = R v.xy / (v.z - k . v.xy), R = B^-1 (paper-independent:
  // inverse of the linear map (xi, eta, 1) -> (xi a1 + eta a2 + d) / dist).
  double r00 = 0.0, r01 = 0.0, r10 = 0.0, r11 = 0.0;
  dvec2 k{0.0};
  dvec3 d{0.0};  // centre - observer
  double dist = 0.0;

  // Cone frame -> world direction (not normalised).
  dvec3 to_world(const dvec3& p) const {
    const dvec3 f = p.x * ex + p.y * ey + p.z * ez;
    return f.x * t1 + f.y * t2 + f.z * cdir;
  }
  dvec3 to_cone(const dvec3& w) const {
    const dvec3 f{glm::dot(w, t1), glm::dot(w, t2), glm::dot(w, cdir)};
    return {glm::dot(f, ex), glm::dot(f, ey), glm::dot(f, ez)};
  }
  // Ellipse coordinates (xi, eta) of the tangent-plane point p.
  dvec2 ellipse_coords(dvec2 p) const {
    const dvec3 f = p.x * ex + p.y * ey + ez;
    const dvec2 q{r00 * f.x + r01 * f.y, r10 * f.x + r11 * f.y};
    const double z = f.z - (k.x * f.x + k.y * f.y);
    return q / z;
  }
};

namespace detail {

// Duff et al. 2017 orthonormal basis, in double.
inline void onb_double(const dvec3& n, dvec3& u, dvec3& v) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  u = dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  v = dvec3(b, sign + n.y * n.y * a, -n.y);
}

// Cyclic Jacobi eigen-decomposition of a symmetric 3x3 matrix (Golub & Van
// Loan, "Matrix Computations", alg. 8.5.3): plain rotations, accurate
// eigenvectors even for the strongly graded matrices of thin or tiny cones
// (entries from 1e-16 to 1 side by side), where the closed-form cubic loses
// the small roots. A rotation is skipped once its off-diagonal entry is
// below 1e-18 of the geometric mean of the two diagonal entries (relative,
// not absolute, convergence). Columns of v are the eigenvectors, accumulated
// only if Vectors (the rotations, hence the eigenvalues, do not depend on it).
template <bool Vectors = true>
inline void jacobi_eigen3(std::array<std::array<double, 3>, 3>& m, std::array<std::array<double, 3>, 3>& v) {
  if constexpr (Vectors)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) v[i][j] = i == j ? 1.0 : 0.0;
  for (int sweep = 0; sweep < 12; ++sweep) {
    bool rotated = false;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        // Skip test |a_pq| <= 1e-15 sqrt(|a_pp a_qq|), squared (no square
        // root): the relative criterion of Demmel & Veselic 1992. Skipping
        // moves the eigenvalues by a relative 1e-15 at most (1e-30 unless
        // a_pp ~ a_qq), leaves the graded small entries of thin or tiny
        // cones alone, and spares the rotations of rounding-level entries
        // (the symmetric frame of a disk leaves ~1e-17 ones).
        const double apq = m[p][q];
        if (apq * apq <= 1e-30 * std::abs(m[p][p] * m[q][q])) continue;
        rotated = true;
        const double theta = (m[q][q] - m[p][p]) / (2.0 * apq);
        // t = tan of the rotation angle, the smaller root (|angle| <= pi/4);
        // 1/(2 theta) when theta^2 would overflow.
        const double t = std::abs(theta) > 1e150
                             ? 0.5 / theta
                             : std::copysign(1.0, theta) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        m[p][p] -= t * apq;
        m[q][q] += t * apq;
        m[p][q] = m[q][p] = 0.0;
        const int r = 3 - p - q;
        const double mrp = m[r][p], mrq = m[r][q];
        m[r][p] = m[p][r] = c * mrp - s * mrq;
        m[r][q] = m[q][r] = s * mrp + c * mrq;
        if constexpr (Vectors)
          for (int i = 0; i < 3; ++i) {
            const double vip = v[i][p], viq = v[i][q];
            v[i][p] = c * vip - s * viq;
            v[i][q] = s * vip + c * viq;
          }
      }
    }
    if (!rotated) break;
  }
}

}  // namespace detail

// What the cone set-up needs of an ellipse, in double, computed once per
// light: the centre and semi-axes, the front normal from a1 x a2 in double
// (the float e.n is off the plane by ~1e-8, which would put an error of
// 1e-8 dist / h in the height h) and |a1 x a2|.
struct ellipse_frame {
  dvec3 center{0.0}, a1{0.0}, a2{0.0}, n{0.0};
  double cross_len = 0.0;
  double flip = 1.0;  // +1 when the front normal is along a1 x a2, -1 when flipped

  explicit ellipse_frame(const ellipse& e) : center(e.center), a1(e.a1), a2(e.a2) {
    const dvec3 cr = glm::cross(a1, a2);
    cross_len = glm::length(cr);
    flip = glm::dot(cr, dvec3(e.n)) > 0.0 ? 1.0 : -1.0;
    n = cr * (flip / cross_len);
  }
};

// The cone of directions from o through the ellipse e, reduced to a
// canonical spherical ellipse; mode says how the light is sampled from o.
// Without Frame only mode, se and omega are set (all that a pdf needs):
// the same rotations and the same arithmetic, so the same mode and omega,
// without the eigenvectors and the maps to the ellipse. `f` is
// ellipse_frame(e), which a sampler keeps.
template <class Solver = newton_carlson_solver, bool Frame = true>
inline ellipse_cone make_ellipse_cone(const ellipse& e, const ellipse_frame& f, const vec3& o) {
  ellipse_cone cone;
  if (!e.faces(o)) return cone;  // mode none: behind or in the plane (the float test every sampler uses)
  cone.mode = ellipse_cone_mode::area;
  const dvec3 od(o);
  const dvec3& n = f.n;
  cone.d = f.center - od;  // exact: a difference of floats in double
  const double dist2 = glm::dot(cone.d, cone.d);
  cone.dist = std::sqrt(dist2);
  const double h = -glm::dot(cone.d, n);
  if (!(h > ellipse_cone_limits::min_height * cone.dist) || !std::isfinite(cone.dist)) return cone;
  const double inv_dist = 1.0 / cone.dist;
  const dvec3 cdir = cone.d * inv_dist;
  // Frame (t1, t2, cdir) with t1 along n x cdir, the normal of the plane
  // through the observer, the centre and the ellipse's normal. For a disk
  // that plane is a plane of symmetry of the cone and t1 one of its
  // principal axes (P below is (R/dist)^2 (I - n n^T) - cdir cdir^T and
  // t1 is orthogonal to n and cdir), so P is block-diagonal in this frame
  // and Jacobi needs a single rotation; for other ellipses it is as good a
  // start as any. The observer on the axis (n x cdir = 0, any frame is
  // principal for a disk) takes the generic basis.
  dvec3 t1 = glm::cross(n, cdir), t2;
  t1 -= glm::dot(t1, cdir) * cdir;  // orthogonal to cdir to the last bit
  const double t1_len2 = glm::dot(t1, t1);
  if (t1_len2 > 1e-300) {
    t1 *= 1.0 / std::sqrt(t1_len2);
    t2 = glm::cross(cdir, t1);
  } else {
    detail::onb_double(cdir, t1, t2);
  }

  // Axes in units of the distance, in the (t1, t2, cdir) frame.
  const dvec3 u1 = f.a1 * inv_dist, u2 = f.a2 * inv_dist;
  const double b00 = glm::dot(u1, t1), b01 = glm::dot(u2, t1);
  const double b10 = glm::dot(u1, t2), b11 = glm::dot(u2, t2);
  const dvec2 g{glm::dot(u1, cdir), glm::dot(u2, cdir)};
  // det B = (u1 x u2) . cdir = -(|a1 x a2| / dist^2) (h / dist) (n . n_geo):
  // from the height h, not from b00 b11 - b01 b10, which cancels for grazing
  // observers.
  const double det = -f.cross_len * (h * inv_dist) * (inv_dist * inv_dist) * f.flip;
  // The cone is {v : v^T Q v <= 0}, Q = M^-T J M^-1 with M = [[B, 0], [g^T, 1]]
  // (columns: a1, a2, centre, all over dist, in this frame) and J =
  // diag(1, 1, -1) (Heitz 2017's cone matrix, in another frame). Q's entries are
  // ~1/b^2 and its small eigenvalue ~1/a^2 drowns in their rounding for
  // elongated cones (a/b = 1e6: 1e-4 relative). Its inverse
  //   P = Q^-1 = M J M^T = [[B B^T, B g], [g^T B^T, |g|^2 - 1]]
  // has the same eigenvectors, eigenvalues p = 1/lambda, entries of the size
  // of the cone and no inverse in it; Jacobi gets its two eigenvalues of
  // largest magnitude and all three eigenvectors to full accuracy. The
  // eigenvalue of smallest magnitude (b^2 when the cone is thin, the axis
  // one when it is wide) is then taken from det P = -(det B)^2, known from h.
  std::array<std::array<double, 3>, 3> pm{}, vec{};
  pm[0][0] = b00 * b00 + b01 * b01;
  pm[1][1] = b10 * b10 + b11 * b11;
  pm[0][1] = pm[1][0] = b00 * b10 + b01 * b11;
  pm[0][2] = pm[2][0] = b00 * g.x + b01 * g.y;
  pm[1][2] = pm[2][1] = b10 * g.x + b11 * g.y;
  pm[2][2] = g.x * g.x + g.y * g.y - 1.0;
  for (const auto& row : pm)
    for (double x : row)
      if (!std::isfinite(x)) return cone;
  detail::jacobi_eigen3<Frame>(pm, vec);
  std::array<double, 3> ev{pm[0][0], pm[1][1], pm[2][2]};
  int ismall = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(ev[i]) < std::abs(ev[ismall])) ismall = i;
  ev[ismall] = -(det * det) / (ev[(ismall + 1) % 3] * ev[(ismall + 2) % 3]);
  // One negative eigenvalue (the axis) and two positive ones: a^2 = -p_a / p_neg.
  int in = 0;
  for (int i = 1; i < 3; ++i)
    if (ev[i] < ev[in]) in = i;
  const int i1 = (in + 1) % 3, i2 = (in + 2) % 3;
  const int imaj = ev[i1] >= ev[i2] ? i1 : i2, imin = imaj == i1 ? i2 : i1;
  const double pneg = ev[in], pmaj = ev[imaj], pmin = ev[imin];
  if (!(pneg < 0.0 && pmin > 0.0)) return cone;
  const double inv_neg = -1.0 / pneg;
  cone.se.a = std::sqrt(pmaj * inv_neg);
  cone.se.b = std::sqrt(pmin * inv_neg);
  if constexpr (Frame) {
    cone.cdir = cdir;
    cone.t1 = t1;
    cone.t2 = t2;
    const double inv_det = 1.0 / det;
    cone.r00 = b11 * inv_det;
    cone.r01 = -b01 * inv_det;
    cone.r10 = -b10 * inv_det;
    cone.r11 = b00 * inv_det;
    cone.k = {cone.r00 * g.x + cone.r10 * g.y, cone.r01 * g.x + cone.r11 * g.y};  // R^T g
    auto column = [&](int j) { return dvec3(vec[0][j], vec[1][j], vec[2][j]); };
    cone.ez = column(in);
    if (cone.ez.z < 0.0) cone.ez = -cone.ez;  // the nappe that contains the centre direction
    cone.ex = column(imaj);
    cone.ey = glm::cross(cone.ez, cone.ex);
  }
  if (!(cone.se.b <= ellipse_cone_limits::max_tangent) ||
      !(cone.se.a <= ellipse_cone_limits::max_ratio * cone.se.b))
    return cone;
  cone.omega = Solver::area(cone.se);
  if (!(cone.omega >= ellipse_cone_limits::min_omega) || !std::isfinite(cone.omega)) return cone;
  cone.mode = ellipse_cone_mode::spherical;
  return cone;
}
template <class Solver = newton_carlson_solver, bool Frame = true>
inline ellipse_cone make_ellipse_cone(const ellipse& e, const vec3& o) {
  return make_ellipse_cone<Solver, Frame>(e, ellipse_frame(e), o);
}

// The parallel map with solver Solver, as the Map policy of
// basic_ellipse_solid_angle_sampler: sample (unit square -> tangent-plane
// point of the canonical cone), invert, and the solver whose Omega the cone
// carries (the pdf is 1 / that Omega). spherical_ellipse_polar.hpp has the
// polar map.
template <class Solver = newton_carlson_solver>
struct parallel_map {
  using solver = Solver;
  static dvec2 sample(dvec2 u, const spherical_ellipse& se, double omega) {
    return square_to_spherical_ellipse<Solver>(u, se, omega);
  }
  static dvec2 invert(dvec2 p, const spherical_ellipse& se, double omega) {
    return spherical_ellipse_to_square<Solver>(p, se, omega);
  }
};

// Light-sampling strategy: uniform in the solid angle of the ellipse from o
// (one-sided: nothing behind), through an area-preserving map of the
// spherical ellipse (Map: parallel_map or polar_map); area sampling with its
// exact pdf where make_ellipse_cone() says the map is unreliable.
template <class Map = parallel_map<>>
struct basic_ellipse_solid_angle_sampler {
  using solver = typename Map::solver;
  ellipse shape;  // fixed after construction (frame_ is derived from it)

  explicit basic_ellipse_solid_angle_sampler(const ellipse& e) : shape(e), frame_(e) {}

  bool faces(const vec3& o) const { return shape.faces(o); }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const ellipse_cone cone = make_ellipse_cone<solver>(shape, frame_, o);
    if (cone.mode == ellipse_cone_mode::none) return false;
    if (cone.mode == ellipse_cone_mode::area) return ellipse_area_sampler{shape}.sample(o, u, s);
    dvec2 xe = cone.ellipse_coords(Map::sample(dvec2(u), cone.se, cone.omega));
    // The map lands inside the ellipse; rounding may leave it ~1e-12 out.
    const double r2 = glm::dot(xe, xe);
    if (r2 > 1.0) xe /= std::sqrt(r2);
    const dvec3 v = cone.d + xe.x * dvec3(shape.a1) + xe.y * dvec3(shape.a2);
    const double len = glm::length(v);
    s.dir = vec3(v / len);
    s.dist = static_cast<float>(len);
    s.pdf = static_cast<float>(square_to_spherical_ellipse_pdf(cone.omega));
    // omega >= min_omega keeps 1/omega finite in float; the checks keep any
    // non-finite sample from reaching the integrator.
    return std::isfinite(s.pdf) && s.pdf > 0.0f && all_finite(s.dir);
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir.
  // The ray test comes first: a direction that misses the light (most
  // directions a BSDF samples) costs no cone set-up. Both branches below
  // would test the same float ray against the same shape.
  float pdf(const vec3& o, const vec3& dir) const {
    float t;
    if (!shape.faces(o) || !shape.intersect({o, dir}, 0.0f, infinity, t)) return 0.0f;
    const ellipse_cone cone = make_ellipse_cone<solver, false>(shape, frame_, o);
    if (cone.mode == ellipse_cone_mode::none) return 0.0f;
    if (cone.mode == ellipse_cone_mode::area) return ellipse_area_sampler{shape}.pdf(o, dir);
    return static_cast<float>(square_to_spherical_ellipse_pdf(cone.omega));
  }

  // The u that sample() maps to dir (dir must hit the ellipse); false where
  // sample() has no sample for o.
  bool invert(const vec3& o, const vec3& dir, vec2& u) const {
    const ellipse_cone cone = make_ellipse_cone<solver>(shape, frame_, o);
    if (cone.mode == ellipse_cone_mode::none) return false;
    if (cone.mode == ellipse_cone_mode::area) {
      float t;
      if (!shape.intersect({o, dir}, 0.0f, infinity, t)) return false;
      u = ellipse_to_square(o + t * dir, shape);
      return true;
    }
    const dvec3 p = cone.to_cone(dvec3(dir));
    if (!(p.z > 0.0)) return false;  // not in the cone's nappe: no tangent-plane point
    u = vec2(Map::invert({p.x / p.z, p.y / p.z}, cone.se, cone.omega));
    return true;
  }

 private:
  ellipse_frame frame_;
};

using ellipse_solid_angle_sampler = basic_ellipse_solid_angle_sampler<>;
using ellipse_solid_angle_sampler_bisection_simpson = basic_ellipse_solid_angle_sampler<parallel_map<bisection_simpson_solver>>;

}  // namespace mcrt
