// The branch-free elementary functions of core/fast_math.hpp against long
// double libm, to the accuracy their comments state, and the packed forms
// against the scalar ones.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "mcrt/core/fast_math.hpp"

namespace {

using mcrt::fast_math::atan2_upper;

// Relative error in units of DBL_EPSILON.
double ulps(double got, long double want) {
  if (want == 0.0L) return got == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return double(std::abs((static_cast<long double>(got) - want) / want)) / std::numeric_limits<double>::epsilon();
}

// (y >= 0, x) pairs: random over many scales and signs, and the edges of
// the reductions (y = |x|, y = tan(pi/8) |x|, y = 0, x = 0, x = -0).
std::vector<std::pair<double, double>> upper_half_plane_points() {
  std::vector<std::pair<double, double>> pts;
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-30.0, 30.0);
  for (int i = 0; i < 200000; ++i) {
    const double y = std::abs(u(rng)) * std::pow(10.0, e(rng)), x = u(rng) * std::pow(10.0, e(rng));
    pts.emplace_back(y, x);
    const double r = std::pow(10.0, e(rng) / 10.0);
    pts.emplace_back(std::abs(u(rng)) * r, u(rng) * r);  // comparable magnitudes: every reduction
  }
  for (double s : {1e-300, 1e-8, 1.0, 3.0, 1e8, 1e300}) {
    const double t8 = 0.41421356237309503;
    for (double x : {s, -s}) {
      pts.emplace_back(s, x);
      pts.emplace_back(t8 * s, x);
      pts.emplace_back(std::nextafter(t8 * s, 0.0), x);
      pts.emplace_back(std::nextafter(t8 * s, 1e308), x);
      pts.emplace_back(0.0, x);
    }
    pts.emplace_back(s, 0.0);
    pts.emplace_back(s, -0.0);
  }
  return pts;
}

// The stated bound: the polynomial's relative error (5e-15, fast_math.hpp)
// plus a few roundings, relative everywhere on y >= 0, so that small angles
// keep their relative precision.
constexpr double atan_ulps = 5e-15 / std::numeric_limits<double>::epsilon() + 4.0;

// atan2_upper against libm.
TEST(FastMath, Atan2UpperMatchesLibm) {
  double worst = 0.0;
  for (const auto& [y, x] : upper_half_plane_points()) {
    const double got = atan2_upper(y, x);
    const long double want = std::atan2(static_cast<long double>(y), static_cast<long double>(x));
    if (want == 0.0L) {
      EXPECT_EQ(got, 0.0) << y << " " << x;
      continue;
    }
    const double err = ulps(got, want);
    worst = std::max(worst, err);
    ASSERT_LE(err, atan_ulps) << "y=" << y << " x=" << x;
  }
  RecordProperty("worst_ulps", std::to_string(worst));
}

TEST(FastMath, SincosQuadrantMatchesLibm) {
  for (int i = 0; i <= 100000; ++i) {
    const double a = (std::numbers::pi / 2.0) * i / 100000.0 * (i % 7 == 0 ? 1e-6 : 1.0);
    double s, c;
    mcrt::fast_math::sincos_quadrant(a, s, c);
    if (a > 0.0) {
      ASSERT_LE(ulps(s, std::sin(static_cast<long double>(a))), 1e-15 / std::numeric_limits<double>::epsilon()) << a;
    }
    // cos: 8e-15 absolute (the fit's relative error times |z C(z)| < 1).
    ASSERT_LE(std::abs(c - double(std::cos(static_cast<long double>(a)))), 8e-15) << a;
  }
}

TEST(FastMath, PackedSquareRootsAndReciprocals) {
  const auto r = mcrt::fast_math::sqrt4(4.0, 2.0, 1e-300, 0.0);
  EXPECT_EQ(r[0], 2.0);
  EXPECT_EQ(r[1], std::sqrt(2.0));
  EXPECT_EQ(r[2], std::sqrt(1e-300));
  EXPECT_EQ(r[3], 0.0);
  const auto ir = mcrt::fast_math::inverse_sqrt4(4.0, 2.0, 9.0, 1e-300);
  EXPECT_EQ(ir[0], 0.5);
  EXPECT_EQ(ir[1], 1.0 / std::sqrt(2.0));
  EXPECT_EQ(ir[2], 1.0 / 3.0);
  EXPECT_EQ(ir[3], 1.0 / std::sqrt(1e-300));
  const auto fr = mcrt::fast_math::reciprocal4(2.0f, 4.0f, 3.0f, 1e-30f);
  EXPECT_EQ(fr[0], 0.5f);
  EXPECT_EQ(fr[2], 1.0f / 3.0f);
  const auto fs = mcrt::fast_math::sqrt4(4.0f, 2.0f, 0.0f, 1e30f);
  EXPECT_EQ(fs[1], std::sqrt(2.0f));
  EXPECT_EQ(fs[3], std::sqrt(1e30f));
}

}  // namespace
