// Tests of the cosine-aware rectangle strategies: exact projected-solid-angle
// sampling (sampling/projected_rectangle.hpp, after Peters 2021) and the
// bilinear pre-warp of the spherical rectangle (sampling/
// bilinear_spherical_rectangle.hpp, Hart et al. 2020 as in pbrt-v4). For
// both: pdf consistency, E[cos/pdf] = projected solid angle of the
// horizon-clipped rectangle (Lambert's polygon formula, support/lambert.hpp),
// chi-square over a battery including the extremes, round trip through the
// inverse, a 10^6-configuration fuzz; for the exact one also the (near-)zero
// variance of cos/pdf.
//
// Every random test uses a fixed seed. The chi-square tests run at the
// per-test level 1 - 0.99^(1/256) (support/chi2.hpp); this file has 22 of
// them. Other statistical bounds are stated where they are used.
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
#include "mcrt/render/light.hpp"
#include "mcrt/sampling/bilinear_spherical_rectangle.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"
#include "support/chi2.hpp"
#include "support/lambert.hpp"
#include "support/solid_angle.hpp"

namespace {

using namespace mcrt;

constexpr double dpi = std::numbers::pi;

// Both strategies are normal-aware (render/light.hpp dispatches n to them).
static_assert(normal_aware_strategy<rect_projected_solid_angle_sampler>);
static_assert(normal_aware_strategy<rect_bilinear_solid_angle_sampler>);

// ------------------------------------------------------------------ cases

struct psa_case {
  std::string name;
  rect shape;
  vec3 o;
  vec3 n;  // receiver's unit normal
};

vec3 unit(double x, double y, double z) { return vec3(glm::normalize(dvec3(x, y, z))); }

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

// Whole and clipped lights (3, 4 and 5 visible vertices), 1e-8, 1e-12 and
// 1e-14 sr (the last on the exact sampler's area fallback), near 2 pi
// (observer 1e-7 above a 2 x 2 light), an observer 2e-6 (1e-6 of the size)
// from the light's plane, thin slivers above a grazing horizon (1e-3 and
// 1e-5 of the light's width visible), aspect 1e4, rotated and flipped.
std::vector<psa_case> psa_battery() {
  const rect unit_rect = xy_rect(-0.5f, 0.5f, -0.5f, 0.5f, 0.0f);  // faces +z
  const rect square2 = xy_rect(-1.0f, 1.0f, -1.0f, 1.0f, 0.0f);
  const rect strip = xy_rect(-5000.0f, 5000.0f, -0.5f, 0.5f, 0.0f);
  const rect cornell = xz_rect(213, 343, 227, 332, 554, true);  // faces -y
  const rect rot_flip = rotated_rect({-1.0, 2.0, 0.25}, 0.5, 3.0, {-1.1, 0.2, 0.9}, true);
  const vec3 rf_o = vec3(dvec3(rot_flip.center()) + 0.7 * dvec3(rot_flip.n) + 0.2 * dvec3(rot_flip.e2));
  const vec3 rf_n = vec3(glm::normalize(-dvec3(rot_flip.n) + 0.9 * glm::normalize(dvec3(rot_flip.e1))));
  return {
      {"cornell_floor", cornell, {278.0f, 1.0f, 279.5f}, {0.0f, 1.0f, 0.0f}},
      {"cornell_wall_clip", cornell, {250.0f, 300.0f, 279.5f}, {1.0f, 0.0f, 0.0f}},
      {"clip_triangle", unit_rect, {0.2f, 0.1f, 1.0f}, unit(1.0, 1.0, -0.2)},
      {"clip_pentagon", unit_rect, {0.2f, 0.1f, 1.0f}, unit(1.0, 1.0, -0.8)},
      {"oblique", unit_rect, {6.0f, -5.0f, 7.0f}, unit(-0.3, 0.8, -1.0)},
      {"tiny_1e8", unit_rect, {0.1f, 0.2f, 1e4f}, unit(0.3, -0.2, -1.0)},
      {"tiny_1e12", unit_rect, {0.1f, 0.2f, 1e6f}, unit(0.3, -0.2, -1.0)},
      {"tiny_1e14", unit_rect, {0.1f, 0.2f, 1e7f}, unit(0.3, -0.2, -1.0)},
      {"near_2pi", square2, {0.1f, -0.2f, 1e-7f}, {0.0f, 0.0f, -1.0f}},
      {"near_2pi_tilted", square2, {0.1f, -0.2f, 1e-7f}, unit(0.5, 0.2, -1.0)},
      {"aspect_clip", strip, {0.0f, 0.0f, 1.0f}, unit(0.3, 0.2, -1.0)},
      {"rotated_flipped", rot_flip, rf_o, rf_n},
      {"plane_1e6", square2, {2.5f, 0.4f, 2e-6f}, {-1.0f, 0.0f, 0.0f}},
      {"sliver_1e3", unit_rect, {0.0f, 0.0f, 1.0f}, unit(1.0, 0.0, 0.499)},
      {"sliver_1e5", unit_rect, {0.0f, 0.0f, 1.0f}, unit(1.0, 0.0, 0.49999)},
      {"sliver_5e2", unit_rect, {0.0f, 0.0f, 1.0f}, unit(1.0, 0.0, 0.45)},
  };
}

psa_case find_case(const std::string& name) {
  for (psa_case& c : psa_battery())
    if (c.name == name) return c;
  ADD_FAILURE() << "no case " << name;
  return {};
}

// The rectangle as the samplers see it (e2 made orthogonal to e1), clipped
// in double at the receiver's horizon n . (p - o) > 0.
std::vector<dvec3> clipped_polygon(const rect& r, const vec3& o, const vec3& n) {
  const dvec3 c(r.corner), e1(r.e1), oo(o), nn = glm::normalize(dvec3(n));
  const dvec3 e2 = dvec3(r.e2) - glm::dot(dvec3(r.e2), e1) / glm::dot(e1, e1) * e1;
  const dvec3 p[4] = {c, c + e1, c + e1 + e2, c + e2};
  std::vector<dvec3> q;
  for (int i = 0; i < 4; ++i) {
    const dvec3 a = p[i], b = p[(i + 1) % 4];
    const double za = glm::dot(a - oo, nn), zb = glm::dot(b - oo, nn);
    if (za > 0.0) q.push_back(a);
    if ((za > 0.0) != (zb > 0.0)) q.push_back(a + (za / (za - zb)) * (b - a));
  }
  return q;
}

// Projected solid angle of the visible part: Lambert's formula
// (test::polygon_irradiance). In double it cancels for the slivers above a
// grazing horizon (terms O(1), sum ~1e-11 for sliver_1e5); where
// Boost.Multiprecision is available the same formula, clip included, runs
// with 50 significant digits.
double reference_psa(const rect& r, const vec3& o, const vec3& n) {
#ifdef MCRT_TEST_MP
  using mp = boost::multiprecision::cpp_bin_float_50;
  struct v3 {
    mp x, y, z;
  };
  const auto add = [](const v3& a, const v3& b) { return v3{a.x + b.x, a.y + b.y, a.z + b.z}; };
  const auto sub = [](const v3& a, const v3& b) { return v3{a.x - b.x, a.y - b.y, a.z - b.z}; };
  const auto mul = [](const mp& k, const v3& a) { return v3{k * a.x, k * a.y, k * a.z}; };
  const auto dot = [](const v3& a, const v3& b) { return mp(a.x * b.x + a.y * b.y + a.z * b.z); };
  const auto cross = [](const v3& a, const v3& b) {
    return v3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  const auto V = [](const vec3& a) { return v3{mp(a.x), mp(a.y), mp(a.z)}; };
  const v3 c = sub(V(r.corner), V(o)), e1 = V(r.e1);
  v3 e2 = V(r.e2), nn = V(n);
  e2 = sub(e2, mul(dot(e2, e1) / dot(e1, e1), e1));
  nn = mul(mp(1) / sqrt(dot(nn, nn)), nn);
  const v3 p[4] = {c, add(c, e1), add(add(c, e1), e2), add(c, e2)};
  std::vector<v3> q;
  for (int i = 0; i < 4; ++i) {
    const v3 a = p[i], b = p[(i + 1) % 4];
    const mp za = dot(a, nn), zb = dot(b, nn);
    if (za > 0) q.push_back(a);
    if ((za > 0) != (zb > 0)) q.push_back(add(a, mul(za / (za - zb), sub(b, a))));
  }
  if (q.size() < 3) return 0.0;
  mp sum = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const v3 cr = cross(q[i], q[(i + 1) % q.size()]);
    const mp sl = sqrt(dot(cr, cr));
    sum += atan2(sl, dot(q[i], q[(i + 1) % q.size()])) * dot(nn, cr) / sl;
  }
  return static_cast<double>(abs(sum) / 2);
#else
  const std::vector<dvec3> q = clipped_polygon(r, o, n);
  if (q.size() < 3) return 0.0;
  return test::polygon_irradiance(dvec3(o), glm::normalize(dvec3(n)), q, 1.0);
#endif
}

double polygon_area(const std::vector<dvec3>& q) {
  dvec3 a(0.0);
  for (std::size_t i = 1; i + 1 < q.size(); ++i) a += glm::cross(q[i] - q[0], q[i + 1] - q[0]);
  return 0.5 * glm::length(a);
}

projected_rectangle::method psa_method(const psa_case& c) {
  return projected_rectangle(spherical_rectangle_detail::make_rect_frame(c.shape), c.shape.corner, c.o, c.n).how();
}

// The density of the exact sampler, independently: cos / Omega_proj
// (Lambert) on the map, d^3 / (h A_visible) on its area fallback, 0 where
// the ray misses or runs below the horizon. In double.
struct psa_reference {
  spherical_rectangle sr;
  dvec3 n;
  double omega, area, h;
  bool map;
  psa_reference(const psa_case& c)
      : sr(c.shape, c.o), n(glm::normalize(dvec3(c.n))), omega(reference_psa(c.shape, c.o, c.n)),
        area(polygon_area(clipped_polygon(c.shape, c.o, c.n))), h(sr.height()),
        map(psa_method(c) == projected_rectangle::method::map) {}
  double operator()(const dvec3& d) const {
    double t;
    if (!sr.intersect(d, t)) return 0.0;
    const double cs = glm::dot(d, n);
    if (!(cs > 0.0)) return 0.0;
    return map ? cs / omega : t * t * t / (h * area);
  }
};

// The density of the bilinear strategy in double: the spherical rectangle's
// density times the bilinear density at its inverse (the definition, with
// spherical_rectangle's double map), 0 below the horizon.
struct bilinear_reference {
  rect_bilinear_solid_angle_sampler smp;
  spherical_rectangle sr;
  dvec3 n;
  bilinear_rect_detail::corner_weights w{};
  bool any = false;
  bilinear_reference(const psa_case& c) : smp(c.shape), sr(c.shape, c.o), n(glm::normalize(dvec3(c.n))) {
    any = smp.weights(c.o, c.n, w);
  }
  double operator()(const dvec3& d) const {
    double t;
    if (!any || !sr.intersect(d, t) || !(glm::dot(d, n) > 0.0)) return 0.0;
    const dvec3 v = t * d;
    return sr.pdf_offset(v) * bilinear_rect_detail::square_to_bilinear_pdf(sr.invert_offset(v), w);
  }
};

// The light's own square: local (s, t) in [0,1]^2 of a point o + v, and the
// point of (s, t) as an offset from o (e2 orthogonalised).
struct light_square {
  dvec3 c, ex, ey, nz;
  double w, l, h;
  light_square(const rect& r, const vec3& o) {
    const dvec3 e1(r.e1), e2(r.e2);
    w = glm::length(e1);
    ex = e1 / w;
    const dvec3 e2o = e2 - glm::dot(e2, ex) * ex;
    l = glm::length(e2o);
    ey = e2o / l;
    c = dvec3(r.corner) - dvec3(o);
    nz = glm::cross(ex, ey);
    h = std::abs(glm::dot(c, nz));
  }
  dvec2 st(const dvec3& v) const { return {glm::dot(v - c, ex) / w, glm::dot(v - c, ey) / l}; }
  dvec3 offset(const dvec2& st) const { return c + st.x * w * ex + st.y * l * ey; }
  // Solid angle per unit (s, t) at the point of st: A h / d^3.
  double jacobian(const dvec2& st) const {
    const double d = glm::length(offset(st));
    return w * l * h / (d * d * d);
  }
};

// Integral over the light's square of density(dir) A h / d^3, by 8 x 8
// Gauss-Legendre on a 32 x 32 grid, cells refined into quarters (to depth
// 7) until two levels agree to 1e-10 (absolute; the mass is at most 1): the
// mass of a density on the visible part, which jumps at the horizon line
// (the cells it crosses end at depth 7, 1/4096 of the side, an error
// < 1e-6). For observers at least ~0.1 of the light's size from its plane,
// where A h / d^3 is smooth on that scale.
template <class Density>
double mass_on_light(const light_square& sq, const Density& density) {
  static constexpr double gx[4] = {0.18343464249564980494, 0.52553240991632898582, 0.79666647741362673959,
                                   0.96028985649753623168};
  static constexpr double gw[4] = {0.36268378337836198297, 0.31370664587788728734, 0.22238103445337447054,
                                   0.10122853629037625915};
  const auto rule = [&](double u0, double u1, double v0, double v1) {
    const double hu = 0.5 * (u1 - u0), hv = 0.5 * (v1 - v0), cu = u0 + hu, cv = v0 + hv;
    double sum = 0.0;
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j) {
        const dvec2 st(cu + (i < 4 ? -gx[i] : gx[i - 4]) * hu, cv + (j < 4 ? -gx[j] : gx[j - 4]) * hv);
        const dvec3 v = sq.offset(st);
        sum += gw[i & 3] * gw[j & 3] * density(v / glm::length(v)) * sq.jacobian(st);
      }
    return sum * hu * hv;
  };
  const auto adaptive = [&](auto&& self, double u0, double u1, double v0, double v1, double whole, int depth) -> double {
    const double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
    const double q[4] = {rule(u0, um, v0, vm), rule(um, u1, v0, vm), rule(u0, um, vm, v1), rule(um, u1, vm, v1)};
    const double parts = q[0] + q[1] + q[2] + q[3];
    if (depth >= 7 || std::abs(parts - whole) <= 1e-10) return parts;
    return self(self, u0, um, v0, vm, q[0], depth + 1) + self(self, um, u1, v0, vm, q[1], depth + 1) +
           self(self, u0, um, vm, v1, q[2], depth + 1) + self(self, um, u1, vm, v1, q[3], depth + 1);
  };
  constexpr int n = 32;
  double mass = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u0 = double(i) / n, u1 = double(i + 1) / n, v0 = double(j) / n, v1 = double(j + 1) / n;
      mass += adaptive(adaptive, u0, u1, v0, v1, rule(u0, u1, v0, v1), 0);
    }
  return mass;
}

// The bilinear strategy's mass above the horizon: 1 when the whole light is
// above it, else mass_on_light.
double bilinear_visible_mass(const psa_case& c, const bilinear_reference& ref) {
  const dvec3 cc(c.shape.corner), e1(c.shape.e1), e2(c.shape.e2), oo(c.o), nn(c.n);
  bool all = true;
  for (const dvec3& p : {cc, cc + e1, cc + e2, cc + e1 + e2}) all = all && glm::dot(p - oo, nn) > 0.0;
  return all ? 1.0 : mass_on_light(light_square(c.shape, c.o), ref);
}

// ------------------------------------------------------------------ the battery itself

TEST(RectProjectedSolidAngle, BatteryCoversTheExtremes) {
  double omega_min = 10.0, s_min = 10.0, s_max = 0.0;
  int clipped[6] = {0, 0, 0, 0, 0, 0}, map = 0, area = 0, complement = 0;
  for (const psa_case& c : psa_battery()) {
    const projected_rectangle pr(spherical_rectangle_detail::make_rect_frame(c.shape), c.shape.corner, c.o, c.n);
    ASSERT_TRUE(pr.valid()) << c.name;
    ++clipped[std::clamp(pr.vertex_count(), 0, 5)];
    (pr.how() == projected_rectangle::method::map ? map : area) += 1;
    complement += pr.how() == projected_rectangle::method::map && pr.complement();
    const double s = spherical_rectangle(c.shape, c.o).solid_angle();
    s_min = std::min(s_min, s);
    s_max = std::max(s_max, s);
    omega_min = std::min(omega_min, reference_psa(c.shape, c.o, c.n));
    // The closed form the map is normalised by, against Lambert on the
    // clipped polygon (1e-7: the reference's own rounding on the slivers).
    if (pr.how() == projected_rectangle::method::map) {
      EXPECT_NEAR(pr.projected_solid_angle() / reference_psa(c.shape, c.o, c.n), 1.0, 1e-9) << c.name;
    }
  }
  EXPECT_LE(s_min, 1.01e-8);
  EXPECT_GE(s_max, 2.0 * dpi - 1e-5);
  EXPECT_GT(clipped[3], 0);
  EXPECT_GT(clipped[4], 0);
  EXPECT_GT(clipped[5], 0);
  EXPECT_GT(map, 0);
  EXPECT_GT(area, 0);
  EXPECT_GT(complement, 0);
  std::cout << "[ battery  ] map " << map << " (complement form " << complement << "), area " << area
            << "; smallest Omega_proj " << omega_min << "\n";
}

// ------------------------------------------------------------------ pdf consistency

// The pdf returned with a sample equals pdf(o, n, dir) for the same float
// direction within 1e-4 relative. The exact sampler evaluates the same
// formula on the same float direction. The bilinear one returns the
// bilinear density at the point u' it warped, pdf() at the preimage of the
// float direction; they differ by the density's variation over the
// direction's rounding, 2^-23 rad, which moves the point on the light by
// 2^-23 d^2 / h: for views more grazing than h / d_max = 1e-3 (near_2pi_tilted,
// plane_1e6) that is a sizeable fraction of the light, and only a factor 2
// is required there. A float direction within ~2^-22 rad of the outline
// may miss the light in its own direction; such misses are counted and must
// stay below 2^-22 times the angular perimeter over the solid angle (times
// 2, plus 2) of the samples.
template <class Sampler>
void check_pdf_consistency(const char* which, bool grazing_tolerance, const std::vector<std::string>& skip = {}) {
  constexpr int n = 20'000;
  pcg32 rng(11, 3);
  for (const psa_case& c : psa_battery()) {
    if (std::find(skip.begin(), skip.end(), c.name) != skip.end()) continue;
    const Sampler smp{c.shape};
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
    const spherical_rectangle sr(c.shape, c.o);
    const dvec3 cc(c.shape.corner), e1(c.shape.e1), e2(c.shape.e2), oo(c.o);
    double perimeter = 0.0;
    const dvec3 p[4] = {cc, cc + e1, cc + e1 + e2, cc + e2};
    for (int k = 0; k < 4; ++k)
      perimeter += test::detail::angle_between(glm::normalize(p[k] - oo), glm::normalize(p[(k + 1) % 4] - oo));
    const double allowed = 2.0 * samples * 0x1p-22 * perimeter / sr.solid_angle() + 2.0;
    double d_max = 0.0;
    for (int k = 0; k < 4; ++k) d_max = std::max(d_max, glm::length(p[k] - oo));
    const bool grazing = sr.height() < 1e-3 * d_max;
    EXPECT_GT(samples, 0) << which << " " << c.name;
    EXPECT_LE(misses, allowed) << which << " " << c.name;
    EXPECT_LE(worst, grazing && grazing_tolerance ? 1.0 : 1e-4) << which << " " << c.name;
  }
}

TEST(RectProjectedSolidAngle, PdfConsistency) {
  check_pdf_consistency<rect_projected_solid_angle_sampler>("exact", false);
}
TEST(RectBilinearSolidAngle, PdfConsistency) {
  // The thin slivers are left out: the bilinear strategy puts all but ~1e-3
  // (1e-5) of its samples below the horizon there.
  check_pdf_consistency<rect_bilinear_solid_angle_sampler>("bilinear", true, {"sliver_1e3", "sliver_1e5"});
}

// The exact sampler returns a sample for every u where the light is
// visible, except where the float direction rounds to or below the
// horizon: its density there is cos / Omega_proj, so that happens with
// probability ~(2^-23 rad / the sliver's angular height)^2, ~1e-6 for
// sliver_1e5; at most 2 in 10^4 are allowed.
TEST(RectProjectedSolidAngle, AlwaysSamplesWhereVisible) {
  pcg32 rng(4, 4);
  for (const psa_case& c : psa_battery()) {
    const rect_projected_solid_angle_sampler smp{c.shape};
    int fails = 0;
    for (int i = 0; i < 10'000; ++i) {
      light_sample s;
      fails += !smp.sample(c.o, c.n, rng.uniform2(), s);
    }
    EXPECT_LE(fails, 2) << c.name;
  }
}

// ------------------------------------------------------------------ E[cos / pdf]

// E[max(cos, 0) / pdf] is the projected solid angle Omega_proj of the
// visible part for any correct sampler (a missing sample contributes 0).
// Samples are drawn in batches of 10^5 (fixed seed) until 5 standard errors
// are at most 0.5 % of Omega_proj (at most 4 * 10^6); then |mean /
// Omega_proj - 1| <= 0.5 % is required, which a correct sampler fails with
// probability < 1e-6. Reference: Lambert's formula on the clipped polygon.
template <class Sampler>
void check_expected_cos_over_pdf(const std::vector<std::string>& skip, const char* which) {
  for (const psa_case& c : psa_battery()) {
    if (std::find(skip.begin(), skip.end(), c.name) != skip.end()) continue;
    const Sampler smp{c.shape};
    const double ref = reference_psa(c.shape, c.o, c.n);
    const dvec3 nn = glm::normalize(dvec3(c.n));
    pcg32 rng(21, 4);
    double sum = 0.0, sum2 = 0.0, se = 0.0, mean = 0.0;
    long count = 0;
    do {
      for (int i = 0; i < 100'000; ++i) {
        light_sample s;
        double f = 0.0;
        if (smp.sample(c.o, c.n, rng.uniform2(), s)) f = std::max(glm::dot(dvec3(s.dir), nn), 0.0) / double(s.pdf);
        sum += f;
        sum2 += f * f;
      }
      count += 100'000;
      mean = sum / double(count);
      se = std::sqrt(std::max(sum2 / double(count) - mean * mean, 0.0) / double(count - 1));
    } while (5.0 * se > 0.005 * ref && count < 4'000'000);
    EXPECT_LE(5.0 * se, 0.005 * ref) << which << " " << c.name << ": the test cannot resolve 0.5 %";
    EXPECT_NEAR(mean / ref, 1.0, 0.005) << which << " " << c.name << ": E[cos/pdf] = " << mean << ", Omega_proj = " << ref
                                        << ", SE " << se << ", " << count << " samples";
  }
}

TEST(RectProjectedSolidAngle, ExpectedCosOverPdfIsProjectedSolidAngle) {
  check_expected_cos_over_pdf<rect_projected_solid_angle_sampler>({}, "exact");
}
// The slivers above a grazing horizon are left out for the bilinear
// strategy: it spends all but ~1e-3, 1e-5 and 5e-2 of its samples below
// the horizon there, and the relative spread of cos/pdf (4.5 for
// sliver_5e2) would need 2e7 samples or more to resolve 0.5 %. Its
// distribution on sliver_5e2 is tested by chi-square on the light.
TEST(RectBilinearSolidAngle, ExpectedCosOverPdfIsProjectedSolidAngle) {
  check_expected_cos_over_pdf<rect_bilinear_solid_angle_sampler>({"sliver_1e3", "sliver_1e5", "sliver_5e2"},
                                                                  "bilinear");
}

// On the map the estimate cos / pdf is Omega_proj for every sample: its
// relative spread must be below 1e-4 (float pdf, 6e-8, and the float
// direction's cosine, ~6e-8 / cos, on the slivers). On the area fallback
// (tiny projected solid angles, see projected_rectangle.hpp) it is that of
// area sampling and is not tested here.
TEST(RectProjectedSolidAngle, CosOverPdfHasNearZeroVariance) {
  for (const psa_case& c : psa_battery()) {
    if (psa_method(c) != projected_rectangle::method::map) continue;
    const rect_projected_solid_angle_sampler smp{c.shape};
    const double ref = reference_psa(c.shape, c.o, c.n);
    const dvec3 nn = glm::normalize(dvec3(c.n));
    pcg32 rng(6, 1);
    double lo = 1e300, hi = -1e300, sum = 0.0, sum2 = 0.0;
    int count = 0;
    for (int i = 0; i < 20'000; ++i) {
      light_sample s;
      ASSERT_TRUE(smp.sample(c.o, c.n, rng.uniform2(), s)) << c.name;
      const double f = glm::dot(dvec3(s.dir), nn) / double(s.pdf) / ref;
      lo = std::min(lo, f);
      hi = std::max(hi, f);
      sum += f;
      sum2 += f * f;
      ++count;
    }
    const double mean = sum / count, sd = std::sqrt(std::max(sum2 / count - mean * mean, 0.0));
    EXPECT_LE(sd, 1e-4) << c.name << ": cos/pdf / Omega_proj in [" << lo << ", " << hi << "]";
    EXPECT_NEAR(mean, 1.0, 1e-4) << c.name;
  }
}

// ------------------------------------------------------------------ chi-square

// Directions, on the bounding cap of the light (support/chi2.hpp), 10^6
// samples. The exact sampler is tested against the independent density of
// psa_reference. The bilinear one against its definition in double
// (bilinear_reference); where the horizon clips the light it returns no
// sample for directions below it, so the test draws until a sample comes
// (the conditional distribution) and divides the density by the mass
// above the horizon (mass_on_light). Float directions within ~1e-7 rad of
// the outline of a small light may miss it in their own direction: the
// harness's rim_miss_fraction allows for that. The mass above the horizon
// is integrated on the light's square, which cannot resolve the density
// A h / d^3 of an observer 1e-7 above a clipped light (near_2pi_tilted) or
// of a strip 1e4 times longer than its height (aspect_clip): those two are
// tested for the exact sampler only (the bilinear one samples them through
// the same spherical rectangle as near_2pi and the other clipped cases).
struct chi2_case {
  std::string name;
  bool bilinear;
};

class RectCosineAwareChi2 : public ::testing::TestWithParam<chi2_case> {};

TEST_P(RectCosineAwareChi2, Directions) {
  const psa_case c = find_case(GetParam().name);
  const test::spherical_cap cap = test::bounding_cap(dvec3(c.o), c.shape);
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.seed = 17;
  opt.zero_pdf_fraction = test::rim_miss_fraction(cap.one_minus_cos);
  test::chi2_result r;
  if (!GetParam().bilinear) {
    const rect_projected_solid_angle_sampler smp{c.shape};
    const psa_reference ref(c);
    const auto sample = [&](pcg32& rng, vec3& d) {
      light_sample s;
      if (!smp.sample(c.o, c.n, rng.uniform2(), s)) return false;
      d = s.dir;
      return true;
    };
    r = test::chi2_test_directions(sample, [&](const dvec3& d) { return ref(d); }, cap.axis, cap.one_minus_cos, opt);
  } else {
    const rect_bilinear_solid_angle_sampler smp{c.shape};
    const bilinear_reference ref(c);
    const double mass = bilinear_visible_mass(c, ref);
    const auto sample = [&](pcg32& rng, vec3& d) {
      for (int tries = 0; tries < 100'000; ++tries) {
        light_sample s;
        if (smp.sample(c.o, c.n, rng.uniform2(), s)) {
          d = s.dir;
          return true;
        }
      }
      return false;
    };
    r = test::chi2_test_directions(sample, [&](const dvec3& d) { return ref(d) / mass; }, cap.axis, cap.one_minus_cos,
                                   opt);
  }
  EXPECT_TRUE(r.passed) << c.name << (GetParam().bilinear ? " (bilinear)" : " (exact)") << "\n" << r.report;
}

std::vector<chi2_case> direction_chi2_cases() {
  std::vector<chi2_case> v;
  for (const char* name : {"cornell_floor", "cornell_wall_clip", "clip_triangle", "clip_pentagon", "tiny_1e8", "near_2pi",
                           "near_2pi_tilted", "aspect_clip", "rotated_flipped"})
    for (const bool b : {false, true})
      if (!b || (std::string(name) != "near_2pi_tilted" && std::string(name) != "aspect_clip")) v.push_back({name, b});
  return v;
}

INSTANTIATE_TEST_SUITE_P(Battery, RectCosineAwareChi2, ::testing::ValuesIn(direction_chi2_cases()),
                         [](const ::testing::TestParamInfo<chi2_case>& info) {
                           return info.param.name + (info.param.bilinear ? "_bilinear" : "_exact");
                         });

// On the light's own square (chi2_test_unit_square), for the slivers no
// direction grid resolves: the observer 1e-6 of the size from the light's
// plane, and the slivers above a grazing horizon. 10^6 samples; the
// density per unit (s, t) is the reference density times A h / d^3, on the
// visible band of the light stretched onto the unit square. The
// bilinear strategy is tested on the sliver it samples at a useful rate
// (sliver_5e2, ~5 % of its samples above the horizon, conditional as above).
class RectCosineAwareChi2Square : public ::testing::TestWithParam<chi2_case> {};

TEST_P(RectCosineAwareChi2Square, OnTheLight) {
  const psa_case c = find_case(GetParam().name);
  const light_square sq(c.shape, c.o);
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.seed = 23;
  test::chi2_result r;
  // The visible band s >= s_lo (the slivers' horizons run along e2),
  // stretched onto the unit square so that the grid resolves it.
  double s_lo = 1.0;
  for (const dvec3& p : clipped_polygon(c.shape, c.o, c.n)) s_lo = std::min(s_lo, sq.st(p - dvec3(c.o)).x);
  s_lo = std::max(s_lo, 0.0);
  const double band = 1.0 - s_lo;
  const auto to_st = [&](const light_sample& s, dvec2& st) {
    st = sq.st(double(s.dist) * dvec3(s.dir));
    st.x = (st.x - s_lo) / band;
    st = glm::clamp(st, dvec2(0.0), dvec2(1.0));  // the float point's rounding at the edges
    return true;
  };
  const auto on_light = [&](const dvec2& b) { return dvec2(s_lo + band * b.x, b.y); };
  long redrawn = 0;
  if (!GetParam().bilinear) {
    const rect_projected_solid_angle_sampler smp{c.shape};
    const psa_reference ref(c);
    // A direction rounding to the horizon returns no sample (see
    // AlwaysSamplesWhereVisible): drawn again, and counted.
    const auto sample = [&](pcg32& rng, dvec2& st) {
      for (int tries = 0; tries < 100; ++tries) {
        light_sample s;
        if (smp.sample(c.o, c.n, rng.uniform2(), s)) return to_st(s, st);
        ++redrawn;
      }
      return false;
    };
    const auto density = [&](const dvec2& b) {
      const dvec2 st = on_light(b);
      const dvec3 v = sq.offset(st);
      return ref(v / glm::length(v)) * sq.jacobian(st) * band;
    };
    r = test::chi2_test_unit_square(sample, density, opt);
  } else {
    const rect_bilinear_solid_angle_sampler smp{c.shape};
    const bilinear_reference ref(c);
    const double mass = bilinear_visible_mass(c, ref);
    const auto sample = [&](pcg32& rng, dvec2& st) {
      for (int tries = 0; tries < 100'000; ++tries) {
        light_sample s;
        if (smp.sample(c.o, c.n, rng.uniform2(), s)) return to_st(s, st);
      }
      return false;
    };
    const auto density = [&](const dvec2& b) {
      const dvec2 st = on_light(b);
      const dvec3 v = sq.offset(st);
      return ref(v / glm::length(v)) * sq.jacobian(st) * band / mass;
    };
    r = test::chi2_test_unit_square(sample, density, opt);
  }
  EXPECT_TRUE(r.passed) << c.name << (GetParam().bilinear ? " (bilinear)" : " (exact)") << "\n" << r.report;
  if (!GetParam().bilinear) {
    EXPECT_LE(redrawn, 20) << c.name;
  }
}

INSTANTIATE_TEST_SUITE_P(Slivers, RectCosineAwareChi2Square,
                         ::testing::Values(chi2_case{"plane_1e6", false}, chi2_case{"sliver_1e3", false},
                                           chi2_case{"sliver_1e5", false}, chi2_case{"sliver_5e2", false},
                                           chi2_case{"plane_1e6", true}, chi2_case{"sliver_5e2", true}),
                         [](const ::testing::TestParamInfo<chi2_case>& info) {
                           return info.param.name + (info.param.bilinear ? "_bilinear" : "_exact");
                         });

// ------------------------------------------------------------------ round trip

// invert(sample(u)) == u. Through the float API the direction's rounding
// (~6e-8 rad) moves u by ~6e-8 / (the light's angular size along that
// coordinate, or ~6e-8 d / (h size) for a view at the grazing angle h / d):
// 1e-3 is required on the cases whose light spans more than 1e-3 rad in
// both directions, seen at more than a few degrees. On the map of the exact sampler, the
// double-precision round trip (projected_rectangle::sample_offset ->
// invert_offset) must hold to 1e-6 on every case of the battery.
template <class Sampler>
void check_round_trip(const char* which) {
  for (const psa_case& c : psa_battery()) {
    if (c.name.rfind("tiny", 0) == 0 || c.name == "plane_1e6" || c.name.rfind("near_2pi", 0) == 0 ||
        c.name.rfind("sliver", 0) == 0)
      continue;
    const Sampler smp{c.shape};
    pcg32 rng(3, 8);
    double worst = 0.0;
    int inverted = 0;
    for (int i = 0; i < 20'000; ++i) {
      const vec2 u = rng.uniform2();
      light_sample s;
      if (!smp.sample(c.o, c.n, u, s)) continue;
      vec2 w;
      if (!smp.invert(c.o, c.n, s.dir, w)) continue;  // a rim direction that misses (see PdfConsistency)
      ++inverted;
      worst = std::max({worst, double(std::abs(w.x - u.x)), double(std::abs(w.y - u.y))});
    }
    EXPECT_GT(inverted, 1000) << which << " " << c.name;
    EXPECT_LE(worst, 1e-3) << which << " " << c.name;
  }
}

TEST(RectProjectedSolidAngle, RoundTrip) {
  check_round_trip<rect_projected_solid_angle_sampler>("exact");
  for (const psa_case& c : psa_battery()) {
    const projected_rectangle pr(spherical_rectangle_detail::make_rect_frame(c.shape), c.shape.corner, c.o, c.n, true);
    if (pr.how() != projected_rectangle::method::map) continue;
    pcg32 rng(5, 5);
    double worst = 0.0;
    for (int i = 0; i < 20'000; ++i) {
      const vec2 u = rng.uniform2();
      dvec3 v;
      ASSERT_TRUE(pr.sample_offset(u, v)) << c.name;
      const dvec2 w = pr.invert_offset(v);
      worst = std::max({worst, std::abs(w.x - u.x), std::abs(w.y - u.y)});
    }
    EXPECT_LE(worst, 1e-6) << c.name;
  }
}
TEST(RectBilinearSolidAngle, RoundTrip) { check_round_trip<rect_bilinear_solid_angle_sampler>("bilinear"); }

// The bilinear warp on its own: round trip, density integrates to 1, the
// floor, and pbrt-v4's corner order (u'.x along e1, u'.y along e2).
TEST(RectBilinearSolidAngle, BilinearWarp) {
  using namespace bilinear_rect_detail;
  const corner_weights w = {0.01, 0.7, 0.2, 1.0};
  pcg32 rng(9, 9);
  double worst = 0.0;
  for (int i = 0; i < 100'000; ++i) {
    const dvec2 u(rng.uniform_double(), rng.uniform_double());
    const dvec2 p = square_to_bilinear(u, w);
    const dvec2 b = bilinear_to_square(p, w);
    worst = std::max({worst, std::abs(b.x - u.x), std::abs(b.y - u.y)});
  }
  EXPECT_LE(worst, 1e-12);
  double mass = 0.0;
  constexpr int m = 400;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) mass += square_to_bilinear_pdf({(i + 0.5) / m, (j + 0.5) / m}, w) / (m * m);
  EXPECT_NEAR(mass, 1.0, 1e-12);
  EXPECT_NEAR(square_to_bilinear_pdf({1.0, 1.0}, w), 4.0 * 1.0 / 1.91, 1e-12);
  // The weights of a receiver looking straight at corner + e1 from close by.
  const rect r = xy_rect(0.0f, 1.0f, 0.0f, 1.0f, 0.0f);
  const rect_bilinear_solid_angle_sampler smp{r};
  corner_weights cw;
  ASSERT_TRUE(smp.weights({1.0f, 0.0f, 0.01f}, {0.0f, 0.0f, -1.0f}, cw));
  EXPECT_NEAR(cw[1], 1.0, 1e-12);
  EXPECT_LT(cw[0], 0.02);
  EXPECT_LT(cw[3], 0.02);
  EXPECT_EQ(cw[2], rect_bilinear_solid_angle_sampler::weight_floor);  // cos = 0.01 / sqrt(2.0001) < floor
}

// ------------------------------------------------------------------ no sample

// Behind the light, in its plane, or with the whole light at or below the
// horizon: faces() as the spherical rectangle, no sample, pdf 0, no inverse.
template <class Sampler>
void check_nothing_to_sample() {
  const rect r = xy_rect(-1.0f, 1.0f, -1.0f, 1.0f, 0.0f);  // faces +z
  const Sampler smp{r};
  pcg32 rng(2, 2);
  for (int i = 0; i < 2000; ++i) {
    const vec3 p(3.0f * rng.uniform() - 1.5f, 3.0f * rng.uniform() - 1.5f, 0.0f);
    const vec3 front = p + vec3(0.0f, 0.0f, 1e-3f + rng.uniform());
    const vec3 behind = p - vec3(0.0f, 0.0f, 1e-3f + rng.uniform());
    const vec3 to_center = glm::normalize(-front);
    // Light wholly below the horizon: n . (corner - front) <= 0 for all corners.
    // (|n_xy . (corner - o)| <= 0.0625 < n_z o_z for o_z >= 0.2.)
    const vec3 n_below = glm::normalize(vec3(0.05f * (rng.uniform() - 0.5f), 0.05f * (rng.uniform() - 0.5f), 1.0f));
    const vec3 front_far = p + vec3(0.0f, 0.0f, 0.2f + rng.uniform());
    for (const auto& [o, n] : {std::pair{front_far, n_below}, std::pair{behind, vec3(0, 0, 1)}, std::pair{behind, vec3(0, 0, -1)},
                                std::pair{p, vec3(0, 0, -1)}}) {
      light_sample s;
      vec2 u;
      EXPECT_FALSE(smp.sample(o, n, rng.uniform2(), s));
      const vec3 d = glm::normalize(vec3(0.1f, 0.2f, 0.0f) - o);
      EXPECT_EQ(smp.pdf(o, n, d), 0.0f);
      EXPECT_FALSE(smp.invert(o, n, d, u));
      EXPECT_EQ(smp.pdf(o, n, to_center), 0.0f);
    }
    EXPECT_TRUE(smp.faces(front));
    EXPECT_FALSE(smp.faces(behind));
  }
}

TEST(RectProjectedSolidAngle, NothingToSample) { check_nothing_to_sample<rect_projected_solid_angle_sampler>(); }
TEST(RectBilinearSolidAngle, NothingToSample) { check_nothing_to_sample<rect_bilinear_solid_angle_sampler>(); }

// ------------------------------------------------------------------ fuzz

// 10^6 configurations: sizes over 8 decades, aspect up to 1e4 either way,
// random or axis-aligned orientation, either side emitting; observers at
// 1e-3 .. 1e7 sizes in any direction, within 1e-7 .. 1e-1 (relative) of the
// plane on either side, exactly in the plane, or behind; receiver normals
// random, grazing (within 1e-4 rad of perpendicular to the direction to the
// light's centre), facing the light, or facing away. Both samplers, one u
// each. Asserted: no NaN / Inf; a sample has a unit direction, a positive
// finite distance and pdf, lies strictly above the horizon (n . dir > 0 in
// double), and its direction hits the rectangle up to the rounding of a
// float direction (bound as in test_spherical_rectangle.cpp's fuzz); no
// sample where the observer is behind or in the plane or the light wholly
// below the horizon, and then pdf 0; pdf(o, n, dir) finite and >= 0. The
// count of samples whose pdf(o, n, dir) differs from the returned pdf by
// more than 1e-3 is reported: at grazing views a float direction does not
// pin down the point it came from (see PdfConsistency).
TEST(RectCosineAware, Fuzz) {
  constexpr int configs = 1'000'000;
  pcg32 rng(2025, 7);
  const auto uni = [&](double a, double b) { return a + (b - a) * rng.uniform_double(); };
  long samples[2] = {0, 0}, none[2] = {0, 0}, strict_miss[2] = {0, 0}, mismatch[2] = {0, 0};
  for (int k = 0; k < configs; ++k) {
    const double scale = std::pow(10.0, uni(-4.0, 4.0));
    const double aspect = std::pow(10.0, uni(-4.0, 4.0));
    const double w = scale * std::sqrt(aspect), l = scale / std::sqrt(aspect);
    const dvec3 center(uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale, uni(-10.0, 10.0) * scale);
    const bool flip = rng.uniform() < 0.5f;
    const bool aligned = rng.uniform() < 0.25f;
    rect r;
    if (aligned) {
      const float x0 = float(center.x - 0.5 * w), y0 = float(center.y - 0.5 * l);
      r = xy_rect(x0, x0 + float(w), y0, y0 + float(l), float(center.z), flip);
    } else {
      const dvec3 axis(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
      r = rotated_rect(center, w, l, glm::length(axis) > 1e-3 ? axis : dvec3(0.0, 0.0, 1.0), flip);
    }
    if (!(r.area > 0.0f) || !std::isfinite(r.area)) continue;
    const dvec3 c(r.corner), e1(r.e1), e2(r.e2), nr(r.n);
    const double size = glm::length(e1) + glm::length(e2);
    vec3 o;
    const float mode = rng.uniform();
    bool behind_or_in = false;
    if (mode < 0.4f) {
      dvec3 d(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
      d = glm::length(d) > 1e-6 ? glm::normalize(d) : nr;
      o = vec3(dvec3(r.center()) + size * std::pow(10.0, uni(-3.0, 7.0)) * d);
    } else if (mode < 0.7f) {
      const double h = (rng.uniform() < 0.5f ? -1.0 : 1.0) * size * std::pow(10.0, uni(-7.0, -1.0));
      o = vec3(c + uni(-1.0, 2.0) * e1 + uni(-1.0, 2.0) * e2 + h * nr);
    } else if (mode < 0.85f && aligned) {
      o = vec3(c + uni(-1.0, 2.0) * e1 + uni(-1.0, 2.0) * e2);
      o.z = r.corner.z;
      behind_or_in = true;
    } else {
      o = vec3(dvec3(r.center()) - size * std::pow(10.0, uni(-3.0, 3.0)) * nr + size * uni(-2.0, 2.0) * glm::normalize(e1));
      behind_or_in = glm::dot(dvec3(o) - c, nr) < 0.0;
    }
    // The receiver's normal.
    const dvec3 to_c = dvec3(r.center()) - dvec3(o);
    const dvec3 tc = glm::length(to_c) > 0.0 ? glm::normalize(to_c) : nr;
    dvec3 nd(uni(-1.0, 1.0), uni(-1.0, 1.0), uni(-1.0, 1.0));
    if (glm::length(nd) < 1e-6) nd = dvec3(0.0, 0.0, 1.0);
    nd = glm::normalize(nd);
    const float nmode = rng.uniform();
    if (nmode < 0.3f) {  // grazing: nearly perpendicular to the direction to the centre
      nd = glm::normalize(nd - glm::dot(nd, tc) * tc + dvec3(1e-30));
      nd = glm::normalize(nd + uni(-1e-4, 1e-4) * tc);
    } else if (nmode < 0.5f) {
      nd = glm::normalize(tc + 0.3 * nd);
    } else if (nmode < 0.6f) {
      nd = -tc;
    }
    const vec3 n(nd);
    const dvec3 nn = glm::normalize(dvec3(n));
    // Whether any corner is above the horizon (in double).
    bool above = false;
    for (const dvec3& p : {c, c + e1, c + e2, c + e1 + e2}) above = above || glm::dot(p - dvec3(o), nn) > 0.0;
    const vec2 u = (k % 64 == 0) ? vec2(0.0f) : (k % 64 == 1) ? vec2(0x1.fffffep-1f) : rng.uniform2();
    for (int which = 0; which < 2; ++which) {
      light_sample s;
      bool ok;
      float p_dir, p_center;
      if (which == 0) {
        const rect_projected_solid_angle_sampler smp{r};
        ok = smp.sample(o, n, u, s);
        p_dir = ok ? smp.pdf(o, n, s.dir) : 0.0f;
        p_center = smp.pdf(o, n, vec3(tc));
      } else {
        const rect_bilinear_solid_angle_sampler smp{r};
        ok = smp.sample(o, n, u, s);
        p_dir = ok ? smp.pdf(o, n, s.dir) : 0.0f;
        p_center = smp.pdf(o, n, vec3(tc));
      }
      ASSERT_TRUE(std::isfinite(p_center) && p_center >= 0.0f) << k << " " << which;
      if (!ok) {
        ++none[which];
        if (behind_or_in || !above) {
          ASSERT_EQ(p_center, 0.0f) << k << " " << which;
        }
        continue;
      }
      ASSERT_FALSE(behind_or_in) << k << " " << which << ": a sample for an observer behind or in the plane";
      ASSERT_TRUE(above) << k << " " << which << ": a sample with the light below the horizon";
      ++samples[which];
      ASSERT_TRUE(all_finite(s.dir) && std::isfinite(s.dist) && std::isfinite(s.pdf)) << k << " " << which;
      ASSERT_NEAR(glm::length(s.dir), 1.0f, 1e-5f) << k << " " << which;
      ASSERT_GT(s.dist, 0.0f) << k << " " << which;
      ASSERT_GT(s.pdf, 0.0f) << k << " " << which;
      ASSERT_GT(glm::dot(dvec3(s.dir), dvec3(n)), 0.0) << k << " " << which << ": below the horizon";
      ASSERT_TRUE(std::isfinite(p_dir) && p_dir >= 0.0f) << k << " " << which;
      if (p_dir > 0.0f && std::abs(double(p_dir) / s.pdf - 1.0) > 1e-3) ++mismatch[which];
      float t;
      if (r.intersect({o, s.dir}, 0.0f, infinity, t)) continue;
      ++strict_miss[which];
      const dvec3 oo(o), dd(s.dir), nrm = glm::normalize(glm::cross(e1, e2));
      const double h = std::abs(glm::dot(oo - c, nrm)), dist = double(s.dist);
      const double tol = 0x1p-20 * (dist / h) * (dist + glm::length(oo) + glm::length(c) + size);
      const double tt = glm::dot(c - oo, nrm) / glm::dot(dd, nrm);
      const dvec3 q = oo + tt * dd - c;
      const double a = glm::dot(q, e1) / glm::dot(e1, e1), b = glm::dot(q, e2) / glm::dot(e2, e2);
      const double ta = tol / glm::length(e1), tb = tol / glm::length(e2);
      if (ta >= 1.0 || tb >= 1.0) continue;
      ASSERT_TRUE(tt > 0.0 && a >= -ta && a <= 1.0 + ta && b >= -tb && b <= 1.0 + tb)
          << k << " " << which << ": direction misses the light by more than rounding: (s, t) = (" << a << ", " << b
          << "), tolerance " << ta << ", " << tb;
    }
  }
  for (int which = 0; which < 2; ++which) {
    std::cout << "[ fuzz     ] " << (which == 0 ? "exact   " : "bilinear") << ": " << samples[which] << " samples, "
              << none[which] << " without; " << strict_miss[which] << " float rect::intersect misses, all within rounding; "
              << mismatch[which] << " pdf(o, n, dir) != sample pdf beyond 1e-3\n";
    EXPECT_GT(samples[which], configs / 10);
  }
}

}  // namespace
