// Tests of exact projected-solid-angle sampling of a triangle light
// (sampling/projected_triangle.hpp, after Peters 2021): the closed form
// against Lambert's polygon formula on the horizon-clipped triangle in
// long double and in 50 digits (an independent path, in world space), pdf
// consistency, E[cos/pdf] = Omega_proj and E[1/pdf] = Omega, chi-square of
// the directions (on the bounding cap, and on the light itself for the
// slivers), the round trip through the inverse, the zero variance of
// cos/pdf, no sample where nothing is visible, and a
// fuzz of 5 * 10^5 configurations.
//
// Every random test uses a fixed seed. The chi-square tests run at the
// per-test level 1 - 0.99^(1/256) ~= 3.9e-5 (support/chi2.hpp: the suite's
// family-wise level 1 % over at most 256 chi-square tests); this file has
// 13 of them. Other statistical bounds are stated where they are used.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#if __has_include(<boost/multiprecision/cpp_bin_float.hpp>)
#include <boost/multiprecision/cpp_bin_float.hpp>
#define MCRT_TEST_MP 1
#endif

#include "mcrt/core/rng.hpp"
#include "mcrt/render/light.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"
#include "mcrt/sampling/projected_triangle.hpp"
#include "support/chi2.hpp"
#include "support/lambert.hpp"
#include "support/solid_angle.hpp"

namespace {

using namespace mcrt;

constexpr double dpi = std::numbers::pi;

static_assert(normal_aware_strategy<triangle_projected_solid_angle_sampler>);

// ------------------------------------------------------------------ cases

triangle make_triangle(const vec3& a, const vec3& b, const vec3& c, bool reverse = false) {
  auto mesh = std::make_shared<triangle_mesh>();
  mesh->p = {a, b, c};
  mesh->indices = {0, 1, 2};
  mesh->reverse_orientation = reverse;
  return {mesh, 0};
}
triangle make_triangle(const dvec3& a, const dvec3& b, const dvec3& c, bool reverse = false) {
  return make_triangle(vec3(a), vec3(b), vec3(c), reverse);
}

vec3 unit(double x, double y, double z) { return vec3(glm::normalize(dvec3(x, y, z))); }

struct psa_case {
  std::string name;
  triangle shape;
  vec3 o;
  vec3 n;  // receiver's unit normal
};

std::array<dvec3, 3> vertices(const triangle& t) {
  return {dvec3(t.vertex(0)), dvec3(t.vertex(1)), dvec3(t.vertex(2))};
}

// The "band" triangle: edge x = 0.5 (y in [-0.5, 0.5]) and apex (-0.5, 0)
// at z = 0, front +z. Seen from (0, 0, 1) by a receiver whose horizon
// crosses the plane z = 0 at x = 0.5 - delta, only a band of width delta
// along the edge x = 0.5 is visible.
triangle band_triangle() { return make_triangle(vec3(0.5f, -0.5f, 0.0f), vec3(0.5f, 0.5f, 0.0f), vec3(-0.5f, 0.0f, 0.0f)); }

// Rotation by the rotation vector rot (axis times angle, Rodrigues).
dvec3 rotate(const dvec3& v, const dvec3& rot) {
  const double angle = glm::length(rot);
  const dvec3 k = rot / angle;
  return v * std::cos(angle) + glm::cross(k, v) * std::sin(angle) + k * glm::dot(k, v) * (1.0 - std::cos(angle));
}

// Whole lights (central and decentral), clipped ones (3 and 4 visible
// vertices), ~1e-8, 1e-12 and 1e-14 sr (the last on the area fallback), a
// small light clipped by a horizon within 0.03 degrees of it (on the area
// fallback, 4 vertices),
// near 2 pi (observer 1e-7 above a large triangle), an observer 2e-6 from
// the light's plane, thin slivers above a grazing horizon (1e-3, 1e-5 and
// 5e-2 of the width visible), aspect 1e4 (clipped), rotated with a
// reversed orientation.
std::vector<psa_case> psa_battery() {
  const triangle floor_tri = make_triangle(vec3(-1.0f, -1.0f, 1.0f), vec3(0.0f, 1.5f, 1.0f), vec3(1.2f, -0.8f, 1.0f));
  const triangle unit_tri = make_triangle(vec3(-0.5f, -0.4f, 0.0f), vec3(0.6f, -0.3f, 0.0f), vec3(-0.1f, 0.5f, 0.0f));
  const triangle big = make_triangle(vec3(-2.0f, -2.0f, 0.0f), vec3(2.0f, -1.5f, 0.0f), vec3(0.1f, 2.0f, 0.0f));
  const triangle strip = make_triangle(vec3(-5000.0f, -0.5f, 0.0f), vec3(5000.0f, -0.5f, 0.0f), vec3(100.0f, 0.5f, 0.0f));
  const dvec3 rot(-1.1, 0.2, 0.9), ctr(-1.0, 2.0, 0.25);
  const dvec3 ra = ctr + rotate({-0.3, -1.5, 0.0}, rot), rb = ctr + rotate({0.4, -1.0, 0.0}, rot),
              rc = ctr + rotate({0.1, 1.6, 0.0}, rot);
  const triangle rev = make_triangle(ra, rb, rc, true);
  const dvec3 rn(rev.normal());
  const vec3 rev_o = vec3(ctr + 0.7 * rn + 0.2 * rotate({0.0, 1.0, 0.0}, rot));
  const vec3 rev_n = vec3(glm::normalize(-rn + 0.9 * rotate({1.0, 0.0, 0.0}, rot)));
  const triangle band = band_triangle();
  return {
      {"floor", floor_tri, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}},
      {"oblique", unit_tri, {6.0f, -5.0f, 7.0f}, unit(-0.3, 0.8, -1.0)},
      {"clip_triangle", unit_tri, {0.2f, 0.1f, 1.0f}, unit(1.0, 0.4, -0.1)},
      {"clip_quad", unit_tri, {0.2f, 0.1f, 1.0f}, unit(1.0, 1.0, -0.3)},
      {"tiny_1e8", unit_tri, {0.1f, 0.2f, 5e3f}, unit(0.3, -0.2, -1.0)},
      {"tiny_1e12", unit_tri, {0.1f, 0.2f, 5e5f}, unit(0.3, -0.2, -1.0)},
      {"tiny_1e14", unit_tri, {0.1f, 0.2f, 5e6f}, unit(0.3, -0.2, -1.0)},
      {"grazing_clip", unit_tri, {0.1f, 0.2f, 1e3f}, unit(1.0, 0.0, -4e-4)},
      {"near_2pi", big, {0.1f, -0.2f, 1e-7f}, {0.0f, 0.0f, -1.0f}},
      {"near_2pi_tilted", big, {0.1f, -0.2f, 1e-7f}, unit(0.5, 0.2, -1.0)},
      {"aspect_clip", strip, {0.0f, 0.0f, 1.0f}, unit(0.3, 0.2, -1.0)},
      {"reversed", rev, rev_o, rev_n},
      {"plane_1e6", band, {0.9f, 0.05f, 2e-6f}, unit(-1.0, 1.5, 0.0)},
      {"sliver_1e3", band, {0.0f, 0.0f, 1.0f}, unit(1.0, 0.0, 0.499)},
      {"sliver_1e5", band, {0.0f, 0.0f, 1.0f}, unit(1.0, 0.0, 0.49999)},
      {"sliver_5e2", band, {0.0f, 0.0f, 1.0f}, unit(1.0, 0.0, 0.45)},
  };
}

psa_case find_case(const std::string& name) {
  for (psa_case& c : psa_battery())
    if (c.name == name) return c;
  ADD_FAILURE() << "no case " << name;
  return {};
}

// ------------------------------------------------------------------ references

// Lambert's formula (Arvo 1995, eq. 2) on the triangle clipped at the
// horizon n . (p - o) > 0, in world space and in the arithmetic T: the
// float vertices, o and n converted exactly, n normalised in T. Shares no
// code with the sampler (which works in the light's frame in double).
template <class T>
T lambert_clipped(const std::array<dvec3, 3>& p, const vec3& o, const vec3& n) {
  using std::atan2, std::sqrt, std::abs;
  struct v3 {
    T x, y, z;
  };
  const auto sub = [](const v3& a, const v3& b) { return v3{a.x - b.x, a.y - b.y, a.z - b.z}; };
  const auto add = [](const v3& a, const v3& b) { return v3{a.x + b.x, a.y + b.y, a.z + b.z}; };
  const auto mul = [](const T& k, const v3& a) { return v3{k * a.x, k * a.y, k * a.z}; };
  const auto dot = [](const v3& a, const v3& b) { return T(a.x * b.x + a.y * b.y + a.z * b.z); };
  const auto cross = [](const v3& a, const v3& b) {
    return v3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  const auto V = [](const dvec3& a) { return v3{T(a.x), T(a.y), T(a.z)}; };
  const v3 oo = V(dvec3(o));
  v3 nn = V(dvec3(n));
  nn = mul(T(1) / sqrt(dot(nn, nn)), nn);
  const v3 q[3] = {sub(V(p[0]), oo), sub(V(p[1]), oo), sub(V(p[2]), oo)};
  std::vector<v3> c;
  for (int i = 0; i < 3; ++i) {
    const v3 a = q[i], b = q[(i + 1) % 3];
    const T za = dot(a, nn), zb = dot(b, nn);
    if (za > 0) c.push_back(a);
    if ((za > 0) != (zb > 0)) c.push_back(add(a, mul(za / (za - zb), sub(b, a))));
  }
  if (c.size() < 3) return T(0);
  T sum = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const v3 cr = cross(c[i], c[(i + 1) % c.size()]);
    const T sl = sqrt(dot(cr, cr));
    sum += atan2(sl, dot(c[i], c[(i + 1) % c.size()])) * dot(nn, cr) / sl;
  }
  return abs(sum) / 2;
}

// The reference Omega_proj: 50 significant digits where Boost.Multiprecision
// is available (needed for the slivers above a grazing horizon, where the
// terms are O(1) and the sum ~1e-11), else long double.
double reference_psa(const triangle& t, const vec3& o, const vec3& n) {
#ifdef MCRT_TEST_MP
  return static_cast<double>(lambert_clipped<boost::multiprecision::cpp_bin_float_50>(vertices(t), o, n));
#else
  return static_cast<double>(lambert_clipped<long double>(vertices(t), o, n));
#endif
}

// The clipped polygon in double (world space).
std::vector<dvec3> clipped_polygon(const triangle& t, const vec3& o, const vec3& n) {
  const std::array<dvec3, 3> p = vertices(t);
  return test::clip_to_horizon(dvec3(o), glm::normalize(dvec3(n)), {p[0], p[1], p[2]});
}

// Solid angle of the visible part: a fan of Van Oosterom-Strackee triangles
// (support/solid_angle.hpp) over the clipped polygon.
double visible_solid_angle(const triangle& t, const vec3& o, const vec3& n) {
  const std::vector<dvec3> q = clipped_polygon(t, o, n);
  double s = 0.0;
  for (std::size_t k = 1; k + 1 < q.size(); ++k) s += test::solid_angle_triangle(dvec3(o), q[0], q[k], q[k + 1]);
  return s;
}

// Whether the horizon of n at o cuts the triangle (some vertex at or below
// it, some above).
bool straddles(const triangle& t, const vec3& o, const vec3& n) {
  int above = 0;
  for (const dvec3& v : vertices(t)) above += glm::dot(v - dvec3(o), dvec3(n)) > 0.0;
  return above == 1 || above == 2;
}

double polygon_area(const std::vector<dvec3>& q) {
  dvec3 a(0.0);
  for (std::size_t i = 1; i + 1 < q.size(); ++i) a += glm::cross(q[i] - q[0], q[i + 1] - q[0]);
  return 0.5 * glm::length(a);
}

projected_triangle make_pt(const psa_case& c, bool with_map = false) {
  return projected_triangle(projected_triangle_detail::make_triangle_frame(c.shape), c.o, c.n, with_map);
}
projected_triangle::method psa_method(const psa_case& c) { return make_pt(c).how(); }

// Ray o + t d against the triangle, in double on its world-space vertices
// (Moller-Trumbore), front side only; t the distance.
bool hit_triangle(const std::array<dvec3, 3>& p, const dvec3& front, const dvec3& o, const dvec3& d, double& t) {
  if (!(glm::dot(d, front) < 0.0) || !(glm::dot(o - p[0], front) > 0.0)) return false;
  const dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0], pv = glm::cross(d, e2);
  const double det = glm::dot(e1, pv);
  const dvec3 tv = o - p[0];
  const double u = glm::dot(tv, pv) / det;
  const dvec3 qv = glm::cross(tv, e1);
  const double v = glm::dot(d, qv) / det;
  t = glm::dot(e2, qv) / det;
  return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0;
}

// The density of the sampler, independently: cos / Omega_proj (Lambert)
// on the map, t^3 / (h A_visible) on its area fallback, 0 where the ray
// misses or runs below the horizon. Per unit solid angle, in double.
struct psa_reference {
  std::array<dvec3, 3> p;
  dvec3 front, o, n;
  double omega, area, h;
  bool map;
  explicit psa_reference(const psa_case& c)
      : p(vertices(c.shape)), front(c.shape.normal()), o(c.o), n(glm::normalize(dvec3(c.n))),
        omega(reference_psa(c.shape, c.o, c.n)), area(polygon_area(clipped_polygon(c.shape, c.o, c.n))),
        map(psa_method(c) == projected_triangle::method::map) {
    const dvec3 ng = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    front = glm::dot(ng, front) > 0.0 ? ng : -ng;
    h = glm::dot(o - p[0], front);
  }
  double operator()(const dvec3& d) const {
    double t;
    if (!hit_triangle(p, front, o, d, t)) return 0.0;
    const double cs = glm::dot(d, n);
    if (!(cs > 0.0)) return 0.0;
    return map ? cs / omega : t * t * t / (h * area);
  }
};

test::spherical_cap bounding_cap(const psa_case& c) {
  const std::array<dvec3, 3> p = vertices(c.shape);
  const dvec3 o(c.o);
  std::vector<dvec3> dirs;
  for (const dvec3& v : p) dirs.push_back(glm::normalize(v - o));
  return test::detail::cap_of_planar_convex(o, (p[0] + p[1] + p[2]) / 3.0, dvec3(c.shape.normal()), p[0], dirs, 0.0);
}

// ------------------------------------------------------------------ Omega_proj

// The battery covers what it claims, and the closed form the map is
// normalised by equals Lambert's formula in 50 digits to 1e-9 (the
// sampler's bound, projected_polygon.hpp); to 1e-9 also against Lambert in
// long double on all but the slivers above a grazing horizon (where it
// cancels), and in double where its condition number is at most 1e4.
TEST(TriangleProjectedSolidAngle, BatteryAgainstLambert) {
  double s_min = 10.0, s_max = 0.0;
  int double_checked = 0;
  int clipped[5] = {0, 0, 0, 0, 0}, whole = 0, map = 0, area = 0, complement = 0, chord = 0;
  for (const psa_case& c : psa_battery()) {
    const projected_triangle pt = make_pt(c);
    ASSERT_TRUE(pt.valid()) << c.name;
    if (straddles(c.shape, c.o, c.n))
      ++clipped[std::clamp(pt.vertex_count(), 0, 4)];
    else
      ++whole;
    (pt.how() == projected_triangle::method::map ? map : area) += 1;
    complement += pt.how() == projected_triangle::method::map && pt.complement();
    chord += pt.how() == projected_triangle::method::map && !pt.complement() &&
             pt.condition_lambert() > projected_triangle::direct_condition;
    const double s = visible_solid_angle(c.shape, c.o, c.n);
    s_min = std::min(s_min, s);
    s_max = std::max(s_max, s);
    const double ref = reference_psa(c.shape, c.o, c.n);
    const triangle_projected_solid_angle_sampler smp{c.shape};
    if (pt.how() == projected_triangle::method::map) {
      EXPECT_NEAR(smp.projected_solid_angle(c.o, c.n) / ref, 1.0, 1e-9) << c.name;
      // long double on the same independent path; and in double by
      // support/lambert.hpp where Lambert's sum is well conditioned (K <= 1e4:
      // its rounding below 1e-11 relative).
      if (c.name.rfind("sliver", 0) != 0) {
        const double ld = double(lambert_clipped<long double>(vertices(c.shape), c.o, c.n));
        EXPECT_NEAR(smp.projected_solid_angle(c.o, c.n) / ld, 1.0, 1e-9) << c.name;
      }
      if (pt.condition_lambert() <= 1e4) {
        const std::array<dvec3, 3> p = vertices(c.shape);
        const double d = test::clipped_polygon_irradiance(dvec3(c.o), glm::normalize(dvec3(c.n)), {p[0], p[1], p[2]}, 1.0);
        EXPECT_NEAR(smp.projected_solid_angle(c.o, c.n) / d, 1.0, 1e-9) << c.name;
        ++double_checked;
      }
    } else {
      EXPECT_EQ(smp.projected_solid_angle(c.o, c.n), 0.0) << c.name;
    }
    std::cout << "[ battery  ] " << c.name << ": " << pt.vertex_count() << " vertices, "
              << (pt.how() == projected_triangle::method::map ? (pt.complement() ? "map (Z)" : "map") : "area")
              << ", K_L " << pt.condition_lambert() << ", Omega_proj " << ref << ", Omega " << s << "\n";
  }
  EXPECT_LE(s_min, 1e-13);
  EXPECT_GE(s_max, 2.0 * dpi - 1e-4);
  EXPECT_GT(clipped[3], 0);
  EXPECT_GT(clipped[4], 0);
  EXPECT_GT(whole, 0);
  EXPECT_GT(map, 0);
  EXPECT_EQ(area, 2);  // tiny_1e14, grazing_clip
  EXPECT_EQ(psa_method(find_case("tiny_1e14")), projected_triangle::method::area);
  EXPECT_EQ(psa_method(find_case("grazing_clip")), projected_triangle::method::area);
  EXPECT_EQ(make_pt(find_case("grazing_clip")).vertex_count(), 4);
  EXPECT_GE(complement, 2);  // sliver_1e3, sliver_1e5
  EXPECT_GT(chord, 0);       // tiny_1e12 at least
  EXPECT_GE(double_checked, 9);
}

// Random triangles and receivers, including straddling and grazing
// horizons, tiny triangles (sizes down to 1e-5 of the distance) and slivers
// (aspect up to 1e4): where the sampler uses its map, Omega_proj equals
// Lambert's formula in 50 digits (long double without Boost) to 1e-9. The
// area fallback is taken only where the rule of projected_rectangle.hpp
// says so: neither Lambert's form nor the complement form (Z) has a
// condition number <= max_condition (small lights straddling or grazing
// the horizon, which this generator makes often).
TEST(TriangleProjectedSolidAngle, RandomAgainstLambert) {
  pcg32 rng(77, 1);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  int tested = 0, clipped = 0, fallback = 0;
  double worst = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double size = std::pow(10.0, uni(-5.0, 0.0));
    const double aspect = std::pow(10.0, uni(0.0, 4.0));
    const dvec3 rot(uni(-2.0, 2.0), uni(-2.0, 2.0), uni(-2.0, 2.0));
    const dvec3 ctr(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
    const double w = size * std::sqrt(aspect), l = size / std::sqrt(aspect);
    const dvec3 a = ctr + rotate({-0.5 * w, -0.5 * l, 0.0}, rot), b = ctr + rotate({0.5 * w, -0.3 * l, 0.0}, rot),
                c = ctr + rotate({uni(-0.5, 0.5) * w, 0.5 * l, 0.0}, rot);
    const triangle t = make_triangle(a, b, c, rng.uniform() < 0.5f);
    const dvec3 front(t.normal());
    // Observer at distance ~1 on the front side; receiver normal random,
    // or through the light (straddling), or grazing it.
    dvec3 dir = glm::normalize(dvec3(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0)));
    if (glm::dot(dir, front) < 0.0) dir = -dir;
    if (glm::dot(dir, front) < 1e-3) continue;
    const vec3 o = vec3(ctr + uni(0.5, 2.0) * dir);
    const dvec3 to_c = glm::normalize(ctr - dvec3(o));
    dvec3 n = glm::normalize(dvec3(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0)));
    const float mode = rng.uniform();
    if (mode < 0.4f) {
      n = glm::normalize(n - glm::dot(n, to_c) * to_c);  // the horizon through the light's centre
    } else if (mode < 0.6f) {
      n = glm::normalize(n - glm::dot(n, to_c) * to_c + uni(-1e-3, 1e-3) * to_c);
    } else if (mode < 0.8f) {
      n = glm::normalize(to_c + 0.5 * n);
    }
    const triangle_projected_solid_angle_sampler smp{t};
    const projected_triangle pt(smp.frame(), o, vec3(n));
    if (!pt.valid()) continue;
    const double ref = reference_psa(t, o, vec3(n));
    if (pt.how() != projected_triangle::method::map) {
      ++fallback;
      EXPECT_GT(pt.condition_lambert(), projected_triangle::max_condition) << k;
      if (pt.omega_complement() > 0.0) {
        EXPECT_GT(pt.condition_complement(), projected_triangle::max_condition) << k;
      }
      continue;
    }
    ++tested;
    clipped += straddles(t, o, vec3(n));
    const double e = std::abs(smp.projected_solid_angle(o, vec3(n)) / ref - 1.0);
    worst = std::max(worst, e);
    EXPECT_LE(e, 1e-9) << k << ": " << smp.projected_solid_angle(o, vec3(n)) << " vs " << ref;
  }
  std::cout << "[ lambert  ] " << tested << " on the map, worst relative error " << worst << "; " << fallback
            << " on the area fallback\n";
  EXPECT_GT(tested, 1500);
  EXPECT_GT(clipped, 500);  // of those on the map
}

// A rectangle split along its diagonal into two triangles: the triangles'
// projected solid angles add up to the rectangle's (projected_rectangle.hpp,
// a separate implementation in the rectangle's own frame) to 1e-9 wherever
// all three are on the map, over 2000 random receivers: above, straddling
// and grazing the horizon, near and far.
TEST(TriangleProjectedSolidAngle, SplitRectangleMatchesRectangle) {
  const rect r = xy_rect(-0.5f, 0.7f, -0.4f, 0.3f, 0.0f);  // faces +z
  const dvec3 c(r.corner), e1(r.e1), e2(r.e2);
  const triangle t1 = make_triangle(c, c + e1, c + e1 + e2), t2 = make_triangle(c, c + e1 + e2, c + e2);
  const rect_projected_solid_angle_sampler rs{r};
  const triangle_projected_solid_angle_sampler s1{t1}, s2{t2};
  pcg32 rng(31, 2);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  int compared = 0, straddling = 0;
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const vec3 o(float(uni(-2.0, 2.0)), float(uni(-2.0, 2.0)), float(std::pow(10.0, uni(-3.0, 2.0))));
    const dvec3 to_c = glm::normalize(dvec3(r.center()) - dvec3(o));
    dvec3 nd = glm::normalize(dvec3(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0)));
    if (rng.uniform() < 0.5f) nd = glm::normalize(nd - glm::dot(nd, to_c) * to_c + uni(-0.2, 0.2) * to_c);
    const vec3 n(nd);
    const auto on_map = [&](const triangle_projected_solid_angle_sampler& s) {
      return projected_triangle(s.frame(), o, n).how() == projected_triangle::method::map;
    };
    const projected_rectangle pr(spherical_rectangle_detail::make_rect_frame(r), r.corner, o, n);
    if (pr.how() != projected_rectangle::method::map || !on_map(s1) || !on_map(s2)) continue;
    ++compared;
    straddling += pr.vertex_count() != 4 || straddles(t1, o, n) || straddles(t2, o, n);
    const double sum = s1.projected_solid_angle(o, n) + s2.projected_solid_angle(o, n);
    const double e = std::abs(sum / rs.projected_solid_angle(o, n) - 1.0);
    worst = std::max(worst, e);
    EXPECT_LE(e, 1e-9) << k;
  }
  std::cout << "[ split    ] " << compared << " receivers compared (" << straddling << " straddling), worst " << worst
            << "\n";
  EXPECT_GT(compared, 1000);
  EXPECT_GT(straddling, 300);
}

// ------------------------------------------------------------------ pdf consistency

// The pdf returned with a sample equals pdf(o, n, dir) of the same float
// direction within 1e-6 relative (both evaluate one formula on one float
// direction; on the area fallback pdf() takes the distance from its own
// ray, which differs from the sampled point's by the direction's
// rounding). A float direction within ~2^-22 rad of the outline may miss
// the light in its own direction; such misses are counted and must stay
// below 2^-22 times the angular perimeter over the solid angle (times 2,
// plus 2) of the samples. The sampler returns a sample for every u where
// the light is visible except where the float direction rounds to the
// horizon (at most 2 in 2 * 10^4 allowed).
TEST(TriangleProjectedSolidAngle, PdfConsistency) {
  constexpr int n = 20'000;
  pcg32 rng(11, 3);
  for (const psa_case& c : psa_battery()) {
    const triangle_projected_solid_angle_sampler smp{c.shape};
    double worst = 0.0;
    int misses = 0, samples = 0;
    for (int i = 0; i < n; ++i) {
      light_sample s;
      if (!smp.sample(c.o, c.n, rng.uniform2(), s)) continue;
      ++samples;
      const float p = smp.pdf(c.o, c.n, s.dir);
      if (p == 0.0f) {
        ++misses;
        continue;
      }
      worst = std::max(worst, std::abs(double(p) / double(s.pdf) - 1.0));
    }
    const std::array<dvec3, 3> p = vertices(c.shape);
    double perimeter = 0.0;
    for (int k = 0; k < 3; ++k)
      perimeter += test::detail::angle_between(glm::normalize(p[k] - dvec3(c.o)), glm::normalize(p[(k + 1) % 3] - dvec3(c.o)));
    const double allowed = 2.0 * samples * 0x1p-22 * perimeter / visible_solid_angle(c.shape, c.o, c.n) + 2.0;
    EXPECT_GE(samples, n - 2) << c.name;
    EXPECT_LE(misses, allowed) << c.name;
    EXPECT_LE(worst, psa_method(c) == projected_triangle::method::map ? 1e-7 : 1e-5) << c.name;
  }
}

// ------------------------------------------------------------------ expectations

// E[max(cos, 0) / pdf] = Omega_proj and E[1 / pdf] = Omega (the solid angle
// of the visible part, Van Oosterom-Strackee) for a correct sampler.
// Samples in batches of 10^5 (fixed seed) until 5 standard errors are at
// most 0.5 % (at most 4 * 10^6); then |mean / reference - 1| <= 0.5 % is
// required, which a correct sampler fails with probability < 1e-6. E[1/pdf]
// = E[Omega_proj / cos] is checked on the map where the light lies above
// the horizon with cos >= 0.05 at every vertex (cos >= 0.05 on all of it):
// where the horizon cuts the light or grazes it, 1/cos has a
// logarithmically divergent second moment and 4 * 10^6 samples do not
// resolve 0.5 %. On the area fallback 1/pdf = h A_visible / t^3 is bounded
// and checked everywhere.
TEST(TriangleProjectedSolidAngle, ExpectationsAreProjectedAndPlainSolidAngle) {
  int solid_angle_cases = 0;
  for (const psa_case& c : psa_battery()) {
    const triangle_projected_solid_angle_sampler smp{c.shape};
    const double ref = reference_psa(c.shape, c.o, c.n), sa = visible_solid_angle(c.shape, c.o, c.n);
    const dvec3 nn = glm::normalize(dvec3(c.n));
    double min_cos = 1.0;
    for (const dvec3& v : vertices(c.shape)) min_cos = std::min(min_cos, glm::dot(glm::normalize(v - dvec3(c.o)), nn));
    const bool check_sa = min_cos >= 0.05 || psa_method(c) == projected_triangle::method::area;
    solid_angle_cases += check_sa;
    pcg32 rng(21, 4);
    double sum[2] = {0, 0}, sum2[2] = {0, 0}, mean[2] = {0, 0}, se[2] = {0, 0};
    long count = 0;
    const auto resolved = [&] { return 5.0 * se[0] <= 0.005 * ref && (!check_sa || 5.0 * se[1] <= 0.005 * sa); };
    do {
      for (int i = 0; i < 100'000; ++i) {
        light_sample s;
        double f[2] = {0.0, 0.0};
        if (smp.sample(c.o, c.n, rng.uniform2(), s)) {
          f[0] = std::max(glm::dot(dvec3(s.dir), nn), 0.0) / double(s.pdf);
          f[1] = 1.0 / double(s.pdf);
        }
        for (int j = 0; j < 2; ++j) sum[j] += f[j], sum2[j] += f[j] * f[j];
      }
      count += 100'000;
      for (int j = 0; j < 2; ++j) {
        mean[j] = sum[j] / double(count);
        se[j] = std::sqrt(std::max(sum2[j] / double(count) - mean[j] * mean[j], 0.0) / double(count - 1));
      }
    } while (!resolved() && count < 4'000'000);
    EXPECT_TRUE(resolved()) << c.name << ": the test cannot resolve 0.5 % (" << count << " samples)";
    EXPECT_NEAR(mean[0] / ref, 1.0, 0.005) << c.name << ": E[cos/pdf] = " << mean[0] << ", Omega_proj = " << ref;
    if (check_sa) {
      EXPECT_NEAR(mean[1] / sa, 1.0, 0.005) << c.name << ": E[1/pdf] = " << mean[1] << ", Omega = " << sa;
    }
    std::cout << "[ expect   ] " << c.name << ": E[cos/pdf] / Omega_proj - 1 = " << mean[0] / ref - 1.0
              << ", E[1/pdf] / Omega - 1 = " << mean[1] / sa - 1.0 << (check_sa ? "" : " (not checked)") << ", "
              << count << " samples\n";
  }
  EXPECT_GE(solid_angle_cases, 7);
}

// On the map, cos / pdf is Omega_proj for every sample (the pdf is computed
// from the float direction returned, so only its rounding to float, 2^-24,
// and the closed form's ~1e-9 remain): |cos / pdf / Omega_proj - 1| <=
// 1e-6 for every one of 2 * 10^4 samples per case, against the 50-digit
// reference. This is what makes direct lighting of a diffuse receiver by
// an unoccluded triangle noise-free.
TEST(TriangleProjectedSolidAngle, CosOverPdfIsConstant) {
  int cases = 0;
  for (const psa_case& c : psa_battery()) {
    if (psa_method(c) != projected_triangle::method::map) continue;
    ++cases;
    const triangle_projected_solid_angle_sampler smp{c.shape};
    const double ref = reference_psa(c.shape, c.o, c.n);
    const dvec3 nn = glm::normalize(dvec3(c.n));
    pcg32 rng(6, 1);
    double worst = 0.0;
    for (int i = 0; i < 20'000; ++i) {
      light_sample s;
      if (!smp.sample(c.o, c.n, rng.uniform2(), s)) continue;  // counted by PdfConsistency
      worst = std::max(worst, std::abs(glm::dot(dvec3(s.dir), nn) / double(s.pdf) / ref - 1.0));
    }
    EXPECT_LE(worst, 1e-6) << c.name;
  }
  EXPECT_EQ(cases, 14);  // all but tiny_1e14 and grazing_clip
}

// ------------------------------------------------------------------ chi-square

// Directions on the bounding cap (support/chi2.hpp), 10^6 samples, against
// the independent density psa_reference. Float directions within ~1e-7
// rad of the outline of a small light may miss it in their own direction:
// rim_miss_fraction allows for that.
class TriangleProjectedSolidAngleChi2 : public ::testing::TestWithParam<std::string> {};

TEST_P(TriangleProjectedSolidAngleChi2, Directions) {
  const psa_case c = find_case(GetParam());
  const test::spherical_cap cap = bounding_cap(c);
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.seed = 17;
  opt.zero_pdf_fraction = test::rim_miss_fraction(cap.one_minus_cos);
  const triangle_projected_solid_angle_sampler smp{c.shape};
  const psa_reference ref(c);
  const auto sample = [&](pcg32& rng, vec3& d) {
    light_sample s;
    if (!smp.sample(c.o, c.n, rng.uniform2(), s)) return false;
    d = s.dir;
    return true;
  };
  const test::chi2_result r =
      test::chi2_test_directions(sample, [&](const dvec3& d) { return ref(d); }, cap.axis, cap.one_minus_cos, opt);
  EXPECT_TRUE(r.passed) << c.name << "\n" << r.report;
}

INSTANTIATE_TEST_SUITE_P(Battery, TriangleProjectedSolidAngleChi2,
                         ::testing::Values("floor", "oblique", "clip_triangle", "clip_quad", "tiny_1e8",
                                           "near_2pi_tilted", "aspect_clip", "reversed"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// On the light itself (chi2_test_unit_square) for the views no direction
// grid resolves: the observer 2e-6 from the light's plane and the slivers
// above a grazing horizon, all on the band triangle. The part x >= x_lo
// (x_lo the smallest x of the visible part) is mapped from the unit square
// by x = x_lo + (0.5 - x_lo) a, y = (2 b - 1) (x + 0.5) / 2, area element
// (0.5 - x_lo) (x + 0.5) da db; the density per unit (a, b) is the
// reference density times h / d^3 times that. 10^6 samples.
class TriangleProjectedSolidAngleChi2Square : public ::testing::TestWithParam<std::string> {};

TEST_P(TriangleProjectedSolidAngleChi2Square, OnTheLight) {
  const psa_case c = find_case(GetParam());
  const triangle_projected_solid_angle_sampler smp{c.shape};
  const psa_reference ref(c);
  double x_lo = 0.5;
  for (const dvec3& p : clipped_polygon(c.shape, c.o, c.n)) x_lo = std::min(x_lo, p.x);
  x_lo = std::max(x_lo, -0.5);
  const double band = 0.5 - x_lo;
  const dvec3 o(c.o);
  const double h = o.z;
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.seed = 23;
  long redrawn = 0;
  const auto sample = [&](pcg32& rng, dvec2& ab) {
    for (int tries = 0; tries < 100; ++tries) {
      light_sample s;
      if (!smp.sample(c.o, c.n, rng.uniform2(), s)) {
        ++redrawn;
        continue;
      }
      const dvec3 p = o + double(s.dist) * dvec3(s.dir);
      const double a = (p.x - x_lo) / band;
      const double b = 0.5 * (p.y / (0.5 * (p.x + 0.5)) + 1.0);
      ab = glm::clamp(dvec2(a, b), dvec2(0.0), dvec2(1.0));  // the float point's rounding at the edges
      return true;
    }
    return false;
  };
  const auto density = [&](const dvec2& ab) {
    const double x = x_lo + band * ab.x, y = (2.0 * ab.y - 1.0) * 0.5 * (x + 0.5);
    const dvec3 v = dvec3(x, y, 0.0) - o;
    const double d = glm::length(v);
    return ref(v / d) * h / (d * d * d) * band * (x + 0.5);
  };
  const test::chi2_result r = test::chi2_test_unit_square(sample, density, opt);
  EXPECT_TRUE(r.passed) << c.name << "\n" << r.report;
  EXPECT_LE(redrawn, 20) << c.name;
}

INSTANTIATE_TEST_SUITE_P(Slivers, TriangleProjectedSolidAngleChi2Square,
                         ::testing::Values("plane_1e6", "sliver_1e3", "sliver_1e5"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// The area fallback on the light itself: the points projected_triangle::
// sample_offset returns (in double: a float direction cannot resolve a
// light of 1e-14 sr), mapped to the unit square by the inverse of (a, b)
// -> P0 + a (P1 - P0) + a b (P2 - P1) (area element 2 A a), against the
// reference density times h / d^3 times 2 A a (2 A a / A_visible on the
// visible part). 10^6 samples, for the whole tiny light and the clipped
// grazing one (the fan of the clipped polygon).
class TriangleAreaFallbackChi2 : public ::testing::TestWithParam<std::string> {};

TEST_P(TriangleAreaFallbackChi2, OnTheLight) {
  const psa_case c = find_case(GetParam());
  const projected_triangle pt = make_pt(c, true);
  ASSERT_EQ(pt.how(), projected_triangle::method::area) << c.name;
  const psa_reference ref(c);
  const std::array<dvec3, 3> p = vertices(c.shape);
  const dvec3 o(c.o), cr = glm::cross(p[1] - p[0], p[2] - p[0]);
  const double a2 = glm::length(cr);  // 2 A
  const dvec3 nz = cr / a2;
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.seed = 29;
  const auto sample = [&](pcg32& rng, dvec2& ab) {
    dvec3 v;
    if (!pt.sample_offset(rng.uniform2(), v)) return false;
    // Barycentric coordinates of o + v, the offsets from p[0] formed first.
    const dvec3 q = (o - p[0]) + v;
    const double b1 = glm::dot(glm::cross(q, p[2] - p[0]), nz) / a2, b2 = glm::dot(glm::cross(p[1] - p[0], q), nz) / a2;
    const double a = b1 + b2;
    ab = glm::clamp(dvec2(a, a > 0.0 ? b2 / a : 0.0), dvec2(0.0), dvec2(1.0));
    return true;
  };
  const auto density = [&](const dvec2& ab) {
    const dvec3 x = p[0] + ab.x * (p[1] - p[0]) + ab.x * ab.y * (p[2] - p[1]);
    const dvec3 v = x - o;
    const double d = glm::length(v);
    return ref(v / d) * ref.h / (d * d * d) * a2 * ab.x;
  };
  const test::chi2_result r = test::chi2_test_unit_square(sample, density, opt);
  EXPECT_TRUE(r.passed) << c.name << "\n" << r.report;
}

INSTANTIATE_TEST_SUITE_P(Fallback, TriangleAreaFallbackChi2, ::testing::Values("tiny_1e14", "grazing_clip"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// ------------------------------------------------------------------ round trip

// invert(sample(u)) == u: in double (projected_triangle::sample_offset ->
// invert_offset) to 1e-6 on every case of the battery on the map and on
// the area fallback; through the float API to 1e-3 on the cases whose
// light spans more than 1e-3 rad seen at more than a few degrees (the
// float direction's rounding, ~6e-8 rad, moves u by ~6e-8 over the
// light's angular size).
TEST(TriangleProjectedSolidAngle, RoundTrip) {
  for (const psa_case& c : psa_battery()) {
    const projected_triangle pt = make_pt(c, true);
    ASSERT_TRUE(pt.can_sample()) << c.name;
    pcg32 rng(5, 5);
    double worst = 0.0;
    for (int i = 0; i < 20'000; ++i) {
      const vec2 u = rng.uniform2();
      dvec3 v;
      ASSERT_TRUE(pt.sample_offset(u, v)) << c.name;
      const dvec2 w = pt.invert_offset(v);
      worst = std::max({worst, std::abs(w.x - u.x), std::abs(w.y - u.y)});
    }
    EXPECT_LE(worst, 1e-6) << c.name;
    if (c.name.rfind("tiny", 0) == 0 || c.name == "grazing_clip" || c.name == "plane_1e6" || c.name.rfind("near_2pi", 0) == 0 ||
        c.name.rfind("sliver", 0) == 0 || c.name == "aspect_clip")
      continue;
    const triangle_projected_solid_angle_sampler smp{c.shape};
    double worst_f = 0.0;
    int inverted = 0;
    for (int i = 0; i < 20'000; ++i) {
      const vec2 u = rng.uniform2();
      light_sample s;
      if (!smp.sample(c.o, c.n, u, s)) continue;
      vec2 w;
      if (!smp.invert(c.o, c.n, s.dir, w)) continue;  // a rim direction that misses (see PdfConsistency)
      ++inverted;
      worst_f = std::max({worst_f, double(std::abs(w.x - u.x)), double(std::abs(w.y - u.y))});
    }
    EXPECT_GT(inverted, 19'000) << c.name;
    EXPECT_LE(worst_f, 1e-3) << c.name;
  }
}

// ------------------------------------------------------------------ no sample

// Behind the light, in its plane, or with the whole light at or below the
// horizon: faces() false for the first two, no sample, pdf 0, no inverse,
// Omega_proj 0; for both orientations of the triangle.
TEST(TriangleProjectedSolidAngle, NothingToSample) {
  for (const bool reverse : {false, true}) {
    const triangle t = make_triangle(vec3(-1.0f, -1.0f, 0.0f), vec3(1.0f, -1.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), reverse);
    const float side = reverse ? -1.0f : 1.0f;  // the front is +z unless reversed
    const triangle_projected_solid_angle_sampler smp{t};
    pcg32 rng(2, 2);
    for (int i = 0; i < 2000; ++i) {
      const vec3 p(3.0f * rng.uniform() - 1.5f, 3.0f * rng.uniform() - 1.5f, 0.0f);
      const vec3 front = p + side * vec3(0.0f, 0.0f, 1e-3f + rng.uniform());
      const vec3 behind = p - side * vec3(0.0f, 0.0f, 1e-3f + rng.uniform());
      const vec3 to_center = glm::normalize(-front);
      // Light wholly below the horizon: |n_xy . (vertex - o)| <= 0.025 * 2 *
      // 1.5 < n_z o_z for |o_z| >= 0.2.
      const vec3 n_below =
          glm::normalize(vec3(0.05f * (rng.uniform() - 0.5f), 0.05f * (rng.uniform() - 0.5f), side));
      const vec3 front_far = p + side * vec3(0.0f, 0.0f, 0.2f + rng.uniform());
      for (const auto& [o, n] : {std::pair{front_far, n_below}, std::pair{behind, vec3(0, 0, 1)},
                                 std::pair{behind, vec3(0, 0, -1)}, std::pair{p, vec3(0, 0, -1)}, std::pair{p, vec3(0, 0, 1)}}) {
        light_sample s;
        vec2 u;
        EXPECT_FALSE(smp.sample(o, n, rng.uniform2(), s));
        const vec3 d = glm::normalize(vec3(0.1f, 0.2f, 0.0f) - o);
        EXPECT_EQ(smp.pdf(o, n, d), 0.0f);
        EXPECT_EQ(smp.pdf(o, n, to_center), 0.0f);
        EXPECT_FALSE(smp.invert(o, n, d, u));
        EXPECT_EQ(smp.projected_solid_angle(o, n), 0.0);
      }
      EXPECT_TRUE(smp.faces(front));
      EXPECT_FALSE(smp.faces(behind));
      EXPECT_FALSE(smp.faces(p));
      // From the front with an upward normal there is a sample.
      light_sample s;
      EXPECT_TRUE(smp.sample(front, vec3(0.0f, 0.0f, -side), rng.uniform2(), s));
    }
  }
  // A degenerate (zero-area) triangle has nothing to sample.
  const triangle_projected_solid_angle_sampler line{
      make_triangle(vec3(0.0f, 0.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(2.0f, 0.0f, 0.0f))};
  light_sample s;
  EXPECT_FALSE(line.faces({0.0f, 0.0f, 1.0f}));
  EXPECT_FALSE(line.sample({0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, -1.0f}, {0.5f, 0.5f}, s));
  EXPECT_EQ(line.pdf({0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, -1.0f}, {0.0f, 0.0f, -1.0f}), 0.0f);
}

// ------------------------------------------------------------------ fuzz

// 5 * 10^5 configurations: sizes over 8 decades, aspect up to 1e4, random or
// axis-aligned orientation, either orientation of the mesh; observers at
// 1e-3 .. 1e7 sizes in any direction, within 1e-7 .. 1e-1 (relative) of the
// plane on either side, exactly in the plane, or behind; receiver normals
// random, grazing (within 1e-4 rad of perpendicular to the direction to the
// centroid), facing the light, or facing away. One u each (the corners of
// the square included). Asserted: no NaN / Inf; a sample has a unit
// direction, a positive finite distance and pdf, lies strictly above the
// horizon (n . dir > 0 in double), and its direction hits the triangle up
// to the rounding of a float direction (the watertight float test, or in
// double within 2^-20 (d / h) times the scene's scale); no sample where the
// observer is behind or in the plane or the light wholly below the
// horizon, and then pdf 0; pdf(o, n, dir) finite, >= 0, and positive for
// the sample's direction where the float test hits, and equal to the
// sample's pdf on the map up to float rounding (1e-6). The count of samples whose pdf(o, n, dir)
// differs from the returned pdf by more than 1e-3 is reported: on the area
// fallback at grazing views t^3 of the float direction's ray differs from
// the sampled point's d^3.
TEST(TriangleProjectedSolidAngle, Fuzz) {
  constexpr int configs = 500'000;
  pcg32 rng(2025, 7);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  long samples = 0, none = 0, strict_miss = 0, mismatch = 0;
  for (int k = 0; k < configs; ++k) {
    const double scale = std::pow(10.0, uni(-4.0, 4.0));
    const double aspect = std::pow(10.0, uni(0.0, 4.0));
    const double w = scale * std::sqrt(aspect), l = scale / std::sqrt(aspect);
    const dvec3 center(uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale);
    const bool reverse = rng.uniform() < 0.5f;
    const bool aligned = rng.uniform() < 0.25f;
    const double apex = uni(-1.0, 1.0);
    dvec3 pa(-0.5 * w, -0.5 * l, 0.0), pb(0.5 * w, -0.5 * l, 0.0), pc(apex * w, 0.5 * l, 0.0);
    if (!aligned) {
      const dvec3 axis(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
      const dvec3 rot = glm::length(axis) > 1e-3 ? axis : dvec3(0.0, 0.0, 1.0);
      pa = rotate(pa, rot), pb = rotate(pb, rot), pc = rotate(pc, rot);
    }
    const vec3 fa(center + pa), fb(center + pb), fc(center + pc);
    const triangle t = make_triangle(aligned ? vec3(fa.x, fa.y, float(center.z)) : fa,
                                     aligned ? vec3(fb.x, fb.y, float(center.z)) : fb,
                                     aligned ? vec3(fc.x, fc.y, float(center.z)) : fc, reverse);
    const std::array<dvec3, 3> p = vertices(t);
    const dvec3 cr = glm::cross(p[1] - p[0], p[2] - p[0]);
    if (!(glm::length(cr) > 0.0)) continue;
    const dvec3 nr = glm::normalize(cr) * (reverse ? -1.0 : 1.0);  // the front
    const dvec3 ctr = (p[0] + p[1] + p[2]) / 3.0;
    const double size = glm::length(p[1] - p[0]) + glm::length(p[2] - p[1]) + glm::length(p[0] - p[2]);
    vec3 o;
    const float mode = rng.uniform();
    bool behind_or_in = false;
    if (mode < 0.4f) {
      dvec3 d(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
      d = glm::length(d) > 1e-6 ? glm::normalize(d) : nr;
      o = vec3(ctr + size * std::pow(10.0, uni(-3.0, 7.0)) * d);
    } else if (mode < 0.7f) {
      const double h = (rng.uniform() < 0.5f ? -1.0 : 1.0) * size * std::pow(10.0, uni(-7.0, -1.0));
      o = vec3(p[0] + uni(-0.5, 1.5) * (p[1] - p[0]) + uni(-0.5, 1.5) * (p[2] - p[0]) + h * nr);
    } else if (mode < 0.85f && aligned) {
      o = vec3(p[0] + uni(-0.5, 1.5) * (p[1] - p[0]) + uni(-0.5, 1.5) * (p[2] - p[0]));
      o.z = float(center.z);
      behind_or_in = true;
    } else {
      o = vec3(ctr - size * std::pow(10.0, uni(-3.0, 3.0)) * nr + size * uni(-2.0, 2.0) * glm::normalize(p[1] - p[0]));
    }
    behind_or_in = behind_or_in || !(glm::dot(dvec3(o) - p[0], nr) > 0.0);
    const dvec3 to_c = ctr - dvec3(o);
    const dvec3 tc = glm::length(to_c) > 0.0 ? glm::normalize(to_c) : -nr;
    dvec3 nd(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
    if (glm::length(nd) < 1e-6) nd = dvec3(0.0, 0.0, 1.0);
    nd = glm::normalize(nd);
    const float nmode = rng.uniform();
    if (nmode < 0.3f) {  // grazing: nearly perpendicular to the direction to the centroid
      nd = glm::normalize(nd - glm::dot(nd, tc) * tc + dvec3(1e-30));
      nd = glm::normalize(nd + uni(-1e-4, 1e-4) * tc);
    } else if (nmode < 0.5f) {
      nd = glm::normalize(tc + 0.3 * nd);
    } else if (nmode < 0.6f) {
      nd = -tc;
    }
    const vec3 n(nd);
    const dvec3 nn = glm::normalize(dvec3(n));
    bool above = false;
    for (const dvec3& v : p) above = above || glm::dot(v - dvec3(o), nn) > 0.0;
    const vec2 u = (k % 64 == 0) ? vec2(0.0f) : (k % 64 == 1) ? vec2(0x1.fffffep-1f) : rng.uniform2();
    const triangle_projected_solid_angle_sampler smp{t};
    light_sample s;
    const bool ok = smp.sample(o, n, u, s);
    const float p_center = smp.pdf(o, n, vec3(tc));
    ASSERT_TRUE(std::isfinite(p_center) && p_center >= 0.0f) << k;
    const double psa = smp.projected_solid_angle(o, n);
    ASSERT_TRUE(std::isfinite(psa) && psa >= 0.0) << k;
    if (!ok) {
      ++none;
      if (behind_or_in || !above) {
        ASSERT_EQ(p_center, 0.0f) << k;
        ASSERT_EQ(smp.projected_solid_angle(o, n), 0.0) << k;
      }
      continue;
    }
    ASSERT_FALSE(behind_or_in) << k << ": a sample for an observer behind or in the plane";
    ASSERT_TRUE(above) << k << ": a sample with the light below the horizon";
    ++samples;
    ASSERT_TRUE(all_finite(s.dir) && std::isfinite(s.dist) && std::isfinite(s.pdf)) << k;
    ASSERT_NEAR(glm::length(s.dir), 1.0f, 1e-5f) << k;
    ASSERT_GT(s.dist, 0.0f) << k;
    ASSERT_GT(s.pdf, 0.0f) << k;
    ASSERT_GT(glm::dot(dvec3(s.dir), nn), 0.0) << k << ": below the horizon";
    const float p_dir = smp.pdf(o, n, s.dir);
    ASSERT_TRUE(std::isfinite(p_dir) && p_dir >= 0.0f) << k;
    // On the map both are cos / Omega_proj of the same float direction, with
    // Omega_proj from two set-ups that the compiler may contract into FMAs
    // differently (an ulp of double, at most one of float).
    if (p_dir > 0.0f && projected_triangle(smp.frame(), o, n).how() == projected_triangle::method::map) {
      ASSERT_LE(std::abs(double(p_dir) / s.pdf - 1.0), 1e-6) << k;
    }
    if (p_dir > 0.0f && std::abs(double(p_dir) / s.pdf - 1.0) > 1e-3) ++mismatch;
    if (intersect_triangle({o, s.dir}, infinity, t.vertex(0), t.vertex(1), t.vertex(2))) continue;
    ++strict_miss;
    const dvec3 oo(o), dd(s.dir);
    const double h = std::abs(glm::dot(oo - p[0], nr)), dist = double(s.dist);
    const double tol = 0x1p-20 * (dist / h) * (dist + glm::length(oo) + glm::length(p[0]) + size);
    const double tt = glm::dot(p[0] - oo, nr) / glm::dot(dd, nr);
    const dvec3 q = oo + tt * dd;
    // Distances of q from the three edge lines, inside positive.
    for (int e = 0; e < 3; ++e) {
      const dvec3 a = p[e], b = p[(e + 1) % 3];
      const double side = glm::dot(glm::cross(b - a, q - a), nr) / glm::length(b - a) * (reverse ? -1.0 : 1.0);
      if (tol >= 0.1 * size) break;
      ASSERT_TRUE(tt > 0.0 && side >= -tol) << k << ": direction misses the triangle by " << -side
                                            << " (tolerance " << tol << ")";
    }
  }
  std::cout << "[ fuzz     ] " << samples << " samples, " << none << " without; " << strict_miss
            << " float intersect_triangle misses, all within rounding; " << mismatch
            << " pdf(o, n, dir) != sample pdf beyond 1e-3\n";
  EXPECT_GT(samples, configs / 10);
}

}  // namespace
