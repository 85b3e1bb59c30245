#pragma once
// Axis-aligned box, optionally rotated about y and translated (Shirley, "The
// Next Week", sec. 7-8: the tall box of the Cornell scenes). Intersected as
// one shape with the slab test (Kay & Kajiya 1986) in its own frame, not as
// six rectangles.
#include "mcrt/geometry/transform.hpp"

namespace mcrt {

struct box {
  vec3 lo{0.0f}, hi{1.0f};
  rigid_y xf{};
  bool flip = false;  // front side inside instead of outside

  bool hit(const ray& world_ray, float tmin, float tmax, hit_record& rec) const {
    const ray r = xf.to_local(world_ray);
    const vec3 inv = 1.0f / r.d;
    const vec3 ta = (lo - r.o) * inv, tb = (hi - r.o) * inv;
    const vec3 tnear = glm::min(ta, tb), tfar = glm::max(ta, tb);
    const float t0 = std::max(std::max(tnear.x, tnear.y), tnear.z);
    const float t1 = std::min(std::min(tfar.x, tfar.y), tfar.z);
    if (!(t0 <= t1)) return false;
    float t;
    vec3 tsel;
    if (t0 > tmin && t0 < tmax) {
      t = t0;
      tsel = tnear;
    } else if (t1 > tmin && t1 < tmax) {
      t = t1;
      tsel = tfar;
    } else {
      return false;
    }
    // Outward normal of the face whose slab gave t.
    vec3 local_n{0.0f};
    const int axis = (tsel.x == t) ? 0 : (tsel.y == t) ? 1 : 2;
    local_n[axis] = r.d[axis] < 0.0f ? 1.0f : -1.0f;
    if (t == t1 && t != t0) local_n[axis] = -local_n[axis];  // leaving through the far face
    rec.t = t;
    rec.p = world_ray.at(t);
    const vec3 outward = xf.rotate(local_n);
    rec.n = flip ? -outward : outward;
    rec.front_face = glm::dot(world_ray.d, rec.n) < 0.0f;
    return true;
  }
};

}  // namespace mcrt
