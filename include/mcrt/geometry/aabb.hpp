#pragma once
// Axis-aligned bounding boxes, and the bounds of each shape of the library
// (what an acceleration structure knows of its primitives).
#include <algorithm>
#include <cmath>

#include "mcrt/core/math.hpp"

namespace mcrt {

// An axis-aligned box; empty when lo > hi.
struct aabb {
  vec3 lo{infinity}, hi{-infinity};

  void grow(const vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
  // Halves first: lo + hi overflows to infinity for coordinates beyond
  // FLT_MAX / 2, which are valid (a vertex at 3.4e38).
  vec3 centroid() const { return 0.5f * lo + 0.5f * hi; }
  float surface_area() const {
    if (empty()) return 0.0f;
    const vec3 d = hi - lo;
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
  int longest_axis() const {
    const vec3 d = hi - lo;
    return d.x > d.y ? (d.x > d.z ? 0 : 2) : (d.y > d.z ? 1 : 2);
  }
};

}  // namespace mcrt
