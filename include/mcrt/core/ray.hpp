#pragma once
// A ray o + t d (Shirley, "Ray Tracing in One Weekend", sec. 4). The direction
// is not required to be unit length unless a function says so.
#include "mcrt/core/math.hpp"

namespace mcrt {

struct ray {
  vec3 o{0.0f};
  vec3 d{0.0f, 0.0f, 1.0f};
  constexpr vec3 at(float t) const { return o + t * d; }
};

}  // namespace mcrt
