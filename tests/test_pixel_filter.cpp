// pbrt-v4's pixel filters with filter importance sampling
// (render/pixel_filter.hpp): box, gaussian and triangle, each a triplet
// sample / pdf / inverse plus pbrt's eval.
//
// - chi-square of sample() against pdf() for six filters (the support
//   mapped affinely onto the unit square), by the harness's
//   chi2_test_unit_square at its per-test level 1 - 0.99^(1/256) ~= 3.9e-5
//   (tests/support/chi2.hpp: 1 % family-wise over at most 256 chi-square
//   tests, Sidak). This file runs 6 of them; docs/tests.md counted about
//   248 elsewhere when it was written (254 of the 256 with these);
// - pdf integrates to 1 and is eval / (the integral of eval), both by
//   composite Gauss-Legendre quadrature; eval is pbrt's formula and
//   integral() pbrt's closed form;
// - inverse() is the CDF of pdf() (quadrature of pdf over [-r, o]);
// - round trips sample(inverse(o)) == o and inverse(sample(u)) == u over
//   grids that include the edges, with tolerances derived from float
//   resolution; exact edges and centre; monotonicity;
// - every sample's weight eval / pdf is the same constant, integral();
// - the gaussian's quantile against a long double reference (Boost's
//   Gauss-Legendre quadrature of the density), to 1 float ulp or 1e-9 r; its
//   tails (u near 0 and 1) stay inside the radius and finite, for radius /
//   sigma from 0.05 to 200 (where g(r) and erfc underflow in double);
// - the box of radius 0.5 reproduces the renderer's pixel point
//   float(x) + u and its camera ray bit for bit.
//
// Every random test uses a fixed seed. Runtime about 2.5 s of one core.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <boost/math/quadrature/gauss.hpp>

#include "mcrt/core/rng.hpp"
#include "mcrt/render/camera.hpp"
#include "mcrt/render/pixel_filter.hpp"
#include "mcrt/render/renderer.hpp"
#include "support/chi2.hpp"

using namespace mcrt;

namespace {

struct named_filter {
  std::string name;
  pixel_filter f;
};

// The six filters of the chi-square tests.
std::vector<named_filter> chi2_filters() {
  return {{"box_default", pixel_filter::box()},
          {"box_1_025", pixel_filter::box({1.0f, 0.25f})},
          {"gaussian_default", pixel_filter::gaussian()},
          {"gaussian_2_1_sigma_07", pixel_filter::gaussian({2.0f, 1.0f}, 0.7f)},
          {"triangle_default", pixel_filter::triangle()},
          {"triangle_1_05", pixel_filter::triangle({1.0f, 0.5f})}};
}

// Those and a few extremes for the deterministic tests: a gaussian wider
// than its support (a parabola, radius / sigma = 0.05), a narrow one
// (radius / sigma = 60 and 10), thin boxes and triangles.
std::vector<named_filter> all_filters() {
  std::vector<named_filter> v = chi2_filters();
  v.push_back({"gaussian_wide", pixel_filter::gaussian(vec2(0.5f), 10.0f)});
  v.push_back({"gaussian_narrow", pixel_filter::gaussian({3.0f, 0.5f}, 0.05f)});
  v.push_back({"box_2_01", pixel_filter::box({2.0f, 0.1f})});
  v.push_back({"triangle_03_3", pixel_filter::triangle({0.3f, 3.0f})});
  return v;
}

std::vector<named_filter> gaussians() {
  return {{"default", pixel_filter::gaussian()},
          {"2_1_sigma_07", pixel_filter::gaussian({2.0f, 1.0f}, 0.7f)},
          {"wide", pixel_filter::gaussian(vec2(0.5f), 10.0f)},
          {"radius_sigma_1", pixel_filter::gaussian({1.0f, 0.8f}, 1.0f)},
          {"narrow", pixel_filter::gaussian({3.0f, 0.5f}, 0.05f)},
          {"very_narrow", pixel_filter::gaussian({4.0f, 1.0f}, 0.02f)}};
}

// --- composite 8-point Gauss-Legendre on [-r, r] in `panels` equal panels
// (even, so that the triangle's kink at 0 is a panel boundary; the support's
// edges are the outer boundaries).
struct node {
  double x, w;
  int panel;
};
std::vector<node> gl_nodes(double r, int panels) {
  static constexpr double gx[4] = {0.18343464249564980494, 0.52553240991632898582, 0.79666647741362673959,
                                   0.96028985649753623168};
  static constexpr double gw[4] = {0.36268378337836198297, 0.31370664587788728734, 0.22238103445337447054,
                                   0.10122853629037625915};
  std::vector<node> out;
  const double h = 2.0 * r / panels;
  for (int p = 0; p < panels; ++p) {
    const double c = -r + (p + 0.5) * h;
    for (int i = 0; i < 4; ++i) {
      out.push_back({c - 0.5 * h * gx[i], 0.5 * h * gw[i], p});
      out.push_back({c + 0.5 * h * gx[i], 0.5 * h * gw[i], p});
    }
  }
  return out;
}
// Panels per axis: fine enough that each is at most ~2 sigma of a gaussian.
int panels_for(const pixel_filter& f, int axis) {
  if (f.kind() != pixel_filter_kind::gaussian) return 16;
  const int n = static_cast<int>(std::ceil(f.radius()[axis] / f.sigma())) * 2;
  return std::max(16, n + (n & 1));
}

// The per-panel integrals of a function of the offset along `axis`,
// integrated over the other axis: cumulative sums are the marginal CDF at
// the panel boundaries.
template <class F>
std::vector<double> panel_integrals(const pixel_filter& f, int axis, F&& fn) {
  const vec2 r = f.radius();
  const std::vector<node> nx = gl_nodes(r[axis], panels_for(f, axis));
  const std::vector<node> ny = gl_nodes(r[1 - axis], panels_for(f, 1 - axis));
  std::vector<double> out(static_cast<std::size_t>(panels_for(f, axis)), 0.0);
  for (const node& a : nx) {
    double row = 0.0;
    for (const node& b : ny) {
      vec2 o;
      o[axis] = static_cast<float>(a.x);
      o[1 - axis] = static_cast<float>(b.x);
      row += b.w * static_cast<double>(fn(o));
    }
    out[static_cast<std::size_t>(a.panel)] += a.w * row;
  }
  return out;
}
template <class F>
double integrate(const pixel_filter& f, F&& fn) {
  double s = 0.0;
  for (double p : panel_integrals(f, 0, fn)) s += p;
  return s;
}

// --- an independent reference for the gaussian in long double: the normal
// density g, f(x) - as pbrt, g(x) - g(r) - written at distance e = r - |x|
// from the edge, integrated by Boost's 30-point Gauss-Legendre rule on
// pieces of width min(sigma, r) / 4, on which the density is smooth and
// such a rule is exact to long double rounding.
long double ref_g(long double x, long double sigma) {
  return std::exp(-0.5L * (x / sigma) * (x / sigma)) / (sigma * std::sqrt(2.0L * std::numbers::pi_v<long double>));
}
// Mass of g - g(r) on [-r, -r + d], d in [0, r]: the distance from the edge
// is cut into pieces of width min(sigma, r) / 4, whose masses are summed
// once (prefix), so that each call integrates only the last piece.
class ref_lower_mass {
 public:
  ref_lower_mass(long double r, long double sigma) : r_(r), s_(sigma), step_(std::min(sigma, r) / 4.0L) {
    prefix_.push_back(0.0L);
    for (long double a = 0.0L; a < r_; a += step_) prefix_.push_back(prefix_.back() + piece(a, std::min(r_, a + step_)));
  }
  long double operator()(long double d) const {
    d = std::clamp(d, 0.0L, r_);
    const auto k = std::min(static_cast<std::size_t>(d / step_), prefix_.size() - 1);
    const long double a = static_cast<long double>(k) * step_;
    return prefix_[k] + (d > a ? piece(a, d) : 0.0L);
  }

 private:
  long double piece(long double a, long double b) const {
    const auto h = [&](long double e) {
      return ref_g(r_ - e, s_) * -std::expm1(-0.5L * e * (2.0L * r_ - e) / (s_ * s_));
    };
    return boost::math::quadrature::gauss<long double, 30>::integrate(h, a, b);
  }
  long double r_, s_, step_;
  std::vector<long double> prefix_;
};

float ulp_at(float x) {
  const float a = std::abs(x);
  return std::max(std::nextafter(a, infinity) - a, a > 0.0f ? a - std::nextafter(a, 0.0f) : 0.0f);
}

// The 1-D density along one axis, pdf(o) integrated over the other axis,
// by closed form: for the tolerances of the round trips.
double axis_density(const pixel_filter& f, int axis, double x) {
  const double r = f.radius()[axis];
  if (std::abs(x) > r) return 0.0;
  switch (f.kind()) {
    case pixel_filter_kind::box:
      return 0.5 / r;
    case pixel_filter_kind::triangle:
      return (r - std::abs(x)) / (r * r);
    case pixel_filter_kind::gaussian: {
      const double s = f.sigma();
      const double g = std::exp(-0.5 * sqr(x / s)) - std::exp(-0.5 * sqr(r / s));
      const double mass = std::erf(r / (s * std::numbers::sqrt2)) * s * std::sqrt(2.0 * std::numbers::pi) -
                          2.0 * r * std::exp(-0.5 * sqr(r / s));
      return g / mass;
    }
  }
  return 0.0;
}

// u values over [0, 1]: a grid of 257 and points next to 0, 1/2 and 1.
std::vector<float> u_grid() {
  std::vector<float> u;
  for (int k = 0; k <= 256; ++k) u.push_back(static_cast<float>(k) / 256.0f);
  for (float e : {0x1p-24f, 0x1p-23f, 0x1p-20f, 0x1p-12f, 1e-3f}) {
    u.push_back(e);
    u.push_back(1.0f - e);
    u.push_back(0.5f - e);
    u.push_back(0.5f + e);
  }
  u.push_back(std::numeric_limits<float>::denorm_min());
  u.push_back(1e-30f);
  u.push_back(0x1p-32f);
  u.push_back(std::nextafter(1.0f, 0.0f));
  return u;
}

}  // namespace

// ------------------------------------------------------------------ factories

TEST(PixelFilter, FactoriesHavePbrtsDefaults) {
  const pixel_filter none;  // the renderer's box
  EXPECT_EQ(none.kind(), pixel_filter_kind::box);
  EXPECT_EQ(none.radius(), vec2(0.5f));
  EXPECT_EQ(pixel_filter::box().radius(), vec2(0.5f));
  const pixel_filter g = pixel_filter::gaussian();
  EXPECT_EQ(g.kind(), pixel_filter_kind::gaussian);
  EXPECT_EQ(g.radius(), vec2(1.5f));
  EXPECT_EQ(g.sigma(), 0.5f);
  const pixel_filter t = pixel_filter::triangle();
  EXPECT_EQ(t.kind(), pixel_filter_kind::triangle);
  EXPECT_EQ(t.radius(), vec2(2.0f));
  EXPECT_EQ(pixel_filter::gaussian({2.0f, 1.0f}, 0.7f).radius(), vec2(2.0f, 1.0f));
}

// pbrt-v4's Evaluate, written out in double; eval is within float rounding
// (the gaussian's 1e-6 of its peak allows for pbrt's own cancellation of
// g(x) - g(r) near the edge, which mcrt avoids).
TEST(PixelFilter, EvalIsPbrtsFilter) {
  pcg32 rng(7, 1);
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    const vec2 r = f.radius();
    const double s = f.sigma();
    const auto g = [&](double x) { return std::exp(-0.5 * sqr(x / s)) / (s * std::sqrt(2.0 * std::numbers::pi)); };
    const double peak = f.kind() == pixel_filter_kind::gaussian ? (g(0) - g(r.x)) * (g(0) - g(r.y))
                        : f.kind() == pixel_filter_kind::triangle ? double(r.x) * r.y
                                                                  : 1.0;
    for (int i = 0; i < 20000; ++i) {
      // Also outside the support, by up to 20 %.
      const vec2 o = (rng.uniform2() * 2.4f - 1.2f) * r;
      const bool inside = std::abs(o.x) <= r.x && std::abs(o.y) <= r.y;
      double ref = 0.0;
      if (f.kind() == pixel_filter_kind::box)
        ref = inside ? 1.0 : 0.0;
      else if (f.kind() == pixel_filter_kind::triangle)
        ref = std::max(0.0, double(r.x) - std::abs(o.x)) * std::max(0.0, double(r.y) - std::abs(o.y));
      else
        ref = std::max(0.0, g(o.x) - g(r.x)) * std::max(0.0, g(o.y) - g(r.y));
      ASSERT_NEAR(f.eval(o), ref, 1e-6 * ref + 1e-6 * peak) << o.x << ", " << o.y;
      if (!inside) {
        ASSERT_EQ(f.eval(o), 0.0f);
        ASSERT_EQ(f.pdf(o), 0.0f);
      }
    }
  }
}

// ------------------------------------------------------------------ chi-square

class PixelFilterChi2 : public ::testing::TestWithParam<int> {};

TEST_P(PixelFilterChi2, SampleFollowsPdf) {
  const named_filter nf = chi2_filters()[static_cast<std::size_t>(GetParam())];
  const pixel_filter& f = nf.f;
  const dvec2 r(f.radius());
  // The support [-rx, rx] x [-ry, ry] mapped affinely onto the unit square
  // (not through inverse(), which would make the test circular): the
  // density per unit square is pdf * 4 rx ry.
  const auto sample = [&](pcg32& rng, dvec2& uv) {
    const vec2 o = f.sample(rng.uniform2());
    uv = (dvec2(o) + r) / (2.0 * r);
    return true;
  };
  const auto density = [&](const dvec2& uv) {
    const dvec2 o = (2.0 * uv - 1.0) * r;
    return static_cast<double>(f.pdf(vec2(o))) * 4.0 * r.x * r.y;
  };
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.res_theta = 100;  // even: the triangle's kink at the centre lies on a grid line
  opt.seed = 1000 + static_cast<std::uint64_t>(GetParam());
  // The float pdf's rounding noise (~1e-7) is below what 1e6 samples resolve.
  opt.quadrature_tolerance = 1e-6;
  const test::chi2_result res = test::chi2_test_unit_square(sample, density, opt);
  EXPECT_TRUE(res.passed) << nf.name << "\n" << res.report;
  EXPECT_NEAR(res.pdf_integral, 1.0, 1e-5);
}

INSTANTIATE_TEST_SUITE_P(Filters, PixelFilterChi2, ::testing::Range(0, 6),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return chi2_filters()[static_cast<std::size_t>(i.param)].name;
                         });

// ------------------------------------------------------------------ densities

TEST(PixelFilter, PdfIntegratesToOneAndIsEvalOverItsIntegral) {
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    const double pdf_mass = integrate(f, [&](vec2 o) { return f.pdf(o); });
    EXPECT_NEAR(pdf_mass, 1.0, 1e-6);
    const double eval_mass = integrate(f, [&](vec2 o) { return f.eval(o); });
    EXPECT_NEAR(f.integral(), eval_mass, 1e-6 * eval_mass);
    // pbrt-v4's closed forms of Filter::Integral.
    const vec2 r = f.radius();
    double closed = 4.0 * r.x * r.y;
    if (f.kind() == pixel_filter_kind::triangle) closed = sqr(double(r.x)) * sqr(double(r.y));
    if (f.kind() == pixel_filter_kind::gaussian) {
      const double s = f.sigma();
      const auto axis = [&](double ra) {
        return std::erf(ra / (s * std::numbers::sqrt2)) -
               2.0 * ra * std::exp(-0.5 * sqr(ra / s)) / (s * std::sqrt(2.0 * std::numbers::pi));
      };
      closed = axis(r.x) * axis(r.y);
    }
    EXPECT_NEAR(f.integral(), closed, 2e-6 * closed);
    // pdf == eval / its integral, pointwise (on and off the quadrature's nodes).
    pcg32 rng(11, 2);
    for (int i = 0; i < 20000; ++i) {
      const vec2 o = (rng.uniform2() * 2.0f - 1.0f) * r;
      const double want = f.eval(o) / eval_mass;
      ASSERT_NEAR(f.pdf(o), want, 2e-6 * want) << o.x << ", " << o.y;
    }
  }
}

// inverse() is the marginal CDF of pdf(): at each panel boundary o of the
// quadrature, inverse(o) along an axis equals the integral of pdf over
// [-r, o] times the whole other axis.
TEST(PixelFilter, InverseIsTheCdfOfPdf) {
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    for (int axis = 0; axis < 2; ++axis) {
      const std::vector<double> mass = panel_integrals(f, axis, [&](vec2 o) { return f.pdf(o); });
      const double r = f.radius()[axis];
      const int n = static_cast<int>(mass.size());
      double cdf = 0.0;
      for (int k = 0; k <= n; ++k) {
        vec2 o(0.0f);
        o[axis] = static_cast<float>(-r + 2.0 * r * k / n);
        ASSERT_NEAR(f.inverse(o)[axis], cdf, 1e-6) << "axis " << axis << " at " << o[axis];
        if (k < n) cdf += mass[static_cast<std::size_t>(k)];
      }
    }
  }
}

// Each sample's filter weight f / pdf is the same constant, the integral:
// normalized, every sample weighs 1 (pbrt-v4's FilterSample weight).
TEST(PixelFilter, EverySampleHasTheSameWeight) {
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    pcg32 rng(13, 3);
    for (int i = 0; i < 20000; ++i) {
      const vec2 o = f.sample(rng.uniform2());
      const float p = f.pdf(o);
      if (p == 0.0f) continue;  // exactly on the edge of a triangle or gaussian (u = 0)
      ASSERT_NEAR(f.eval(o) / p / f.integral(), 1.0, 2e-6) << o.x << ", " << o.y;
    }
  }
}

// ------------------------------------------------------------------ round trips

// inverse(sample(u)) == u. The offset x is within half a float ulp,
// <= 2^-24 |x|, of the exact quantile, which moves u by p(x) |x| 2^-24 <=
// 2^-25 (p(x) |x| <= 1/2 for every filter here: the box's at its edges, at
// most 1/4 for the triangle and e^-1/2 / sqrt(2 pi) ~ 0.24 for the
// gaussian), and u is rounded by up to 2^-25: |du| <= 2^-24, tested to
// 2^-22.
TEST(PixelFilter, InverseOfSampleIsTheIdentity) {
  const std::vector<float> us = u_grid();
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    double worst = 0.0;
    for (float a : us)
      for (float b : {0.0f, 0.3f, 1.0f}) {
        for (const vec2 u : {vec2(a, b), vec2(b, a)}) {
          const vec2 back = f.inverse(f.sample(u));
          worst = std::max({worst, std::abs(double(back.x) - u.x), std::abs(double(back.y) - u.y)});
          ASSERT_NEAR(back.x, u.x, 0x1p-22) << u.x;
          ASSERT_NEAR(back.y, u.y, 0x1p-22) << u.y;
        }
      }
    pcg32 rng(17, 4);
    for (int i = 0; i < 100000; ++i) {
      const vec2 u = rng.uniform2();
      const vec2 back = f.inverse(f.sample(u));
      worst = std::max({worst, std::abs(double(back.x) - u.x), std::abs(double(back.y) - u.y)});
      ASSERT_NEAR(back.x, u.x, 0x1p-22) << u.x;
      ASSERT_NEAR(back.y, u.y, 0x1p-22) << u.y;
    }
    RecordProperty(name + "_worst_du", std::to_string(worst));
  }
}

// sample(inverse(o)) == o. u = inverse(o) is rounded by up to 2^-25 (plus
// the CDF's own ~1e-7 relative), which moves the offset by 2^-25 / p(o); the
// offset is rounded by half an ulp: |do| <= 2^-22 r + 2^-23 / p(o). At the
// far edge p -> 0 and a float u only resolves offsets ~sqrt(2^-24) r
// apart (the CDF is quadratic there): the bound grows accordingly. The
// edges and the centre round-trip exactly.
TEST(PixelFilter, SampleOfInverseIsTheIdentity) {
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    for (int axis = 0; axis < 2; ++axis) {
      const float r = f.radius()[axis];
      std::vector<float> os;
      for (int k = -256; k <= 256; ++k) os.push_back(r * static_cast<float>(k) / 256.0f);
      for (float e : {0x1p-24f, 0x1p-20f, 0x1p-12f, 1e-3f}) {
        os.push_back(r * (1.0f - e));
        os.push_back(-r * (1.0f - e));
        os.push_back(r * e);
        os.push_back(-r * e);
      }
      for (float o : os) {
        vec2 p(0.0f);
        p[axis] = o;
        const float u = f.inverse(p)[axis];
        const float back = f.sample(f.inverse(p))[axis];
        vec2 q(0.0f);
        q[axis] = back;
        // In u the round trip holds everywhere.
        ASSERT_NEAR(f.inverse(q)[axis], u, 0x1p-22) << "axis " << axis << " offset " << o;
        // In offsets, where the float u resolves them: not where the mass
        // beyond o is below 2^-20, since float u's next to 1 are 2^-24 apart
        // (a narrow gaussian's offsets beyond ~5.5 sigma all have u = 1, and
        // only the check in u applies).
        if (o > 0.0f && 1.0f - u < 0x1p-20f) continue;
        const double dens = axis_density(f, axis, o);
        const double tol = 0x1p-22 * r + (dens > 0.0 ? 0x1p-23 / dens : infinity);
        ASSERT_NEAR(back, o, tol) << "axis " << axis << " offset " << o << " density " << dens;
      }
      vec2 lo(0.0f), hi(0.0f), mid(0.0f);
      lo[axis] = -r;
      hi[axis] = r;
      EXPECT_EQ(f.sample(f.inverse(lo))[axis], -r);
      EXPECT_EQ(f.sample(f.inverse(hi))[axis], r);
      EXPECT_EQ(f.sample(f.inverse(mid))[axis], 0.0f);
    }
  }
}

// u = 0, 1/2, 1 map exactly to -r, 0, r and back; sample is monotone in
// each coordinate and never leaves the support.
TEST(PixelFilter, EdgesCentreAndMonotonicity) {
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    const vec2 r = f.radius();
    EXPECT_EQ(f.sample(vec2(0.0f)), -r);
    EXPECT_EQ(f.sample(vec2(1.0f)), r);
    EXPECT_EQ(f.sample(vec2(0.5f)), vec2(0.0f));
    EXPECT_EQ(f.inverse(-r), vec2(0.0f));
    EXPECT_EQ(f.inverse(r), vec2(1.0f));
    EXPECT_EQ(f.inverse(vec2(0.0f)), vec2(0.5f));
    // Offsets outside the support are clamped onto it.
    EXPECT_EQ(f.inverse(-2.0f * r), vec2(0.0f));
    EXPECT_EQ(f.inverse(2.0f * r), vec2(1.0f));
    for (int axis = 0; axis < 2; ++axis) {
      float prev = -r[axis];
      for (int k = 0; k <= (1 << 16); ++k) {
        vec2 u(0.5f);
        u[axis] = static_cast<float>(k) * 0x1p-16f;
        const float o = f.sample(u)[axis];
        ASSERT_GE(o, prev) << "u " << u[axis];
        ASSERT_LE(std::abs(o), r[axis]);
        ASSERT_EQ(f.sample(u)[1 - axis], 0.0f);
        prev = o;
      }
    }
  }
}

// ------------------------------------------------------------------ the gaussian

// The quantile to float accuracy: the exact CDF F (long double quadrature)
// brackets u between the offsets 1 ulp (or 1e-9 r) either side of sample(u):
// F(x - delta) <= u <= F(x + delta), delta = max(ulp(x), 1e-9 r).
TEST(PixelFilter, GaussianQuantileToFloatAccuracy) {
  for (const auto& [name, f] : gaussians()) {
    SCOPED_TRACE(name);
    for (int axis = 0; axis < 2; ++axis) {
      const long double r = f.radius()[axis], s = f.sigma();
      const ref_lower_mass mass(r, s);
      const long double half = mass(r);
      const auto cdf_lower = [&](long double x) {  // x in [-r, 0]
        return mass(std::clamp(x, -r, 0.0L) + r) / (2.0L * half);
      };
      std::vector<float> us = u_grid();
      for (int k = 1; k < 64; ++k) us.push_back(static_cast<float>(k) / 128.0f);  // u in (0, 1/2)
      for (float u : us) {
        vec2 uu(0.5f);
        uu[axis] = u;
        const float o = f.sample(uu)[axis];
        // Mirror into the lower half: v = min(u, 1 - u), both exact here.
        const long double v = std::min<long double>(u, 1.0L - u);
        const long double x = u < 0.5f ? o : -o;
        const long double delta = std::max<long double>(ulp_at(o), 1e-9L * r);
        ASSERT_LE(cdf_lower(x - delta), v) << "axis " << axis << " u " << u << " offset " << o;
        ASSERT_GE(cdf_lower(x + delta), v) << "axis " << axis << " u " << u << " offset " << o;
      }
    }
  }
}

// Tails: u next to 0 and 1 (down to the smallest denormal and the float
// below 1) give finite offsets inside [-r, r], in order, with finite pdf and
// inverse, and the mirror image sample(1 - u) = -sample(u) where 1 - u is
// exact; also when g(r) and erfc(r / (sigma sqrt 2)) underflow in double.
TEST(PixelFilter, GaussianTailsStayInsideTheRadiusAndFinite) {
  const std::vector<float> low = {0.0f, std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::min(),
                                  1e-30f, 0x1p-32f, 0x1p-24f, 0x1p-20f, 1e-4f, 1e-2f};
  std::vector<float> us = low;
  for (auto it = low.rbegin(); it != low.rend(); ++it) us.push_back(1.0f - *it);  // 1 - 2^-24 and 1 itself
  for (const auto& [name, f] : gaussians()) {
    SCOPED_TRACE(name);
    for (int axis = 0; axis < 2; ++axis) {
      const float r = f.radius()[axis];
      float prev = -r;
      for (float u : us) {
        vec2 uu(0.5f);
        uu[axis] = u;
        const vec2 o = f.sample(uu);
        ASSERT_TRUE(std::isfinite(o[axis])) << u;
        ASSERT_GE(o[axis], -r) << u;
        ASSERT_LE(o[axis], r) << u;
        ASSERT_GE(o[axis], prev) << u;
        prev = o[axis];
        const float p = f.pdf(o), back = f.inverse(o)[axis];
        ASSERT_TRUE(std::isfinite(p) && p >= 0.0f) << u;
        ASSERT_TRUE(std::isfinite(back) && back >= 0.0f && back <= 1.0f) << u;
        ASSERT_TRUE(std::isfinite(f.eval(o))) << u;
        if (u > 0.0f && u < 1.0f && u >= 0x1p-24f && 1.0f - (1.0f - u) == u) {
          vec2 mirror(0.5f);
          mirror[axis] = 1.0f - u;
          ASSERT_EQ(f.sample(mirror)[axis], -o[axis]) << u;
        }
      }
      // Strictly inside for u a float of the 24-bit grid in (0, 1) when the
      // edge is resolved (the density there is not below float resolution).
      vec2 first(0.5f);
      first[axis] = 0x1p-24f;
      if (f.sigma() >= 0.1f * r) {
        EXPECT_GT(f.sample(first)[axis], -r);
      }
    }
  }
}

// ------------------------------------------------------------------ the pixel point

// The box of radius 0.5 gives the renderer's point float(x) + u bit for bit,
// and pixel_ray through it is the renderer's ray.
TEST(PixelFilter, BoxHalfReproducesTheUnfilteredPixelPoint) {
  const pixel_filter box;
  const camera cam({0.3f, 1.5f, -2.0f}, {0.0f, 0.2f, 0.0f}, {0.0f, 1.0f, 0.0f}, 50.0f, 1.5f);
  const int width = 1920, height = 1280;
  const float inv_w = 1.0f / width, inv_h = 1.0f / height;
  pcg32 rng(19, 5);
  std::vector<vec2> us = {vec2(0.0f), vec2(std::nextafter(1.0f, 0.0f)), vec2(0x1p-24f), vec2(1e-30f, 0.2f),
                          vec2(std::numeric_limits<float>::denorm_min(), 0.5f), vec2(0.25f, 0.75f)};
  for (int i = 0; i < 2000; ++i) us.push_back(rng.uniform2());
  const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
  for (int x : {0, 1, 2, 3, 7, 100, 511, 1023, 1919, 4095, 65535, 1 << 20})
    for (int y : {0, 1, 5, 639, 1279, 8191})
      for (const vec2 u : us) {
        const vec2 p = box.film_point(x, y, u);
        ASSERT_EQ(bits(p.x), bits(static_cast<float>(x) + u.x)) << x << " " << u.x;
        ASSERT_EQ(bits(p.y), bits(static_cast<float>(y) + u.y)) << y << " " << u.y;
        if (x < width && y < height) {
          const ray a = pixel_ray(cam, 0, 0, p, inv_w, inv_h), b = pixel_ray(cam, x, y, u, inv_w, inv_h);
          for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(bits(a.o[k]), bits(b.o[k]));
            ASSERT_EQ(bits(a.d[k]), bits(b.d[k]));
          }
        }
      }
  // Its offset is u - 1/2 (exact for u >= 1/4, where u - 1/2 is a float).
  for (int i = 0; i < 1000; ++i) {
    const vec2 u = rng.uniform2();
    const vec2 o = box.sample(u);
    EXPECT_NEAR(o.x, u.x - 0.5, 0x1p-26);
    if (u.x >= 0.25f) {
      EXPECT_EQ(o.x, u.x - 0.5f);
    }
  }
}

// pbrt-v4's pFilm = pixel + (0.5, 0.5) + offset for every filter, to float
// rounding of the sum.
TEST(PixelFilter, FilmPointIsPixelCentrePlusOffset) {
  pcg32 rng(23, 6);
  for (const auto& [name, f] : all_filters()) {
    SCOPED_TRACE(name);
    for (int i = 0; i < 2000; ++i) {
      const vec2 u = rng.uniform2();
      const int x = static_cast<int>(rng.next_u32() % 2048), y = static_cast<int>(rng.next_u32() % 2048);
      const vec2 p = f.film_point(x, y, u), o = f.sample(u);
      const double ex = x + 0.5 + o.x, ey = y + 0.5 + o.y;
      ASSERT_NEAR(p.x, ex, 2.0 * ulp_at(static_cast<float>(ex)) + 1e-7 * f.radius().x) << x << " " << u.x;
      ASSERT_NEAR(p.y, ey, 2.0 * ulp_at(static_cast<float>(ey)) + 1e-7 * f.radius().y) << y << " " << u.y;
    }
  }
}
