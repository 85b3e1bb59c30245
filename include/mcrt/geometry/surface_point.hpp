#pragma once
// Hit points of analytic shapes put back onto their surface, with a
// conservative bound on the distance that remains between the computed
// point and the true surface (hit_record::offset). The ray's own point
// o + t d is off the surface by the rounding of t, which grows with the
// ray's length (1e-3 for a camera 10^4 away); moving the point back onto
// the surface makes the bound depend only on the point's coordinates, as
// pbrt-v4 does for its spheres and disks (Pharr et al., "Physically Based
// Rendering", 4th ed., sec. 6.8.4-6.8.5). The bounds follow Higham's model
// of rounding, gamma(n) = n u / (1 - n u) per chain of n roundings
// (rounding_gamma, core/math.hpp).
#include "mcrt/core/math.hpp"

namespace mcrt {

// A point moved onto the plane dot(n, x) = plane, and its bound.
struct plane_point {
  vec3 p;
  float offset;  // a bound on |dot(n, p) - plane| in exact arithmetic
};

// p moved along the unit normal n onto the plane dot(n, x) = plane (the
// plane of the shape's intersection test, n and plane as stored: the
// surface a ray leaving p is tested against). The computed residual of the
// moved point, dot(n, q) - plane, is a dot of three products and one
// subtraction: within gamma(4) of the terms' magnitudes T of its true
// value, so q lies within |residual| + gamma(4) T of the plane. A ray
// leaving q is tested with the same computation at its origin (t = (plane
// - dot(n, o)) / dot(n, d), which must come out negative for a ray moving
// away), whose rounding is another gamma(4) T: the offset covers both, with
// one more gamma(1) T for n not being exactly of unit length (|n|^2 = 1
// within a few ulps, which scales how far the offset moves along n).
inline plane_point onto_plane(const vec3& p, const vec3& n, float plane) {
  const vec3 q = p - (glm::dot(n, p) - plane) * n;
  const float residual = glm::dot(n, q) - plane;
  const float terms = glm::dot(glm::abs(n), glm::abs(q)) + std::abs(plane);
  return {q, std::abs(residual) + rounding_gamma(9) * terms};
}

// A point on a sphere and its bound along the normal.
struct sphere_point {
  vec3 p;
  float offset;  // a bound on | |p - center| - radius | in exact arithmetic
};

// p moved radially onto the sphere of the given centre and radius: the
// local point p - center scaled to length radius (pbrt-v4's
// Sphere::BasicIntersect, whose bound for the scaled point is gamma(5) |p|
// in the sphere's frame, eq. 6.37), then moved back by the centre, one
// more rounding of each coordinate, gamma(1) |q| (the intersection test
// subtracts the centre again, gamma(1) of the local point: gamma(6) on
// it). The offset is twice the bound along the normal: a ray leaving q
// must start outside (or inside) the sphere by more than the rounding of
// the test it is put to, whose sign of c = |o - center|^2 - radius^2
// decides which side the origin is on and is computed to within about
// gamma(5) radius^2, less than the 2 radius gamma(6) radius by which the
// doubled offset moves it.
inline sphere_point onto_sphere(const vec3& p, const vec3& center, float radius) {
  vec3 local = p - center;
  local *= radius / glm::length(local);
  const vec3 q = center + local;
  const vec3 error = rounding_gamma(6) * glm::abs(local) + rounding_gamma(1) * glm::abs(q);
  // Along the normal local / radius: dot(|n|, error).
  return {q, 2.0f * glm::dot(glm::abs(local), error) / radius};
}

}  // namespace mcrt
