#pragma once
// Axis-aligned box, optionally rotated about y and translated (Shirley, "The
// Next Week", sec. 7-8: the tall box of the Cornell scenes). Intersected as
// one shape with the slab test (Kay & Kajiya 1986) in its own frame, not as
// six rectangles.
#include "mcrt/geometry/aabb.hpp"
#include "mcrt/geometry/transform.hpp"

namespace mcrt {

struct box {
  vec3 lo{0.0f}, hi{1.0f};
  rigid_y xf{};
  bool flip = false;  // front side inside instead of outside

  // The box of the eight corners in the world.
  aabb bounds() const {
    aabb b;
    for (int c = 0; c < 8; ++c) b.grow(xf.to_world({(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z}));
    return b;
  }

  bool intersect(const ray& world_ray, float tmin, float tmax, float& t) const {
    const ray r = xf.to_local(world_ray);
    const vec3 inv = 1.0f / r.d;
    const vec3 ta = (lo - r.o) * inv, tb = (hi - r.o) * inv;
    const vec3 tnear = glm::min(ta, tb), tfar = glm::max(ta, tb);
    const float t0 = std::max(std::max(tnear.x, tnear.y), tnear.z);
    const float t1 = std::min(std::min(tfar.x, tfar.y), tfar.z);
    if (!(t0 <= t1)) return false;
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

  // The hit record of a hit at t found by intersect(): the face is the one
  // whose plane the local hit point is nearest to, relative to the box size.
  // The hit point is that local point moved onto the face's plane exactly,
  // then to the world, with the bound of that transform's rounding in the
  // record's offset: the ray's own point o + t d may lie inside the box by
  // its rounding (1e-5 of a 500-unit scene), and a ray leaving a face at a
  // grazing angle from there would meet the box again.
  void surface(const ray& world_ray, float t, hit_record& rec) const {
    vec3 p = xf.to_local(world_ray.at(t));
    int axis;
    float sign;
    face_of(p, axis, sign);
    vec3 local_n(0.0f);
    local_n[axis] = sign;
    p[axis] = sign < 0.0f ? lo[axis] : hi[axis];
    rec.t = t;
    rec.p = xf.to_world(p);
    const vec3 outward = xf.rotate(local_n);
    // Twice the bound of the world point's rounding: once for where the
    // point truly lies, once for the rounding of the move back to the box's
    // frame that a leaving ray's slab test makes (the inverse rigid motion,
    // the same magnitudes), so that its origin lands outside the face (or
    // inside, for a ray going in) in the box's frame too.
    rec.offset = 2.0f * glm::dot(glm::abs(outward), xf.to_world_error(p));
    rec.n = flip ? -outward : outward;
    rec.front_face = glm::dot(world_ray.d, rec.n) < 0.0f;
  }

  // surface()'s front_face alone (the face and its normal, not the point
  // or its bound).
  bool front_face(const ray& world_ray, float t) const {
    int axis;
    float sign;
    face_of(xf.to_local(world_ray.at(t)), axis, sign);
    vec3 local_n(0.0f);
    local_n[axis] = sign;
    const vec3 outward = xf.rotate(local_n);
    return glm::dot(world_ray.d, flip ? -outward : outward) < 0.0f;
  }

  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    float t;
    if (!intersect(r, tmin, tmax, t)) return false;
    surface(r, t, rec);
    return true;
  }

 private:
  // The face of the local point p: the one whose plane p is nearest to,
  // relative to the box's size (axis, and sign -1 for lo, +1 for hi).
  void face_of(const vec3& p, int& axis, float& sign) const {
    const vec3 size = hi - lo;
    const vec3 dlo = glm::abs(p - lo) / size, dhi = glm::abs(p - hi) / size;
    axis = 0;
    sign = 0.0f;
    float best = infinity;
    for (int i = 0; i < 3; ++i) {
      if (dlo[i] < best) best = dlo[i], axis = i, sign = -1.0f;
      if (dhi[i] < best) best = dhi[i], axis = i, sign = 1.0f;
    }
  }
};

}  // namespace mcrt
