#pragma once
// Uniform sampling of a rectangle by area (Shirley, "The Rest of Your Life",
// sec. 9; A. Checa Molina, "Visualizacion realista por Monte-Carlo",
// undergraduate thesis, Universidad de Granada, 2020, sec. 4.1):
// X = corner + u1 e1 + u2 e2, with density 1/A per unit area, converted to a
// density per unit solid angle at the observer by d^2 / (|cos| A).
#include "mcrt/geometry/rect.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

inline vec3 square_to_rect(vec2 u, const rect& r) { return r.corner + u.x * r.e1 + u.y * r.e2; }
// Density per unit AREA on the rectangle.
inline float square_to_rect_pdf(const rect& r) { return 1.0f / r.area; }
inline vec2 rect_to_square(const vec3& p, const rect& r) {
  const vec3 q = p - r.corner;
  return {glm::dot(q, r.e1_dual), glm::dot(q, r.e2_dual)};
}

// Light-sampling strategy: uniform by area. One-sided: an observer on the
// back of the rectangle gets no sample (the light emits nothing there).
struct rect_area_sampler {
  rect shape;

  bool faces(const vec3& o) const { return shape.faces(o); }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const float h = glm::dot(o - shape.corner, shape.n);  // height above the plane
    if (!(h > 0.0f)) return false;
    const vec3 v = square_to_rect(u, shape) - o;
    const float d2 = glm::dot(v, v);
    s.dist = std::sqrt(d2);
    s.dir = v / s.dist;
    // |cos| at the light = h / dist, computed from the height, not from the
    // rounded direction, so sample() and pdf() agree to the last bits.
    s.pdf = area_to_solid_angle(square_to_rect_pdf(shape), d2, h / s.dist);
    return std::isfinite(s.pdf) && s.pdf > 0.0f;
  }

  // Density per unit SOLID ANGLE at o of the direction dir (unit).
  float pdf(const vec3& o, const vec3& dir) const {
    const float h = glm::dot(o - shape.corner, shape.n);
    float t;
    if (!(h > 0.0f) || !shape.intersect({o, dir}, 0.0f, infinity, t)) return 0.0f;
    return area_to_solid_angle(square_to_rect_pdf(shape), t * t, h / t);
  }
};

}  // namespace mcrt
