// Fuzz test of solid-angle sampling of ellipses, by the parallel map
// (sampling/spherical_ellipse.hpp) and by the polar map
// (sampling/spherical_ellipse_polar.hpp), each over 10^6 random configurations: axis ratios up to 1e4, observers from
// grazing (1e-7 of the distance) to far off-axis, either side, near and far.
// Every sample must be a finite unit direction that hits the ellipse (up to
// the float rounding of the direction), with a finite positive pdf equal to
// pdf(o, dir); where no sample is returned the observer must be behind and
// pdf 0.
#include <gtest/gtest.h>

#include <cmath>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_ellipse_polar.hpp"
#include "support/ellipse_cases.hpp"

namespace {

using namespace mcrt;

ellipse_cone_mode mode_of(const ellipse& e, const vec3& o) { return make_ellipse_cone(e, o).mode; }

using test::random_unit_vector;

template <class Sampler>
void fuzz(const char* map_name) {
  pcg32 rng(2024, 5);
  constexpr int configurations = 1'000'000;
  long no_sample = 0, ill_conditioned = 0, spherical = 0, far_misses = 0, rim_misses = 0;
  for (int i = 0; i < configurations; ++i) {
    // Ellipse: random orientation, size 10^[-3, 2], axis ratio 10^[0, 4].
    const vec3 u = random_unit_vector(rng);
    vec3 v = glm::normalize(glm::cross(u, random_unit_vector(rng)));
    if (!all_finite(v)) v = glm::normalize(glm::cross(u, vec3(0.3f, 0.5f, 0.8f)));
    const float r1 = std::pow(10.0f, -3.0f + 5.0f * rng.uniform());
    const float r2 = r1 * std::pow(10.0f, -4.0f * rng.uniform());
    const vec3 center = 10.0f * (2.0f * rng.uniform2().x - 1.0f) * random_unit_vector(rng);
    const ellipse e = ellipse::make(center, r1 * u, r2 * v, rng.uniform() < 0.5f);
    // Observer: distance 10^[-2, 3] times r1, direction mixing grazing ones in.
    vec3 dir = random_unit_vector(rng);
    const float kind = rng.uniform();
    if (kind < 0.25f) {  // grazing: height 10^[-7, -1] of the distance
      dir -= glm::dot(dir, e.n) * e.n;
      dir = glm::normalize(dir) + std::pow(10.0f, -7.0f + 6.0f * rng.uniform()) * (rng.uniform() < 0.8f ? e.n : -e.n);
      dir = glm::normalize(dir);
    }
    const vec3 o = center + r1 * std::pow(10.0f, -2.0f + 5.0f * rng.uniform()) * dir;
    const Sampler smp{e};
    light_sample s;
    const vec2 uu = rng.uniform2();
    if (!smp.sample(o, uu, s)) {
      ++no_sample;
      ASSERT_FALSE(smp.faces(o)) << i;
      ASSERT_EQ(smp.pdf(o, glm::normalize(center - o)), 0.0f) << i;
      continue;
    }
    ASSERT_TRUE(smp.faces(o)) << i;
    if (make_ellipse_cone(e, o).mode == ellipse_cone_mode::spherical) ++spherical;
    ASSERT_TRUE(all_finite(s.dir)) << i;
    ASSERT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.0f) << i;
    ASSERT_TRUE(std::isfinite(s.dist) && s.dist > 0.0f) << i;
    ASSERT_NEAR(glm::length(s.dir), 1.0f, 1e-5f) << i;
    // Hit test in double of the float direction; the tolerance is the float
    // rounding of the direction (~1.2e-7 rad) and of the observer and centre
    // (~6e-8 of their magnitude) projected on the ellipse's narrow axis.
    const dvec3 od(o), cd(e.center), nd(e.n), dd(s.dir);
    const double h = glm::dot(od - cd, nd), den = -glm::dot(dd, nd);
    if (den < 4e-7) {
      // The float direction is within its own rounding of parallel to the
      // plane (observers ~1e-7 from it): no hit test is meaningful.
      ++ill_conditioned;
      const float p = smp.pdf(o, s.dir);
      ASSERT_TRUE(std::isfinite(p) && p >= 0.0f) << i;
      continue;
    }
    const double t = h / den;
    const dvec3 q = od + t * dd - cd;
    const double x = glm::dot(q, dvec3(e.a1_dual)), y = glm::dot(q, dvec3(e.a2_dual));
    const double r = std::sqrt(x * x + y * y);
    const double slack = (5e-7 * t / den + 2e-7 * (glm::length(od) + glm::length(cd)) / den) / static_cast<double>(r2);
    if (r > 1.0 + slack) ++far_misses;
    const float p = smp.pdf(o, s.dir);
    ASSERT_TRUE(std::isfinite(p) && p >= 0.0f) << i;
    if (p == 0.0f) {
      ++rim_misses;  // float direction rounded off the rim
      ASSERT_LE(r, 1.0 + slack) << i << " mode " << int(make_ellipse_cone(e, o).mode) << " r1 " << r1 << " r2 " << r2 << " h/dist " << h / glm::length(od - cd) << " dist " << glm::length(od - cd) << " a " << make_ellipse_cone(e, o).se.a << " b " << make_ellipse_cone(e, o).se.b << " t " << t << " den " << den;
    } else if (mode_of(e, o) == ellipse_cone_mode::area && 4e-7 / den > 1e-5) {
      // Area fallback at grazing incidence: d^2 / (|cos| A) from a float
      // direction is conditioned by 1/|cos| (the hit point moves by
      // ~1e-7 t / |cos|); only finiteness and positivity are meaningful.
      ++ill_conditioned;
      ASSERT_GT(p, 0.0f) << i;
    } else {
      ASSERT_NEAR(p / s.pdf, 1.0f, 1e-4f) << i;
    }
  }
  EXPECT_EQ(far_misses, 0);
  // Rim misses (each already checked to lie within the float rounding of
  // the direction) and ill-conditioned grazing cases are only counted: the
  // fuzz draws slivers down to 1e-10 rad wide, far below float resolution.
  EXPECT_GT(spherical, configurations / 2);
  std::printf("%s map: no sample %ld, spherical map %ld, rim misses %ld, ill-conditioned area pdf %ld, of %d\n",
              map_name, no_sample, spherical, rim_misses, ill_conditioned, configurations);
}

TEST(SphericalEllipseSlow, FuzzParallel) { fuzz<ellipse_solid_angle_sampler>("parallel"); }
TEST(SphericalEllipseSlow, FuzzPolar) { fuzz<ellipse_polar_solid_angle_sampler>("polar"); }

}  // namespace
