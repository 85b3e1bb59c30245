#pragma once
// Uniform sampling of the solid angle subtended by an ellipse (or disk)
// through the area-preserving POLAR parametrization of the spherical
// ellipse of Guillen, Urena, King, Fajardo, Georgiev, Lopez-Moreno and
// Jarabo 2017, "Area-Preserving Parametrizations for Spherical Ellipses"
// (EGSR 2017): the first coordinate picks the azimuth phi about the cone
// axis by the area of the sector it closes, the second the angle theta from
// the axis along that azimuth. The canonical spherical ellipse, its solid
// angle and the reduction of an ellipse seen from an observer to it are
// those of spherical_ellipse.hpp (the parallel map of the same paper).
//
// The map. In the cone frame of spherical_ellipse.hpp (cone {X^2/a^2 +
// Y^2/b^2 <= Z^2}, a >= b the tangents of the semi-axes alpha, beta), phi is
// the polar angle in the tangent plane Z = 1 and theta the angle from the
// axis; dOmega = sin(theta) dtheta dphi. The boundary is
//   tan^2 theta_max(phi) = 1 / (cos^2 phi / a^2 + sin^2 phi / b^2),
// and the polar map (the paper's polar mapping) is
//   phi   from Omega(phi) = u1 Omega,  Omega(phi) = int_0^phi (1 - cos theta_max(phi')) dphi',
//   theta from 1 - cos theta = u2 (1 - cos theta_max(phi)).
// The four quadrants hold Omega/4 each; u1 picks the quadrant and the
// equation is solved inside the first one, mirrored in the second and
// fourth so that the map is continuous across the quadrant boundaries
// (u1 = (q + v)/4 in quadrants q = 0, 2 and (q + 1 - v)/4 in q = 1, 3).
//
// The boundary is parametrized by its eccentric angle t in the tangent
// plane, (a cos t, b sin t) (tan phi = (b/a) tan t), where
//   r^2 = tan^2 theta_max = a^2 cos^2 t + b^2 sin^2 t,  S = sqrt(1 + r^2) = 1 / cos theta_max,
//   1 - cos theta_max = r^2 / (S (S + 1))              (no cancellation),
//   dOmega/dt = (1 - cos theta_max) dphi/dt = a b / (S (S + 1)).
//
// Sector area in closed form. The paper writes Omega(phi) with Booth's
// formula, phi - c Pi(n; t | k): the azimuth minus the integral of
// cos theta_max, an incomplete elliptic integral of the third kind. For a
// small cone both terms are ~phi while Omega(phi) ~ a b t / 2, so the
// difference loses a factor ~2 / (a b) over the quadrant (2e10 at
// a = b = 1e-5, 2.6e4 at a = 1, b = 1e-4). Merging the Carlson forms as
// spherical_ellipse.hpp does for the parallel map cannot help: with phi or
// t as the variable, 1 - cos theta_max dphi splits into a part rational in
// them (giving phi) and an elliptic part, and a Legendre reduction
// evaluates the two apart. Instead, along the boundary take
// Q = tan^2(theta_max / 2) as the variable: with cos theta = (1 - Q)/(1 + Q),
// tan^2 theta = 4 Q / (1 - Q)^2 and the boundary equation solved for sin^2 phi,
//   Omega(phi) = int_{Q(phi)}^{Q_a} (1 - Q) dQ / sqrt((Q_a - Q)(Q - Q_b)(1/Q_a - Q)(1/Q_b - Q)),
// Q_a = tan^2(alpha/2), Q_b = tan^2(beta/2): an elliptic integral whose
// integrand is positive and whose only poles are at Q = infinity. Writing
// 1 - Q = (1 - Q_a) + (Q_a - Q), both positive on the path, and substituting
// Q = Q_a - 1 / (1/D1 + tau) turns the two parts into Carlson's R_F and R_J
// (DLMF 19.16.1-2) with positive coefficients:
//   Omega = 2 s' sqrt(e3 e4) [ (1 - Q_a) R_F(c'^2, Y, Z) + (D1 / 3) R_J(c'^2, Y, Z, 1) ],
//   D1 = Q_a - Q(phi),  D2 = Q(phi) - Q_b,  s'^2 = D1 / (D1 + D2),  c'^2 = D2 / (D1 + D2),
//   e3 = 1 / (1/Q_a - Q_a) = a^2 / (4 sqrt(1 + a^2)),  e4 = 1 / (1/Q_b - Q_a),
//   Y = 1 + D1 e3,  Z = 1 + D1 e4,
// (R_F(x, y, z) = 1/2 int_0^inf dtau / sqrt((tau + x)(tau + y)(tau + z)) and
// R_J adds a factor 3 / (tau + p)). Every input is formed without
// subtraction: with q = tan(theta/2) = r / (1 + S), 1 - q^2 = 2 / (1 + S),
// 1/q^2 - q^2 = 4 S / r^2, 1 - Q_a Q_b = (1 - Q_a) + Q_a (1 - Q_b), and
//   Q_1 - Q_2 = 2 (r_1^2 - r_2^2) / ((S_1 + 1)(S_2 + 1)(S_1 + S_2)),
//   r_a^2 - r^2 = (a^2 - b^2) sin^2 t,  r^2 - r_b^2 = (a^2 - b^2) cos^2 t,
// so s'^2 and c'^2 are sin^2 t and cos^2 t times ratios of the S's, free of
// a^2 - b^2 (a disk, a = b, is no special case). The only subtraction left is
// a^2 - b^2 = (a - b)(a + b), exact to rounding. Against 50-digit quadrature
// the formula holds to ~1e-15 relative over make_ellipse_cone's whole
// spherical range (b from 1e-15 to 1e6, a/b up to 1e8, t over the quadrant);
// wide elongated cones only cost more duplication steps in Carlson's loop
// (Y ~ a / (2 max(b, 1)) for a >> 1).
//
// Solver. Newton on f = Omega_q(t) - v Omega/4 in w = pi/2 - t, the angle
// from the minor axis: wide elongated cones put most of their area per unit
// t within ~b/a of the minor axis, where t = pi/2 - w itself would resolve
// only steps of 2e-16 rad (an area of ~(a/b) 2e-16 Omega) while w keeps its
// relative precision. |f'| = a b / (S (S + 1)) is monotone on the quadrant,
// which makes the cheap error bound of spherical_ellipse.hpp's Newton solver
// valid here too (see invert()).
// Initial guess: the planar-ellipse sector, exact for small cones, applied
// to the Lambert azimuthal equal-area image of the spherical ellipse (radius
// 2 sin(theta/2), which preserves area): an ellipse of semi-axes
// 2 sin(alpha/2), 2 sin(beta/2) would have its sector at
//   tan phi = (sin(beta/2) / sin(alpha/2)) tan(pi/2 v),
// which is right for small cones (a b / 2 t) and for wide ones (Omega ~ phi).
//
// Fallbacks and the mode (spherical, area, none) are make_ellipse_cone()'s,
// so sample() and pdf() always agree; the polar map adds no threshold of
// its own.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "mcrt/core/carlson.hpp"
#include "mcrt/core/math.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"

namespace mcrt {

// A boundary point of the canonical spherical ellipse by the sine and cosine
// of its eccentric angle t in [0, pi/2] (first quadrant): the tangent-plane
// point (a c, b s). s, c >= 0.
struct spherical_ellipse_polar_ray {
  double s = 0.0, c = 1.0;
};

// What the sector area needs of one spherical ellipse, computed once per
// sample. Overflow and underflow: a <= 1e8 b <= 1e14 and Omega >= 1e-30 sr
// (make_ellipse_cone's limits) keep a^2, a b and e3 e4 ~ (a b / 4)^2 in range.
struct spherical_ellipse_polar_consts {
  double a = 0.0, b = 0.0, ab = 0.0;
  double d = 0.0;             // a^2 - b^2
  double sa = 1.0, sb = 1.0;  // sqrt(1 + a^2), sqrt(1 + b^2)
  double one_minus_qa = 1.0;  // 1 - Q_a = 2 / (1 + sa)
  double e3 = 0.0, e4 = 0.0;  // 1 / (1/Q_a - Q_a), 1 / (1/Q_b - Q_a)
  double sqrt_e3e4 = 0.0;
  double guess = 1.0;  // tan t / tan xi of the Lambert initial guess, >= 1

  explicit spherical_ellipse_polar_consts(const spherical_ellipse& se) : a(se.a), b(se.b) {
    ab = a * b;
    d = (a - b) * (a + b);
    sa = std::sqrt(1.0 + a * a);
    sb = std::sqrt(1.0 + b * b);
    one_minus_qa = 2.0 / (1.0 + sa);
    const double qa = a * a / sqr(1.0 + sa), qb = b * b / sqr(1.0 + sb);
    e3 = a * a / (4.0 * sa);
    // 1/Q_b - Q_a = (1 - Q_a Q_b) / Q_b, 1 - Q_a Q_b = (1 - Q_a) + Q_a (1 - Q_b).
    e4 = qb / (one_minus_qa + qa * 2.0 / (1.0 + sb));
    // Two roots: e3 e4 ~ (a b / 4)^2 underflows below a b ~ 1e-154, outside
    // make_ellipse_cone's range but not outside these functions' domain.
    sqrt_e3e4 = std::sqrt(e3) * std::sqrt(e4);
    // Lambert image semi-axes: 2 sin(alpha/2) = a sqrt(2 / (sa (sa + 1))); the
    // guess tan t = (a / b) (sin(beta/2) / sin(alpha/2)) tan xi.
    guess = std::sqrt(sa * (sa + 1.0) / (sb * (sb + 1.0)));
  }
};

// dOmega/dt at the boundary point: a b / (S (S + 1)), S = 1 / cos theta_max.
inline double spherical_ellipse_polar_density(const spherical_ellipse_polar_consts& k,
                                              spherical_ellipse_polar_ray ray) {
  const double st = std::sqrt(1.0 + sqr(k.a * ray.c) + sqr(k.b * ray.s));
  return k.ab / (st * (st + 1.0));
}

// Solid angle of the sector of the first quadrant between the major axis
// (t = 0) and the ray through the boundary point at eccentric angle t: the
// Carlson form of the header comment.
inline double spherical_ellipse_polar_sector(const spherical_ellipse_polar_consts& k,
                                             spherical_ellipse_polar_ray ray) {
  const double s2 = ray.s * ray.s, c2 = ray.c * ray.c;
  const double st = std::sqrt(1.0 + sqr(k.a * ray.c) + sqr(k.b * ray.s));
  const double sa1 = k.sa + 1.0, st1 = st + 1.0, sb1 = k.sb + 1.0;
  // D1 = Q_a - Q(t) = 2 (a^2 - b^2) sin^2 t / ((sa + 1)(st + 1)(sa + st))
  const double d1 = 2.0 * k.d * s2 / (sa1 * st1 * (k.sa + st));
  // s'^2 = D1 / (Q_a - Q_b), c'^2 = D2 / (Q_a - Q_b) with a^2 - b^2 cancelled
  const double sp2 = s2 * sb1 * (k.sa + k.sb) / (st1 * (k.sa + st));
  const double cp2 = c2 * sa1 * (k.sa + k.sb) / (st1 * (st + k.sb));
  double rf, rj;
  carlson_rf_rj(cp2, 1.0 + d1 * k.e3, 1.0 + d1 * k.e4, 1.0, rf, rj);
  return 2.0 * std::sqrt(sp2) * k.sqrt_e3e4 * (k.one_minus_qa * rf + d1 / 3.0 * rj);
}

// Solid angle of the whole spherical ellipse by the polar closed form: four
// quadrant sectors (t = pi/2: D2 = 0, s' = 1). Agrees with
// spherical_ellipse_area() (AGM) to rounding.
inline double spherical_ellipse_polar_area(const spherical_ellipse& se) {
  return 4.0 * spherical_ellipse_polar_sector(spherical_ellipse_polar_consts(se), {1.0, 0.0});
}

// Safeguarded Newton for the sector equation Omega_q(t) = v Omega / 4.
struct spherical_ellipse_polar_solver {
  // Newton stops once |Omega_q(t) - v Omega/4| <= tolerance * Omega: far
  // below float resolution of u1 (6e-8), well above the closed form's
  // rounding (~1e-15 relative).
  static constexpr double tolerance = 1e-9;
  // Safety net only: bisection alone halves the bracket [0, pi/2] to one
  // ulp in ~55 steps; Newton needs a handful.
  static constexpr int max_iterations = 60;

  // The boundary point with Omega_q(t) = v Omega / 4, v in [0, 1];
  // `iterations` (optional) reports the number of sector evaluations.
  static spherical_ellipse_polar_ray invert(const spherical_ellipse_polar_consts& k, double omega, double v,
                                            int* iterations = nullptr) {
    constexpr double half_pi = 0.5 * std::numbers::pi;
    if (iterations) *iterations = 0;
    // The ends of the quadrant exactly (and a NaN v to the major axis), so
    // that u1 = 0 and u1 = 1 meet on the major axis and the quadrant
    // boundaries land on the axes without a solve.
    if (!(v > 0.0)) return {0.0, 1.0};
    if (!(v < 1.0)) return {1.0, 0.0};
    const double goal = 0.25 * omega * v;
    // Initial guess (header comment): tan t = guess tan(pi/2 v), as the angle
    // w = pi/2 - t from the minor axis.
    const double xi = half_pi * v;
    double w = std::atan2(std::cos(xi), k.guess * std::sin(xi));
    // f(w) = Omega_q(pi/2 - w) - goal decreases on [0, pi/2]; the bracket
    // [lo, hi] shrinks with the sign of f and a Newton step leaving it is
    // replaced by bisection. |f'| = density decreases in w, so (as in
    // newton_carlson_solver) after a Newton step d the new residual is at
    // most |d| |density(w + d) - density(w)|: a step whose bound is within
    // the tolerance is accepted without evaluating the sector.
    double lo = 0.0, hi = half_pi;
    spherical_ellipse_polar_ray ray{std::cos(w), std::sin(w)};
    for (int it = 1; it <= max_iterations; ++it) {
      if (iterations) *iterations = it;
      const double f = spherical_ellipse_polar_sector(k, ray) - goal;
      if (std::abs(f) <= tolerance * omega) break;
      (f > 0.0 ? lo : hi) = w;
      const double fp = spherical_ellipse_polar_density(k, ray);  // -f'(w)
      double next = w + f / fp;
      const bool newton = next > lo && next < hi;
      if (!newton) next = 0.5 * (lo + hi);
      if (next == w) break;  // the bracket is down to one ulp
      const double step = next - w;
      w = next;
      ray = {std::cos(w), std::sin(w)};
      if (newton && std::abs(step) * std::abs(spherical_ellipse_polar_density(k, ray) - fp) <= tolerance * omega)
        break;
    }
    return ray;
  }
};

namespace detail {

// u1 -> quadrant and the area fraction v inside it, mirrored in the odd
// quadrants (u1 = (q + v)/4 for q = 0, 2 and (q + 1 - v)/4 for q = 1, 3).
inline int polar_quadrant(double u1, double& v) {
  const double x = 4.0 * std::clamp(u1, 0.0, 1.0);  // a caller's u1 rounded outside [0, 1]
  const int q = std::min(static_cast<int>(x), 3);  // u1 = 1 is the end (v = 1) of the last quadrant
  v = x - q;
  if (q & 1) v = 1.0 - v;
  return q;
}

}  // namespace detail

// --- the polar map on the canonical spherical ellipse. Directions are
// tangent-plane points (x, y) of Z = 1 in the cone frame (the direction
// normalize(x, y, 1)), as for the parallel map.

// u in [0,1]^2 -> tangent-plane point; `iterations` (optional) reports the
// solver's sector evaluations.
inline dvec2 square_to_spherical_ellipse_polar(dvec2 u, const spherical_ellipse& se, double omega,
                                               int* iterations = nullptr) {
  const spherical_ellipse_polar_consts k(se);
  double v;
  const int q = detail::polar_quadrant(u.x, v);
  const spherical_ellipse_polar_ray ray = spherical_ellipse_polar_solver::invert(k, omega, v, iterations);
  // Boundary point (a c, b s): tan theta_max = r, 1 - cos theta_max = r^2 / (S (S + 1)).
  const double bx = k.a * ray.c, by = k.b * ray.s;
  const double r2 = bx * bx + by * by, r = std::sqrt(r2), st = std::sqrt(1.0 + r2);
  // u2 outside [0, 1] (a caller's rounding) would put the point outside the
  // ellipse or make cos theta negative.
  const double u2 = std::clamp(u.y, 0.0, 1.0);
  // 1 - cos theta = h = u2 (1 - cos theta_max); cos theta = 1 - h as the sum
  // (1 - u2) + u2 cos theta_max (no cancellation when theta nears pi/2), and
  // tan theta = sqrt(h (2 - h)) / (1 - h); at u2 = 1 it is r.
  const double h = u2 * r2 / (st * (st + 1.0));
  const double cos_t = (1.0 - u2) + u2 / st;
  const double tan_t = std::sqrt(h * (1.0 + cos_t)) / cos_t;
  // r > 0 always: r >= b > 0.
  const double x = tan_t * bx / r, y = tan_t * by / r;
  return {q == 0 || q == 3 ? x : -x, q < 2 ? y : -y};
}

// Density per unit SOLID ANGLE: 1 / Omega on the spherical ellipse.
inline double square_to_spherical_ellipse_polar_pdf(double omega) { return 1.0 / omega; }

// Tangent-plane point (inside the ellipse) -> u in [0,1]^2.
inline dvec2 spherical_ellipse_polar_to_square(dvec2 p, const spherical_ellipse& se, double omega) {
  const spherical_ellipse_polar_consts k(se);
  // The boundary point on the ray through p: eccentric direction (|x|/a, |y|/b).
  const double ex = std::abs(p.x) / k.a, ey = std::abs(p.y) / k.b, n = std::hypot(ex, ey);
  const spherical_ellipse_polar_ray ray = n > 0.0 ? spherical_ellipse_polar_ray{ey / n, ex / n}
                                                  : spherical_ellipse_polar_ray{0.0, 1.0};  // centre: u2 = 0
  // omega (the caller's, e.g. the AGM of spherical_ellipse_area) and four
  // closed-form quadrants agree to ~1e-15, not exactly: clamp the fraction.
  const double v = std::clamp(spherical_ellipse_polar_sector(k, ray) / (0.25 * omega), 0.0, 1.0);
  // Quadrants as in polar_quadrant; -0 counts as +0 (the map is continuous
  // across the axes, both sides give the same u1).
  const bool xneg = p.x < 0.0, yneg = p.y < 0.0;
  const double u1 = !yneg ? (!xneg ? v : 2.0 - v) : (xneg ? 2.0 + v : 4.0 - v);
  // u2 = (1 - cos theta) / (1 - cos theta_max), both as r^2 / (S (S + 1));
  // r2 >= b^2 > 0. Clamped: a point given on or just outside the rim.
  const double rho2 = p.x * p.x + p.y * p.y, srho = std::sqrt(1.0 + rho2);
  const double r2 = sqr(k.a * ray.c) + sqr(k.b * ray.s), st = std::sqrt(1.0 + r2);
  const double u2 = rho2 / (srho * (srho + 1.0)) * (st * (st + 1.0)) / r2;
  return {std::clamp(0.25 * u1, 0.0, 1.0), std::clamp(u2, 0.0, 1.0)};
}

// The polar map as the Map policy of basic_ellipse_solid_angle_sampler
// (spherical_ellipse.hpp): the same cone set-up, fallbacks, thresholds and
// solid angle (the AGM of spherical_ellipse_area) as the parallel map.
struct polar_map {
  using solver = newton_carlson_solver;  // whose Omega the cone carries
  static dvec2 sample(dvec2 u, const spherical_ellipse& se, double omega) {
    return square_to_spherical_ellipse_polar(u, se, omega);
  }
  static dvec2 invert(dvec2 p, const spherical_ellipse& se, double omega) {
    return spherical_ellipse_polar_to_square(p, se, omega);
  }
};

// Light-sampling strategy: uniform in the solid angle of the ellipse from o
// (one-sided) through the polar map.
using ellipse_polar_solid_angle_sampler = basic_ellipse_solid_angle_sampler<polar_map>;

}  // namespace mcrt
