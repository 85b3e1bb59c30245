#pragma once
// What a ray-surface intersection reports (Shirley, "Ray Tracing in One
// Weekend", sec. 6).
#include <cstdint>

#include "mcrt/core/math.hpp"

namespace mcrt {

struct hit_record {
  vec3 p{0.0f};       // hit point
  vec3 n{0.0f};       // unit normal of the surface's front side (after any flip)
  float t = 0.0f;     // ray parameter of the hit
  std::uint32_t material = 0;
  bool front_face = true;  // the ray arrives at the front side: dot(d, n) < 0

  // The unit normal on the side the ray came from (shading normal).
  vec3 facing_normal() const { return front_face ? n : -n; }
};

}  // namespace mcrt
