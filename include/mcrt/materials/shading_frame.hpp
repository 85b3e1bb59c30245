#pragma once
// The local shading frame the BSDFs work in (pbrt-v4, 4th ed., sec. 9.1.1):
// z is the shading normal n, x the tangent (the dpdu direction, along which
// an anisotropic roughness alpha_x applies), y = z x x, right-handed.
// Also the spherical-coordinate helpers of that frame (pbrt-v4's CosTheta,
// Tan2Theta, CosPhi, ... of sec. 3.8.3), which the microfacet code uses.
#include <cmath>

#include "mcrt/core/math.hpp"

namespace mcrt {

struct shading_frame {
  vec3 x{1.0f, 0.0f, 0.0f}, y{0.0f, 1.0f, 0.0f}, z{0.0f, 0.0f, 1.0f};

  // Any orthonormal frame around the unit vector n, without branches on its
  // direction (Duff et al. 2017, "Building an Orthonormal Basis, Revisited",
  // listing 3): used when no tangent is known or the hint is useless.
  static shading_frame from_normal(const vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    shading_frame f;
    f.x = vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.y = vec3(b, sign + n.y * n.y * a, -n.y);
    f.z = n;
    return f;
  }

  // The frame with z = n (unit) and x the part of the tangent hint t
  // orthogonal to n (Gram-Schmidt), so that alpha_x follows the hint.
  static shading_frame from_normal_tangent(const vec3& n, const vec3& t) {
    // Gram-Schmidt twice ("twice is enough", Giraud et al. 2005): one pass
    // leaves t' orthogonal to n only to ~1e-7 |t| / |t'|, which is poor when
    // the hint is nearly parallel to n; the second pass restores ~1e-7.
    vec3 tp = t - glm::dot(n, t) * n;
    tp -= glm::dot(n, tp) * n;
    const float len2 = glm::dot(tp, tp), t2 = glm::dot(t, t);
    // Fallback guard: a hint parallel to n (within sin = 1e-6, where t' is
    // rounding noise), zero, or not finite carries no tangent direction.
    if (!(len2 > 1e-12f * t2) || !std::isfinite(len2)) return from_normal(n);
    shading_frame f;
    f.z = n;
    f.x = tp / std::sqrt(len2);
    f.y = glm::cross(n, f.x);  // unit: n and x are orthonormal
    return f;
  }

  vec3 to_local(const vec3& v) const { return {glm::dot(v, x), glm::dot(v, y), glm::dot(v, z)}; }
  vec3 to_world(const vec3& v) const { return v.x * x + v.y * y + v.z * z; }
};

// --- spherical coordinates of a unit vector w in the local frame (pbrt-v4,
// sec. 3.8.3): theta from +z, phi from +x towards +y.
inline float cos_theta(const vec3& w) { return w.z; }
inline float cos2_theta(const vec3& w) { return w.z * w.z; }
inline float abs_cos_theta(const vec3& w) { return std::abs(w.z); }
// sin^2 as x^2 + y^2 rather than 1 - z^2: no cancellation near the pole, and
// the same value for a vector that is not exactly unit.
inline float sin2_theta(const vec3& w) { return w.x * w.x + w.y * w.y; }
inline float sin_theta(const vec3& w) { return std::sqrt(sin2_theta(w)); }
inline float tan2_theta(const vec3& w) { return sin2_theta(w) / cos2_theta(w); }  // inf in the tangent plane
// cos phi, sin phi; at the pole (sin theta = 0) phi is taken as 0.
inline float cos_phi(const vec3& w) {
  const float s = sin_theta(w);
  return s == 0.0f ? 1.0f : std::clamp(w.x / s, -1.0f, 1.0f);
}
inline float sin_phi(const vec3& w) {
  const float s = sin_theta(w);
  return s == 0.0f ? 0.0f : std::clamp(w.y / s, -1.0f, 1.0f);
}
// Strictly on the same side of the tangent plane (pbrt-v4's SameHemisphere).
inline bool same_hemisphere(const vec3& w, const vec3& wp) { return w.z * wp.z > 0.0f; }

}  // namespace mcrt
