#pragma once
// Instancing (Shirley, "The Next Week", sec. 8): a shape is intersected in
// its own frame by moving the ray there, instead of moving the shape.
// rigid_y is Shirley's rotate_y followed by translate; transformed<S> wraps
// any shape that has hit().
#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/hit_record.hpp"

namespace mcrt {

// x_world = R_y(angle) x_local + offset.
struct rigid_y {
  float cos_t = 1.0f, sin_t = 0.0f;
  vec3 offset{0.0f};

  static rigid_y make(float degrees, const vec3& offset) {
    const float r = glm::radians(degrees);
    return {std::cos(r), std::sin(r), offset};
  }
  vec3 rotate(const vec3& v) const {  // local -> world direction
    return {cos_t * v.x + sin_t * v.z, v.y, -sin_t * v.x + cos_t * v.z};
  }
  vec3 unrotate(const vec3& v) const {  // world -> local direction
    return {cos_t * v.x - sin_t * v.z, v.y, sin_t * v.x + cos_t * v.z};
  }
  vec3 to_world(const vec3& p) const { return rotate(p) + offset; }
  // A bound on the rounding error of each component of to_world(p): two
  // products, a sum and the offset's sum per component, gamma(3) of the
  // terms' magnitudes (pbrt-v4's Transform applied with error), with one
  // more rounding for the float cosine and sine, whose rotation is not
  // exactly orthogonal.
  vec3 to_world_error(const vec3& p) const {
    const float g = rounding_gamma(4);
    return g * vec3(std::abs(cos_t * p.x) + std::abs(sin_t * p.z) + std::abs(offset.x), std::abs(p.y) + std::abs(offset.y),
                    std::abs(sin_t * p.x) + std::abs(cos_t * p.z) + std::abs(offset.z));
  }
  vec3 to_local(const vec3& p) const { return unrotate(p - offset); }
  ray to_local(const ray& r) const { return {to_local(r.o), unrotate(r.d)}; }
};

template <class Shape>
struct transformed {
  Shape shape;
  rigid_y xf;

  // A rigid motion keeps t: intersect in the shape's frame.
  bool intersect(const ray& r, float tmin, float tmax, float& t) const {
    return shape.intersect(xf.to_local(r), tmin, tmax, t);
  }

  // The hit record of a hit at t, moved back to the world: the shape's
  // point in its frame, moved by the rigid motion, with the shape's own
  // bound plus twice the motion's rounding (once for the world point, once
  // for the move back a leaving ray's test makes; see box.hpp).
  void surface(const ray& r, float t, hit_record& rec) const {
    shape.surface(xf.to_local(r), t, rec);
    const vec3 local_p = rec.p;
    rec.p = xf.to_world(local_p);
    rec.n = xf.rotate(rec.n);
    rec.offset += 2.0f * glm::dot(glm::abs(rec.n), xf.to_world_error(local_p));
  }

  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    float t;
    if (!intersect(r, tmin, tmax, t)) return false;
    surface(r, t, rec);
    return true;
  }
};

}  // namespace mcrt
