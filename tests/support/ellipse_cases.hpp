#pragma once
// What the tests of the ellipse's solid-angle samplers share: the battery of
// normal and extreme configurations (an ellipse and an observer each), the
// density a sampler claims recomputed in double, and random unit vectors for
// the fuzz tests.
#include <cmath>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"

namespace mcrt::test {

struct ellipse_case {
  std::string name;
  ellipse shape;
  vec3 o;
};

// An ellipse with semi-axes r1, r2 in an arbitrary orientation (rotation by
// `angle` about `axis`), observer at `o_local` in the ellipse's frame
// (x along a1, y along a2, z along the front normal), shifted by `shift`.
inline ellipse_case make_ellipse_case(std::string name, float r1, float r2, vec3 o_local, vec3 axis = {0, 0, 1},
                                      float angle = 0, vec3 shift = {0, 0, 0}, bool flip = false) {
  const glm::mat3 rot = glm::mat3(glm::rotate(glm::mat4(1.0f), angle, glm::normalize(axis)));
  const vec3 ex = rot * vec3(1, 0, 0), ey = rot * vec3(0, 1, 0), ez = rot * vec3(0, 0, 1);
  ellipse_case c;
  c.name = std::move(name);
  c.shape = ellipse::make(shift, r1 * ex, r2 * ey, flip);
  const vec3 front = flip ? -ez : ez;
  c.o = shift + o_local.x * ex + o_local.y * ey + o_local.z * front;
  return c;
}

// Normal and extreme configurations; the names say which.
inline std::vector<ellipse_case> ellipse_battery() {
  const vec3 tilt{0.3f, -0.8f, 0.5f};
  return {
      make_ellipse_case("disk_overhead", 1, 1, {0, 0, 2}),
      make_ellipse_case("disk_offaxis", 1, 1, {1.5f, 0.7f, 0.8f}, tilt, 0.7f, {3, -2, 5}),
      make_ellipse_case("ellipse_3to1_tilted", 3, 1, {0.5f, 2.0f, 1.5f}, tilt, 1.9f, {-1, 4, 2}),
      make_ellipse_case("ellipse_flipped", 2, 0.5f, {0.2f, 0.1f, 0.6f}, tilt, 2.4f, {0, 1, 0}, true),
      make_ellipse_case("ellipse_10to1_close", 1, 0.1f, {0.2f, 0.05f, 0.3f}, tilt, 0.9f),
      make_ellipse_case("disk_close_near_2pi", 1, 1, {0.1f, 0, 1e-3f}),
      make_ellipse_case("disk_far_offaxis", 1, 1, {60, 25, 1}),
      make_ellipse_case("disk_tiny_1em8sr", 5.64e-5f, 5.64e-5f, {0, 0, 1}),
      make_ellipse_case("disk_grazing_1em6", 1, 1, {3, 0, 3e-6f}),
      make_ellipse_case("disk_grazing_1em6_near_rim", 1, 1, {1.1f, 0, 1.1e-6f}),
      make_ellipse_case("ratio_1e2", 1, 1e-2f, {0.3f, 0.1f, 1}, tilt, 0.4f),
      make_ellipse_case("ratio_1e3", 1, 1e-3f, {0.3f, 0.1f, 1}, tilt, 1.1f),
      make_ellipse_case("ratio_1e4", 1, 1e-4f, {0.3f, 0.1f, 1}),
      make_ellipse_case("ratio_1e4_side", 1e-4f, 1, {0.3f, 0.1f, 1}),
      make_ellipse_case("ratio_1e3_grazing", 1, 1e-3f, {2, 0.5f, 1e-3f}),
      make_ellipse_case("ratio_1e4_grazing_fallback", 1e-4f, 1, {0, 2, 1e-4f}),
      make_ellipse_case("ratio_1e4_tiny_1em8sr", 5.64e-3f, 5.64e-7f, {0.3f, 0.7f, 0.8f}),
  };
}

// The configurations of ellipse_battery() with the given names.
inline std::vector<ellipse_case> ellipse_cases_named(const std::vector<std::string>& names) {
  std::vector<ellipse_case> out;
  for (const ellipse_case& c : ellipse_battery())
    for (const std::string& n : names)
      if (c.name == n) out.push_back(c);
  return out;
}

// Density claimed by a solid-angle sampler of e whose cone carries the solid
// angle of Solver, in double: the same mode decision, then 1/Omega on the
// ellipse (a double hit test) or the area density.
template <class Solver = newton_carlson_solver>
double ellipse_pdf_double(const ellipse& e, const vec3& o, const dvec3& dir) {
  const ellipse_cone cone = make_ellipse_cone<Solver>(e, o);
  if (cone.mode == ellipse_cone_mode::none) return 0.0;
  const dvec3 n(e.n), od(o), c(e.center);
  const double h = glm::dot(od - c, n), den = -glm::dot(dir, n);
  if (!(den > 0.0)) return 0.0;
  const double t = h / den;
  const dvec3 q = od + t * dir - c;
  const double x = glm::dot(q, dvec3(e.a1_dual)), y = glm::dot(q, dvec3(e.a2_dual));
  // 1e-5 of slack in r^2: a float direction sampled on the rim can round
  // to just outside it (the mass of that band is ~1e-5 of the light's).
  if (x * x + y * y > 1.0 + 1e-5) return 0.0;
  if (cone.mode == ellipse_cone_mode::spherical) return 1.0 / cone.omega;
  return t * t / (den * static_cast<double>(e.area));  // d^2 / (|cos| A) with |cos| = den
}

// A uniformly distributed unit vector (rejection from the cube).
inline vec3 random_unit_vector(pcg32& rng) {
  for (;;) {
    const vec3 d{2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f};
    const float l2 = glm::dot(d, d);
    if (l2 > 1e-4f && l2 <= 1.0f) return d / std::sqrt(l2);
  }
}

}  // namespace mcrt::test
