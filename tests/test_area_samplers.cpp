// Tests of the area samplers (rect_area_sampler, ellipse_area_sampler,
// sphere_cone_sampler), of the warps they are built on, and of the
// statistical harness itself (support/chi2.hpp, support/solid_angle.hpp).
//
// Every random test uses a fixed seed, so results are reproducible. The
// chi-square tests run at the per-test level 1 - 0.99^(1/256) ~= 3.9e-5: a 1%
// family-wise false-rejection rate over the whole suite (Sidak correction for
// at most 256 chi-square tests; see support/chi2.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <numbers>
#include <ostream>
#include <string>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "mcrt/sampling/sphere_cone.hpp"
#include "mcrt/sampling/warp.hpp"
#include "support/chi2.hpp"
#include "support/solid_angle.hpp"

namespace {

using namespace mcrt;
using test::chi2_result;
using test::spherical_cap;

constexpr double dpi = std::numbers::pi;
constexpr std::size_t chi2_samples = 1'000'000;

// A chi-square report is printed with the failure; with the environment
// variable MCRT_CHI2_VERBOSE set, it is printed in every case.
void expect_chi2_passed(const chi2_result& r, const std::string& what = {}) {
  EXPECT_TRUE(r.passed) << what << r.report;
  if (r.passed && std::getenv("MCRT_CHI2_VERBOSE") != nullptr) std::cout << what << r.report;
}
void expect_chi2_rejected(const chi2_result& r) {
  EXPECT_FALSE(r.passed) << r.report;
  if (!r.passed && std::getenv("MCRT_CHI2_VERBOSE") != nullptr) std::cout << r.report;
}

// ------------------------------------------------------------------ cases

// The Cornell box light of Shirley's "The Next Week" (130 x 105 at y = 554,
// emitting downwards) and the disk that replaces it in cornell_disk.json.
const rect cornell_light = xz_rect(213.0f, 343.0f, 227.0f, 332.0f, 554.0f, true);
const ellipse cornell_disk = ellipse::make({278.0f, 554.0f, 279.5f}, {65.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 65.0f});

// An orientation with no axis-aligned edge: e1 . e2 = 0, n ~ (0.6, -1.2, 1.25).
const vec3 tilted_origin{1.0f, 2.0f, 3.0f};
const vec3 tilted_e1{2.0f, 1.0f, 0.0f};
const vec3 tilted_e2{-0.25f, 0.5f, 0.6f};

template <class Sampler>
struct sampler_case {
  std::string name;
  Sampler sampler;
  vec3 o;

  friend void PrintTo(const sampler_case& c, std::ostream* os) {
    *os << c.name << " (observer " << c.o.x << ", " << c.o.y << ", " << c.o.z << ")";
  }
};

template <class Sampler>
std::string case_name(const testing::TestParamInfo<sampler_case<Sampler>>& info) {
  return info.param.name;
}

std::vector<sampler_case<rect_area_sampler>> rect_cases() {
  const rect tilted = rect::make(tilted_origin, tilted_e1, tilted_e2);
  const rect up = xz_rect(213.0f, 343.0f, 227.0f, 332.0f, 554.0f, false);
  return {
      {"cornell_floor_below", {cornell_light}, {278.0f, 0.0f, 279.5f}},
      {"cornell_floor_corner", {cornell_light}, {20.0f, 0.0f, 530.0f}},
      // 20 below the centre: the light fills most of the hemisphere. Much
      // closer, 1/pdf = A cos / d^2 is so heavy-tailed that E[1/pdf] needs
      // far more samples than a unit test affords.
      {"close", {cornell_light}, {270.0f, 534.0f, 285.0f}},
      // 0.5 below the plane, 63 beyond the edge x = 213.
      {"grazing", {cornell_light}, {150.0f, 553.5f, 300.0f}},
      // 5e4 away: about 4.4e-6 sr.
      {"far", {cornell_light}, {30278.0f, -39446.0f, 279.5f}},
      {"flipped_seen_from_above", {up}, {300.0f, 700.0f, 250.0f}},
      {"tilted", {tilted}, tilted.center() + 1.3f * tilted.n + 0.4f * tilted_e1},
  };
}

std::vector<sampler_case<ellipse_area_sampler>> ellipse_cases() {
  const ellipse tilted = ellipse::make(tilted_origin, tilted_e1, tilted_e2);
  const ellipse thin = ellipse::make({278.0f, 554.0f, 279.5f}, {100.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 2.0f});
  const ellipse up = ellipse::make({278.0f, 554.0f, 279.5f}, {65.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 65.0f}, true);
  return {
      {"cornell_floor_below", {cornell_disk}, {278.0f, 0.0f, 279.5f}},
      {"cornell_floor_corner", {cornell_disk}, {20.0f, 0.0f, 530.0f}},
      {"close", {cornell_disk}, {270.0f, 534.0f, 285.0f}},
      {"grazing", {cornell_disk}, {153.0f, 553.5f, 300.0f}},
      {"far", {cornell_disk}, {30278.0f, -39446.0f, 279.5f}},
      {"thin", {thin}, {250.0f, 0.0f, 400.0f}},
      {"flipped_seen_from_above", {up}, {300.0f, 700.0f, 250.0f}},
      {"tilted", {tilted}, tilted.center + 1.3f * tilted.n + 0.4f * tilted_e1},
  };
}

std::vector<sampler_case<sphere_cone_sampler>> sphere_cases() {
  const sphere unit{{0.0f, 0.0f, 0.0f}, 1.0f};
  return {
      // Shirley's glass sphere seen from just below the light.
      {"cornell_sphere_from_light", {sphere{{190.0f, 90.0f, 190.0f}, 90.0f}}, {278.0f, 553.0f, 279.5f}},
      {"close", {unit}, 1.05f * glm::normalize(vec3(0.6f, 0.8f, 0.3f))},
      {"far", {unit}, 1e3f * glm::normalize(vec3(-0.3f, 0.5f, 0.8f))},  // ~3.1e-6 sr
      {"very_far", {unit}, {6e3f, -8e3f, 0.0f}},                        // ~3.1e-8 sr
  };
}

// ------------------------------------------------------------------ helpers

template <class Sampler>
chi2_result run_chi2(const Sampler& s, const vec3& o, std::uint64_t seed) {
  const spherical_cap cap = test::bounding_cap(dvec3(o), s.shape);
  return test::chi2_test_directions(
      [&](pcg32& rng, vec3& dir) {
        light_sample ls;
        if (!s.sample(o, rng.uniform2(), ls)) return false;
        dir = ls.dir;
        return true;
      },
      [&](const vec3& dir) { return s.pdf(o, dir); }, cap.axis, cap.one_minus_cos,
      {.sample_count = chi2_samples, .seed = seed, .zero_pdf_fraction = test::rim_miss_fraction(cap.one_minus_cos)});
}

// Whether the point of the unit square lies within rounding distance of the
// rim of the shape it is mapped to, for a distant observer: a direction
// rounded to float is ~1e-7 rad off, i.e. ~1e-7 d / size in these
// coordinates (6e-5 for the Cornell light seen from 5e4 away, 1e-3 of the
// cone's radius for a sphere's cone of 1e-4 rad); the thresholds are a few
// times larger.
bool near_rim(const rect_area_sampler&, vec2 u) {
  return std::min(std::min(u.x, 1.0f - u.x), std::min(u.y, 1.0f - u.y)) <= 1e-3f;
}
bool near_rim(const ellipse_area_sampler&, vec2 u) { return u.x >= 1.0f - 2e-3f; }
bool near_rim(const sphere_cone_sampler&, vec2 u) { return u.x >= 1.0f - 1e-2f; }

// The pdf that comes with a sample equals pdf(o, dir) for its direction.
// The one exception is a direction that, rounded to float, misses the
// shape's rim: pdf(o, dir) is then 0, as for any ray that misses. Those must
// come from the rim (near_rim) and be rare (rim_miss_fraction).
template <class Sampler>
void expect_pdf_matches_sample(const Sampler& s, const vec3& o) {
  constexpr int n = 200'000;
  const spherical_cap cap = test::bounding_cap(dvec3(o), s.shape);
  pcg32 rng(11, 5);
  int mismatches = 0, rim_misses = 0;
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const vec2 u = rng.uniform2();
    light_sample ls;
    ASSERT_TRUE(s.sample(o, u, ls)) << "sample " << i;
    ASSERT_GT(ls.pdf, 0.0f);
    ASSERT_NEAR(glm::length(ls.dir), 1.0f, 1e-6f);
    const double p = s.pdf(o, ls.dir);
    if (p == 0.0 && near_rim(s, u)) {
      ++rim_misses;
      continue;
    }
    const double rel = std::abs(p - ls.pdf) / ls.pdf;
    worst = std::max(worst, rel);
    if (!(rel <= 1e-4) && mismatches++ < 5)
      ADD_FAILURE() << "pdf(o, dir) = " << p << " but sample() reported " << ls.pdf << " for u = (" << u.x << ", "
                    << u.y << "), dir (" << ls.dir.x << ", " << ls.dir.y << ", " << ls.dir.z << ")";
  }
  EXPECT_EQ(mismatches, 0) << "of " << n << " samples; worst relative difference " << worst;
  EXPECT_LE(rim_misses, test::rim_miss_fraction(cap.one_minus_cos) * n) << "samples at the rim with pdf 0";
}

// E[1/pdf] = integral of (1/pdf) pdf d(omega) = solid angle of the support.
// 1e6 samples; the test also asserts that 1% is at least 4 standard errors
// of the estimate (standard error from the sample variance), so a correct
// sampler fails it with probability below 1e-4.
template <class Sampler>
void expect_inverse_pdf_mean_is_solid_angle(const Sampler& s, const vec3& o) {
  const double exact = test::solid_angle(dvec3(o), s.shape);
  constexpr int n = 1'000'000;
  pcg32 rng(3, 17);
  double mean = 0.0, m2 = 0.0;  // Welford
  for (int i = 0; i < n; ++i) {
    light_sample ls;
    ASSERT_TRUE(s.sample(o, rng.uniform2(), ls));
    const double w = 1.0 / static_cast<double>(ls.pdf);
    const double delta = w - mean;
    mean += delta / (i + 1);
    m2 += delta * (w - mean);
  }
  const double std_error = std::sqrt(m2 / (n - 1) / n);
  EXPECT_LE(4.0 * std_error, 0.01 * exact) << "the 1% tolerance is too tight for this configuration";
  EXPECT_NEAR(mean, exact, 0.01 * exact) << "standard error " << std_error;
}

// ------------------------------------------------------------------ rectangle

class RectAreaSampler : public testing::TestWithParam<sampler_case<rect_area_sampler>> {};

TEST_P(RectAreaSampler, PdfMatchesSample) { expect_pdf_matches_sample(GetParam().sampler, GetParam().o); }

TEST_P(RectAreaSampler, InversePdfMeanIsSolidAngle) {
  expect_inverse_pdf_mean_is_solid_angle(GetParam().sampler, GetParam().o);
}

TEST_P(RectAreaSampler, ChiSquare) {
  const chi2_result r = run_chi2(GetParam().sampler, GetParam().o, 101);
  expect_chi2_passed(r);
}

INSTANTIATE_TEST_SUITE_P(Cases, RectAreaSampler, testing::ValuesIn(rect_cases()), case_name<rect_area_sampler>);

// ------------------------------------------------------------------ ellipse

class EllipseAreaSampler : public testing::TestWithParam<sampler_case<ellipse_area_sampler>> {};

TEST_P(EllipseAreaSampler, PdfMatchesSample) { expect_pdf_matches_sample(GetParam().sampler, GetParam().o); }

TEST_P(EllipseAreaSampler, InversePdfMeanIsSolidAngle) {
  expect_inverse_pdf_mean_is_solid_angle(GetParam().sampler, GetParam().o);
}

TEST_P(EllipseAreaSampler, ChiSquare) {
  const chi2_result r = run_chi2(GetParam().sampler, GetParam().o, 202);
  expect_chi2_passed(r);
}

INSTANTIATE_TEST_SUITE_P(Cases, EllipseAreaSampler, testing::ValuesIn(ellipse_cases()),
                         case_name<ellipse_area_sampler>);

// ------------------------------------------------------------------ sphere

class SphereConeSampler : public testing::TestWithParam<sampler_case<sphere_cone_sampler>> {};

TEST_P(SphereConeSampler, PdfMatchesSample) { expect_pdf_matches_sample(GetParam().sampler, GetParam().o); }

TEST_P(SphereConeSampler, InversePdfMeanIsSolidAngle) {
  expect_inverse_pdf_mean_is_solid_angle(GetParam().sampler, GetParam().o);
}

TEST_P(SphereConeSampler, ChiSquare) {
  const chi2_result r = run_chi2(GetParam().sampler, GetParam().o, 303);
  expect_chi2_passed(r);
}

INSTANTIATE_TEST_SUITE_P(Cases, SphereConeSampler, testing::ValuesIn(sphere_cases()),
                         case_name<sphere_cone_sampler>);

// ------------------------------------------------------------------ no sample

// Observers that a strategy has nothing to offer: sample() returns false and
// pdf() is 0 in every direction.
template <class Sampler>
void expect_no_sample(const Sampler& s, const vec3& o, const vec3& toward) {
  pcg32 rng(5, 9);
  for (int i = 0; i < 1000; ++i) {
    light_sample ls;
    EXPECT_FALSE(s.sample(o, rng.uniform2(), ls)) << "sample " << i;
    const vec3 d = square_to_uniform_sphere(rng.uniform2());
    EXPECT_EQ(s.pdf(o, d), 0.0f);
  }
  EXPECT_EQ(s.pdf(o, glm::normalize(toward - o)), 0.0f);
  EXPECT_EQ(s.pdf(o, -glm::normalize(toward - o)), 0.0f);
  EXPECT_FALSE(s.faces(o));
}

TEST(NoSample, RectObserverBehindOrInPlane) {
  const rect_area_sampler s{cornell_light};
  expect_no_sample(s, {278.0f, 700.0f, 279.5f}, cornell_light.center());  // above a light facing down
  expect_no_sample(s, {300.0f, 554.1f, 250.0f}, cornell_light.center());  // just behind it
  expect_no_sample(s, {100.0f, 554.0f, 250.0f}, cornell_light.center());  // in its plane
  const rect_area_sampler up{xz_rect(213.0f, 343.0f, 227.0f, 332.0f, 554.0f, false)};
  expect_no_sample(up, {278.0f, 0.0f, 279.5f}, cornell_light.center());
}

TEST(NoSample, EllipseObserverBehindOrInPlane) {
  const ellipse_area_sampler s{cornell_disk};
  expect_no_sample(s, {278.0f, 700.0f, 279.5f}, cornell_disk.center);
  expect_no_sample(s, {300.0f, 554.1f, 250.0f}, cornell_disk.center);
  expect_no_sample(s, {100.0f, 554.0f, 250.0f}, cornell_disk.center);
  const ellipse_area_sampler up{
      ellipse::make({278.0f, 554.0f, 279.5f}, {65.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 65.0f}, true)};
  expect_no_sample(up, {278.0f, 0.0f, 279.5f}, cornell_disk.center);
}

TEST(NoSample, SphereObserverInside) {
  const sphere_cone_sampler s{sphere{{1.0f, 2.0f, 3.0f}, 2.0f}};
  expect_no_sample(s, {1.0f, 2.0f, 3.0f}, {5.0f, 5.0f, 5.0f});  // at the centre
  expect_no_sample(s, {1.5f, 1.0f, 3.5f}, {5.0f, 5.0f, 5.0f});  // off-centre
}

// ------------------------------------------------------------------ warps

// Periodic distance on [0, 1).
double periodic_distance(double a, double b) {
  const double d = std::abs(a - b);
  return std::min(d, 1.0 - d);
}

// u -> point/direction -> u. The second coordinate of the polar warps is an
// angle, ill-conditioned at the pole (error ~ rounding / radius): it is
// compared only where the radius is at least 0.1, and the forward images
// are compared everywhere instead.
TEST(Warp, RectRoundTrip) {
  for (const rect& r : {cornell_light, rect::make(tilted_origin, tilted_e1, tilted_e2)}) {
    pcg32 rng(21, 1);
    for (int i = 0; i < 100'000; ++i) {
      const vec2 u = rng.uniform2();
      const vec2 v = rect_to_square(square_to_rect(u, r), r);
      ASSERT_NEAR(v.x, u.x, 1e-4);
      ASSERT_NEAR(v.y, u.y, 1e-4);
    }
  }
}

TEST(Warp, EllipseRoundTrip) {
  for (const ellipse& e : {cornell_disk, ellipse::make(tilted_origin, tilted_e1, tilted_e2)}) {
    const float size = glm::length(e.a1) + glm::length(e.a2);
    pcg32 rng(22, 1);
    for (int i = 0; i < 100'000; ++i) {
      const vec2 u = rng.uniform2();
      const vec3 p = square_to_ellipse(u, e);
      const vec2 v = ellipse_to_square(p, e);
      ASSERT_NEAR(v.x, u.x, 1e-4);
      if (u.x >= 0.01f) {
        ASSERT_LE(periodic_distance(v.y, u.y), 1e-4) << "u = " << u.x << ", " << u.y;
      }
      ASSERT_LE(glm::length(square_to_ellipse(v, e) - p), 1e-4f * size);
    }
  }
}

TEST(Warp, CosineHemisphereRoundTrip) {
  pcg32 rng(23, 1);
  for (int i = 0; i < 100'000; ++i) {
    const vec2 u = rng.uniform2();
    const vec3 d = square_to_cosine_hemisphere(u);
    ASSERT_NEAR(glm::length(d), 1.0f, 1e-6f);
    const vec2 v = cosine_hemisphere_to_square(d);
    ASSERT_NEAR(v.x, u.x, 1e-4);
    if (u.x >= 0.01f) {
      ASSERT_LE(periodic_distance(v.y, u.y), 1e-4) << "u = " << u.x << ", " << u.y;
    }
    ASSERT_LE(glm::length(square_to_cosine_hemisphere(v) - d), 1e-4f);
  }
}

TEST(Warp, UniformSphereRoundTrip) {
  pcg32 rng(24, 1);
  for (int i = 0; i < 100'000; ++i) {
    const vec2 u = rng.uniform2();
    const vec3 d = square_to_uniform_sphere(u);
    ASSERT_NEAR(glm::length(d), 1.0f, 1e-6f);
    const vec2 v = uniform_sphere_to_square(d);
    ASSERT_NEAR(v.x, u.x, 1e-4);
    if (std::sqrt(d.x * d.x + d.y * d.y) >= 0.1f) {
      ASSERT_LE(periodic_distance(v.y, u.y), 1e-4) << "u = " << u.x << ", " << u.y;
    }
    ASSERT_LE(glm::length(square_to_uniform_sphere(v) - d), 1e-4f);
  }
}

TEST(Warp, UniformConeRoundTrip) {
  for (const float omc : {1e-6f, 1e-4f, 0.3f, 1.0f, 1.9f}) {
    pcg32 rng(25, 1);
    for (int i = 0; i < 100'000; ++i) {
      const vec2 u = rng.uniform2();
      const vec3 d = square_to_uniform_cone(u, omc);
      ASSERT_NEAR(glm::length(d), 1.0f, 1e-6f);
      ASSERT_GT(square_to_uniform_cone_pdf(d, omc), 0.0f);
      const vec2 v = uniform_cone_to_square(d, omc);
      ASSERT_NEAR(v.x, u.x, 1e-4) << "1 - cos theta_max = " << omc;
      if (u.x >= 0.01f) {
        ASSERT_LE(periodic_distance(v.y, u.y), 1e-4) << "u = " << u.x << ", " << u.y;
      }
      ASSERT_LE(glm::length(square_to_uniform_cone(v, omc) - d), 1e-4f * std::sqrt(omc));
    }
  }
}

// The concentric disk map (the thin lens): inside the unit disk, its own
// inverse, and pdf 1/pi inside, 0 outside.
TEST(Warp, ConcentricDiskRoundTrip) {
  pcg32 rng(26, 1);
  for (int i = 0; i < 200'000; ++i) {
    const vec2 u = rng.uniform2();
    const vec2 p = square_to_uniform_disk_concentric(u);
    ASSERT_LE(glm::length(p), 1.0f + 1e-6f);
    ASSERT_FLOAT_EQ(square_to_uniform_disk_concentric_pdf(p * (1.0f - 1e-6f)), inv_pi);
    const vec2 v = uniform_disk_concentric_to_square(p);
    ASSERT_NEAR(v.x, u.x, 2e-5) << "u = " << u.x << ", " << u.y;
    ASSERT_NEAR(v.y, u.y, 2e-5) << "u = " << u.x << ", " << u.y;
  }
  EXPECT_EQ(square_to_uniform_disk_concentric(vec2(0.5f)), vec2(0.0f));  // the centre, no 0/0
  EXPECT_EQ(square_to_uniform_disk_concentric_pdf(vec2(0.8f, 0.61f)), 0.0f);
  // The square's corners go to the diagonals, its edge midpoints to the axes.
  EXPECT_LT(glm::length(square_to_uniform_disk_concentric(vec2(1.0f, 1.0f)) - vec2(std::sqrt(0.5f))), 1e-6f);
  EXPECT_LT(glm::length(square_to_uniform_disk_concentric(vec2(0.5f, 0.0f)) - vec2(0.0f, -1.0f)), 1e-6f);
}

// Uniform over the disk, tested as directions: a point uniform on the unit
// disk lifted to the hemisphere (z = sqrt(1 - r^2)) is cosine-distributed
// (Malley's method), so the lifted samples must pass the chi-square test
// against cos(theta) / pi.
TEST(Warp, ConcentricDiskChiSquare) {
  const chi2_result r = test::chi2_test_directions(
      [](pcg32& rng, vec3& d) {
        const vec2 p = square_to_uniform_disk_concentric(rng.uniform2());
        d = vec3(p, safe_sqrt(1.0f - glm::dot(p, p)));
        return true;
      },
      [](const vec3& d) { return square_to_cosine_hemisphere_pdf(d); }, dvec3(0, 0, 1), 1.0,
      {.sample_count = chi2_samples, .seed = 404});
  expect_chi2_passed(r);
}

TEST(Warp, CosineHemisphereChiSquare) {
  const chi2_result r = test::chi2_test_directions(
      [](pcg32& rng, vec3& d) {
        d = square_to_cosine_hemisphere(rng.uniform2());
        return true;
      },
      [](const vec3& d) { return square_to_cosine_hemisphere_pdf(d); }, dvec3(0, 0, 1), 1.0,
      {.sample_count = chi2_samples, .seed = 401});
  expect_chi2_passed(r);
}

TEST(Warp, UniformSphereChiSquare) {
  const chi2_result r = test::chi2_test_directions(
      [](pcg32& rng, vec3& d) {
        d = square_to_uniform_sphere(rng.uniform2());
        return true;
      },
      [](const vec3&) { return square_to_uniform_sphere_pdf(); }, dvec3(0, 0, 1), 2.0,
      {.sample_count = chi2_samples, .seed = 402});
  expect_chi2_passed(r);
}

TEST(Warp, UniformConeChiSquare) {
  std::uint64_t seed = 403;
  for (const float omc : {1e-4f, 0.3f, 1.5f}) {
    const chi2_result r = test::chi2_test_directions(
        [omc](pcg32& rng, vec3& d) {
          d = square_to_uniform_cone(rng.uniform2(), omc);
          return true;
        },
        [omc](const vec3& d) { return square_to_uniform_cone_pdf(d, omc); }, dvec3(0, 0, 1),
        std::min(2.0, 1.01 * omc), {.sample_count = chi2_samples, .seed = seed++});
    expect_chi2_passed(r, "1 - cos theta_max = " + std::to_string(omc) + "\n");
  }
}

// ------------------------------------------------------------------ harness

TEST(Chi2Harness, SignificanceIsSidakCorrected) {
  const double alpha = test::chi2_per_test_significance();
  EXPECT_NEAR(std::pow(1.0 - alpha, test::chi2_max_tests_in_suite), 0.99, 1e-12);
  EXPECT_NEAR(alpha, 3.9258e-5, 1e-8);
}

TEST(Chi2Harness, SurvivalFunction) {
  // dof = 2: Q(1, x/2) = exp(-x/2) exactly.
  for (const double x : {0.1, 1.0, 10.0, 50.0}) EXPECT_NEAR(test::chi2_survival(x, 2), std::exp(-0.5 * x), 1e-14);
  // dof = 1: Q(1/2, x/2) = erfc(sqrt(x/2)).
  for (const double x : {0.01, 1.0, 9.0, 30.0})
    EXPECT_NEAR(test::chi2_survival(x, 1), std::erfc(std::sqrt(0.5 * x)), 1e-13 * std::erfc(std::sqrt(0.5 * x)) + 1e-15);
  // Many degrees of freedom, as in the tests: the median of chi2(k) is about
  // k (1 - 2/(9k))^3 (Wilson & Hilferty 1931), and Q falls as x grows.
  for (const int k : {100, 5000, 20000}) {
    const double median = k * std::pow(1.0 - 2.0 / (9.0 * k), 3.0);
    EXPECT_NEAR(test::chi2_survival(median, k), 0.5, 2e-3);
    EXPECT_GT(test::chi2_survival(0.8 * k, k), test::chi2_survival(1.0 * k, k));
    EXPECT_GT(test::chi2_survival(1.0 * k, k), test::chi2_survival(1.2 * k, k));
  }
}

// Uniform cone in double about +z; the harness must resolve caps of ~1e-9 sr.
struct double_cone {
  double omc;
  bool operator()(pcg32& rng, vec3& d) const {
    const double u = rng.uniform_double() * omc, phi = 2.0 * dpi * rng.uniform_double();
    const double s = std::sqrt(u * (2.0 - u));
    d = vec3(dvec3(s * std::cos(phi), s * std::sin(phi), 1.0 - u));
    return true;
  }
  double operator()(const dvec3& d) const {
    const dvec3 n = glm::normalize(d);
    const double u = 0.5 * glm::dot(n - dvec3(0, 0, 1), n - dvec3(0, 0, 1));
    return u <= omc ? 1.0 / (2.0 * dpi * omc) : 0.0;
  }
};

TEST(Chi2Harness, ResolvesTinyCaps) {
  const double_cone cone{1.6e-10};  // 1e-9 sr
  const chi2_result r =
      test::chi2_test_directions(cone, cone, dvec3(0, 0, 1), 1.2 * cone.omc, {.sample_count = chi2_samples, .seed = 501});
  expect_chi2_passed(r);
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

// The harness must be able to fail: samplers whose pdf is wrong are rejected.

TEST(Chi2Harness, RejectsCosineSamplesAgainstUniformPdf) {
  const chi2_result r = test::chi2_test_directions(
      [](pcg32& rng, vec3& d) {
        d = square_to_cosine_hemisphere(rng.uniform2());
        return true;
      },
      [](const vec3& d) { return d.z > 0.0f ? 0.5 / dpi : 0.0; }, dvec3(0, 0, 1), 1.0,
      {.sample_count = 200'000, .seed = 601});
  expect_chi2_rejected(r);
  EXPECT_LT(r.p_value, test::chi2_per_test_significance());
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

// Uniform on the Cornell light, but the pdf claims a light 1% larger in
// both directions: every sample has pdf > 0 and the pdf integrates to 1,
// only the statistic can tell.
TEST(Chi2Harness, RejectsPdfOfASlightlyLargerRectangle) {
  const vec3 o{278.0f, 0.0f, 279.5f};
  const rect_area_sampler s{cornell_light};
  const rect wider = xz_rect(213.0f - 0.65f, 343.0f + 0.65f, 227.0f - 0.525f, 332.0f + 0.525f, 554.0f, true);
  const rect_area_sampler claimed{wider};
  const spherical_cap cap = test::bounding_cap(dvec3(o), wider);
  const chi2_result r = test::chi2_test_directions(
      [&](pcg32& rng, vec3& d) {
        light_sample ls;
        if (!s.sample(o, rng.uniform2(), ls)) return false;
        d = ls.dir;
        return true;
      },
      [&](const vec3& d) { return claimed.pdf(o, d); }, cap.axis, cap.one_minus_cos,
      {.sample_count = chi2_samples, .seed = 602});
  expect_chi2_rejected(r);
  EXPECT_LT(r.p_value, test::chi2_per_test_significance()) << r.report;
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

// Same support, density off by a few percent: u1 -> u1^1.05 on the light
// while the pdf stays uniform by area.
TEST(Chi2Harness, RejectsSlightlyNonUniformAreaSamples) {
  const vec3 o{278.0f, 0.0f, 279.5f};
  const rect_area_sampler s{cornell_light};
  const spherical_cap cap = test::bounding_cap(dvec3(o), cornell_light);
  const chi2_result r = test::chi2_test_directions(
      [&](pcg32& rng, vec3& d) {
        vec2 u = rng.uniform2();
        u.x = std::pow(u.x, 1.05f);
        light_sample ls;
        if (!s.sample(o, u, ls)) return false;
        d = ls.dir;
        return true;
      },
      [&](const vec3& d) { return s.pdf(o, d); }, cap.axis, cap.one_minus_cos,
      {.sample_count = chi2_samples, .seed = 603});
  expect_chi2_rejected(r);
  EXPECT_LT(r.p_value, test::chi2_per_test_significance()) << r.report;
}

// Samples where the claimed pdf is 0 (a light 1% smaller than the sampled
// one), samples outside the cap, a pdf that does not integrate to 1, and a
// sampler that gives up: each is a failure, and the report says which.
TEST(Chi2Harness, RejectsSamplesWherePdfIsZero) {
  const vec3 o{278.0f, 0.0f, 279.5f};
  const rect_area_sampler s{cornell_light};
  const rect_area_sampler claimed{
      xz_rect(213.0f + 0.65f, 343.0f - 0.65f, 227.0f + 0.525f, 332.0f - 0.525f, 554.0f, true)};
  const spherical_cap cap = test::bounding_cap(dvec3(o), cornell_light);
  const chi2_result r = test::chi2_test_directions(
      [&](pcg32& rng, vec3& d) {
        light_sample ls;
        if (!s.sample(o, rng.uniform2(), ls)) return false;
        d = ls.dir;
        return true;
      },
      [&](const vec3& d) { return claimed.pdf(o, d); }, cap.axis, cap.one_minus_cos,
      {.sample_count = 100'000, .seed = 604});
  expect_chi2_rejected(r);
  EXPECT_NE(r.report.find("pdf 0"), std::string::npos) << r.report;
}

TEST(Chi2Harness, RejectsSamplesOutsideTheCap) {
  const chi2_result r = test::chi2_test_directions(
      [](pcg32& rng, vec3& d) {
        d = square_to_uniform_cone(rng.uniform2(), 0.3f);
        return true;
      },
      [](const vec3& d) { return square_to_uniform_cone_pdf(d, 0.3f); }, dvec3(0, 0, 1), 0.29,
      {.sample_count = 100'000, .seed = 605});
  expect_chi2_rejected(r);
  EXPECT_NE(r.report.find("outside the cap"), std::string::npos) << r.report;
}

TEST(Chi2Harness, RejectsPdfThatDoesNotIntegrateToOne) {
  const chi2_result r = test::chi2_test_directions(
      [](pcg32& rng, vec3& d) {
        d = square_to_uniform_cone(rng.uniform2(), 0.3f);
        return true;
      },
      [](const vec3& d) { return 1.01f * square_to_uniform_cone_pdf(d, 0.3f); }, dvec3(0, 0, 1), 0.31,
      {.sample_count = 100'000, .seed = 606});
  expect_chi2_rejected(r);
  EXPECT_NEAR(r.pdf_integral, 1.01, 1e-4);
  EXPECT_NE(r.report.find("integrates to"), std::string::npos) << r.report;
}

TEST(Chi2Harness, RejectsSamplerThatGivesUp) {
  const chi2_result r = test::chi2_test_directions(
      [](pcg32& rng, vec3& d) {
        d = square_to_uniform_sphere(rng.uniform2());
        return d.z < 0.99f;
      },
      [](const vec3&) { return square_to_uniform_sphere_pdf(); }, dvec3(0, 0, 1), 2.0,
      {.sample_count = 100'000, .seed = 607});
  expect_chi2_rejected(r);
  EXPECT_NE(r.report.find("returned false"), std::string::npos) << r.report;
}

// ------------------------------------------------------------------ references

// Disk of radius R seen on its axis from height h: 2 pi (1 - h / sqrt(h^2 + R^2)),
// written as 2 pi R^2 / (sqrt(h^2 + R^2) (sqrt(h^2 + R^2) + h)) to avoid cancellation.
double disk_on_axis(double h, double radius) {
  const double s = std::sqrt(h * h + radius * radius);
  return 2.0 * dpi * radius * radius / (s * (s + h));
}

TEST(SolidAngle, EllipseMatchesDiskOnAxis) {
  const dvec3 c(1.0, -2.0, 0.5), a1(0.0, 3.0, 0.0), a2(0.0, 0.0, 3.0);  // normal +x
  for (const double h : {1e-3, 0.1, 1.0, 3.0, 100.0, 1e4, 1e6}) {
    const double exact = disk_on_axis(h, 3.0);
    EXPECT_NEAR(test::solid_angle_ellipse(c + dvec3(h, 0, 0), c, a1, a2), exact, 1e-10 * exact) << "h = " << h;
    EXPECT_NEAR(test::solid_angle_ellipse(c - dvec3(h, 0, 0), c, a1, a2), exact, 1e-10 * exact) << "h = " << h;
  }
}

// Solid angle of the polygon inscribed in the ellipse (n vertices, fan of
// Van Oosterom-Strackee triangles), Richardson-extrapolated in 1/n^2: an
// independent reference for off-axis observers.
double ellipse_by_polygons(const dvec3& o, const dvec3& c, const dvec3& a1, const dvec3& a2, int n) {
  const auto polygon = [&](int m) {
    double sum = 0.0;
    for (int i = 0; i < m; ++i) {
      const double t0 = 2.0 * dpi * i / m, t1 = 2.0 * dpi * (i + 1) / m;
      sum += test::solid_angle_triangle(o, c, c + std::cos(t0) * a1 + std::sin(t0) * a2,
                                        c + std::cos(t1) * a1 + std::sin(t1) * a2);
    }
    return sum;
  };
  const double coarse = polygon(n), fine = polygon(2 * n);
  return fine + (fine - coarse) / 3.0;
}

TEST(SolidAngle, EllipseMatchesPolygonFans) {
  const dvec3 c(278.0, 554.0, 279.5), a1(65.0, 0.0, 0.0), a2(0.0, 0.0, 30.0);
  for (const dvec3& o : {dvec3(278.0, 0.0, 279.5), dvec3(20.0, 0.0, 530.0), dvec3(300.0, 544.0, 290.0),
                         dvec3(150.0, 553.5, 300.0), dvec3(1e4, -3e3, 2e3)}) {
    const double ref = ellipse_by_polygons(o, c, a1, a2, 4096);
    // The foot of the observer lies inside the ellipse for only some of
    // these: both branches of the boundary formula are exercised.
    EXPECT_NEAR(test::solid_angle_ellipse(o, c, a1, a2), ref, 1e-9 * ref)
        << "observer " << o.x << ", " << o.y << ", " << o.z;
  }
}

// Rectangle 2a x 2b seen from height h above its centre: 4 asin(ab / sqrt((a^2 + h^2)(b^2 + h^2))).
TEST(SolidAngle, RectMatchesCenteredClosedForm) {
  const double a = 65.0, b = 52.5;
  const dvec3 corner(213.0, 554.0, 227.0), e1(2 * a, 0.0, 0.0), e2(0.0, 0.0, 2 * b);
  for (const double h : {1e-2, 1.0, 554.0, 1e5}) {
    const double exact = 4.0 * std::asin(a * b / std::sqrt((a * a + h * h) * (b * b + h * h)));
    const dvec3 o = corner + 0.5 * (e1 + e2) - dvec3(0.0, h, 0.0);
    EXPECT_NEAR(test::solid_angle_rect(o, corner, e1, e2), exact, 1e-12 * exact) << "h = " << h;
  }
  // Far away, Omega -> A cos / d^2 (relative error ~ (size / d)^2); 1e-9 sr.
  const double d = 1.1e7, area = 4.0 * a * b;
  const dvec3 o = corner + 0.5 * (e1 + e2) + d * glm::normalize(dvec3(3.0, -4.0, 1.0));
  const double cos_light = 4.0 / std::sqrt(26.0);
  EXPECT_NEAR(test::solid_angle_rect(o, corner, e1, e2), area * cos_light / (d * d), 1e-6 * area / (d * d));
}

TEST(SolidAngle, EllipseAndRectAreConsistentForThinShapes) {
  // A very thin ellipse and rectangle (same bounding box) subtend solid
  // angles in the ratio of their areas, pi/4, for a distant observer.
  const dvec3 c(0.0), a1(1.0, 0.0, 0.0), a2(0.0, 1e-3, 0.0);
  const dvec3 o(0.3, 0.2, 1e3);
  const double ell = test::solid_angle_ellipse(o, c, a1, a2);
  const double rec = test::solid_angle_rect(o, c - a1 - a2, 2.0 * a1, 2.0 * a2);
  EXPECT_NEAR(ell / rec, dpi / 4.0, 1e-6);
}

TEST(SolidAngle, SphereClosedForm) {
  EXPECT_NEAR(test::solid_angle_sphere(dvec3(0, 0, 2), dvec3(0.0), 1.0), 2 * dpi * (1 - std::sqrt(0.75)), 1e-15);
  EXPECT_NEAR(test::solid_angle_sphere(dvec3(0, 0, 1e5), dvec3(0.0), 1.0), dpi * 1e-10, 1e-20);
  EXPECT_EQ(test::solid_angle_sphere(dvec3(0.5, 0, 0), dvec3(0.0), 1.0), 4 * dpi);
}

// Every direction towards the shape lies in its bounding cap; where
// max_cap_over_shape > 0, the cap is at most that many times the shape's
// solid angle.
template <class Shape, class PointOnShape>
void expect_cap_holds_shape(const Shape& shape, const dvec3& o, PointOnShape point, double max_cap_over_shape) {
  const spherical_cap cap = test::bounding_cap(o, shape);
  ASSERT_GT(cap.one_minus_cos, 0.0);
  ASSERT_LE(cap.one_minus_cos, 2.0);
  EXPECT_NEAR(glm::length(cap.axis), 1.0, 1e-12);
  pcg32 rng(31, 7);
  for (int i = 0; i < 100'000; ++i) {
    const dvec3 d = glm::normalize(point(rng.uniform_double(), rng.uniform_double()) - o);
    ASSERT_LE(0.5 * glm::dot(d - cap.axis, d - cap.axis), cap.one_minus_cos) << "sample " << i;
  }
  for (int i = 0; i < 4096; ++i) {  // the boundary / corners, densely
    const double t = i / 4096.0;
    for (const dvec3& p : {point(1.0, t), point(0.0, t), point(t, 0.0), point(t, 1.0)}) {
      const dvec3 d = glm::normalize(p - o);
      ASSERT_LE(0.5 * glm::dot(d - cap.axis, d - cap.axis), cap.one_minus_cos);
    }
  }
  if (max_cap_over_shape > 0.0) {
    EXPECT_LE(2.0 * dpi * cap.one_minus_cos, max_cap_over_shape * test::solid_angle(o, shape));
  }
}

TEST(BoundingCap, HoldsRectangles) {
  const rect tilted = rect::make(tilted_origin, tilted_e1, tilted_e2);
  for (const auto& c : rect_cases()) {
    const rect& r = c.sampler.shape;
    const auto point = [&](double s, double t) { return dvec3(r.corner) + s * dvec3(r.e1) + t * dvec3(r.e2); };
    expect_cap_holds_shape(r, dvec3(c.o), point, 0.0);
  }
  // Just above the light's plane, inside its outline: about a hemisphere.
  const auto point = [&](double s, double t) {
    return dvec3(cornell_light.corner) + s * dvec3(cornell_light.e1) + t * dvec3(cornell_light.e2);
  };
  expect_cap_holds_shape(cornell_light, dvec3(230.0, 553.99, 300.0), point, 1.1);
  const auto tilted_point = [&](double s, double t) {
    return dvec3(tilted.corner) + s * dvec3(tilted.e1) + t * dvec3(tilted.e2);
  };
  expect_cap_holds_shape(tilted, dvec3(tilted.center() - 0.01f * tilted.n), tilted_point, 1.1);
}

TEST(BoundingCap, HoldsEllipses) {
  for (const auto& c : ellipse_cases()) {
    const ellipse& e = c.sampler.shape;
    // (s, t) -> sqrt(s) (cos 2 pi t a1 + sin 2 pi t a2): s = 1 is the rim.
    const auto point = [&](double s, double t) {
      const double r = std::sqrt(s), phi = 2.0 * dpi * t;
      return dvec3(e.center) + r * std::cos(phi) * dvec3(e.a1) + r * std::sin(phi) * dvec3(e.a2);
    };
    expect_cap_holds_shape(e, dvec3(c.o), point, 0.0);
  }
}

TEST(BoundingCap, HoldsSpheres) {
  for (const auto& c : sphere_cases()) {
    const sphere& s = c.sampler.shape;
    // Points on the sphere, uniformly.
    const auto point = [&](double u, double v) {
      const double z = 1.0 - 2.0 * u, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * dpi * v;
      return dvec3(s.center) + static_cast<double>(s.radius) * dvec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    expect_cap_holds_shape(s, dvec3(c.o), point, 1.05);
  }
  EXPECT_EQ(test::bounding_cap(dvec3(0.1, 0.0, 0.0), sphere{{0.0f, 0.0f, 0.0f}, 1.0f}).one_minus_cos, 2.0);
}

}  // namespace
