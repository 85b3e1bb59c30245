#pragma once
// What a ray-surface intersection reports (Shirley, "Ray Tracing in One
// Weekend", sec. 6).
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "mcrt/core/math.hpp"

namespace mcrt {

namespace detail {

// v one float further in the direction of off's sign (v itself where off
// is 0, or where v is an infinity of off's sign): pbrt-v4's NextFloatUp for off > 0 and
// NextFloatDown for off < 0, with one branch fewer. In a float's bits a
// step away from zero is +1 and a step towards it -1, so the step is +1
// where v and off have the same sign and -1 where they differ; a zero v
// becomes the smallest denormal of off's sign.
inline float step_away(float v, float off) {
  if (off == 0.0f) return v;
  if (v == 0.0f) return std::copysign(std::numeric_limits<float>::denorm_min(), off);
  const bool further = std::signbit(v) == std::signbit(off);  // away from zero
  if (further && std::isinf(v)) return v;
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(v);
  return std::bit_cast<float>(further ? bits + 1u : bits - 1u);
}

}  // namespace detail

struct hit_record {
  vec3 p{0.0f};       // hit point
  vec3 n{0.0f};       // unit normal of the surface's front side (after any flip)
  float t = 0.0f;     // ray parameter of the hit
  std::uint32_t material = 0;
  bool front_face = true;  // the ray arrives at the front side: dot(d, n) < 0
  // A bound on how far the computed p may lie from the true surface along
  // n (the rounding of its computation, dot(|n|, error bound of p)); 0 where
  // p lies exactly on it (the coordinate planes of axis-aligned rectangles).
  // A ray leaving the surface starts this far off it on the side it leaves
  // to (spawn_origin), and rays are then intersected from t = 0: a shape's
  // own test cannot meet the surface it leaves (Pharr et al., "Physically
  // Based Rendering", 4th ed., sec. 6.8.6). Every shape sets it.
  float offset = 0.0f;
  // Where the shape has them (triangles of meshes): the unit shading normal
  // (interpolated vertex normals, on the side of n), the texture coordinates
  // and the surface's tangent dp/du. ns is zero where the shape has no
  // shading normal: shading_normal() is then n.
  vec3 ns{0.0f};
  vec2 uv{0.0f};
  vec3 dpdu{0.0f};

  // The unit normal on the side the ray came from (geometric normal).
  vec3 facing_normal() const { return front_face ? n : -n; }
  // The unit shading normal on the front side (n where there is none).
  vec3 shading_normal() const { return ns == vec3(0.0f) ? n : ns; }
  // The unit shading normal on the side a ray along d came from (the
  // facing normal where the shape has no shading normal).
  vec3 facing_shading_normal(const vec3& d) const {
    if (ns == vec3(0.0f)) return facing_normal();
    return glm::dot(d, ns) < 0.0f ? ns : -ns;
  }

  // The origin of a ray leaving p along dir: p moved off the surface by
  // `offset` to the side dir points into, each coordinate then rounded
  // away from the surface, so that the move's own rounding cannot undo it
  // (pbrt-v4's OffsetRayOrigin). p itself where the offset is 0.
  vec3 spawn_origin(const vec3& dir) const {
    if (offset == 0.0f) return p;
    const vec3 off = (glm::dot(dir, n) < 0.0f ? -offset : offset) * n;
    const vec3 o = p + off;
    return {detail::step_away(o.x, off.x), detail::step_away(o.y, off.y), detail::step_away(o.z, off.z)};
  }
};

}  // namespace mcrt
