#pragma once
// Uniform sampling of a triangle by area, converted to a density per unit
// solid angle at the observer by d^2 / (|cos| A) (Shirley, "The Rest of Your
// Life", sec. 9; Veach 1997, eq. 8.10). The map from the unit square is
// Turk's square-root map (Graphics Gems, 1990; Pharr et al., "Physically
// Based Rendering", 3rd ed., sec. 13.6.5): b0 = 1 - sqrt(u1), b1 = u2
// sqrt(u1), which is area-preserving and has the closed-form inverse
// u1 = (1 - b0)^2, u2 = b1 / (1 - b0).
#include <cfloat>
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
    // The point relative to o from p0 - o and the edges: their rounding is
    // relative to the triangle's size and distance, where b0 p0 + b1 p1 +
    // b2 p2 - o rounds relative to the coordinates' magnitude (a triangle
    // 1e-5 of its coordinates in size had 5-18 % of its samples' directions
    // miss it once rounded: bench/triangle_nan_hunt.cpp).
    const vec3 v = (p0 - o) + b.y * (p1 - p0) + (1.0f - b.x - b.y) * (p2 - p0);
    const float d2 = glm::dot(v, v);
    s.dist = std::sqrt(d2);
    s.dir = v / s.dist;
    // |cos| at the light = h / dist, from the height, as pdf() computes it.
    s.pdf = area_to_solid_angle(square_to_triangle_pdf(area), d2, h / s.dist);
    return std::isfinite(s.pdf) && s.pdf > 0.0f;
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir: the ray
  // meets the plane at t = h / -(dir . n), in double, relative to p0, and
  // the point is tested against the three edges there. (In float, with the
  // scene's watertight ray test, the directions sample() returns missed
  // the triangle at 15 % of the far observers of bench/triangle_nan_hunt's
  // slivers, whose width is below the float spacing of their coordinates,
  // and at 66 % of those within 1e-6 of its size from its plane.)
  float pdf(const vec3& o, const vec3& dir) const {
    using dvec = glm::dvec3;
    const dvec q(dvec(o) - dvec(p0)), nd(n), dd(dir);
    const double h = glm::dot(q, nd);
    if (!(h > 0.0)) return 0.0f;
    const double dz = glm::dot(dd, nd);
    if (!(dz < 0.0)) return 0.0f;
    const double t = h / -dz;
    const dvec x = q + t * dd;  // the hit point relative to p0
    const dvec e1 = dvec(p1) - dvec(p0), e2 = dvec(p2) - dvec(p0), ng = glm::cross(e1, e2);
    // Edge functions of the three edges (p0 p1, p1 p2, p2 p0) about ng: the
    // same sign (or 0, on an edge) inside.
    const double c0 = glm::dot(glm::cross(e1, x), ng), c1 = glm::dot(glm::cross(e2 - e1, x - e1), ng),
                 c2 = glm::dot(glm::cross(-e2, x - e2), ng);
    if (!((c0 >= 0.0 && c1 >= 0.0 && c2 >= 0.0) || (c0 <= 0.0 && c1 <= 0.0 && c2 <= 0.0))) {
      // Off by rounding at an edge: the scene's own watertight ray test,
      // which takes the edge's points (a sample on the edge, whose float
      // direction the double test puts just outside it).
      if (!intersect_triangle({o, dir}, infinity, p0, p1, p2)) return 0.0f;
    }
    const double p = t * t * t / (double(area) * h);  // t^2 / (A cos), cos = h / t
    return p <= double(FLT_MAX) ? float(p) : 0.0f;
  }
};

}  // namespace mcrt
