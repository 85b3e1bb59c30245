#pragma once
// A planar ellipse given by its centre and two orthogonal semi-axes; equal
// lengths make a disk.
#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/aabb.hpp"
#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/geometry/surface_point.hpp"

namespace mcrt {

struct ellipse {
  vec3 center{0.0f};
  vec3 a1{1.0f, 0.0f, 0.0f};  // first semi-axis
  vec3 a2{0.0f, 1.0f, 0.0f};  // second semi-axis, orthogonal to a1
  vec3 n{0.0f, 0.0f, 1.0f};   // unit normal of the front (emitting) side: +-normalize(a1 x a2)
  vec3 a1_dual{1.0f, 0.0f, 0.0f};  // a1 / |a1|^2
  vec3 a2_dual{0.0f, 1.0f, 0.0f};
  float plane = 0.0f;  // dot(n, center)
  float area = pi;     // pi |a1| |a2|

  static ellipse make(const vec3& center, const vec3& a1, const vec3& a2, bool flip = false) {
    ellipse e;
    e.center = center;
    e.a1 = a1;
    e.a2 = a2;
    const vec3 c = glm::cross(a1, a2);
    const float len = glm::length(c);
    e.n = (flip ? -1.0f : 1.0f) * (c / len);
    e.a1_dual = a1 / glm::dot(a1, a1);
    e.a2_dual = a2 / glm::dot(a2, a2);
    e.plane = glm::dot(e.n, center);
    e.area = pi * len;
    return e;
  }

  bool faces(const vec3& o) const { return glm::dot(o - center, n) > 0.0f; }

  // The tight box: along axis i the ellipse reaches sqrt(a1_i^2 + a2_i^2)
  // from its centre.
  aabb bounds() const {
    const vec3 reach = glm::sqrt(a1 * a1 + a2 * a2);
    return {center - reach, center + reach};
  }

  bool intersect(const ray& r, float tmin, float tmax, float& t) const {
    const float denom = glm::dot(n, r.d);
    t = (plane - glm::dot(n, r.o)) / denom;
    if (!(t > tmin && t < tmax)) return false;
    const vec3 q = r.at(t) - center;
    return sqr(glm::dot(q, a1_dual)) + sqr(glm::dot(q, a2_dual)) <= 1.0f;
  }

  // The hit record of a hit at t found by intersect(): the ray's point
  // moved onto the plane, with its error bound (surface_point.hpp).
  void surface(const ray& r, float t, hit_record& rec) const {
    rec.t = t;
    const plane_point q = onto_plane(r.at(t), n, plane);
    rec.p = q.p;
    rec.offset = q.offset;
    rec.n = n;
    rec.front_face = glm::dot(r.d, n) < 0.0f;
  }

  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    float t;
    if (!intersect(r, tmin, tmax, t)) return false;
    surface(r, t, rec);
    return true;
  }
};

}  // namespace mcrt
