#pragma once
// Uniform sampling of an ellipse by area (A. Checa Molina, "Visualizacion
// realista por Monte-Carlo", undergraduate thesis, Universidad de Granada,
// 2020, sec. 4.2): the polar map
// X = c + sqrt(u1) cos(2 pi u2) a1 + sqrt(u1) sin(2 pi u2) a2, whose Jacobian
// is constant thanks to the square root; density 1/(pi |a1| |a2|) per unit
// area, d^2 / (|cos| A) per unit solid angle.
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

inline vec3 square_to_ellipse(vec2 u, const ellipse& e) {
  const float r = std::sqrt(u.x), phi = two_pi * u.y;
  return e.center + (r * std::cos(phi)) * e.a1 + (r * std::sin(phi)) * e.a2;
}
// Density per unit AREA on the ellipse.
inline float square_to_ellipse_pdf(const ellipse& e) { return 1.0f / e.area; }
inline vec2 ellipse_to_square(const vec3& p, const ellipse& e) {
  const vec3 q = p - e.center;
  const float x = glm::dot(q, e.a1_dual), y = glm::dot(q, e.a2_dual);
  float phi = std::atan2(y, x);
  if (phi < 0.0f) phi += two_pi;
  return {x * x + y * y, phi / two_pi};
}

// Light-sampling strategy: uniform by area, one-sided.
struct ellipse_area_sampler {
  ellipse shape;

  bool faces(const vec3& o) const { return shape.faces(o); }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const float h = glm::dot(o - shape.center, shape.n);
    if (!(h > 0.0f)) return false;
    const vec3 v = square_to_ellipse(u, shape) - o;
    const float d2 = glm::dot(v, v);
    s.dist = std::sqrt(d2);
    s.dir = v / s.dist;
    s.pdf = area_to_solid_angle(square_to_ellipse_pdf(shape), d2, h / s.dist);
    return std::isfinite(s.pdf) && s.pdf > 0.0f;
  }

  // Density per unit SOLID ANGLE at o of the direction dir (unit).
  float pdf(const vec3& o, const vec3& dir) const {
    const float h = glm::dot(o - shape.center, shape.n);
    float t;
    if (!(h > 0.0f) || !shape.intersect({o, dir}, 0.0f, infinity, t)) return 0.0f;
    return area_to_solid_angle(square_to_ellipse_pdf(shape), t * t, h / t);
  }
};

}  // namespace mcrt
