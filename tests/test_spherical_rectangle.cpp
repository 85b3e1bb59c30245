// Tests of solid-angle sampling of rectangles (sampling/spherical_rectangle.hpp,
// Urena, Fajardo & King 2013): the solid angle against a 50-digit reference,
// pdf consistency, E[1/pdf] = S, chi-square over a battery of extreme
// configurations, the round trip sample -> inverse, one-sidedness, and a
// fuzz test over 10^6 random and extreme configurations.
//
// Every random test uses a fixed seed. The chi-square tests run at the
// per-test level 1 - 0.99^(1/256) (support/chi2.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#if __has_include(<boost/multiprecision/cpp_bin_float.hpp>)
#include <boost/multiprecision/cpp_bin_float.hpp>
#define MCRT_TEST_MP 1
#endif

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "support/chi2.hpp"
#include "support/solid_angle.hpp"

namespace {

using namespace mcrt;

constexpr double dpi = std::numbers::pi;

// ------------------------------------------------------------------ cases

struct rect_case {
  std::string name;
  rect shape;
  vec3 o;
};

// A w x l rectangle centred at `center`, rotated by the rotation vector
// `rot` (axis times angle, Rodrigues), built in double and rounded.
rect rotated_rect(const dvec3& center, double w, double l, const dvec3& rot, bool flip) {
  const double angle = glm::length(rot);
  const dvec3 k = rot / angle;
  const auto rotate = [&](const dvec3& v) {
    return v * std::cos(angle) + glm::cross(k, v) * std::sin(angle) + k * glm::dot(k, v) * (1.0 - std::cos(angle));
  };
  const dvec3 e1 = rotate({w, 0.0, 0.0}), e2 = rotate({0.0, l, 0.0});
  return rect::make(vec3(center - 0.5 * (e1 + e2)), vec3(e1), vec3(e2), flip);
}

// Solid angles from 1e-8 sr to within 1e-6 of 2 pi, grazing observers at
// 1e-6 of the light's size, aspect 1e4, arbitrary orientations, flipped
// lights; both the spherical map and the area fallback. In every case float
// directions resolve the rectangle (the lines of sight to the tiny ones run
// along a coordinate axis, where directions keep their relative precision).
std::vector<rect_case> rect_battery() {
  const rect unit = xy_rect(-0.5f, 0.5f, -0.5f, 0.5f, 0.0f);
  const rect square2 = xy_rect(-1.0f, 1.0f, -1.0f, 1.0f, 0.0f);
  const rect strip = xy_rect(-5000.0f, 5000.0f, -0.5f, 0.5f, 0.0f);  // aspect 1e4
  const rect rot = rotated_rect({0.3, -0.2, 0.5}, 2.0, 0.7, {0.3, 0.4, 0.5}, false);
  const rect rot_flip = rotated_rect({-1.0, 2.0, 0.25}, 0.5, 3.0, {-1.1, 0.2, 0.9}, true);
  std::vector<rect_case> v = {
      {"tiny_1e8", unit, {0.1f, 0.2f, 1e4f}},
      {"tiny_1e10", unit, {0.1f, 0.2f, 1e5f}},
      {"tiny_1e11", unit, {0.1f, 0.2f, 3.1623e5f}},
      {"oblique_1e4", unit, {60.0f, 50.0f, 70.0f}},
      {"oblique_1e2", unit, {6.0f, -5.0f, 7.0f}},
      {"overhead_1", unit, {0.1f, 0.05f, 0.5f}},
      {"near_2pi", square2, {0.1f, -0.2f, 1e-7f}},
      {"grazing_inside", square2, {0.3f, -0.2f, 1e-6f}},
      {"grazing_edge", square2, {0.3f, -1.000001f, 1e-6f}},
      {"grazing_corner", square2, {1.000001f, 1.000001f, 1e-6f}},
      {"grazing_outside", square2, {2.5f, 0.4f, 1e-6f}},
      {"aspect_overhead", strip, {0.0f, 0.0f, 1.0f}},
      {"aspect_edge_grazing", strip, {10.0f, -0.500001f, 1e-6f}},
      {"aspect_side_grazing", strip, {0.0f, -1.5f, 1e-6f}},
      {"aspect_end", strip, {5003.0f, 0.2f, 0.5f}},
      {"rotated", rot, vec3(dvec3(rot.center()) + 1.2 * dvec3(rot.n) + 0.5 * dvec3(rot.e1) - 0.3 * dvec3(rot.e2))},
      {"rotated_far", rot, vec3(dvec3(rot.center()) + 90.0 * dvec3(rot.n) - 60.0 * dvec3(rot.e1))},
      {"rotated_flipped", rot_flip, vec3(dvec3(rot_flip.center()) + 0.7 * dvec3(rot_flip.n) + 0.2 * dvec3(rot_flip.e2))},
      {"cornell", xz_rect(213, 343, 227, 332, 554, true), {278.0f, 1.0f, 279.5f}},
  };
  return v;
}

// The battery for the direction chi-square harness (support/chi2.hpp): every
// case that harness can take. It integrates the pdf on cells refined down to
// 1/256 of a cell's side, which cannot resolve the thin slivers of grazing
// views from outside; and it fails on any sample whose float direction
// misses the light, which happens at a rate ~1e-7 rad / (angular size) for
// small lights off the coordinate axes (oblique_1e4, rotated_far). Those
// cases are covered by the chi-square test on the rectangle below.
std::vector<rect_case> rect_chi2_battery() {
  std::vector<rect_case> v;
  for (rect_case& c : rect_battery())
    if (c.name != "grazing_outside" && c.name != "aspect_side_grazing" && c.name != "aspect_edge_grazing" &&
        c.name != "tiny_1e10" && c.name != "oblique_1e4" && c.name != "rotated_far")
      v.push_back(std::move(c));
  return v;
}

// Sum of the angles between the directions to consecutive corners: the
// angular length of the light's outline seen from o.
double angular_perimeter(const rect& r, const vec3& o) {
  const dvec3 c(r.corner), e1(r.e1), e2(r.e2), oo(o);
  const dvec3 p[4] = {c, c + e1, c + e1 + e2, c + e2};
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    const dvec3 a = glm::normalize(p[i] - oo), b = glm::normalize(p[(i + 1) % 4] - oo);
    sum += 2.0 * std::asin(std::min(1.0, 0.5 * glm::length(a - b)));
  }
  return sum;
}

// Solid angle of the parallelogram as two triangles by Van Oosterom &
// Strackee with 50 significant digits (Boost.Multiprecision), so no
// cancellation anywhere; test::solid_angle (double) without Boost.
double reference_solid_angle(const rect& r, const vec3& o) {
#ifdef MCRT_TEST_MP
  using mp = boost::multiprecision::cpp_bin_float_50;
  struct v3 {
    mp x, y, z;
  };
  const auto sub = [](const v3& a, const v3& b) { return v3{a.x - b.x, a.y - b.y, a.z - b.z}; };
  const auto dot = [](const v3& a, const v3& b) { return mp(a.x * b.x + a.y * b.y + a.z * b.z); };
  const auto cross = [](const v3& a, const v3& b) {
    return v3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  const auto tri = [&](const v3& a, const v3& b, const v3& c) {
    const mp la = sqrt(dot(a, a)), lb = sqrt(dot(b, b)), lc = sqrt(dot(c, c));
    const mp num = abs(dot(a, cross(b, c)));
    return mp(2 * atan2(num, la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la));
  };
  const v3 oo{o.x, o.y, o.z}, c{r.corner.x, r.corner.y, r.corner.z};
  const v3 e1{r.e1.x, r.e1.y, r.e1.z}, e2{r.e2.x, r.e2.y, r.e2.z};
  const v3 a = sub(c, oo);
  const v3 b{a.x + e1.x, a.y + e1.y, a.z + e1.z}, d{a.x + e2.x, a.y + e2.y, a.z + e2.z};
  const v3 f{b.x + e2.x, b.y + e2.y, b.z + e2.z};
  return static_cast<double>(tri(a, b, f) + tri(a, f, d));
#else
  return test::solid_angle(dvec3(o), r);
#endif
}

// The sampler treats the parallelogram spanned by float edges as the
// rectangle with e2 made orthogonal to e1: their solid angles differ at the
// order of the angle between e1 and e2 minus pi/2.
double shear_tolerance(const rect& r) {
  const double c = std::abs(glm::dot(dvec3(r.e1), dvec3(r.e2))) / (glm::length(dvec3(r.e1)) * glm::length(dvec3(r.e2)));
  return std::max(1e-12, 10.0 * c);
}

// ------------------------------------------------------------------ solid angle

TEST(SphericalRectangle, SolidAngleMatchesReference) {
  for (const rect_case& c : rect_battery()) {
    const spherical_rectangle sr(c.shape, c.o);
    ASSERT_TRUE(sr.valid()) << c.name;
    const double ref = reference_solid_angle(c.shape, c.o);
    EXPECT_NEAR(sr.solid_angle() / ref, 1.0, shear_tolerance(c.shape)) << c.name << ": S = " << sr.solid_angle() << ", ref " << ref;
  }
}

TEST(SphericalRectangle, BatteryCoversTheExtremesAndBothPaths) {
  // The battery is meant to include solid angles from 1e-8 sr to within
  // 1e-6 of 2 pi and both the map and the area fallback.
  double s_min = 10.0, s_max = 0.0;
  int map = 0, area = 0;
  for (const rect_case& c : rect_battery()) {
    const spherical_rectangle sr(c.shape, c.o);
    s_min = std::min(s_min, sr.solid_angle());
    s_max = std::max(s_max, sr.solid_angle());
    (sr.uses_map() ? map : area) += 1;
  }
  EXPECT_LE(s_min, 1.01e-8);
  EXPECT_GE(s_max, 2.0 * dpi - 1e-6);
  EXPECT_LT(s_max, 2.0 * dpi);
  EXPECT_GT(map, 0);
  EXPECT_GT(area, 0);
}

// ------------------------------------------------------------------ pdf consistency

// pdf returned with a sample == pdf(o, dir) for the same direction, to 1e-4
// (measured: ~1e-7). A float direction is off by up to ~2^-22 rad, so a
// sample within that of the outline can miss in its own direction; the
// fraction of such samples is at most 2^-22 * (angular perimeter) / S, and
// the misses must stay below twice that (plus 2 for the count's spread).
TEST(SphericalRectangle, PdfConsistency) {
  constexpr int n = 20'000;
  pcg32 rng(11, 3);
  for (const rect_case& c : rect_battery()) {
    const rect_solid_angle_sampler smp{c.shape};
    ASSERT_TRUE(smp.faces(c.o)) << c.name;
    const spherical_rectangle sr(c.shape, c.o);
    double worst = 0.0;
    int misses = 0;
    for (int i = 0; i < n; ++i) {
      light_sample s;
      ASSERT_TRUE(smp.sample(c.o, rng.uniform2(), s)) << c.name;
      const float p = smp.pdf(c.o, s.dir);
      if (p == 0.0f) {
        ++misses;
        continue;
      }
      worst = std::max(worst, std::abs(double(p) / double(s.pdf) - 1.0));
    }
    const double allowed = 2.0 * n * 0x1p-22 * angular_perimeter(c.shape, c.o) / sr.solid_angle() + 2.0;
    EXPECT_LE(misses, allowed) << c.name;
    EXPECT_LE(worst, 1e-4) << c.name;
  }
}

// On the map the pdf is exactly 1/S for every direction that hits.
TEST(SphericalRectangle, MapPdfIsConstant) {
  for (const rect_case& c : rect_battery()) {
    const spherical_rectangle sr(c.shape, c.o);
    if (!sr.uses_map()) continue;
    pcg32 rng(5, 9);
    for (int i = 0; i < 1000; ++i) {
      const dvec3 v = sr.sample_offset(rng.uniform2());
      EXPECT_EQ(sr.pdf_offset(v), 1.0 / sr.solid_angle()) << c.name;
    }
  }
}

// ------------------------------------------------------------------ E[1/pdf] = S

// The estimator 1/pdf of the solid angle is unbiased for any correct
// sampler. N = 2e5 samples, fixed seed; the sample standard error SE is
// computed, and the test requires 5 SE <= 0.5 % of S (so that a pass is
// informative and a correct sampler fails with probability < 1e-6) and
// |mean - S| <= 0.5 % S. On the map 1/pdf = S for every sample (SE = 0);
// on the area fallback the spread of d^3 / (h A) sets SE.
TEST(SphericalRectangle, ExpectedInversePdfIsSolidAngle) {
  constexpr int n = 200'000;
  for (const rect_case& c : rect_battery()) {
    const rect_solid_angle_sampler smp{c.shape};
    const double ref = reference_solid_angle(c.shape, c.o);
    pcg32 rng(21, 4);
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
      light_sample s;
      ASSERT_TRUE(smp.sample(c.o, rng.uniform2(), s)) << c.name;
      const double w = 1.0 / double(s.pdf);
      sum += w;
      sum2 += w * w;
    }
    const double mean = sum / n;
    const double se = std::sqrt(std::max(sum2 / n - mean * mean, 0.0) / (n - 1));
    EXPECT_LE(5.0 * se, 0.005 * ref) << c.name << ": the test cannot resolve 0.5 %";
    EXPECT_NEAR(mean / ref, 1.0, 0.005) << c.name << ": E[1/pdf] = " << mean << ", S = " << ref << ", SE " << se;
  }
}

// ------------------------------------------------------------------ chi-square

class SphericalRectangleChi2 : public ::testing::TestWithParam<rect_case> {};

TEST_P(SphericalRectangleChi2, MatchesPdf) {
  const rect_case& c = GetParam();
  const rect_solid_angle_sampler smp{c.shape};
  const spherical_rectangle sr(c.shape, c.o);
  const auto sample = [&](pcg32& rng, vec3& d) {
    light_sample s;
    if (!smp.sample(c.o, rng.uniform2(), s)) return false;
    d = s.dir;
    return true;
  };
  // The density in double (grid directions keep their bits).
  const auto pdf = [&](const dvec3& d) {
    double t;
    return sr.intersect(d, t) ? sr.pdf_offset(t * d) : 0.0;
  };
  const test::spherical_cap cap = test::bounding_cap(dvec3(c.o), c.shape);
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.seed = 17;
  const test::chi2_result r = test::chi2_test_directions(sample, pdf, cap.axis, cap.one_minus_cos, opt);
  EXPECT_TRUE(r.passed) << c.name << " (" << (sr.uses_map() ? "map" : "area") << ", S = " << sr.solid_angle()
                        << ")\n"
                        << r.report;
}

INSTANTIATE_TEST_SUITE_P(Battery, SphericalRectangleChi2, ::testing::ValuesIn(rect_chi2_battery()),
                         [](const ::testing::TestParamInfo<rect_case>& info) { return info.param.name; });

// Chi-square on the rectangle itself, for every case of the battery
// including the grazing slivers the direction harness cannot resolve. Each
// sample's point o + dist * dir (double; the float direction's rounding
// moves it by ~1e-7 of dist, far below a cell) is binned on a 32 x 32 grid
// of the rectangle's (s, t) coordinates. The probability of a cell is its
// solid angle over S on the map (50-digit reference_solid_angle of the
// cell and of the whole rectangle) and its area over A on the area
// fallback. Cells expecting < 5 samples are pooled; p-value from
// test::chi2_survival, level as for the harness.
TEST(SphericalRectangle, Chi2OnTheRectangle) {
  constexpr int res = 32;
  constexpr int n = 500'000;
  for (const rect_case& c : rect_battery()) {
    const rect_solid_angle_sampler smp{c.shape};
    const spherical_rectangle sr(c.shape, c.o);
    const dvec3 corner(c.shape.corner), e1(c.shape.e1), e2(c.shape.e2), o(c.o);
    const double total = reference_solid_angle(c.shape, c.o);
    std::vector<double> expected(res * res), observed(res * res, 0.0);
    for (int i = 0; i < res; ++i)
      for (int j = 0; j < res; ++j) {
        const rect cell = rect::make(vec3(0.0f), vec3(e1 / double(res)), vec3(e2 / double(res)));
        double p;
        if (sr.uses_map()) {
          // The cell as a rect relative to o (offsets keep all their bits).
          rect rc = cell;
          rc.corner = vec3(corner - o + (double(i) / res) * e1 + (double(j) / res) * e2);
          p = reference_solid_angle(rc, vec3(0.0f)) / total;
        } else {
          p = 1.0 / (res * res);
        }
        expected[i * res + j] = p * n;
      }
    pcg32 rng(29, 5);
    const dvec3 ex = glm::normalize(e1), ey = glm::normalize(e2 - glm::dot(e2, ex) * ex);
    const double w = glm::length(e1), l = glm::dot(e2, ey);
    for (int k = 0; k < n; ++k) {
      light_sample s;
      ASSERT_TRUE(smp.sample(c.o, rng.uniform2(), s)) << c.name;
      const dvec3 q = double(s.dist) * dvec3(s.dir) - (corner - o);
      const int i = std::clamp(int(glm::dot(q, ex) / w * res), 0, res - 1);
      const int j = std::clamp(int(glm::dot(q, ey) / l * res), 0, res - 1);
      observed[i * res + j] += 1.0;
    }
    // Pool in increasing order of expectation (as support/chi2.hpp).
    std::vector<int> order(res * res);
    for (int i = 0; i < res * res; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return expected[a] < expected[b]; });
    double stat = 0.0, po = 0.0, pe = 0.0;
    int bins = 0;
    for (const int k : order) {
      po += observed[k];
      pe += expected[k];
      if (pe >= 5.0) {
        stat += (po - pe) * (po - pe) / pe;
        po = pe = 0.0;
        ++bins;
      }
    }
    if (pe > 0.0) stat += (po - pe) * (po - pe) / std::max(pe, 1e-300);
    // Seen from just above its interior (near_2pi) a light puts all but
    // ~1e-6 of its solid angle into the cell under the observer: nothing
    // to test on this grid; the direction harness covers that case.
    if (bins < 2) continue;
    const double pval = test::chi2_survival(stat, bins - 1);
    EXPECT_GE(pval, test::chi2_per_test_significance())
        << c.name << " (" << (sr.uses_map() ? "map" : "area") << "): chi2 = " << stat << ", dof " << bins - 1;
  }
}

// ------------------------------------------------------------------ round trip

// invert(sample(u)) == u within 1e-4 wherever the map is used (in double
// offsets: a float point far from the origin would round the rectangle
// itself), and within 1e-3 through the float point API on moderate cases.
TEST(SphericalRectangle, RoundTrip) {
  for (const rect_case& c : rect_battery()) {
    const spherical_rectangle sr(c.shape, c.o);
    if (!sr.uses_map()) continue;
    pcg32 rng(3, 8);
    double worst = 0.0;
    for (int i = 0; i < 50'000; ++i) {
      const vec2 u = rng.uniform2();
      const dvec2 w = sr.invert_offset(sr.sample_offset(u));
      worst = std::max({worst, std::abs(w.x - u.x), std::abs(w.y - u.y)});
    }
    EXPECT_LE(worst, 1e-4) << c.name;
  }
  const rect r = xz_rect(213, 343, 227, 332, 554, true);
  for (const vec3 o : {vec3(278, 300, 279), vec3(100, 540, 500), vec3(400, 1, 0)}) {
    const spherical_rectangle sr(r, o);
    ASSERT_TRUE(sr.uses_map());
    pcg32 rng(4, 1);
    for (int i = 0; i < 10'000; ++i) {
      const vec2 u = rng.uniform2();
      const vec2 w = sr.invert(sr.sample(u));
      EXPECT_NEAR(w.x, u.x, 1e-3);
      EXPECT_NEAR(w.y, u.y, 1e-3);
    }
  }
}

// The corners of the unit square go to the corners of the rectangle.
TEST(SphericalRectangle, CornersMapToCorners) {
  for (const rect_case& c : rect_battery()) {
    const spherical_rectangle sr(c.shape, c.o);
    const dvec3 d = dvec3(c.shape.corner) - dvec3(c.o), e1(c.shape.e1), e2(c.shape.e2);
    const double size = glm::length(e1) + glm::length(e2);
    EXPECT_LE(glm::length(sr.sample_offset({0.0f, 0.0f}) - d), 1e-6 * size) << c.name;
    EXPECT_LE(glm::length(sr.sample_offset({0.0f, 1.0f}) - (d + e2)), 1e-6 * size) << c.name;
    EXPECT_LE(glm::length(sr.sample_offset({1.0f, 0.0f}) - (d + e1)), 1e-6 * size) << c.name;
  }
}

// ------------------------------------------------------------------ one-sided

TEST(SphericalRectangle, BehindOrInThePlaneGetsNothing) {
  const rect lights[] = {xz_rect(-1, 1, -2, 2, 3, false), xz_rect(-1, 1, -2, 2, 3, true),
                         xy_rect(0, 5, 0, 1e-3f, -1, false), yz_rect(-1e3f, 1e3f, 0, 1, 0, true)};
  pcg32 rng(2, 2);
  for (const rect& r : lights) {
    const rect_solid_angle_sampler smp{r};
    const vec3 c = r.center();
    for (int i = 0; i < 1000; ++i) {
      // In the plane (exactly: the rectangles are axis-aligned) and behind it.
      const vec3 in_plane = r.corner + (3.0f * rng.uniform() - 1.0f) * r.e1 + (3.0f * rng.uniform() - 1.0f) * r.e2;
      const vec3 behind = in_plane - (1e-3f + 10.0f * rng.uniform()) * r.n;
      for (const vec3& o : {in_plane, behind}) {
        EXPECT_FALSE(smp.faces(o));
        EXPECT_FALSE(spherical_rectangle(r, o).valid());
        light_sample s;
        EXPECT_FALSE(smp.sample(o, rng.uniform2(), s));
        EXPECT_EQ(smp.pdf(o, glm::normalize(c - o)), 0.0f);
      }
      // In front, any direction away from the light: pdf 0.
      const vec3 front = in_plane + (1e-3f + rng.uniform()) * r.n;
      EXPECT_TRUE(smp.faces(front));
      EXPECT_EQ(smp.pdf(front, r.n), 0.0f);
    }
  }
}

// A flipped light is the same light seen from the other side.
TEST(SphericalRectangle, FlipSwapsTheFacingSide) {
  const rect a = rotated_rect({0.3, -0.2, 0.5}, 2.0, 0.7, {0.3, 0.4, 0.5}, false);
  const rect b = rotated_rect({0.3, -0.2, 0.5}, 2.0, 0.7, {0.3, 0.4, 0.5}, true);
  const vec3 o_front = a.center() + 1.5f * a.n + 0.4f * a.e1;
  const vec3 o_back = a.center() - 1.5f * a.n + 0.4f * a.e1;
  const spherical_rectangle fa(a, o_front), fb(b, o_back);
  ASSERT_TRUE(fa.valid());
  ASSERT_TRUE(fb.valid());
  EXPECT_FALSE(spherical_rectangle(a, o_back).valid());
  EXPECT_FALSE(spherical_rectangle(b, o_front).valid());
  // Mirror-symmetric observers see the same solid angle.
  EXPECT_NEAR(fa.solid_angle(), fb.solid_angle(), 1e-6 * fa.solid_angle());
}

// ------------------------------------------------------------------ fuzz

// 10^6 configurations: sizes over 8 decades (1e-4 .. 1e4), aspect up to
// 1e4 either way, random or axis-aligned orientation, either side emitting;
// observers at random distances (1e-3 .. 1e7 sizes), within 1e-7 .. 1e-1
// (relative) of the plane on either side, exactly in the plane, or behind.
// Asserted: no NaN / Inf; a returned sample has a unit direction, a
// positive distance and a finite positive pdf, and its direction hits the
// rectangle (rect::intersect); no sample and pdf 0 behind or in the plane.
// A float direction from a grazing observer can miss by rounding alone
// (its angle to the plane is ~h / d, its error ~1e-7 rad); such a miss is
// accepted only if the ray, intersected in double with the exact plane,
// lands within the rounding bound 2^-20 (d / h)(d + |o| + |corner| + |e1| +
// |e2|) of the rectangle (or the bound exceeds the rectangle), and the
// count of those misses is reported.
TEST(SphericalRectangle, Fuzz) {
  constexpr int configs = 1'000'000;
  pcg32 rng(2024, 7);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  long samples = 0, none = 0, facing_without_sample = 0, strict_miss = 0, map = 0, area = 0, pdf_mismatch = 0;
  for (int k = 0; k < configs; ++k) {
    const double scale = std::pow(10.0, uni(-4.0, 4.0));
    const double aspect = std::pow(10.0, uni(-4.0, 4.0));
    const double w = scale * std::sqrt(aspect), l = scale / std::sqrt(aspect);
    const dvec3 center(uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale);
    const bool flip = rng.uniform() < 0.5;
    const bool aligned = rng.uniform() < 0.25;
    rect r;
    if (aligned) {
      const float x0 = float(center.x - 0.5 * w), y0 = float(center.y - 0.5 * l);
      r = xy_rect(x0, x0 + float(w), y0, y0 + float(l), float(center.z), flip);
    } else {
      const dvec3 axis(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
      r = rotated_rect(center, w, l, glm::length(axis) > 1e-3 ? axis : dvec3(0.0, 0.0, 1.0), flip);
    }
    if (!(r.area > 0.0f) || !std::isfinite(r.area)) continue;
    const dvec3 c(r.corner), e1(r.e1), e2(r.e2), n(r.n);
    const double size = glm::length(e1) + glm::length(e2);
    vec3 o;
    const float mode = rng.uniform();
    bool must_fail = false;
    if (mode < 0.4f) {  // anywhere around it
      dvec3 d(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
      d = glm::length(d) > 1e-6 ? glm::normalize(d) : n;
      o = vec3(dvec3(r.center()) + size * std::pow(10.0, uni(-3.0, 7.0)) * d);
    } else if (mode < 0.7f) {  // near the plane, either side
      const double h = (rng.uniform() < 0.5f ? -1.0 : 1.0) * size * std::pow(10.0, uni(-7.0, -1.0));
      o = vec3(c + uni(-1.0, 2.0) * e1 + uni(-1.0, 2.0) * e2 + h * n);
    } else if (mode < 0.85f && aligned) {  // exactly in the plane
      o = vec3(c + uni(-1.0, 2.0) * e1 + uni(-1.0, 2.0) * e2);
      o.z = r.corner.z;
      must_fail = true;
    } else {  // behind
      o = vec3(dvec3(r.center()) - size * std::pow(10.0, uni(-3.0, 3.0)) * n +
               size * uni(-2.0, 2.0) * glm::normalize(e1));
      must_fail = glm::dot(dvec3(o) - c, n) < 0.0;
    }
    const rect_solid_angle_sampler smp{r};
    const vec2 u = (k % 64 == 0) ? vec2(0.0f) : (k % 64 == 1) ? vec2(0x1.fffffep-1f) : rng.uniform2();
    light_sample s;
    const bool ok = smp.sample(o, u, s);
    const vec3 to_center = glm::normalize(r.center() - o);
    if (!ok) {
      ++none;
      if (!smp.faces(o)) ASSERT_EQ(smp.pdf(o, to_center), 0.0f) << k;
      else ++facing_without_sample;  // the area pdf would overflow a float
      continue;
    }
    ASSERT_FALSE(must_fail) << k << ": a sample for an observer behind or in the plane";
    ++samples;
    const spherical_rectangle sr(r, o);
    (sr.uses_map() ? map : area) += 1;
    ASSERT_TRUE(all_finite(s.dir) && std::isfinite(s.dist) && std::isfinite(s.pdf)) << k;
    ASSERT_NEAR(glm::length(s.dir), 1.0f, 1e-5f) << k;
    ASSERT_GT(s.dist, 0.0f) << k;
    ASSERT_GT(s.pdf, 0.0f) << k;
    const float p = smp.pdf(o, s.dir);
    ASSERT_TRUE(std::isfinite(p) && p >= 0.0f) << k;
    if (p > 0.0f && std::abs(double(p) / s.pdf - 1.0) > 1e-4) ++pdf_mismatch;
    float t;
    if (r.intersect({o, s.dir}, 0.0f, infinity, t)) continue;
    ++strict_miss;
    // The miss must be explained by rounding (see above).
    const dvec3 oo(o), dd(s.dir), nn = glm::normalize(glm::cross(e1, e2));
    const double h = std::abs(glm::dot(oo - c, nn)), dist = double(s.dist);
    const double tol = 0x1p-20 * (dist / h) * (dist + glm::length(oo) + glm::length(c) + size);
    const double tt = glm::dot(c - oo, nn) / glm::dot(dd, nn);
    const dvec3 q = oo + tt * dd - c;
    const double a = glm::dot(q, e1) / glm::dot(e1, e1), b = glm::dot(q, e2) / glm::dot(e2, e2);
    const double ta = tol / glm::length(e1), tb = tol / glm::length(e2);
    // Where the bound exceeds the rectangle, a float direction cannot even
    // tell on which side of the plane it runs: nothing to check.
    if (ta >= 1.0 || tb >= 1.0) continue;
    ASSERT_TRUE(tt > 0.0 && a >= -ta && a <= 1.0 + ta && b >= -tb && b <= 1.0 + tb)
        << k << ": direction misses the light by more than rounding: (s, t) = (" << a << ", " << b
        << "), tolerance " << ta << ", " << tb;
  }
  std::cout << "[ fuzz     ] " << configs << " configurations: " << samples << " samples (" << map << " map, " << area
            << " area), " << none << " without a sample (" << facing_without_sample << " of them facing); " << strict_miss
            << " float rect::intersect misses, all within rounding; " << pdf_mismatch
            << " pdf(o, dir) != sample pdf beyond 1e-4\n";
  // About 35 % of the observers face the light (half of the random and
  // near-plane ones).
  EXPECT_GT(samples, configs * 3 / 10);
  EXPECT_LE(facing_without_sample, samples / 1000);
}

// ------------------------------------------------------------------ fast path

// rect_solid_angle_sampler serves most observers by its fast path and the
// rest by spherical_rectangle. Over 3e5 random configurations (sizes over 6
// decades, aspect up to 1e3, random orientation, either side emitting;
// observers from 1e-2 to 1e4 sizes away in any direction, or within 1e-5 ..
// 1 size of the plane): wherever the fast path is taken, the sample's pdf
// is 1 / S of spherical_rectangle to the rounding of a float (6e-8), pdf(o,
// dir) returns the same value for the sample's own direction whenever it
// hits, and the direction is spherical_rectangle's map of the same u to
// within 4 units of 2^-24 (float rounding of two directions: measured 1).
// The fast path must cover a good part of the configurations and sample
// must fail exactly where spherical_rectangle is invalid.
TEST(SphericalRectangle, FastPathMatchesTheExactMap) {
  pcg32 rng(77, 13);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  long valid = 0, fast = 0;
  double worst_pdf = 0.0, worst_dir = 0.0;
  for (int k = 0; k < 300'000; ++k) {
    const double scale = std::pow(10.0, uni(-3.0, 3.0)), aspect = std::pow(10.0, uni(-3.0, 3.0));
    const double w = scale * std::sqrt(aspect), l = scale / std::sqrt(aspect);
    const dvec3 center(uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale);
    const dvec3 axis(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
    const rect r = rotated_rect(center, w, l, glm::length(axis) > 1e-3 ? axis : dvec3(0.0, 0.0, 1.0), rng.uniform() < 0.5f);
    const double size = w + l;
    vec3 o;
    if (k % 2 == 0) {
      const dvec3 d = glm::normalize(dvec3(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0)) + dvec3(1e-9));
      o = vec3(dvec3(r.center()) + size * std::pow(10.0, uni(-2.0, 4.0)) * d);
    } else {
      o = vec3(dvec3(r.corner) + uni(-1.0, 2.0) * dvec3(r.e1) + uni(-1.0, 2.0) * dvec3(r.e2) +
               size * std::pow(10.0, uni(-5.0, 0.0)) * dvec3(r.n));
    }
    const rect_solid_angle_sampler smp{r};
    const spherical_rectangle sr(r, o);
    light_sample s;
    const vec2 u = rng.uniform2();
    const bool ok = smp.sample(o, u, s);
    if (!sr.valid()) {
      ASSERT_FALSE(ok) << k;
      ASSERT_FALSE(smp.fast_path(o)) << k;
      continue;
    }
    ++valid;
    if (!smp.fast_path(o)) continue;
    ++fast;
    ASSERT_TRUE(ok) << k;
    worst_pdf = std::max(worst_pdf, std::abs(double(s.pdf) * sr.solid_angle() - 1.0));
    const float p = smp.pdf(o, s.dir);
    if (p != 0.0f) {
      ASSERT_EQ(p, s.pdf) << k;
    }
    const dvec3 v = sr.sample_offset(u);
    worst_dir = std::max(worst_dir, glm::length(dvec3(s.dir) - dvec3(vec3(v / glm::length(v)))) / 0x1p-24);
  }
  std::cout << "[ fast     ] " << fast << " of " << valid << " facing configurations on the fast path; worst |pdf S - 1| "
            << worst_pdf << ", worst direction difference " << worst_dir << " x 2^-24\n";
  EXPECT_GT(fast, valid / 3);
  EXPECT_LE(worst_pdf, 1.2e-7);
  EXPECT_LE(worst_dir, 4.0);
}

// The chi-square and E[1/pdf] tests above run through rect_solid_angle_sampler:
// the battery must exercise both of its paths.
TEST(SphericalRectangle, BatteryCoversBothSamplerPaths) {
  int fast = 0, exact = 0;
  for (const rect_case& c : rect_battery()) (rect_solid_angle_sampler{c.shape}.fast_path(c.o) ? fast : exact) += 1;
  EXPECT_GE(fast, 3);
  EXPECT_GE(exact, 3);
}

// Everywhere inside the Cornell box (the light of BM_SampleRectSolidAngle,
// observers from just below the ceiling to the floor) the fast path serves
// all but the observers within fast_min_sine of the light's plane.
TEST(SphericalRectangle, CornellBoxTakesTheFastPath) {
  const rect r = xz_rect(213, 343, 227, 332, 554, true);
  const rect_solid_angle_sampler smp{r};
  pcg32 rng(8, 8);
  int fast = 0, n = 0;
  for (int i = 0; i < 100'000; ++i) {
    const vec3 o(555.0f * rng.uniform(), 553.0f * rng.uniform(), 555.0f * rng.uniform());
    ++n;
    fast += smp.fast_path(o);
  }
  EXPECT_GE(fast, n * 99 / 100);
}

}  // namespace
