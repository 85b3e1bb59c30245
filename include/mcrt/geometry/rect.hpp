#pragma once
// A rectangle given by a corner and two orthogonal edges. The axis-aligned
// rectangles of Shirley's "The Next Week" (sec. 7), xz_rect, xy_rect and
// yz_rect, are made by the factories at the end of this header; they are the
// same shape, so every sampling strategy serves all of them.
#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/aabb.hpp"
#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/geometry/surface_point.hpp"

namespace mcrt {

struct rect {
  vec3 corner{0.0f};
  vec3 e1{1.0f, 0.0f, 0.0f};  // first edge
  vec3 e2{0.0f, 1.0f, 0.0f};  // second edge, orthogonal to e1
  vec3 n{0.0f, 0.0f, 1.0f};   // unit normal of the front (emitting) side: +-normalize(e1 x e2)
  // Derived by make(); kept so hit() is a handful of multiply-adds.
  vec3 e1_dual{1.0f, 0.0f, 0.0f};  // e1 / |e1|^2, so dot(p - corner, e1_dual) is in [0,1] inside
  vec3 e2_dual{0.0f, 1.0f, 0.0f};
  float plane = 0.0f;  // dot(n, corner)
  float area = 1.0f;

  // front = +normalize(cross(e1, e2)), reversed when flip is true.
  static rect make(const vec3& corner, const vec3& e1, const vec3& e2, bool flip = false) {
    rect r;
    r.corner = corner;
    r.e1 = e1;
    r.e2 = e2;
    const vec3 c = glm::cross(e1, e2);
    r.area = glm::length(c);
    r.n = (flip ? -1.0f : 1.0f) * (c / r.area);
    r.e1_dual = e1 / glm::dot(e1, e1);
    r.e2_dual = e2 / glm::dot(e2, e2);
    r.plane = glm::dot(r.n, corner);
    return r;
  }

  vec3 center() const { return corner + 0.5f * (e1 + e2); }

  // The box of the four corners.
  aabb bounds() const {
    aabb b;
    for (const vec3& p : {corner, corner + e1, corner + e2, corner + e1 + e2}) b.grow(p);
    return b;
  }

  // Is o strictly on the front side of the rectangle's plane?
  bool faces(const vec3& o) const { return glm::dot(o - corner, n) > 0.0f; }

  // Ray parameter of the hit with the rectangle in (tmin, tmax), either side.
  bool intersect(const ray& r, float tmin, float tmax, float& t) const {
    const float denom = glm::dot(n, r.d);
    t = (plane - glm::dot(n, r.o)) / denom;  // +-inf or NaN when parallel: rejected below
    if (!(t > tmin && t < tmax)) return false;
    const vec3 q = r.at(t) - corner;
    const float a = glm::dot(q, e1_dual), b = glm::dot(q, e2_dual);
    return a >= 0.0f && a <= 1.0f && b >= 0.0f && b <= 1.0f;
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

// Shirley's axis-aligned rectangles. Front normals: xz +y, xy +z, yz +x.
inline rect xz_rect(float x0, float x1, float z0, float z1, float k, bool flip = false) {
  return rect::make({x0, k, z0}, {0.0f, 0.0f, z1 - z0}, {x1 - x0, 0.0f, 0.0f}, flip);
}
inline rect xy_rect(float x0, float x1, float y0, float y1, float k, bool flip = false) {
  return rect::make({x0, y0, k}, {x1 - x0, 0.0f, 0.0f}, {0.0f, y1 - y0, 0.0f}, flip);
}
inline rect yz_rect(float y0, float y1, float z0, float z1, float k, bool flip = false) {
  return rect::make({k, y0, z0}, {0.0f, y1 - y0, 0.0f}, {0.0f, 0.0f, z1 - z0}, flip);
}

}  // namespace mcrt
