#pragma once
// Shirley's axis-aligned rectangles ("The Next Week", sec. 7) as a shape of
// their own for intersection: the plane is a coordinate plane, so a hit
// costs one division and four comparisons instead of the general rectangle's
// dot products. The same rectangle as a general `rect` (geometry/rect.hpp)
// is what the light samplers use; to_rect() converts.
#include "mcrt/geometry/rect.hpp"

namespace mcrt {

// Axis is the plane's normal axis: 0 (yz_rect, x = k), 1 (xz_rect, y = k),
// 2 (xy_rect, z = k). The in-plane axes are a = (Axis+1)%3, b = (Axis+2)%3,
// with a in [a0, a1] and b in [b0, b1]. Front normal: +Axis, or -Axis when
// flipped.
template <int Axis>
struct axis_rect {
  static constexpr int a = (Axis + 1) % 3, b = (Axis + 2) % 3;
  float a0 = 0.0f, a1 = 1.0f, b0 = 0.0f, b1 = 1.0f, k = 0.0f;
  bool flip = false;

  vec3 normal() const {
    vec3 n(0.0f);
    n[Axis] = flip ? -1.0f : 1.0f;
    return n;
  }

  // The same rectangle as a general one, with the same front side.
  rect to_rect() const {
    vec3 c, ea(0.0f), eb(0.0f);
    c[Axis] = k;
    c[a] = a0;
    c[b] = b0;
    ea[a] = a1 - a0;
    eb[b] = b1 - b0;
    return rect::make(c, ea, eb, flip);  // cross(e_a, e_b) = +e_Axis for the cyclic order
  }

  bool intersect(const ray& r, float tmin, float tmax, float& t) const {
    t = (k - r.o[Axis]) / r.d[Axis];  // +-inf or NaN when parallel: rejected below
    const float pa = r.o[a] + t * r.d[a], pb = r.o[b] + t * r.d[b];
    // Non-short-circuit '&': one well-predicted branch instead of six.
    return (t > tmin) & (t < tmax) & (pa >= a0) & (pa <= a1) & (pb >= b0) & (pb <= b1);
  }

  // The hit record of a hit at t found by intersect().
  void surface(const ray& r, float t, hit_record& rec) const {
    rec.t = t;
    rec.p = r.at(t);
    // Exactly on the plane, so no error bound: a ray leaving it has t = 0
    // for this plane, which the test's t > tmin = 0 rejects.
    rec.p[Axis] = k;
    rec.offset = 0.0f;
    rec.n = normal();
    rec.front_face = (r.d[Axis] < 0.0f) != flip;
  }

  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    float t;
    if (!intersect(r, tmin, tmax, t)) return false;
    surface(r, t, rec);
    return true;
  }
};

using yz_rect_shape = axis_rect<0>;
using xz_rect_shape = axis_rect<1>;
using xy_rect_shape = axis_rect<2>;

}  // namespace mcrt
