#pragma once
// Orthonormal basis around a unit vector (Shirley, "The Rest of Your Life",
// sec. 7), built without branches on the axis by Duff et al. 2017,
// "Building an Orthonormal Basis, Revisited".
#include "mcrt/core/math.hpp"

namespace mcrt {

struct onb {
  vec3 u, v, w;  // w is the given axis

  explicit onb(const vec3& n) : w(n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    u = vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    v = vec3(b, sign + n.y * n.y * a, -n.y);
  }
  vec3 to_world(const vec3& a) const { return a.x * u + a.y * v + a.z * w; }
  vec3 to_local(const vec3& a) const { return {glm::dot(a, u), glm::dot(a, v), glm::dot(a, w)}; }
};

}  // namespace mcrt
