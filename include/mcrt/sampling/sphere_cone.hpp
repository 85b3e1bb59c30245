#pragma once
// Sampling a sphere uniformly in the solid angle it subtends (Shirley, "The
// Rest of Your Life", sec. 12): a uniform cone around the direction to the
// centre, with half-angle asin(r / d).
#include "mcrt/core/onb.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

struct sphere_cone_sampler {
  sphere shape;

  // An observer inside (or on) the sphere sees it in every direction: no
  // cone to sample, so it gets no sample.
  bool faces(const vec3& o) const {
    const vec3 v = shape.center - o;
    return glm::dot(v, v) > shape.radius * shape.radius;
  }

  // 1 - cos(theta_max) = (r/d)^2 / (1 + sqrt(1 - (r/d)^2)): no cancellation
  // for small or distant spheres.
  static float one_minus_cos_max(float r2_over_d2) {
    return r2_over_d2 / (1.0f + safe_sqrt(1.0f - r2_over_d2));
  }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const vec3 v = shape.center - o;
    const float d2 = glm::dot(v, v), r2 = shape.radius * shape.radius;
    if (!(d2 > r2)) return false;
    const float d = std::sqrt(d2);
    const float omc = one_minus_cos_max(r2 / d2);
    const vec3 local = square_to_uniform_cone(u, omc);
    s.dir = glm::normalize(onb(v / d).to_world(local));
    // Distance to the near intersection along dir: d cos - sqrt(r^2 - d^2 sin^2).
    const float sin2 = local.x * local.x + local.y * local.y;
    s.dist = d * local.z - safe_sqrt(r2 - d2 * sin2);
    s.pdf = 1.0f / (two_pi * omc);
    return std::isfinite(s.pdf);
  }

  // Density per unit SOLID ANGLE: 1 / (2 pi (1 - cos theta_max)) inside the cone.
  float pdf(const vec3& o, const vec3& dir) const {
    const vec3 v = shape.center - o;
    const float d2 = glm::dot(v, v), r2 = shape.radius * shape.radius;
    if (!(d2 > r2)) return 0.0f;
    const vec3 w = v / std::sqrt(d2);
    const float omc = one_minus_cos_max(r2 / d2);
    const float omc_dir = 0.5f * glm::dot(dir - w, dir - w);  // 1 - cos, cancellation-free
    return omc_dir <= omc ? 1.0f / (two_pi * omc) : 0.0f;
  }
};

}  // namespace mcrt
