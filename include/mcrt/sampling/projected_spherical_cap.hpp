#pragma once
// Sampling a sphere by PROJECTED solid angle: the exact area-preserving
// radial map of Urena & Georgiev 2018, "Stratified Sampling of Projected
// Spherical Caps" (EGSR 2018, CGF 37(4)), below [UG18], from the unit square
// to the orthographic projection of the sphere's cap of directions onto the
// tangent plane of the receiver. Sample, pdf and inverse in the Mitsuba
// warp.h / pbrt-v4 sampling.h layout (square_to_projected_cap,
// square_to_projected_cap_pdf, projected_cap_to_square), and the light
// strategy sphere_projected_solid_angle_sampler with the normal-aware
// interface of light_sample.hpp.
//
// Geometry [UG18 sec. 3]. Seen from o, a sphere (centre c, radius r, d =
// |c - o| > r) fills the cap of directions within alpha of w = (c - o) / d,
// sin alpha = r / d. In the receiver's frame (z the unit normal n, x along the
// part of w orthogonal to n, y = z x x) the axis is w = (cos b, 0, sin b),
// sin b = h / d, h = (c - o) . n the height of the centre above the receiving
// plane (b = pi/2 - theta_c). Projected orthographically onto the plane z = 0 a
// direction lands in the unit disk, and the projected solid angle of a set of
// directions above the horizon is the AREA of its projection (d omega_perp =
// cos theta d omega = dx dy). The cap's rim projects to an ellipse with centre
// (xe, 0), xe = cos alpha cos b, semi-axes sin alpha |sin b| (along x) and
// sin alpha (along y). With mu = sin b / sin alpha = h / r:
//  * mu >= 1: the sphere lies wholly above the receiving plane, the cap wholly
//    above the horizon; its projection is the ellipse, of area
//    pi sin^2 alpha sin b = pi sin^2 alpha cos theta_c;
//  * 0 <= mu < 1: the cap crosses the horizon with its axis above it; the
//    visible part projects to the ellipse plus a lune between the ellipse and
//    the unit circle (the horizon), the two tangent at (cos alpha / cos b,
//    +-yl) [UG18 sec. 3];
//  * -1 < mu < 0: the centre is below the plane (a sphere sunk partly below
//    it): the visible part projects to the lune alone;
//  * mu <= -1: wholly below the horizon: no sample, pdf 0.
//
// The radial map [UG18 sec. 4.2]. The upper half (y >= 0) of the region is
// swept by rays from the ellipse centre, by polar angle; the area swept, A_r
// [UG18 eqs. 20, 23], over the half area is the angular coordinate, and along
// a ray r^2 is uniform between the inner boundary (the ellipse for the lune,
// the centre otherwise) and the outer one. The lower half is the mirror image:
// u.y in [0, 1/2) sweeps the lower half from the far side (polar angle pi)
// back to the axis, u.y in [1/2, 1) the upper half from the axis to the far
// side, so the map is continuous in the plane; u.x is r^2 (the radial part).
//
// Why the radial map and not the parallel one [UG18 sec. 4.1]: the parallel
// map needs a numerical inversion even for a cap wholly above the horizon
// (the area of an ellipse below a horizontal line is Kepler's equation),
// whereas the radial map is closed-form there (the polar map of the disk,
// scaled to the ellipse), the common case, little dearer than the cone
// sampler; with the lune too, the rays past the tangency point end on the
// ellipse and are again closed-form.
//
// Numerics. Everything is computed in double in coordinates scaled to the
// cap: X = (x - xe) / sin^2 alpha, Y = y / sin alpha (an affine map: rays from
// the ellipse centre stay rays and the radial map is the same map; areas scale
// by sin^3 alpha). There the ellipse is (X / mu)^2 + Y^2 = 1 and the horizon
// the circle sin^2 alpha X^2 + 2 xe X + Y^2 = 1 + cos^2 alpha mu^2, both of size
// ~1 whatever the size of the cap (for a small cap the circle tends to the
// parabola X = (1 + mu^2 - Y^2) / 2), so nothing cancels for far spheres
// (solid angles down to 1e-8 sr and far below). In these coordinates:
//  * the ray to the circle is parametrised by the polar angle gamma, on the
//    unit circle, of the point Q where it meets the circle: sin gamma =
//    sin alpha Y_Q, X_Q = kappa - Y_Q^2 / (1 + cos gamma), kappa = (1 - xe) /
//    sin^2 alpha = 1 / (1 + cos alpha) + cos alpha mu^2 / (1 + cos b);
//  * the area swept to the circle [UG18 eq. 25] is not the paper's
//    (theta - asin(xe sin theta) + ...) / 2 in the polar angle theta about
//    the ellipse centre (for a small cap a difference of O(1) terms giving
//    O(alpha^3)) but sector minus triangle, (gamma - xe sin gamma) / 2,
//    i.e. Kepler's equation in gamma; scaled,
//      A_C'(gamma) = ((gamma - sin gamma) / sin^3 alpha + kappa Y_Q) / 2,
//    a sum of positive terms, gamma - sin gamma by its Taylor series;
//  * the area swept to the ellipse [UG18 eq. 24] is (|mu| / 2) atan2(|mu| Y, X);
//  * the lune's radial width: along the ray, 1 - (r_e / r_c)^2 = gap
//    (X_Q + |mu| S) / (X_Q^2 + mu^2 Y_Q^2), S = sqrt(1 - Y_Q^2), with gap the
//    distance between circle and ellipse at height Y_Q,
//      gap = (cos b S - cos alpha |mu|)^2 / (sin^2 alpha (X_Q + |mu| S) + 2 xe),
//      cos b S - cos alpha |mu| = cos^2 b (yl - Y)(yl + Y) / (cos b S + cos alpha |mu|)
//    (the circle's equation at the ellipse's point is minus a perfect square):
//    the lune's width vanishes as a square at the tangency without cancelling;
//  * z = sqrt(1 - x^2 - y^2) of a sample is sin alpha sqrt(-C), -C formed as
//    a sum of squares inside the ellipse ((mu cos alpha - cos b X_d)^2 + 1 - s)
//    and as (1 - rho)((1 + rho)(...) + 2 xe X_Q) on a ray to the circle, so
//    directions near the horizon keep their relative precision.
//
// Projected solid angle (the irradiance factor E / L of a constant-radiance
// sphere) in closed form: Omega_p = 2 sin^3 alpha H, H the scaled half area,
//    H = pi mu / 2                                        (mu >= 1)
//    H = pi mu / 2 + A_C'(gamma_l) - (mu / 2) phi_l        (0 <= mu < 1)
//    H = A_C'(gamma_l) - (|mu| / 2) phi_l                  (-1 < mu < 0)
// with gamma_l = atan2(sin alpha sqrt(1 - mu^2), cos alpha) (the tangency
// point on the unit circle) and phi_l = atan2(sqrt(1 - mu^2), cos alpha |mu|)
// (its angle in the ellipse's own disk coordinates): [UG18 sec. 3] E and L
// from their area functions at the tangency ray. The same quantity is pi times
// the configuration factor of a tilted differential element to a sphere that
// its plane cuts (Howell, "A Catalog of Radiation Heat Transfer Configuration
// Factors", section B, plane element of any tilt to a sphere, plane of the
// element intersecting the sphere; Siegel & Howell, "Thermal Radiation Heat
// Transfer"):
//    Omega_p = asin(yl sin a) + sin^2 a sin b psi - cos a sqrt(sin^2 a - sin^2 b),
//    psi = acos(-cos a sin b / (sin a cos b)), yl sin a = sqrt(sin^2 a - sin^2 b) / cos b,
// which cancels catastrophically for small or barely visible caps; the tests
// use it, in 50-digit arithmetic, as the independent reference.
//
// Thin lunes. For a sphere that pokes above the receiving plane by a sliver
// (1 + mu small) the lune's area is A_C' - A_E', two terms of size ~
// sqrt(1 + mu) whose difference is ~(1 + mu)^(5/2): the closed form loses
// ~A_C'(gamma_l) / H ulps. Past lune_closed_form_ratio (see projected_cap) the
// lune's area function is instead the 8-point Gauss-Legendre quadrature of
// the cancellation-free radial integrand, in psi = asin Y; the integrand is
// then analytic on a disk about [0, asin yl] several times its size, and the
// rule exact to rounding (~1e-15); Omega_p is that quadrature to the tangency,
// and the map the same Newton iteration on it (~8x dearer, but such slivers
// carry (1 + mu)^(5/2) of the sphere's light). Measured against Howell's
// formula in 113-bit arithmetic: relative error of Omega_p <= 1e-12 for every
// 1 + mu >= 1e-7 and sin alpha <= 1 - 1e-6, <= 1e-10 for observers closer to
// the sphere; at 1 + mu = 1e-8, <= 5e-11; at 1e-10 (below the resolution of
// the float inputs) ~5e-5.
//
// Inversion of the area function [UG18 sec. 5: Newton's method with a
// bisection safeguard], in gamma (the circle's polar angle, in which the area
// is smooth up to the tangency even for caps of nearly a hemisphere, where it
// has a square-root singularity in Y): Newton steps on A(gamma) - target
// within a bracket [lo, hi] that every evaluation tightens; a step leaving the
// bracket is replaced by bisection. Stops when a step is below
// newton_tolerance = 1e-12 of gamma_l (the last iterate is then within ~1e-24
// of the root by quadratic convergence), when the residual is within
// newton_residual = 4 eps of the size of the terms the area function adds
// (its rounding level: H, or A_C'(gamma_l) for the closed form of a lune), or
// after newton_max_iterations (64: bisection alone reaches 2^-64). 4.7 area
// evaluations on average over the crossing caps of the tests, 11 at most.
#include <cfloat>
#include <cmath>
#include <numbers>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/core/onb.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

namespace projected_cap_detail {

inline constexpr double dpi = std::numbers::pi;

// (a - sin a) / a^3 for a in [0, pi/2], sn = sin a, to a few ulp: the
// Taylor series a^3 / 3! - a^5 / 5! + ... below 1 (the term left out is below
// 1e-18 relative), a - sin a directly beyond (it cancels at most 6 / a^2 <= 6 ulps).
inline double angle_minus_sine_ratio(double a, double sn) {
  if (a < 1.0) {
    const double a2 = a * a;
    return 1.0 / 6.0 -
           a2 * (1.0 / 120.0 -
                 a2 * (1.0 / 5040.0 -
                       a2 * (1.0 / 362880.0 -
                             a2 * (1.0 / 39916800.0 -
                                   a2 * (1.0 / 6227020800.0 -
                                         a2 * (1.0 / 1307674368000.0 - a2 * (1.0 / 355687428096000.0)))))));
  }
  return (a - sn) / (a * a * a);
}

// sin and cos of a in [0, pi]: fast_math::sincos_quadrant on min(a, pi - a),
// the cosine's sign that of pi / 2 - a. Without a branch: the angle comes
// from a uniform sample, so a branch would be mispredicted half the time.
inline void sincos_half_turn(double a, double& s, double& c) {
  const double rest = dpi - a;
  fast_math::sincos_quadrant(std::min(a, rest), s, c);
  c = std::copysign(c, rest - a);
}

// 8-point Gauss-Legendre rule on [-1, 1] (nodes +-x, weights w).
inline constexpr double gl_x[4] = {0.18343464249564980494, 0.52553240991632898582, 0.79666647741362673959,
                                   0.96028985649753623168};
inline constexpr double gl_w[4] = {0.36268378337836198297, 0.31370664587788728734, 0.22238103445337447054,
                                   0.10122853629037625915};

}  // namespace projected_cap_detail

// The projection of a cap of directions onto the tangent plane of the
// receiver, set up once per (cap, normal), in the scaled coordinates of the
// header comment, and the area functions of the radial map.
struct projected_cap {
  enum class kind : unsigned char { none, ellipse, ellipse_lune, lune };

  // When the lune's area function is a quadrature instead of the closed form
  // (header comment). The closed form loses ~A_C'(gamma_l) / H ulps, so it is
  // replaced once that ratio passes lune_closed_form_ratio (1e3: errors up to
  // ~1e-13), provided the tangency height yl is at most
  // lune_quadrature_max_height (0.75), up to which the 8-point rule in psi =
  // asin Y is exact to ~1e-13 (beyond, the integrand's singularities near
  // psi = pi/2, at distance ~cos alpha for a close observer, slow it down), and
  // whatever yl once the ratio passes lune_closed_form_max_ratio (1e5, where
  // the closed form could lose 1e-11). Thresholds measured against Howell's
  // formula in 113-bit arithmetic over sin alpha in [1e-4, 1 - 1e-10] and
  // 1 + mu in [1e-10, 2].
  static constexpr double lune_closed_form_ratio = 1e3;
  static constexpr double lune_closed_form_max_ratio = 1e5;
  static constexpr double lune_quadrature_max_height = 0.75;
  static constexpr double newton_tolerance = 1e-12;
  static constexpr double newton_residual = 4.0 * DBL_EPSILON;
  static constexpr int newton_max_iterations = 64;

  kind type = kind::none;
  bool quadrature = false;  // the lune's area by Gauss-Legendre (thin lunes)
  double sin_a = 0.0, cos_a = 1.0, mu = 0.0, cos_b = 1.0;
  double xe = 0.0;     // ellipse centre, cos alpha cos b
  double kappa = 0.0;  // (1 - xe) / sin^2 alpha: where the circle meets the X axis
  double n0 = 1.0;     // 1 + cos^2 alpha mu^2: the circle is sin^2 a X^2 + 2 xe X + Y^2 = n0
  double yl = 0.0, xl = 0.0;  // tangency point of ellipse and circle (scaled; crossing caps)
  double gamma_l = 0.0;       // its polar angle on the unit circle
  double area_l = 0.0;        // A_C'(gamma_l): the area swept up to the tangency ray
  double phi_l = 0.0;         // the tangency point's polar angle in the ellipse's disk coordinates
  double half_area = 0.0;     // H, the scaled area of the upper half
  double area_scale = 0.0;    // the size of the terms the area function sums (its rounding is ~eps of it)
  double omega = 0.0;         // projected solid angle 2 sin^3 alpha H, in sr

  // A point Q of the circle (the horizon) by its polar angle gamma on the unit
  // circle, in scaled coordinates.
  struct circle_point {
    double gamma = 0.0, sn = 0.0, cs = 1.0, x = 0.0, y = 0.0;
  };

  // From sin alpha > 0, cos alpha >= 0, mu = sin b / sin alpha and cos b >= 0.
  // cos alpha and cos b as computed from the geometry, not as sqrt(1 - sin^2):
  // see sphere_projected_view.
  static projected_cap make(double sin_a, double cos_a, double mu, double cos_b) {
    using projected_cap_detail::dpi;
    projected_cap p;
    p.sin_a = sin_a, p.cos_a = cos_a, p.mu = mu, p.cos_b = cos_b;
    if (!(sin_a > 0.0) || !(mu > -1.0) || !(cos_a >= 0.0) || !(cos_b >= 0.0) || !std::isfinite(mu)) return p;
    p.xe = cos_a * cos_b;
    if (mu >= 1.0) {
      // The ellipse alone: its map and inverse need neither the circle
      // (kappa, n0) nor the tangency point.
      p.type = kind::ellipse;
      p.half_area = 0.5 * dpi * mu;
    } else {
      p.kappa = 1.0 / (1.0 + cos_a) + cos_a * mu * mu / (1.0 + cos_b);
      p.n0 = 1.0 + cos_a * cos_a * mu * mu;
      const double am = std::abs(mu);
      const double root = std::sqrt((1.0 - am) * (1.0 + am));  // sqrt(1 - mu^2)
      p.yl = root / cos_b;
      p.xl = cos_a * mu * mu / cos_b;
      p.gamma_l = fast_math::atan2_upper(sin_a * root, cos_a);
      p.area_l = p.circle_area(p.circle_at(p.gamma_l));
      p.phi_l = fast_math::atan2_upper(root, cos_a * am);
      if (mu >= 0.0) {
        p.type = kind::ellipse_lune;
        p.half_area = 0.5 * dpi * mu + (p.area_l - 0.5 * mu * p.phi_l);
      } else {
        p.type = kind::lune;
        const double closed = p.area_l - 0.5 * am * p.phi_l;
        // Negated comparisons: a closed form that cancelled to <= 0 or NaN
        // takes the quadrature.
        p.quadrature = !(closed * lune_closed_form_ratio >= p.area_l) &&
                       (p.yl <= lune_quadrature_max_height || !(closed * lune_closed_form_max_ratio >= p.area_l));
        p.half_area = p.quadrature ? p.lune_area_quadrature(p.yl) : closed;
      }
    }
    // The closed forms add or subtract terms up to A_C'(gamma_l); the
    // quadrature sums positive terms.
    p.area_scale = p.quadrature ? p.half_area : std::max(p.half_area, p.area_l);
    p.omega = 2.0 * (sin_a * sin_a * sin_a) * p.half_area;
    if (!(p.omega > 0.0) || !std::isfinite(p.omega)) p.type = kind::none;
    return p;
  }

  bool valid() const { return type != kind::none; }

  circle_point circle_at(double gamma) const {
    circle_point q;
    q.gamma = gamma;
    fast_math::sincos_quadrant(gamma, q.sn, q.cs);
    q.y = q.sn / sin_a;
    q.x = kappa - q.y * q.y / (1.0 + q.cs);  // (cos gamma - xe) / sin^2 alpha
    return q;
  }
  // The circle's point at height Y in [0, yl].
  circle_point circle_at_height(double y) const {
    circle_point q;
    q.y = y;
    q.sn = sin_a * y;
    q.cs = std::sqrt(std::max((1.0 - q.sn) * (1.0 + q.sn), 0.0));
    q.gamma = fast_math::atan2_upper(q.sn, q.cs);
    q.x = kappa - y * y / (1.0 + q.cs);
    return q;
  }

  // A_C': the area swept from the ellipse centre to the circle up to the ray
  // through q (scaled; header comment), and its derivative in gamma,
  // (1 - xe cos gamma) / (2 sin^3 alpha) = (Y^2 / (1 + cos gamma) + kappa cos gamma) / (2 sin alpha).
  double circle_area(const circle_point& q) const {
    const double g = q.gamma / sin_a;
    return 0.5 * (g * g * g * projected_cap_detail::angle_minus_sine_ratio(q.gamma, q.sn) + kappa * q.y);
  }
  double circle_area_derivative(const circle_point& q) const {
    return 0.5 * (q.y * q.y / (1.0 + q.cs) + kappa * q.cs) / sin_a;
  }

  // The lune's radial integrand per unit Y, dD/dY = (1 - e^2)(X + Y^2 /
  // (sin^2 a X + xe)) / 2, e = r_e / r_c along the ray to the circle's point
  // (X, Y), S = sqrt(1 - Y^2); 1 - e^2 from the gap between circle and
  // ellipse at height Y (header comment), >= 0 and vanishing as (yl - Y)^2 at
  // the tangency. Also returns 1 - e^2.
  double lune_integrand(double y, double s, double x, double& one_minus_e2) const {
    const double am = std::abs(mu);
    const double w = cos_b * cos_b * (yl - y) * (yl + y) / (cos_b * s + cos_a * am);  // cos b S - cos a |mu|
    const double gap = w * w / (sin_a * sin_a * (x + am * s) + 2.0 * xe);
    const double q = x * x + am * am * y * y;
    one_minus_e2 = q > 0.0 ? std::min(gap * (x + am * s) / q, 1.0) : 1.0;
    return 0.5 * one_minus_e2 * (x + y * y / (sin_a * sin_a * x + xe));
  }
  double lune_integrand(const circle_point& q, double& one_minus_e2) const {
    return lune_integrand(q.y, std::sqrt(std::max((1.0 - q.y) * (1.0 + q.y), 0.0)), q.x, one_minus_e2);
  }
  // D: the lune's area swept up to the ray through q: A_C' - A_E', or the
  // quadrature for thin lunes; and its derivative in gamma.
  double lune_area(const circle_point& q) const {
    if (quadrature) return lune_area_quadrature(q.y);
    const double am = std::abs(mu);
    return circle_area(q) - 0.5 * am * fast_math::atan2_upper(am * q.y, q.x);
  }
  double lune_area_derivative(const circle_point& q) const {
    double e;
    return lune_integrand(q, e) * q.cs / sin_a;  // dY / d gamma = cos gamma / sin alpha
  }
  // D up to height Y by 8-point Gauss-Legendre in psi = asin Y (Y = sin psi,
  // dY = cos psi d psi, removing the branch point of S at Y = 1).
  double lune_area_quadrature(double y) const {
    using namespace projected_cap_detail;
    const double psi = fast_math::atan2_upper(y, std::sqrt(std::max((1.0 - y) * (1.0 + y), 0.0)));
    const double h = 0.5 * psi;
    double sum = 0.0;
    for (int i = 0; i < 8; ++i) {
      const double node = h * (1.0 + (i < 4 ? -gl_x[i] : gl_x[i - 4]));
      double sn, cs, e;
      fast_math::sincos_quadrant(node, sn, cs);
      const double c = std::sqrt(std::max((1.0 - sin_a * sn) * (1.0 + sin_a * sn), 0.0));
      sum += gl_w[i & 3] * cs * lune_integrand(sn, cs, kappa - sn * sn / (1.0 + c), e);
    }
    return h * sum;
  }
  // The area function the map inverts in the crossing cases, at q, and its
  // derivative in gamma.
  double area(const circle_point& q) const { return type == kind::lune ? lune_area(q) : circle_area(q); }
  double area_derivative(const circle_point& q) const {
    return type == kind::lune ? lune_area_derivative(q) : circle_area_derivative(q);
  }

  // The circle's point Q in [0, gamma_l] of the ray whose swept area is
  // `target` (circle part of ellipse_lune, or the lune), by the safeguarded
  // Newton iteration of the header comment. iterations (optional): the number
  // of area evaluations.
  circle_point solve(double target, int* iterations = nullptr) const {
    double lo = 0.0, hi = gamma_l, g;
    if (type == kind::ellipse_lune) {
      // A_C' >= kappa Y / 2 and A_C' ~ (kappa + Y^2 / 6) Y / 2 for small caps:
      // the linear guess lies right of the root, where the Newton iterates of
      // this convex function decrease monotonically. gamma ~ sin alpha Y.
      g = std::min(gamma_l, sin_a * 2.0 * target / kappa);
    } else {
      // The lune's area rises linearly from 0 and meets its total with zero
      // first and second derivatives (the tangency): 1 - cbrt(1 - u) of
      // gamma_l is the root of that shape.
      g = gamma_l * (1.0 - std::cbrt(std::max(1.0 - target / half_area, 0.0)));
    }
    circle_point q;
    int it = 0;
    for (; it < newton_max_iterations; ++it) {
      q = circle_at(g);
      const double r = area(q) - target;
      if (std::abs(r) <= newton_residual * area_scale) break;
      if (r > 0.0) {
        hi = g;
      } else {
        lo = g;
      }
      double next = g - r / area_derivative(q);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - g) <= newton_tolerance * gamma_l) {
        q = circle_at(next);
        ++it;
        break;
      }
      g = next;
    }
    if (iterations != nullptr) *iterations = it + 1;
    return q;
  }
};

// A point of the projected cap in scaled coordinates (X, Y), with -C = (1 -
// x^2 - y^2) / sin^2 alpha >= 0 (so z = sin alpha sqrt(-C)).
struct projected_cap_point {
  double x = 0.0, y = 0.0, minus_c = 0.0;
};

// u in [0,1)^2 -> the point of the projected cap in scaled coordinates
// (header comment): the radial map. pc must be valid().
inline projected_cap_point square_to_projected_cap_scaled(dvec2 u, const projected_cap& pc) {
  using namespace projected_cap_detail;
  using kind = projected_cap::kind;
  const double s = u.x, t2 = 2.0 * u.y - 1.0;  // exact for u.y in float
  const double sign = t2 < 0.0 ? -1.0 : 1.0, ua = std::abs(t2);
  const double mu = pc.mu;
  projected_cap_point p;
  if (pc.type == kind::ellipse || (pc.type == kind::ellipse_lune && mu > 0.0 && ua * pc.half_area >= pc.area_l)) {
    // The ellipse: polar map of the disk, scaled (X = mu X_d, Y = Y_d)
    // [UG18 sec. 4.2]; for ellipse_lune, the rays past the tangency ray.
    double a = dpi * ua;
    if (pc.type == kind::ellipse_lune) a = std::min(pc.phi_l + 2.0 * (ua * pc.half_area - pc.area_l) / mu, dpi);
    double sn, cs;
    sincos_half_turn(a, sn, cs);
    const double rho = std::sqrt(s);
    const double xd = rho * cs;
    p.x = mu * xd;
    p.y = sign * rho * sn;
    const double e = mu * pc.cos_a - pc.cos_b * xd;
    p.minus_c = e * e + (1.0 - s);
  } else {
    const projected_cap::circle_point q = pc.solve(ua * pc.half_area);
    // r^2 uniform between r_e^2 and r_c^2 (r_e = 0 in the ellipse_lune's
    // circle part): rho = r / r_c, 1 - rho^2 = (1 - s)(1 - e^2).
    double one_minus_e2 = 1.0;
    if (pc.type == kind::lune) pc.lune_integrand(q, one_minus_e2);
    const double one_minus_rho2 = (1.0 - s) * one_minus_e2;
    const double rho = std::sqrt(1.0 - one_minus_rho2);
    p.x = rho * q.x;
    p.y = sign * rho * q.y;
    // -C(rho Q) = (1 - rho)((1 + rho)(sin^2 a X_Q^2 + Y_Q^2) + 2 xe X_Q), as C(Q) = 0.
    const double sa = pc.sin_a;
    p.minus_c = one_minus_rho2 / (1.0 + rho) * ((1.0 + rho) * (sa * sa * q.x * q.x + q.y * q.y) + 2.0 * pc.xe * q.x);
  }
  return p;
}

// The unit direction (receiver's frame) of a scaled point.
inline dvec3 projected_cap_direction(const projected_cap_point& p, const projected_cap& pc) {
  const double sa = pc.sin_a;
  return {pc.xe + sa * sa * p.x, sa * p.y, sa * std::sqrt(std::max(p.minus_c, 0.0))};
}

// u in [0,1)^2 -> unit direction (x, y, z) in the receiver's frame (z the
// normal, x towards the cap's axis), uniform in projected solid angle over
// the part of the cap above the horizon. u.x is the radial coordinate (r^2
// between the region's inner and outer boundary along the ray), u.y the
// angular one (the swept area, lower half first). pc must be valid().
inline dvec3 square_to_projected_cap(dvec2 u, const projected_cap& pc) {
  return projected_cap_direction(square_to_projected_cap_scaled(u, pc), pc);
}
inline dvec3 square_to_projected_cap(vec2 u, const projected_cap& pc) { return square_to_projected_cap(dvec2(u), pc); }

// Whether the unit direction d (receiver's frame) lies in the cap and above
// the horizon. 1 - cos(angle to the axis) as |d - w|^2 / 2, cancellation-free.
inline bool projected_cap_contains(const dvec3& d, const projected_cap& pc) {
  if (!pc.valid() || !(d.z > 0.0)) return false;
  const dvec3 w(pc.cos_b, 0.0, pc.sin_a * pc.mu);
  const dvec3 e = d - w;
  return 0.5 * glm::dot(e, e) <= pc.sin_a * pc.sin_a / (1.0 + pc.cos_a);
}

// Density per unit PROJECTED solid angle: 1 / Omega_p on the visible cap.
inline double square_to_projected_cap_pdf(const dvec3& d, const projected_cap& pc) {
  return projected_cap_contains(d, pc) ? 1.0 / pc.omega : 0.0;
}
// The same per unit SOLID angle: cos theta / Omega_p = d.z / Omega_p.
inline double square_to_projected_cap_pdf_solid_angle(const dvec3& d, const projected_cap& pc) {
  return projected_cap_contains(d, pc) ? d.z / pc.omega : 0.0;
}

// Scaled point of the projected cap -> unit square; the inverse of
// square_to_projected_cap_scaled.
inline dvec2 projected_cap_scaled_to_square(double x, double y_signed, const projected_cap& pc) {
  using namespace projected_cap_detail;
  using kind = projected_cap::kind;
  const double mu = pc.mu, y = std::abs(y_signed);
  const double sign = y_signed < 0.0 ? -1.0 : 1.0;
  double s, area;
  if (pc.type == kind::ellipse || (pc.type == kind::ellipse_lune && mu > 0.0 && y * pc.xl - x * pc.yl >= 0.0)) {
    // Inside the ellipse (past the tangency ray for ellipse_lune): polar
    // coordinates of the disk.
    const double xd = x / mu;
    s = xd * xd + y * y;
    const double a = fast_math::atan2_upper(y, xd);
    area = pc.type == kind::ellipse ? a / dpi * pc.half_area : pc.area_l + 0.5 * mu * (a - pc.phi_l);
  } else {
    // The ray from the ellipse centre through (x, y) meets the circle at r_c,
    // the positive root of (sin^2 a c^2 + s^2) r^2 + 2 xe c r - n0 = 0.
    const double sa = pc.sin_a;
    const double len = std::sqrt(x * x + y * y);
    const double c = len > 0.0 ? x / len : 1.0, sn = len > 0.0 ? y / len : 0.0;
    const double rc = pc.n0 / (pc.xe * c + std::sqrt(pc.xe * pc.xe * c * c + pc.n0 * (sa * sa * c * c + sn * sn)));
    const projected_cap::circle_point q = pc.circle_at_height(rc * sn);
    const double one_minus_rho2 = (rc - len) * (rc + len) / (rc * rc);
    if (pc.type == kind::ellipse_lune) {
      s = 1.0 - one_minus_rho2;
      area = pc.circle_area(q);
    } else {
      // s = (rho^2 - e^2) / (1 - e^2) = 1 - (1 - rho^2) / (1 - e^2).
      double one_minus_e2;
      pc.lune_integrand(q, one_minus_e2);
      s = one_minus_e2 > 0.0 ? 1.0 - one_minus_rho2 / one_minus_e2 : 0.5;
      area = pc.lune_area(q);
    }
  }
  const double ua = std::clamp(area / pc.half_area, 0.0, 1.0);
  return {std::clamp(s, 0.0, 1.0), 0.5 + 0.5 * sign * ua};
}

// Unit direction of the visible cap (receiver's frame) -> unit square; the
// inverse of square_to_projected_cap. The scaled coordinates X = (x - xe) /
// sin^2 alpha and Y = y / sin alpha carry the rounding of d (~1e-16 absolute)
// divided by sin^2 alpha: round trips through a direction are exact to
// ~1e-16 / (sin^2 alpha times the region's width in scaled units).
inline dvec2 projected_cap_to_square(const dvec3& d, const projected_cap& pc) {
  const double sa = pc.sin_a;
  return projected_cap_scaled_to_square((d.x - pc.xe) / (sa * sa), d.y / sa, pc);
}

// Caps wholly above the horizon, the common case, take a short path in mixed
// precision: what cancels is formed in double from the float inputs (c - o
// exactly, the height h' = (c - o) . n and the in-plane part p' = |n|^2 (c -
// o) - h' n, d^2 - r^2), everything else in float: the square roots and
// reciprocals, the frame, the polar map of the ellipse [UG18 sec. 4.2] and
// the direction, which is returned in float anyway. A float direction formed
// from float terms of size <= 1 is within a few ulp (~2e-7 rad) of the exact
// one, against half an ulp for the double path rounded at the end: the
// difference is invisible beside the float direction's own resolution
// (sphere_cone_sampler makes its directions the same way). The density is
// cos theta / Omega_p with Omega_p = pi sin^2 alpha sin b = pi r^2 h / d^3,
// no cancellation (h >= r), so it keeps float precision for every cap size.
//
// Which caps take it is decided from the double quantities h' and |n|^2
// alone (projected_cap_above::holds), identically by sample() and pdf().
struct projected_cap_above {
  // Whether the cap lies wholly above the horizon: h >= r, i.e. h' >= 0 and
  // h'^2 >= r^2 |n|^2 (no square root, so nothing rounds before the test).
  static bool holds(double hn, double nl2, double r2) { return hn >= 0.0 && hn * hn >= r2 * nl2; }

  vec3 ez{0.0f}, ex{0.0f}, ey{0.0f};
  float sin_a = 0.0f, cos_a = 0.0f, mu = 0.0f, cos_b = 0.0f, xe = 0.0f;
  float inv_omega = 0.0f;  // d^3 / (pi r^2 h)

  // From v = c - o (double, exact), d2 = |v|^2 > r2 = r^2, the normal nd
  // (|nd|^2 = nl2 > 0) and hn = v . nd, with holds(hn, nl2, r2): ez and
  // inv_omega (the density's part) and, with_map, sin alpha, cos alpha, mu,
  // cos b and the frame (ex along p', ey = ez x ex). The square roots and
  // reciprocals come four at a time. false if the density overflows a float.
  bool make(const dvec3& v, double d2, double r, const dvec3& nd, double nl2, double hn, bool with_map) {
    const double r2 = r * r;
    dvec3 pn(0.0);
    double pn2 = 1.0;
    if (with_map) {
      pn = nl2 * v - hn * nd;
      pn2 = glm::dot(pn, pn);
      if (pn2 < 1e-8 * d2 * nl2 * nl2) {
        // Axis within 1e-4 rad of the normal: p' carries an error of a few ulp
        // of d along n; one more projection makes it orthogonal again.
        pn -= (glm::dot(pn, nd) / nl2) * nd;
        pn2 = glm::dot(pn, pn);
      }
    }
    // |n|, d, sqrt(d^2 - r^2), |p'| = |n|^2 |p|; then 1 / |n|, 1 / d, 1 / |p'|, |n| / (pi r^2 h') = 1 / (pi r^2 h).
    const auto roots = fast_math::sqrt4(float(nl2), float(d2), float(d2 - r2), float(pn2));
    const float pl = roots[3] > 0.0f ? roots[3] : 1.0f;
    const auto inv = fast_math::reciprocal4(roots[0], roots[1], pl, pi * float(r2 * hn));
    const float inv_nl = inv[0], d = roots[1], inv_d = inv[1];
    ez = vec3(nd) * inv_nl;
    inv_omega = float(d2) * d * roots[0] * inv[3];
    if (!(inv_omega > 0.0f) || !(inv_omega <= FLT_MAX)) return false;
    if (!with_map) return true;
    const float rf = float(r);
    sin_a = rf * inv_d;
    cos_a = roots[2] * inv_d;
    mu = float(hn) * inv_nl / rf;
    cos_b = roots[3] * (inv_nl * inv_nl) * inv_d;
    xe = cos_a * cos_b;
    if (roots[3] > 0.0f) {
      ex = vec3(pn) * inv[2];
    } else {  // axis along the normal: any x will do (the ellipse is a circle about the origin)
      ex = onb(ez).u;
    }
    ey = glm::cross(ez, ex);
    return true;
  }

  // u -> unit direction (world): the polar map of the disk scaled to the
  // ellipse, the same map as square_to_projected_cap for mu >= 1 (u.x the
  // radial coordinate r^2, u.y the swept area, lower half first).
  vec3 sample(vec2 u) const {
    const float t2 = 2.0f * u.y - 1.0f;  // exact
    double sn, cs;
    projected_cap_detail::sincos_half_turn(projected_cap_detail::dpi * std::abs(double(t2)), sn, cs);
    const float rho = std::sqrt(u.x);
    const float xd = rho * float(cs), yd = std::copysign(rho * float(sn), t2);
    const float e = mu * cos_a - cos_b * xd;
    const float z = sin_a * std::sqrt(e * e + (1.0f - u.x));  // a sum of squares: no cancellation near the horizon
    const float x = xe + sin_a * sin_a * mu * xd, y = sin_a * yd;
    return x * ex + y * ey + z * ez;
  }

  // Density per unit SOLID ANGLE of the unit direction dir in the cap.
  float density(const vec3& dir) const { return glm::dot(dir, ez) * inv_omega; }
};

// The receiver's frame and the projected cap of a sphere seen from o with
// unit normal n, in double: z = n (normalised), x along the part of c - o
// orthogonal to n. cos alpha and cos b are taken from quantities that do not
// cancel (d^2 - r^2 of float inputs, the length of the orthogonal part of
// c - o), sin b = h / d and mu = h / r from the height h = (c - o) . n.
//
// The sampler uses it for caps that cross the horizon (projected_cap_above
// takes the others); projected_solid_angle() and the tests for all. A cap
// above the horizon gets Omega_p = pi r^2 h / d^3 and, with the frame, the
// few members its closed-form map needs. The square roots and reciprocals
// the set-up needs are formed together (fast_math::sqrt4), so they overlap
// instead of queueing on the divider one after the other.
struct sphere_projected_view {
  dvec3 v{0.0};  // c - o
  double d2 = 0.0, d = 0.0, inv_d = 0.0, r = 0.0;
  double tangent = 0.0;      // sqrt(d^2 - r^2), the distance to the rim
  double inv_omega = 0.0;    // 1 / cap.omega
  dvec3 ex{1.0, 0.0, 0.0}, ey{0.0, 1.0, 0.0}, ez{0.0, 0.0, 1.0};
  projected_cap cap;

  // false (and cap invalid) if o is inside or on the sphere, n is not a
  // direction, or the cap lies wholly below the horizon. with_frame: also
  // ex, ey and the whole cap (sampling needs them); without, a cap above the
  // horizon gets only its type, omega and inv_omega (all the density needs).
  bool make(const sphere& sp, const vec3& o, const vec3& n, bool with_frame) {
    using projected_cap_detail::dpi;
    v = dvec3(sp.center) - dvec3(o);  // exact: a difference of floats in double
    d2 = glm::dot(v, v);
    r = sp.radius;
    const double r2 = r * r;  // exact: r is a float
    if (!(d2 > r2) || !(r > 0.0)) return false;
    const dvec3 nd(n);
    const double nl2 = glm::dot(nd, nd);
    if (!(nl2 > 0.0) || !std::isfinite(nl2)) return false;
    // With the normal unnormalised: h' = |n| h and p' = |n|^2 p, p the part of
    // c - o in the receiving plane, so that every square root and reciprocal
    // the set-up needs comes from two packed operations issued together.
    const double hn = glm::dot(v, nd);
    dvec3 pn = nl2 * v - hn * nd;
    double pn2 = glm::dot(pn, pn);
    if (pn2 < 1e-8 * d2 * nl2 * nl2) {
      // Axis within 1e-4 rad of the normal: p carries an error of a few ulp
      // of d along n; one more projection makes it orthogonal again.
      pn -= (glm::dot(pn, nd) / nl2) * nd;
      pn2 = glm::dot(pn, pn);
    }
    const auto roots = fast_math::sqrt4(nl2, d2, d2 - r2, pn2);            // |n|, d, sqrt(d^2 - r^2), |p'|
    const auto inv = fast_math::inverse_sqrt4(nl2, d2, r2, pn2 > 0.0 ? pn2 : 1.0);  // their reciprocals, 1 / r
    d = roots[1], inv_d = inv[1], tangent = roots[2];
    const double inv_nl = inv[0];
    ez = nd * inv_nl;
    const double h = hn * inv_nl;
    if (!(h > -r)) return false;  // wholly below the horizon
    if (projected_cap_above::holds(hn, nl2, r2)) {
      // Wholly above the horizon: Omega_p = pi sin^2 alpha sin b = pi r^2 h / d^3.
      inv_omega = d2 * d / (dpi * r2 * h);
      cap = projected_cap{};
      cap.type = inv_omega > 0.0 && inv_omega <= DBL_MAX ? projected_cap::kind::ellipse : projected_cap::kind::none;
      cap.omega = 1.0 / inv_omega;
      if (!with_frame) return cap.valid();
      // The ellipse's map needs only these (projected_cap::make, mu >= 1).
      cap.sin_a = r * inv_d, cap.cos_a = tangent * inv_d, cap.mu = h * inv[2];
      cap.cos_b = roots[3] * inv_nl * inv_nl * inv_d;
      cap.xe = cap.cos_a * cap.cos_b;
      cap.half_area = cap.area_scale = 0.5 * dpi * cap.mu;
    } else {
      cap = projected_cap::make(r * inv_d, tangent * inv_d, h * inv[2], roots[3] * inv_nl * inv_nl * inv_d);
      inv_omega = 1.0 / cap.omega;
    }
    if (!cap.valid()) return false;
    if (with_frame) {
      if (pn2 > 0.0) {
        ex = pn * inv[3];
      } else {  // axis along the normal: any x will do (the ellipse is a circle about the origin)
        const double sign = std::copysign(1.0, ez.z);
        const double a = -1.0 / (sign + ez.z), b = ez.x * ez.y * a;
        ex = dvec3(1.0 + sign * ez.x * ez.x * a, sign * b, -sign * ez.x);
      }
      ey = glm::cross(ez, ex);
    }
    return true;
  }
};

// Light-sampling strategy: the sphere by projected solid angle (the
// normal-aware form of light_sample.hpp). pdf per unit SOLID angle cos theta /
// Omega_p on the part of the cap above the horizon of n, 0 elsewhere; no
// sample and pdf 0 when the cap lies wholly below the horizon or o is inside
// the sphere. An unoccluded sphere of constant radiance L on a diffuse
// receiver then gets the estimate L cos theta / pdf = L Omega_p for every
// sample: zero variance. Like sphere_cone_sampler, it ignores sphere::flip.
//
// Agreement of sample and pdf: the pdf returned with a sample is computed as
// pdf() computes it, from the direction as returned (rounded to float), so
// the two agree to the last bit and cos theta / pdf is Omega_p whatever the
// rounding. A float direction is within ~6e-8 rad of the exact one: near the
// rim of the cap it may fall outside the sphere (pdf() then gives 0, as for
// any ray that misses; a fraction ~2^-20 / alpha of the samples, as for
// sphere_cone_sampler, more for lunes thinner than that), and a sample within
// ~1e-7 of the horizon may round below it: that one is not returned (false;
// its share of the estimate is ~1e-14). A configuration whose density would
// overflow a float (Omega_p below ~1e-38 of cos theta) gets no sample, and
// pdf 0.
struct sphere_projected_solid_angle_sampler {
  sphere shape;

  // Whether sample() can return a direction for o with some normal: o outside the sphere.
  bool faces(const vec3& o) const {
    const dvec3 v = dvec3(shape.center) - dvec3(o);
    return glm::dot(v, v) > double(shape.radius) * double(shape.radius);
  }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    const dvec3 v = dvec3(shape.center) - dvec3(o);  // exact: a difference of floats in double
    const double d2 = glm::dot(v, v), r = shape.radius, r2 = r * r;
    const dvec3 nd(n);
    const double nl2 = glm::dot(nd, nd), hn = glm::dot(v, nd);
    if (d2 > r2 && nl2 > 0.0 && std::isfinite(nl2) && projected_cap_above::holds(hn, nl2, r2)) {
      projected_cap_above cap;
      if (!cap.make(v, d2, r, nd, nl2, hn, true)) return false;
      s.dir = cap.sample(u);
      s.pdf = cap.density(s.dir);
      if (!(s.pdf > 0.0f) || !(s.pdf <= FLT_MAX)) return false;  // rounded below the horizon / overflow
      s.dist = near_distance(v, d2, r2, dvec3(s.dir));
      return true;
    }
    sphere_projected_view view;
    if (!view.make(shape, o, n, true)) return false;
    const dvec3 l = square_to_projected_cap(u, view.cap);
    s.dir = vec3(l.x * view.ex + l.y * view.ey + l.z * view.ez);
    const dvec3 dir(s.dir);
    const double p = glm::dot(dir, view.ez) * view.inv_omega;
    if (!(p > 0.0) || !(p <= double(FLT_MAX))) return false;  // rounded below the horizon / overflow
    s.pdf = float(p);
    s.dist = near_distance(view.v, view.d2, r2, dir);
    return s.pdf > 0.0f;
  }

  // Density per unit SOLID ANGLE at o, receiver normal n, of the unit
  // direction dir: cos theta / Omega_p on the cap above the horizon.
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const {
    const dvec3 dd(dir);
    if (!(glm::dot(dd, dvec3(n)) > 0.0)) return 0.0f;  // below the horizon
    const dvec3 v = dvec3(shape.center) - dvec3(o);
    const double d2 = glm::dot(v, v), r2 = double(shape.radius) * double(shape.radius);
    if (!(d2 > r2)) return 0.0f;
    // In the cap: 1 - cos(angle to the axis) <= 1 - cos alpha = r^2 / (d^2 +
    // d sqrt(d^2 - r^2)), both without cancellation, multiplied out.
    const double d = std::sqrt(d2);
    const dvec3 e = dd - v * (1.0 / d);
    if (!(0.5 * glm::dot(e, e) * (d2 + d * std::sqrt(d2 - r2)) <= r2)) return 0.0f;
    const dvec3 nd(n);
    const double nl2 = glm::dot(nd, nd), hn = glm::dot(v, nd);
    if (nl2 > 0.0 && std::isfinite(nl2) && projected_cap_above::holds(hn, nl2, r2)) {
      projected_cap_above cap;
      if (!cap.make(v, d2, double(shape.radius), nd, nl2, hn, false)) return 0.0f;
      const float p = cap.density(dir);
      return p > 0.0f && p <= FLT_MAX ? p : 0.0f;
    }
    sphere_projected_view view;
    if (!view.make(shape, o, n, false)) return 0.0f;
    const double p = glm::dot(dd, view.ez) * view.inv_omega;
    return p > 0.0 && p <= double(FLT_MAX) ? float(p) : 0.0f;
  }

  // Projected solid angle of the sphere's visible part at o, normal n (0 if
  // none): the irradiance from a constant-radiance sphere is L times it.
  double projected_solid_angle(const vec3& o, const vec3& n) const {
    sphere_projected_view view;
    return view.make(shape, o, n, false) ? view.cap.omega : 0.0;
  }

 private:
  // Distance along the unit dir to the near intersection, (d^2 - r^2) / (b +
  // sqrt(r^2 - p^2)), b = dir . (c - o), p^2 the squared distance of the
  // centre from the ray: no cancellation near the sphere or far from it. A
  // direction that misses by rounding gets the tangent distance. The terms
  // in double, the last square root and division in float: the distance is
  // returned as a float, and both are well conditioned (a sum of positive
  // terms, a quotient).
  static float near_distance(const dvec3& v, double d2, double r2, const dvec3& dir) {
    const double b = glm::dot(dir, v);
    const dvec3 perp = v - b * dir;
    const double disc = std::max(r2 - glm::dot(perp, perp), 0.0);
    return float(d2 - r2) / (float(b) + std::sqrt(float(disc)));
  }
};

}  // namespace mcrt
