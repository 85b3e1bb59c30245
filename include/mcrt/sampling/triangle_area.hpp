#pragma once
// Uniform sampling of a triangle by area, converted to a density per unit
// solid angle at the observer by d^2 / (|cos| A) (Shirley, "The Rest of Your
// Life", sec. 9; Veach 1997, eq. 8.10). The map from the unit square is
// Turk's square-root map (Graphics Gems, 1990; Pharr et al., "Physically
// Based Rendering", 3rd ed., sec. 13.6.5): b0 = 1 - sqrt(u1), b1 = u2
// sqrt(u1), which is area-preserving and has the closed-form inverse
// u1 = (1 - b0)^2, u2 = b1 / (1 - b0).
#include <cmath>

#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

// u in [0,1)^2 -> barycentric coordinates (b0, b1), b2 = 1 - b0 - b1.
inline vec2 square_to_triangle(vec2 u) {
  const float s = std::sqrt(u.x);
  return {1.0f - s, u.y * s};
}
// Density per unit AREA of the triangle, for the barycentric map above.
inline float square_to_triangle_pdf(float area) { return 1.0f / area; }
// The inverse: barycentric (b0, b1) -> the unit square.
inline vec2 triangle_to_square(vec2 b) {
  const float s = 1.0f - b.x;
  return {s * s, s > 0.0f ? b.y / s : 0.0f};
}

// Light-sampling strategy: uniform by area over one triangle of a mesh.
// One-sided: an observer behind the front side gets no sample.
struct triangle_area_sampler {
  triangle shape;
  // Fixed after construction: the vertices, front normal and area.
  vec3 p0{0.0f}, p1{0.0f}, p2{0.0f}, n{0.0f, 0.0f, 1.0f};
  float area = 0.0f;

  // back: sample the triangle's back side instead (the other half of a
  // two-sided light).
  explicit triangle_area_sampler(const triangle& t, bool back = false)
      : shape(t), p0(t.vertex(0)), p1(t.vertex(1)), p2(t.vertex(2)), n(back ? -t.normal() : t.normal()), area(t.area()) {}

  bool faces(const vec3& o) const { return glm::dot(o - p0, n) > 0.0f; }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const float h = glm::dot(o - p0, n);  // height above the plane
    if (!(h > 0.0f)) return false;
    const vec2 b = square_to_triangle(u);
    const vec3 v = b.x * p0 + b.y * p1 + (1.0f - b.x - b.y) * p2 - o;
    const float d2 = glm::dot(v, v);
    s.dist = std::sqrt(d2);
    s.dir = v / s.dist;
    // |cos| at the light = h / dist, from the height, as pdf() computes it.
    s.pdf = area_to_solid_angle(square_to_triangle_pdf(area), d2, h / s.dist);
    return std::isfinite(s.pdf) && s.pdf > 0.0f;
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir.
  float pdf(const vec3& o, const vec3& dir) const {
    const float h = glm::dot(o - p0, n);
    if (!(h > 0.0f)) return 0.0f;
    const std::optional<triangle_hit> hit = intersect_triangle({o, dir}, infinity, p0, p1, p2);
    if (!hit) return 0.0f;
    return area_to_solid_angle(square_to_triangle_pdf(area), hit->t * hit->t, h / hit->t);
  }
};

}  // namespace mcrt
