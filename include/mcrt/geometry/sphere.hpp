#pragma once
// Sphere (Shirley, "Ray Tracing in One Weekend", sec. 5-6).
#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/aabb.hpp"
#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/geometry/surface_point.hpp"

namespace mcrt {

struct sphere {
  vec3 center{0.0f};
  float radius = 1.0f;
  bool flip = false;  // front side inside instead of outside

  aabb bounds() const { return {center - vec3(radius), center + vec3(radius)}; }

  bool intersect(const ray& r, float tmin, float tmax, float& t) const {
    // Half-b form; the discriminant is computed from the distance of the ray
    // to the centre (Haines et al., "Precision Improvements for Ray/Sphere
    // Intersection", Ray Tracing Gems ch. 7), which stays accurate when the
    // sphere is small and far away.
    const vec3 oc = r.o - center;
    const float a = glm::dot(r.d, r.d);
    const float half_b = glm::dot(oc, r.d);
    const vec3 perp = oc - (half_b / a) * r.d;
    const float disc = a * (radius * radius - glm::dot(perp, perp));
    if (disc < 0.0f) return false;
    const float sq = std::sqrt(disc);
    // q = -(half_b + sign(half_b) sq) avoids cancellation; roots c/q and q/a.
    const float q = -(half_b + std::copysign(sq, half_b));
    const float c = glm::dot(oc, oc) - radius * radius;
    float t0 = q / a, t1 = c / q;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > tmin && t0 < tmax) {
      t = t0;
      return true;
    }
    if (t1 > tmin && t1 < tmax) {
      t = t1;
      return true;
    }
    return false;
  }

  // The hit record of a hit at t found by intersect(): the ray's point
  // moved onto the sphere, with its error bound (surface_point.hpp).
  void surface(const ray& r, float t, hit_record& rec) const {
    rec.t = t;
    const sphere_point q = onto_sphere(r.at(t), center, radius);
    rec.p = q.p;
    rec.offset = q.offset;
    const vec3 outward = (rec.p - center) / radius;
    rec.n = flip ? -outward : outward;
    rec.front_face = glm::dot(r.d, rec.n) < 0.0f;
  }

  // surface()'s front_face from the ray's own point, not moved onto the
  // sphere (the same side but within rounding of a grazing hit).
  bool front_face(const ray& r, float t) const {
    const float d = glm::dot(r.d, r.at(t) - center);
    return flip ? d > 0.0f : d < 0.0f;
  }

  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    float t;
    if (!intersect(r, tmin, tmax, t)) return false;
    surface(r, t, rec);
    return true;
  }
};

}  // namespace mcrt
