// Tests of solid-angle sampling of triangles (sampling/spherical_triangle.hpp,
// Arvo 1995): the solid angle against a 50-digit Van Oosterom-Strackee
// reference at the extremes (1e-10 sr to 2 pi - 6e-7 sr, slivers of aspect
// 1e4, observers 1e-6 of the size from the plane) and over random extreme
// configurations; the map against Arvo's own formulas evaluated in 50
// digits; pdf consistency and pdf = 1 / Omega; E[1/pdf] = Omega and
// E[cos/pdf] = the projected solid angle (Lambert's polygon formula);
// chi-square of the directions (support/chi2.hpp) and on the triangle
// itself; round trips; one-sidedness; a fuzz test of 10^6 configurations.
//
// Every random test uses a fixed seed. The chi-square tests run at the
// per-test level 1 - 0.99^(1/256) ~= 3.9e-5 (support/chi2.hpp: 1 %
// family-wise over the suite, Sidak).
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>


#include "mcrt/core/rng.hpp"
#include "mcrt/mcrt.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"
#include "support/chi2.hpp"
#include "support/lambert.hpp"
#include "support/solid_angle.hpp"
#include "support/spherical_triangle_reference.hpp"

namespace {

using namespace mcrt;

constexpr double dpi = std::numbers::pi;
constexpr double eps = DBL_EPSILON;

// ------------------------------------------------------------------ cases

struct tri_case {
  std::string name;
  vec3 p0, p1, p2, o;
  bool reverse = false;  // the mesh's ReverseOrientation
};

std::shared_ptr<triangle_mesh> mesh_of(const vec3& a, const vec3& b, const vec3& c, bool reverse) {
  auto m = std::make_shared<triangle_mesh>();
  m->p = {a, b, c};
  m->indices = {0, 1, 2};
  m->reverse_orientation = reverse;
  return m;
}
triangle triangle_of(const tri_case& c) { return triangle{mesh_of(c.p0, c.p1, c.p2, c.reverse), 0}; }

// Rodrigues rotation of v by the rotation vector rot (axis times angle).
dvec3 rotate(const dvec3& v, const dvec3& rot) {
  const double angle = glm::length(rot);
  const dvec3 k = rot / angle;
  return v * std::cos(angle) + glm::cross(k, v) * std::sin(angle) + k * glm::dot(k, v) * (1.0 - std::cos(angle));
}

// The extremes of the brief: solid angles from 1e-10 sr to 2 pi - 6e-7 sr,
// observers 1e-6 (relative to the size) above the plane inside, beyond an
// edge and a vertex, and outside; slivers of aspect 1e4 seen from above,
// grazing and end-on, in each of the three vertex orders (the map starts at
// p0); arbitrary orientation, a reversed mesh. Lines of sight to the tiny
// ones run along a coordinate axis, where float directions keep their
// relative precision.
std::vector<tri_case> battery() {
  const vec3 q0(-1, -1, 0), q1(2, -1, 0), q2(-1, 2, 0);                      // size 3, front +z
  const vec3 s0(-0.5f, 0, 0), s1(0.5f, 0, 0), s2(0.1f, 1e-4f, 0);            // sliver, aspect 1e4, front +z
  const vec3 t0(-0.5f, -0.5f, 0), t1(1, -0.5f, 0), t2(-0.5f, 0.8f, 0);       // area 0.975, front +z
  const dvec3 rot(0.3, -0.7, 0.4), centre(0.5, -1.0, 2.0);
  const auto place = [&](const dvec3& p) { return vec3(centre + rotate(p, rot)); };
  const vec3 r0 = place({-0.6, -0.4, 0}), r1 = place({0.9, -0.2, 0}), r2 = place({0.1, 0.7, 0});
  const dvec3 rn = rotate({0, 0, 1}, rot);
  return {
      {"overhead", {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2f, 0.3f, 1}},
      {"tiny_1e8", t0, t1, t2, {0.1f, 0.2f, 1e4f}},
      {"tiny_1e10", t0, t1, t2, {0.1f, 0.2f, 1e5f}},
      {"near_2pi", q0, q1, q2, {0.1f, -0.2f, 1e-7f}},
      {"grazing_inside", q0, q1, q2, {0.3f, -0.2f, 3e-6f}},
      {"grazing_edge", q0, q1, q2, {0.3f, -1.000002f, 3e-6f}},
      {"grazing_vertex", q0, q1, q2, {-1.000002f, -1.000002f, 3e-6f}},
      {"grazing_outside", q0, q1, q2, {3.0f, 0.5f, 3e-6f}},
      {"sliver_overhead", s0, s1, s2, {0, 0, 0.3f}},
      {"sliver_overhead_r1", s1, s2, s0, {0, 0, 0.3f}},
      {"sliver_overhead_r2", s2, s0, s1, {0, 0, 0.3f}},
      {"sliver_grazing", s0, s1, s2, {0, -0.2f, 1e-6f}},
      {"sliver_grazing_r1", s1, s2, s0, {0, -0.2f, 1e-6f}},
      {"sliver_grazing_r2", s2, s0, s1, {0, -0.2f, 1e-6f}},
      {"sliver_end", s0, s1, s2, {2.0f, 0, 0.01f}},
      {"sliver_far", s0, s1, s2, {0, 0, 30.0f}},
      {"rotated", r0, r1, r2, vec3(centre + rotate({0.2, 0.1, 0.8}, rot))},
      {"rotated_far", r0, r1, r2, vec3(centre + 60.0 * rn + dvec3(20.0, -10.0, 5.0))},
      {"rotated_reversed", r0, r1, r2, vec3(centre - rotate({0.2, 0.1, 0.5}, rot)), true},
      {"cornell_half", {343, 554, 332}, {213, 554, 227}, {343, 554, 227}, {278, 1, 279.5f}},  // front -y
  };
}

// Cases the direction chi-square harness resolves: its adaptive cell
// integration (refined to 1/32 of a cell across the light's edge) does not
// integrate slivers 3e-4 rad thin or less to the accuracy 10^6 samples
// resolve (the expected counts of the rim cells come out 10-70 % off), nor
// the slivers of grazing views; float directions miss lights below ~1e-9 sr
// at a measurable rate (support/chi2.hpp). Those cases are covered by the
// chi-square test on the triangle.
bool direction_harness_resolves(const std::string& name) {
  return name != "tiny_1e10" && name.find("grazing") == std::string::npos && name.find("sliver") == std::string::npos;
}

double size_of(const tri_case& c) {
  return std::max({glm::length(dvec3(c.p1) - dvec3(c.p0)), glm::length(dvec3(c.p2) - dvec3(c.p1)),
                   glm::length(dvec3(c.p0) - dvec3(c.p2))});
}
// Height of o above the plane (always > 0 for the battery).
double height_of(const tri_case& c) {
  const dvec3 n = glm::normalize(glm::cross(dvec3(c.p1) - dvec3(c.p0), dvec3(c.p2) - dvec3(c.p0)));
  return std::abs(glm::dot(dvec3(c.o) - dvec3(c.p0), n));
}
double max_distance(const tri_case& c) {
  const dvec3 o(c.o);
  return std::max({glm::length(dvec3(c.p0) - o), glm::length(dvec3(c.p1) - o), glm::length(dvec3(c.p2) - o)});
}

// v rounded to float. Not inlined: GCC 12's SLP vectorizer (-O3) was seen
// to keep the double value of a double -> float -> double round trip, so
// that "float" vertices were not floats.
[[gnu::noinline]] vec3 to_float(const dvec3& v) { return vec3(v); }

spherical_triangle set_up(const tri_case& c) { return {dvec3(c.o), dvec3(c.p0), dvec3(c.p1), dvec3(c.p2)}; }

// ------------------------------------------------------------------ 50-digit references

using mcrt::test::arvo_reference;
using mcrt::test::reference_solid_angle;

double reference_solid_angle(const tri_case& c) {
  return reference_solid_angle(dvec3(c.o), dvec3(c.p0), dvec3(c.p1), dvec3(c.p2));
}

// The map's accuracy (header comment): a point of the triangle is formed in
// double from offsets of the size of the triangle, so its direction is off
// by ~eps L / h at most, L the largest distance to a vertex, h the height:
// 16 eps (1 + L / h) rad is the bound the tests hold it to.
double map_tolerance(const tri_case& c) { return 16.0 * eps * (1.0 + max_distance(c) / height_of(c)); }

// ------------------------------------------------------------------ solid angle

TEST(SphericalTriangle, SolidAngleMatchesReference) {
  for (const tri_case& c : battery()) {
    const spherical_triangle st = set_up(c);
    ASSERT_TRUE(st.valid()) << c.name;
    const double ref = reference_solid_angle(c);
    // spherical_triangle's Omega: a few ulp everywhere (measured <= 4 ulp).
    EXPECT_NEAR(st.solid_angle() / ref, 1.0, 8.0 * eps) << c.name << ": " << st.solid_angle() << " vs " << ref;
    EXPECT_NEAR(2.0 * dpi - st.solid_angle(), 2.0 * dpi - ref, 8.0 * eps * 2.0 * dpi) << c.name;
    // The free Van Oosterom-Strackee function: a few ulp except where its
    // denominator cancels (two vertex directions nearly opposite), where the
    // error is bounded by ~eps |a||b||c| / |den + i num| (header comment).
    const dvec3 o(c.o), a = dvec3(c.p0) - o, b = dvec3(c.p1) - o, cc = dvec3(c.p2) - o;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(cc);
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, cc) * lb + glm::dot(b, cc) * la;
    const double num = std::abs(spherical_triangle_detail::orientation_triple(o, dvec3(c.p0), dvec3(c.p1), dvec3(c.p2)));
    const double condition = la * lb * lc / std::hypot(den, num);
    const double vos = triangle_solid_angle(o, dvec3(c.p0), dvec3(c.p1), dvec3(c.p2));
    EXPECT_NEAR(vos / ref, 1.0, 16.0 * eps * (1.0 + condition / (0.5 * ref))) << c.name;
    // The support's double reference (plain triple product): ~eps L / h.
    const double support = test::solid_angle_triangle(o, dvec3(c.p0), dvec3(c.p1), dvec3(c.p2));
    EXPECT_NEAR(support / ref, 1.0, 1e-8) << c.name;
  }
}

TEST(SphericalTriangle, BatteryCoversTheExtremes) {
  double s_min = 10.0, s_max = 0.0, h_min = 1.0, aspect_max = 0.0;
  for (const tri_case& c : battery()) {
    const double s = reference_solid_angle(c);
    s_min = std::min(s_min, s), s_max = std::max(s_max, s);
    h_min = std::min(h_min, height_of(c) / size_of(c));
    const double area = 0.5 * glm::length(glm::cross(dvec3(c.p1) - dvec3(c.p0), dvec3(c.p2) - dvec3(c.p0)));
    aspect_max = std::max(aspect_max, size_of(c) * size_of(c) / (2.0 * area));  // base / height
  }
  EXPECT_LE(s_min, 1e-8);
  EXPECT_GE(s_max, 2.0 * dpi - 1e-6);
  EXPECT_LT(s_max, 2.0 * dpi);
  EXPECT_LE(h_min, 1.01e-6);
  EXPECT_GE(aspect_max, 0.99e4);
}

// Random configurations over the extremes: sizes over 6 decades, slivers to
// aspect 1e5, observers 1e-7 .. 1e3 sizes from the plane, above the
// interior, near edges and vertices, and far outside. Omega to 16 ulp of the
// 50-digit reference everywhere, and 2 pi - Omega to 16 ulp of 2 pi.
TEST(SphericalTriangle, SolidAngleOverRandomExtremes) {
  pcg32 rng(404, 1);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  double worst = 0.0, worst_c = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double scale = std::pow(10.0, uni(-3.0, 3.0)), aspect = std::pow(10.0, uni(0.0, 5.0));
    const dvec3 rot(uni(-2.0, 2.0), uni(-2.0, 2.0), uni(-2.0, 2.0)), centre(uni(-5.0, 5.0), uni(-5.0, 5.0), uni(-5.0, 5.0));
    const double apex = uni(-0.5, 1.5);
    const dvec3 l0(-0.5, 0, 0), l1(0.5, 0, 0), l2(apex, 1.0 / aspect, 0);
    // The inputs of the sampler are floats: the vertices and the observer
    // are kept in float variables and widened where they are used.
    const auto place = [&](const dvec3& p) { return to_float(scale * (centre + rotate(p, rot))); };
    const vec3 f0 = place(l0), f1 = place(l1), f2 = place(l2);
    const dvec3 p0(f0), p1(f1), p2(f2);
    const dvec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    // Foot: inside, near an edge, near a vertex, or anywhere; height over 10 decades.
    const double w1 = uni(0.0, 1.0), w2 = uni(0.0, 1.0 - w1);
    dvec3 foot = (1.0 - w1 - w2) * p0 + w1 * p1 + w2 * p2;
    const int mode = k % 4;
    if (mode == 1) foot = p0 + uni(-0.1, 1.1) * (p1 - p0);
    if (mode == 2) foot = p2 + scale * 1e-5 * dvec3(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
    if (mode == 3) foot = scale * (centre + dvec3(uni(-3.0, 3.0), uni(-3.0, 3.0), uni(-3.0, 3.0)));
    const vec3 fo = to_float(foot + scale * std::pow(10.0, uni(-7.0, 3.0)) * n);
    const dvec3 o(fo);
    const spherical_triangle st(o, p0, p1, p2);
    if (!st.valid()) continue;
    const double ref = reference_solid_angle(o, p0, p1, p2);
    worst = std::max(worst, std::abs(st.solid_angle() / ref - 1.0));
    worst_c = std::max(worst_c, std::abs((2.0 * dpi - st.solid_angle()) - (2.0 * dpi - ref)) / (2.0 * dpi));
  }
  std::cout << "[ omega    ] worst relative error " << worst / eps << " ulp, of 2 pi - Omega " << worst_c / eps
            << " ulp of 2 pi\n";
  EXPECT_LE(worst, 16.0 * eps);
  EXPECT_LE(worst_c, 16.0 * eps);
}

// ------------------------------------------------------------------ the map

// The closed forms of the header against Arvo's formulas in 50 digits, for
// the same u: within map_tolerance (16 eps (1 + L/h) rad).
TEST(SphericalTriangle, MapMatchesArvoIn50Digits) {
  for (const tri_case& c : battery()) {
    const spherical_triangle st = set_up(c);
    pcg32 rng(7, 3);
    double worst = 0.0;
    for (int i = 0; i < 300; ++i) {
      const dvec2 u(rng.uniform_double(), rng.uniform_double());
      const dvec3 ref = arvo_reference(dvec3(c.o), dvec3(c.p0), dvec3(c.p1), dvec3(c.p2), u.x, u.y);
      worst = std::max(worst, glm::length(st.sample_direction(u) - ref));
    }
    EXPECT_LE(worst, map_tolerance(c)) << c.name;
  }
}

// The corners of the unit square go to the vertices: u1 = 0 is the edge
// from p1 to p0, (1, 1) is p2.
TEST(SphericalTriangle, CornersMapToVertices) {
  for (const tri_case& c : battery()) {
    const spherical_triangle st = set_up(c);
    const dvec3 o(c.o);
    // The map's accuracy (map_tolerance, in rad) times the distance.
    const double tol = map_tolerance(c) * max_distance(c);
    EXPECT_LE(glm::length(st.sample_offset({0.0, 0.0}) - (dvec3(c.p1) - o)), tol) << c.name;
    EXPECT_LE(glm::length(st.sample_offset({0.5, 0.0}) - (dvec3(c.p1) - o)), tol) << c.name;
    EXPECT_LE(glm::length(st.sample_offset({0.0, 1.0}) - (dvec3(c.p0) - o)), tol) << c.name;
    EXPECT_LE(glm::length(st.sample_offset({1.0, 1.0}) - (dvec3(c.p2) - o)), tol) << c.name;
  }
}

// ------------------------------------------------------------------ pdf

// Every sample's pdf equals pdf(o, s.dir) exactly (the same set-up), every
// sample's float direction hits the triangle (pdf > 0), and the pdf is
// 1 / Omega to the rounding of a float.
TEST(SphericalTriangle, PdfConsistency) {
  for (const tri_case& c : battery()) {
    const triangle_solid_angle_sampler smp{triangle_of(c)};
    ASSERT_TRUE(smp.faces(c.o)) << c.name;
    const double ref = reference_solid_angle(c);
    pcg32 rng(11, 3);
    for (int i = 0; i < 20'000; ++i) {
      light_sample s;
      ASSERT_TRUE(smp.sample(c.o, rng.uniform2(), s)) << c.name;
      ASSERT_EQ(smp.pdf(c.o, s.dir), s.pdf) << c.name << " sample " << i;
      ASSERT_NEAR(double(s.pdf) * ref, 1.0, 0x1p-23) << c.name;
      ASSERT_NEAR(glm::length(s.dir), 1.0f, 1e-6f) << c.name;
      // The distance is that of the hit along the float direction.
      const dvec3 x = dvec3(c.o) + double(s.dist) * dvec3(s.dir);
      const dvec3 n = glm::normalize(glm::cross(dvec3(c.p1) - dvec3(c.p0), dvec3(c.p2) - dvec3(c.p0)));
      ASSERT_LE(std::abs(glm::dot(x - dvec3(c.p0), n)), 1e-6 * (double(s.dist) + glm::length(dvec3(c.o)))) << c.name;
    }
  }
}

// E[1/pdf] = Omega (1/pdf is constant on the map) and E[cos/pdf] = the
// projected solid angle at a receiver facing the plane and at a tilted one
// that the horizon cuts (Lambert's formula, support/lambert.hpp, on the
// clipped polygon). N = 5 10^5, fixed seed; the sample standard error SE is
// computed, and the test requires 5 SE <= 0.5 % (so that a pass is
// informative and a correct sampler fails with probability < 1e-6) and the
// estimate within 0.5 % of the reference.
TEST(SphericalTriangle, ExpectedWeightsAreSolidAngleAndProjectedSolidAngle) {
  constexpr int n = 500'000;
  for (const tri_case& c : battery()) {
    const triangle_solid_angle_sampler smp{triangle_of(c)};
    const double ref = reference_solid_angle(c);
    const dvec3 o(c.o);
    const dvec3 toward = -dvec3(smp.n);  // from the front towards the plane
    const dvec3 centroid = (dvec3(c.p0) + dvec3(c.p1) + dvec3(c.p2)) / 3.0;
    const dvec3 tilted = glm::normalize(toward + 0.8 * glm::normalize(centroid - o) + dvec3(0.3, -0.2, 0.1));
    const std::vector<dvec3> poly = {dvec3(c.p0), dvec3(c.p1), dvec3(c.p2)};
    const dvec3 receivers[2] = {toward, tilted};
    pcg32 rng(21, 4);
    double w_sum = 0.0, sum[2] = {0.0, 0.0}, sum2[2] = {0.0, 0.0};
    for (int i = 0; i < n; ++i) {
      light_sample s;
      ASSERT_TRUE(smp.sample(c.o, rng.uniform2(), s)) << c.name;
      const double w = 1.0 / double(s.pdf);
      w_sum += w;
      for (int r = 0; r < 2; ++r) {
        const double f = std::max(0.0, glm::dot(dvec3(s.dir), receivers[r])) * w;
        sum[r] += f, sum2[r] += f * f;
      }
    }
    EXPECT_NEAR(w_sum / n / ref, 1.0, 0.005) << c.name;
    for (int r = 0; r < 2; ++r) {
      const double psa = test::clipped_polygon_irradiance(o, receivers[r], poly, 1.0);
      if (!(psa > 1e-3 * ref)) continue;  // the tilted receiver sees next to nothing of a grazing light
      const double mean = sum[r] / n, se = std::sqrt(std::max(sum2[r] / n - mean * mean, 0.0) / (n - 1));
      EXPECT_LE(5.0 * se, 0.005 * psa) << c.name << " receiver " << r << ": the test cannot resolve 0.5 %";
      EXPECT_NEAR(mean / psa, 1.0, 0.005) << c.name << " receiver " << r << ": E[cos/pdf] = " << mean
                                          << ", projected solid angle " << psa << ", SE " << se;
    }
  }
}

// ------------------------------------------------------------------ chi-square

class SphericalTriangleChi2 : public ::testing::TestWithParam<tri_case> {};

TEST_P(SphericalTriangleChi2, DirectionsMatchPdf) {
  const tri_case& c = GetParam();
  const triangle_solid_angle_sampler smp{triangle_of(c)};
  const spherical_triangle st = set_up(c);
  const auto sample = [&](pcg32& rng, vec3& d) {
    light_sample s;
    if (!smp.sample(c.o, rng.uniform2(), s)) return false;
    d = s.dir;
    return true;
  };
  // The density in double (grid directions keep their bits).
  const auto pdf = [&](const dvec3& d) {
    double t;
    return st.hits(d, t) ? st.pdf() : 0.0;
  };
  const dvec3 o(c.o), p[3] = {dvec3(c.p0), dvec3(c.p1), dvec3(c.p2)};
  const std::vector<dvec3> dirs = {glm::normalize(p[0] - o), glm::normalize(p[1] - o), glm::normalize(p[2] - o)};
  const dvec3 n = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
  const test::spherical_cap cap = test::detail::cap_of_planar_convex(o, (p[0] + p[1] + p[2]) / 3.0, n, p[0], dirs, 0.0);
  test::chi2_options opt;
  // 10^6 samples at the extremes of the solid angle, 5 10^5 elsewhere.
  opt.sample_count = c.name == "tiny_1e8" || c.name == "near_2pi" ? 1'000'000 : 500'000;
  opt.seed = 17;
  const test::chi2_result r = test::chi2_test_directions(sample, pdf, cap.axis, cap.one_minus_cos, opt);
  EXPECT_TRUE(r.passed) << c.name << " (Omega = " << st.solid_angle() << ")\n" << r.report;
}

std::vector<tri_case> chi2_battery() {
  std::vector<tri_case> v;
  for (tri_case& c : battery())
    if (direction_harness_resolves(c.name)) v.push_back(std::move(c));
  return v;
}

INSTANTIATE_TEST_SUITE_P(Battery, SphericalTriangleChi2, ::testing::ValuesIn(chi2_battery()),
                         [](const ::testing::TestParamInfo<tri_case>& info) { return info.param.name; });

// Chi-square on the triangle itself, for every case including the grazing
// slivers the direction harness cannot resolve: the triangle is cut into
// res^2 = 1024 congruent sub-triangles (the barycentric grid of step 1/32),
// the points of the map (spherical_triangle::sample_offset, in double: a
// float direction of a grazing view meets the plane up to ~6e-8 / sin(view
// angle) of the distance away, a good part of a cell) are binned by their
// barycentric coordinates, and a cell's probability is its solid angle over
// the triangle's (the 50-digit reference for both). The sampler's float
// directions are those of the map rounded (PdfConsistency, Fuzz) and go
// through the direction harness above where it resolves them. Cells
// expecting < 5 samples are pooled; p-value from test::chi2_survival at the
// harness's level.
TEST(SphericalTriangle, Chi2OnTheTriangle) {
  constexpr int res = 32;
  constexpr int n = 400'000;
  for (const tri_case& c : battery()) {
    const spherical_triangle st = set_up(c);
    const dvec3 o(c.o), p0(c.p0), e1 = dvec3(c.p1) - p0, e2 = dvec3(c.p2) - p0;
    const double total = reference_solid_angle(c);
    // Cell (i, j, up): barycentric (w1, w2) in the lower triangle (i, j),
    // (i + 1, j), (i, j + 1) or the upper (i + 1, j), (i + 1, j + 1),
    // (i, j + 1), in units of 1/res; index 2 (i res + j) + up.
    std::vector<double> expected(2 * res * res, 0.0), observed(2 * res * res, 0.0);
    double mass = 0.0;
    const auto vertex = [&](int i, int j) { return p0 + (double(i) / res) * e1 + (double(j) / res) * e2; };
    for (int i = 0; i < res; ++i)
      for (int j = 0; i + j < res; ++j) {
        const double lower = reference_solid_angle(o, vertex(i, j), vertex(i + 1, j), vertex(i, j + 1)) / total;
        expected[2 * (i * res + j)] = lower * n;
        mass += lower;
        if (i + j + 1 < res) {
          const double upper = reference_solid_angle(o, vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)) / total;
          expected[2 * (i * res + j) + 1] = upper * n;
          mass += upper;
        }
      }
    ASSERT_NEAR(mass, 1.0, 1e-12) << c.name;
    // Barycentric coordinates of a point by least squares in the plane.
    const double g11 = glm::dot(e1, e1), g12 = glm::dot(e1, e2), g22 = glm::dot(e2, e2), det = g11 * g22 - g12 * g12;
    pcg32 rng(29, 5);
    for (int k = 0; k < n; ++k) {
      const dvec3 q = (o - p0) + st.sample_offset({rng.uniform_double(), rng.uniform_double()});
      const double r1 = glm::dot(q, e1), r2 = glm::dot(q, e2);
      const double w1 = std::clamp((g22 * r1 - g12 * r2) / det, 0.0, 1.0) * res;
      const double w2 = std::clamp((g11 * r2 - g12 * r1) / det, 0.0, 1.0) * res;
      int i = std::min(int(w1), res - 1), j = std::min(int(w2), res - 1);
      if (i + j > res - 1) j = res - 1 - i;  // rounding just outside the hypotenuse
      const int up = (w1 - i) + (w2 - j) > 1.0 && i + j + 1 < res ? 1 : 0;
      observed[2 * (i * res + j) + up] += 1.0;
    }
    std::vector<int> order;
    for (int k = 0; k < 2 * res * res; ++k)
      if (expected[k] > 0.0 || observed[k] > 0.0) order.push_back(k);
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
    if (pe > 0.0) stat += (po - pe) * (po - pe) / pe;
    ASSERT_FALSE(po > 0.0 && !(pe > 0.0)) << c.name << ": samples in cells of probability 0";
    // Seen from just above its interior (near_2pi, grazing_inside) a light
    // puts almost all of its solid angle into the cells around the foot:
    // too few bins to test here; the direction harness covers near_2pi.
    if (bins < 8) continue;
    const double pval = test::chi2_survival(stat, bins - 1);
    EXPECT_GE(pval, test::chi2_per_test_significance()) << c.name << ": chi2 = " << stat << ", dof " << bins - 1;
  }
}

// ------------------------------------------------------------------ round trips

// u -> offset -> inverse -> u, in double, within 1e-12 + 1e-15 L / h (the
// map's accuracy, map_tolerance, over the derivative of the direction by
// u, ~ the triangle's angular size); dir -> u -> dir within map_tolerance
// for directions to random points of the triangle.
TEST(SphericalTriangle, RoundTrips) {
  for (const tri_case& c : battery()) {
    const spherical_triangle st = set_up(c);
    const dvec3 o(c.o), p0(c.p0), p1(c.p1), p2(c.p2);
    pcg32 rng(3, 8);
    double worst_u = 0.0, worst_d = 0.0;
    for (int i = 0; i < 20'000; ++i) {
      const dvec2 u(rng.uniform_double(), rng.uniform_double());
      const dvec2 w = st.invert_offset(st.sample_offset(u));
      worst_u = std::max({worst_u, std::abs(w.x - u.x), std::abs(w.y - u.y)});
      const double b1 = rng.uniform_double(), b2 = rng.uniform_double();
      const double s = std::sqrt(b1);
      const dvec3 d = glm::normalize((1.0 - s) * (p0 - o) + s * (1.0 - b2) * (p1 - o) + s * b2 * (p2 - o));
      worst_d = std::max(worst_d, glm::length(st.sample_direction(st.invert_offset(d)) - d));
    }
    EXPECT_LE(worst_u, 1e-12 + 1e-15 * max_distance(c) / height_of(c)) << c.name;
    EXPECT_LE(worst_d, map_tolerance(c)) << c.name;
  }
  // Through the float API: sampler.inverse(o, s.dir) recovers u to the
  // float rounding of the direction over moderate cases.
  for (const tri_case& c : battery()) {
    if (c.name != "overhead" && c.name != "rotated" && c.name != "cornell_half" && c.name != "sliver_overhead") continue;
    const triangle_solid_angle_sampler smp{triangle_of(c)};
    pcg32 rng(4, 1);
    for (int i = 0; i < 10'000; ++i) {
      const vec2 u = rng.uniform2();
      light_sample s;
      ASSERT_TRUE(smp.sample(c.o, u, s));
      const vec2 w = smp.inverse(c.o, s.dir);
      EXPECT_NEAR(w.x, u.x, 1e-3) << c.name;
      EXPECT_NEAR(w.y, u.y, 1e-3) << c.name;
    }
  }
}

// ------------------------------------------------------------------ one-sided

TEST(SphericalTriangle, BehindOrInThePlaneGetsNothing) {
  pcg32 rng(2, 2);
  const vec3 a(-1, -2, 3), b(1, -2, 3), d(0.3f, 2, 3);  // in the plane z = 3
  for (const bool reverse : {false, true}) {
    const triangle t{mesh_of(a, b, d, reverse), 0};
    const triangle_solid_angle_sampler smp{t};
    const triangle_area_sampler area{t};
    const vec3 n = t.normal(), c = (a + b + d) / 3.0f;
    for (int i = 0; i < 2000; ++i) {
      const vec3 in_plane(4.0f * rng.uniform() - 2.0f, 6.0f * rng.uniform() - 3.0f, 3.0f);  // exactly z = 3
      const vec3 behind = in_plane - (1e-3f + 10.0f * rng.uniform()) * n;
      for (const vec3& o : {in_plane, behind}) {
        EXPECT_FALSE(smp.faces(o));
        light_sample s;
        EXPECT_FALSE(smp.sample(o, rng.uniform2(), s));
        EXPECT_EQ(smp.pdf(o, glm::normalize(c - o)), 0.0f);
        EXPECT_EQ(smp.pdf(o, -glm::normalize(c - o)), 0.0f);
        EXPECT_EQ(smp.faces(o), area.faces(o));
      }
      // In front: a sample, and pdf 0 for a direction away from the light.
      const vec3 front = in_plane + (1e-3f + rng.uniform()) * n;
      EXPECT_TRUE(smp.faces(front));
      EXPECT_EQ(smp.faces(front), area.faces(front));
      light_sample s;
      EXPECT_TRUE(smp.sample(front, rng.uniform2(), s));
      EXPECT_EQ(smp.pdf(front, n), 0.0f);
    }
  }
  // Shading normals decide the front as for triangle::normal().
  auto m = mesh_of(a, b, d, false);
  m->n = {vec3(0, 0, -1), vec3(0, 0.1f, -1), vec3(0.1f, 0, -1)};
  const triangle_solid_angle_sampler smp{triangle{m, 0}};
  EXPECT_TRUE(smp.faces({0, 0, 2}));
  EXPECT_FALSE(smp.faces({0, 0, 4}));
}

// A reversed mesh is the same light seen from the other side, with the same
// solid angle for mirror observers.
TEST(SphericalTriangle, ReverseOrientationSwapsTheFacingSide) {
  const vec3 a(-1, -2, 3), b(1, -2, 3), d(0.3f, 2, 3);
  const triangle_solid_angle_sampler front{triangle{mesh_of(a, b, d, false), 0}};
  const triangle_solid_angle_sampler back{triangle{mesh_of(a, b, d, true), 0}};
  const vec3 above(0.2f, 0.1f, 4.5f), below(0.2f, 0.1f, 1.5f);
  EXPECT_TRUE(front.faces(above));
  EXPECT_FALSE(front.faces(below));
  EXPECT_TRUE(back.faces(below));
  EXPECT_FALSE(back.faces(above));
  light_sample s1, s2;
  ASSERT_TRUE(front.sample(above, {0.3f, 0.6f}, s1));
  ASSERT_TRUE(back.sample(below, {0.3f, 0.6f}, s2));
  EXPECT_EQ(s1.pdf, s2.pdf);
  EXPECT_NEAR(s1.dir.z, -s2.dir.z, 1e-6f);
}

// ------------------------------------------------------------------ fuzz

// 10^6 configurations: sizes over 8 decades (1e-4 .. 1e4), slivers to
// aspect 1e4 with the apex anywhere along the base (also obtuse), random
// orientation, either side emitting; observers anywhere around (1e-3 .. 1e3
// sizes away), within 1e-6 .. 1e-1 (relative) of the plane on either side
// (above the interior, near edges, near vertices, outside), exactly in the
// plane (axis-aligned triangles), or behind. Asserted: no NaN / Inf; a
// returned sample has a unit direction, a positive finite distance and the
// pdf 1 / Omega; its float direction hits the triangle (the double test of
// pdf(); where the triangle is less than 2^-21 rad wide, no float direction
// may hit it, and those are counted); no sample and pdf 0 behind or in the
// plane. The misses of the renderer's float intersect_triangle are counted
// and reported, not asserted.
TEST(SphericalTriangle, Fuzz) {
  constexpr int configs = 1'000'000;
  pcg32 rng(2024, 7);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  long samples = 0, none = 0, float_misses = 0, float_misses_unresolved = 0, resolved_samples = 0, unresolved = 0;
  bool first_miss_reported = false;
  for (int k = 0; k < configs; ++k) {
    const double scale = std::pow(10.0, uni(-4.0, 4.0));
    const double aspect = std::pow(10.0, uni(0.0, 4.0));
    const double apex = uni(-1.0, 2.0);
    const dvec3 centre(uni(-10.0, 10.0), uni(-10.0, 10.0), uni(-10.0, 10.0));
    const bool aligned = rng.uniform() < 0.25f;
    dvec3 l[3] = {{-0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}, {apex - 0.5, 1.0 / aspect, 0.0}};
    if (rng.uniform() < 0.5f) std::swap(l[0], l[1]);  // either winding
    const int first = int(rng.next_u32() % 3);         // any vertex first
    const dvec3 rot = aligned ? dvec3(0.0, 0.0, 1e-300) : dvec3(uni(-2.0, 2.0), uni(-2.0, 2.0), uni(-2.0, 2.0));
    vec3 p[3];
    for (int i = 0; i < 3; ++i) {
      const dvec3 v = aligned ? l[(first + i) % 3] : rotate(l[(first + i) % 3], rot);
      p[i] = to_float(scale * (centre + v));
    }
    const bool reverse = rng.uniform() < 0.5f;
    const triangle t{mesh_of(p[0], p[1], p[2], reverse), 0};
    const dvec3 d0(p[0]), d1(p[1]), d2(p[2]);
    const dvec3 wn = glm::cross(d1 - d0, d2 - d0);
    if (!(glm::length(wn) > 0.0) || !std::isfinite(glm::length(wn))) continue;  // rounded to a segment
    const vec3 n = t.normal();
    const dvec3 un = glm::normalize(wn) * (glm::dot(wn, dvec3(n)) > 0.0 ? 1.0 : -1.0);  // front, in double
    const double size = std::max({glm::length(d1 - d0), glm::length(d2 - d1), glm::length(d0 - d2)});
    const float mode = rng.uniform();
    dvec3 o;
    bool must_fail = false;
    if (mode < 0.35f) {  // anywhere around it
      dvec3 dir(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
      dir = glm::length(dir) > 1e-6 ? glm::normalize(dir) : un;
      o = (d0 + d1 + d2) / 3.0 + size * std::pow(10.0, uni(-3.0, 3.0)) * dir;
    } else if (mode < 0.75f) {  // near the plane, either side, over the interior, near edges or vertices, or outside
      const double h = (rng.uniform() < 0.5f ? -1.0 : 1.0) * size * std::pow(10.0, uni(-6.0, -1.0));
      const double w1 = uni(0.0, 1.0), w2 = uni(0.0, 1.0 - w1);
      dvec3 foot = (1.0 - w1 - w2) * d0 + w1 * d1 + w2 * d2;
      const int where = int(rng.next_u32() % 4);
      if (where == 1) foot = d0 + uni(-0.1, 1.1) * (d1 - d0) + size * uni(-1e-6, 1e-6) * glm::normalize(d2 - d0);
      if (where == 2) foot = d2 + size * uni(-1e-5, 1e-5) * glm::normalize(d1 - d0);
      if (where == 3) foot = d0 + uni(-3.0, 3.0) * (d1 - d0) + uni(-3.0, 3.0) * (d2 - d0);
      o = foot + h * un;
    } else if (mode < 0.85f && aligned) {  // exactly in the plane
      o = d0 + uni(-1.0, 2.0) * (d1 - d0) + uni(-1.0, 2.0) * (d2 - d0);
      o.z = d0.z;
      must_fail = true;
    } else {  // behind
      o = (d0 + d1 + d2) / 3.0 - size * std::pow(10.0, uni(-3.0, 3.0)) * un + size * uni(-2.0, 2.0) * glm::normalize(d1 - d0);
    }
    const vec3 of = to_float(o);
    // Whether the float observer is behind (or in the plane), exactly.
    const double side = glm::dot(dvec3(of) - d0, wn) * (glm::dot(wn, dvec3(n)) > 0.0 ? 1.0 : -1.0);
    if (side <= 0.0) must_fail = true;
    const triangle_solid_angle_sampler smp{t};
    const vec2 u = (k % 64 == 0) ? vec2(0.0f) : (k % 64 == 1) ? vec2(0x1.fffffep-1f) : rng.uniform2();
    light_sample s;
    const bool ok = smp.sample(of, u, s);
    const vec3 to_centre = glm::normalize(vec3((d0 + d1 + d2) / 3.0) - of);
    if (!ok) {
      ++none;
      ASSERT_TRUE(must_fail) << k << ": no sample for an observer in front";
      ASSERT_FALSE(smp.faces(of)) << k;
      ASSERT_EQ(smp.pdf(of, to_centre), 0.0f) << k;
      continue;
    }
    ASSERT_FALSE(must_fail) << k << ": a sample for an observer behind or in the plane";
    ++samples;
    ASSERT_TRUE(all_finite(s.dir) && std::isfinite(s.dist) && std::isfinite(s.pdf)) << k;
    ASSERT_NEAR(glm::length(s.dir), 1.0f, 1e-6f) << k;
    ASSERT_GT(s.dist, 0.0f) << k;
    ASSERT_GT(s.pdf, 0.0f) << k;
    const double omega = spherical_triangle(dvec3(of), d0, d1, d2).solid_angle();
    ASSERT_EQ(s.pdf, float(1.0 / omega)) << k;
    const float pd = smp.pdf(of, s.dir);
    if (pd != s.pdf) {
      // The float direction misses in the double test: allowed only where no
      // float direction resolves the triangle (sample() tried to move it in).
      ++unresolved;
      ASSERT_EQ(pd, 0.0f) << k;
      // The triangle's angular width across its longest side (2 Omega /
      // that side's angle) below 2^-21 rad, 8 float roundings of a direction.
      const dvec3 oo(of), u0 = glm::normalize(d0 - oo), u1 = glm::normalize(d1 - oo), u2 = glm::normalize(d2 - oo);
      const auto angle = [](const dvec3& x, const dvec3& y) { return 2.0 * std::asin(std::min(1.0, 0.5 * glm::length(x - y))); };
      const double width = 2.0 * omega / std::max({angle(u0, u1), angle(u1, u2), angle(u2, u0)});
      ASSERT_LT(width, 0x1p-21) << k << ": a float direction that misses a light of " << omega << " sr, " << width
                                << " rad wide";
      continue;
    }
    // The renderer's watertight float test, for information only (the
    // sampler's contract is the double test above): its misses are counted
    // separately where float arithmetic should resolve the triangle (a view
    // at least 0.1 rad above the plane, a triangle at least 2^-12 rad wide,
    // a hit farther than 1e-2 of the coordinates' magnitude) and elsewhere.
    {
      const dvec3 oo(of), u0 = glm::normalize(d0 - oo), u1 = glm::normalize(d1 - oo), u2 = glm::normalize(d2 - oo);
      const auto angle = [](const dvec3& x, const dvec3& y) { return 2.0 * std::asin(std::min(1.0, 0.5 * glm::length(x - y))); };
      const double width = 2.0 * omega / std::max({angle(u0, u1), angle(u1, u2), angle(u2, u0)});
      const double sin_view = std::abs(glm::dot(dvec3(s.dir), un));
      const double coord = std::max({glm::length(d0), glm::length(d1), glm::length(d2), glm::length(oo)});
      const bool resolved = width > 0x1p-12 && sin_view > 0.1 && double(s.dist) > 1e-2 * coord;
      if (!intersect_triangle({of, s.dir}, infinity, p[0], p[1], p[2])) {
        ++(resolved ? float_misses : float_misses_unresolved);
        if (resolved && !first_miss_reported) {
          first_miss_reported = true;
          std::cout << "[ fuzz     ] first intersect_triangle miss of a resolved sample: configuration " << k
                    << ", distance " << s.dist << ", coordinates up to " << coord << ", sin(view) " << sin_view
                    << ", width " << width << " rad\n";
        }
      }
      resolved_samples += resolved;
    }
  }
  std::cout << "[ fuzz     ] " << configs << " configurations: " << samples << " samples, " << none
            << " without (all behind or in the plane); " << unresolved
            << " float directions that cannot resolve the triangle (< 2^-21 rad wide); misses of the float "
            << "intersect_triangle where the double test hits: " << float_misses << " of " << resolved_samples
            << " resolved samples, " << float_misses_unresolved << " of the others\n";
  // About 37 % of the observers face the light (half of the random and
  // near-plane ones).
  EXPECT_GT(samples, configs * 35 / 100);
  EXPECT_GT(resolved_samples, samples / 10);
}

}  // namespace
