// Tests of the polar parametrization of the spherical ellipse
// (sampling/spherical_ellipse_polar.hpp, Guillen et al. 2017) on the
// canonical cone: the Carlson closed form of the sector area against an
// independent quadrature, the whole solid angle against the parallel map's,
// the map against its own definition (sector area equation and theta
// equation, evaluated from the returned direction only), the Newton solver's
// stopping rule and iteration count, continuity across the quadrants, the
// round trip sample -> inverse, and finiteness over 10^5 random canonical
// cones. The light-sampling strategy (pdf consistency, E[1/pdf], round trip,
// one-sidedness, fallback, chi-square) is tested with the parallel map's in
// test_spherical_ellipse.cpp, and fuzzed over 10^6 configurations in
// test_spherical_ellipse_slow.cpp.
//
// Every random test uses a fixed seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_ellipse_polar.hpp"
#include "support/solid_angle.hpp"

namespace {

using namespace mcrt;

constexpr double dpi = std::numbers::pi;

// A small number for RecordProperty (std::to_string prints 0.000000).
std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// ------------------------------------------------------------------ reference quadrature

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from the
// Tricomi initial guesses; Golub-Welsch would do as well).
struct gauss_legendre {
  std::vector<double> x, w;
  explicit gauss_legendre(int n) : x(n), w(n) {
    for (int i = 0; i < n; ++i) {
      double z = std::cos(dpi * (i + 0.75) / (n + 0.5)), dp = 0.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::abs(dz) < 1e-16) break;
      }
      x[i] = z;
      w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

const gauss_legendre& gl20() {
  static const gauss_legendre g(20);
  return g;
}

// 1 - cos theta_max(phi) from the boundary equation tan^2 theta_max =
// 1 / (cos^2 phi / a^2 + sin^2 phi / b^2), as r^2 / (S (S + 1)): written out
// here from the definition, not taken from the header.
double one_minus_cos_max(double a, double b, double phi) {
  const double c = std::cos(phi), s = std::sin(phi);
  const double r2 = 1.0 / (c * c / (a * a) + s * s / (b * b)), st = std::sqrt(1.0 + r2);
  return r2 / (st * (st + 1.0));
}

// int_0^psi (1 - cos theta_max(phi)) dphi for psi in [0, pi/2] by composite
// 20-point Gauss-Legendre on segments that grow geometrically (x2) from
// 1e-3 b/a at phi = 0, where an elongated cone has its feature of width
// ~b/a, each split in 4: a few 1e-15 relative for the cones below.
double sector_quadrature(double a, double b, double psi) {
  const gauss_legendre& g = gl20();
  double sum = 0.0, lo = 0.0, w = 1e-3 * b / a;
  while (lo < psi) {
    const double hi = std::min(psi, w);  // w > lo: it starts above 0 and doubles
    for (int k = 0; k < 4; ++k) {
      const double s0 = lo + (hi - lo) * k / 4.0, s1 = lo + (hi - lo) * (k + 1) / 4.0;
      const double m = 0.5 * (s0 + s1), r = 0.5 * (s1 - s0);
      for (std::size_t i = 0; i < g.x.size(); ++i) sum += r * g.w[i] * one_minus_cos_max(a, b, m + r * g.x[i]);
    }
    lo = hi;
    w *= 2.0;
  }
  return sum;
}

// int_0^phi (1 - cos theta_max) for phi in [0, 2 pi): whole quadrants plus
// a part, by the symmetry of theta_max under phi -> -phi and phi -> pi - phi.
double sector_quadrature_full(double a, double b, double phi) {
  const double quarter = sector_quadrature(a, b, 0.5 * dpi);
  const int k = std::min(3, static_cast<int>(phi / (0.5 * dpi)));
  const double rem = std::clamp(phi - k * 0.5 * dpi, 0.0, 0.5 * dpi);
  return k % 2 == 0 ? k * quarter + sector_quadrature(a, b, rem)
                    : (k + 1) * quarter - sector_quadrature(a, b, 0.5 * dpi - rem);
}

// Canonical cones: sizes from tiny (1e-5) to wide (b = 1e6) and axis ratios
// up to 1e4 (1e8 where stated).
std::vector<spherical_ellipse> canonical_cones() {
  std::vector<spherical_ellipse> out;
  for (double a : {1e-5, 1e-3, 0.2, 1.0, 5.0, 1e3, 1e6})
    for (double ratio : {1.0, 1.7, 30.0, 1e4}) out.push_back({a, a / ratio});
  out.push_back({1e10, 1e6});  // wide and elongated: b at max_tangent, a/b = 1e4
  out.push_back({1e4, 1e-4});  // a/b = 1e8, the largest ratio make_ellipse_cone maps
  return out;
}

// ------------------------------------------------------------------ closed form

// The Carlson form of the quadrant sector against the quadrature, at
// boundary points spread over the quadrant (t eccentric angle).
TEST(SphericalEllipsePolar, SectorAgainstQuadrature) {
  double worst = 0.0;
  for (const spherical_ellipse& se : canonical_cones()) {
    const spherical_ellipse_polar_consts k(se);
    for (double t : {1e-7, 0.05, 0.4, 0.9, 1.3, 1.55, 1.5707, 0.5 * dpi}) {
      const spherical_ellipse_polar_ray ray{std::sin(t), t == 0.5 * dpi ? 0.0 : std::cos(t)};
      const double phi = std::atan2(se.b * ray.s, se.a * ray.c);
      const double ref = sector_quadrature(se.a, se.b, phi), got = spherical_ellipse_polar_sector(k, ray);
      const double rel = std::abs(got / ref - 1.0);
      worst = std::max(worst, rel);
      EXPECT_LE(rel, 1e-12) << se.a << " " << se.b << " t " << t;
    }
  }
  RecordProperty("worst_sector_relative_error", sci(worst));
}

// 4 quadrant sectors = the parallel map's solid angle (AGM), and the exact
// cap 2 pi (1 - cos alpha) for a = b.
TEST(SphericalEllipsePolar, AreaMatchesParallelAndCap) {
  for (const spherical_ellipse& se : canonical_cones()) {
    const double polar = spherical_ellipse_polar_area(se), agm = spherical_ellipse_area(se);
    EXPECT_NEAR(polar / agm, 1.0, 1e-13) << se.a << " " << se.b;
    if (se.a == se.b) {
      const double sa = std::sqrt(1.0 + se.a * se.a);
      EXPECT_NEAR(polar / (2.0 * dpi * se.a * se.a / (sa * (sa + 1.0))), 1.0, 1e-14) << se.a;
    }
  }
}

// ------------------------------------------------------------------ the map against its definition

// From the returned tangent-plane point alone: its azimuth phi must close a
// sector of area u1 Omega (|residual| <= 1e-6 Omega, by the quadrature) and
// its angle theta must satisfy 1 - cos theta = u2 (1 - cos theta_max(phi))
// (to 1e-6), over sizes from 1e-5 to b = 1e6, axis ratios to 1e4 (1e8 for
// one cone) and u over the four quadrants.
TEST(SphericalEllipsePolar, MapSatisfiesItsDefinition) {
  double worst_area = 0.0, worst_theta = 0.0;
  pcg32 rng(31, 7);
  for (const spherical_ellipse& se : canonical_cones()) {
    const double omega = spherical_ellipse_area(se);
    std::vector<dvec2> us = {{1e-6, 0.5}, {0.1, 0.3}, {0.2499, 0.9}, {0.25, 0.5}, {0.26, 1.0},
                             {0.5, 0.7}, {0.61, 0.01}, {0.75, 0.5}, {0.9, 0.2}, {1.0 - 1e-6, 0.6}};
    for (int i = 0; i < 6; ++i) us.push_back({rng.uniform_double(), rng.uniform_double()});
    for (const dvec2& u : us) {
      const dvec2 p = square_to_spherical_ellipse_polar(u, se, omega);
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y)) << se.a << " " << se.b;
      double phi = std::atan2(p.y, p.x);
      if (phi < 0.0) phi += 2.0 * dpi;
      const double area_res = std::abs(sector_quadrature_full(se.a, se.b, phi) - u.x * omega) / omega;
      worst_area = std::max(worst_area, area_res);
      EXPECT_LE(area_res, 1e-6) << se.a << " " << se.b << " u " << u.x << " " << u.y;
      const double rho2 = p.x * p.x + p.y * p.y, srho = std::sqrt(1.0 + rho2);
      const double u2 = rho2 / (srho * (srho + 1.0)) / one_minus_cos_max(se.a, se.b, phi);
      worst_theta = std::max(worst_theta, std::abs(u2 - u.y));
      EXPECT_NEAR(u2, u.y, 1e-6) << se.a << " " << se.b << " u " << u.x << " " << u.y;
    }
  }
  RecordProperty("worst_area_residual", sci(worst_area));
  RecordProperty("worst_theta_residual", sci(worst_theta));
}

// The solver's own stopping rule |Omega_q(t) - v Omega/4| <= 1e-9 Omega over
// 10^5 random cones (sizes 10^[-5, 6], ratios 10^[0, 4]) and v, and its cost:
// sector evaluations per solve on average and at most.
TEST(SphericalEllipsePolar, SolverResidualAndIterations) {
  pcg32 rng(8, 21);
  long total = 0;
  int most = 0;
  constexpr int n = 100000;
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const double a = std::pow(10.0, -5.0 + 11.0 * rng.uniform_double());
    const double b = std::min(1e6, a / std::pow(10.0, 4.0 * rng.uniform_double()));
    const spherical_ellipse se{std::max(a, b), b};
    const spherical_ellipse_polar_consts k(se);
    const double omega = spherical_ellipse_area(se), v = rng.uniform_double();
    int it = 0;
    const spherical_ellipse_polar_ray ray = spherical_ellipse_polar_solver::invert(k, omega, v, &it);
    const double res = std::abs(spherical_ellipse_polar_sector(k, ray) - 0.25 * v * omega) / omega;
    worst = std::max(worst, res);
    ASSERT_LE(res, 1e-9) << se.a << " " << se.b << " v " << v;
    total += it;
    most = std::max(most, it);
  }
  const double mean = static_cast<double>(total) / n;
  // Measured 1.5 evaluations per solve on average, at most 3: the Lambert
  // initial guess is within Newton's quadratic range.
  EXPECT_LE(mean, 2.5);
  EXPECT_LE(most, 8);
  RecordProperty("mean_sector_evaluations", sci(mean));
  RecordProperty("max_sector_evaluations", std::to_string(most));
  RecordProperty("worst_residual", sci(worst));
}

// Continuity across the quadrant boundaries (the odd quadrants are mirrored).
TEST(SphericalEllipsePolar, ContinuousAcrossQuadrants) {
  for (const spherical_ellipse& se : {spherical_ellipse{0.8, 0.3}, spherical_ellipse{1e-4, 1e-6}}) {
    const double omega = spherical_ellipse_area(se);
    for (double q : {0.25, 0.5, 0.75}) {
      const dvec2 lo = square_to_spherical_ellipse_polar({q - 1e-12, 0.6}, se, omega);
      const dvec2 hi = square_to_spherical_ellipse_polar({q + 1e-12, 0.6}, se, omega);
      EXPECT_NEAR(lo.x, hi.x, 1e-6 * se.a) << q;
      EXPECT_NEAR(lo.y, hi.y, 1e-6 * se.a) << q;
    }
    // u1 = 0 and u1 = 1 meet on the major axis.
    const dvec2 first = square_to_spherical_ellipse_polar({0.0, 0.6}, se, omega);
    const dvec2 last = square_to_spherical_ellipse_polar({1.0, 0.6}, se, omega);
    EXPECT_NEAR(first.x, last.x, 1e-9 * se.a);
    EXPECT_NEAR(first.y, last.y, 1e-9 * se.a);
  }
}

// ------------------------------------------------------------------ round trip

// In double on the canonical ellipse: inverse(sample(u)) = u within 1e-4
// (in fact ~1e-9, the solver's tolerance) for axis ratios up to 1e8 and
// sizes from 1e-9 to b = 1e5; samples stay inside the ellipse.
TEST(SphericalEllipsePolar, RoundTripCanonical) {
  double worst = 0.0;
  for (double a : {1e-5, 1e-2, 0.5, 3.0, 1e3, 1e5})
    for (double ratio : {1.0, 1.5, 10.0, 1e4, 1e8}) {
      const spherical_ellipse se{a, a / ratio};
      const double omega = spherical_ellipse_area(se);
      pcg32 rng(2, 7);
      for (int i = 0; i < 500; ++i) {
        const dvec2 u{rng.uniform_double(), rng.uniform_double()};
        const dvec2 p = square_to_spherical_ellipse_polar(u, se, omega);
        ASSERT_LE(sqr(p.x / se.a) + sqr(p.y / se.b), 1.0 + 1e-9) << a << " " << ratio;
        const dvec2 v = spherical_ellipse_polar_to_square(p, se, omega);
        worst = std::max({worst, std::abs(v.x - u.x), std::abs(v.y - u.y)});
        ASSERT_NEAR(v.x, u.x, 1e-4) << a << " " << ratio << " u " << u.x << " " << u.y;
        ASSERT_NEAR(v.y, u.y, 1e-4) << a << " " << ratio << " u " << u.x << " " << u.y;
      }
    }
  EXPECT_LT(worst, 1e-6);
  RecordProperty("worst_round_trip", sci(worst));
}

// The light-sampling strategy (pdf consistency, E[1/pdf], round trip,
// one-sidedness, fallback, chi-square of directions and on the light's own
// square) is tested for both maps in test_spherical_ellipse.cpp.

// ------------------------------------------------------------------ finiteness

// 10^5 random canonical cones over make_ellipse_cone's whole spherical range
// (b 10^[-9, 6], a/b 10^[0, 8]) and u including the corners: finite points
// inside the ellipse, finite inverses in [0,1]^2.
TEST(SphericalEllipsePolar, FiniteOverRandomCanonicalCones) {
  pcg32 rng(77, 3);
  for (int i = 0; i < 100000; ++i) {
    const double b = std::pow(10.0, -9.0 + 15.0 * rng.uniform_double());
    const double a = b * std::pow(10.0, 8.0 * rng.uniform_double());
    const spherical_ellipse se{a, b};
    const double omega = spherical_ellipse_area(se);
    ASSERT_TRUE(std::isfinite(omega) && omega > 0.0) << a << " " << b;
    dvec2 u{rng.uniform_double(), rng.uniform_double()};
    if (i % 16 == 0) u = {static_cast<double>(i / 16 % 5) / 4.0, static_cast<double>(i / 80 % 2)};
    const dvec2 p = square_to_spherical_ellipse_polar(u, se, omega);
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y)) << a << " " << b << " u " << u.x << " " << u.y;
    ASSERT_LE(sqr(p.x / a) + sqr(p.y / b), 1.0 + 1e-9) << a << " " << b << " u " << u.x << " " << u.y;
    const dvec2 v = spherical_ellipse_polar_to_square(p, se, omega);
    ASSERT_TRUE(v.x >= 0.0 && v.x <= 1.0 && v.y >= 0.0 && v.y <= 1.0) << a << " " << b;
    ASSERT_TRUE(std::isfinite(square_to_spherical_ellipse_polar_pdf(omega)));
  }
}


}  // namespace
