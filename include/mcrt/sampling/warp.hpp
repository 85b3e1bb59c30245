#pragma once
// Warps from the unit square to directions, each with its pdf and inverse
// (names after Mitsuba 3's core/warp.h). Directions are in a local frame
// with z as the axis. Also the 1-D linear warp the bilinear pre-warps of
// the spherical rectangle and ellipse are built from.
#include <algorithm>
#include <cmath>

#include "mcrt/core/math.hpp"

namespace mcrt {

// --- cosine-weighted hemisphere (Malley's method via the polar disk map)
inline vec3 square_to_cosine_hemisphere(vec2 u) {
  const float r = std::sqrt(u.x), phi = two_pi * u.y;
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  return {x, y, safe_sqrt(1.0f - u.x)};  // 1 - x^2 - y^2 may round below 0
}
// Density per unit solid angle: cos(theta) / pi on the upper hemisphere.
inline float square_to_cosine_hemisphere_pdf(const vec3& d) {
  return d.z > 0.0f ? d.z * inv_pi : 0.0f;
}
inline vec2 cosine_hemisphere_to_square(const vec3& d) {
  float phi = std::atan2(d.y, d.x);
  if (phi < 0.0f) phi += two_pi;
  return {d.x * d.x + d.y * d.y, phi / two_pi};
}

// --- uniform disk, Shirley and Chiu's concentric map ("A low distortion map
// between disk and square", JGT 2(3), 1997; pbrt-v4's
// SampleUniformDiskConcentric): the square [-1,1]^2's concentric squares go
// to concentric circles, so strata stay compact (the thin lens).
inline vec2 square_to_uniform_disk_concentric(vec2 u) {
  const vec2 o = 2.0f * u - vec2(1.0f);
  if (o.x == 0.0f && o.y == 0.0f) return {0.0f, 0.0f};  // the centre: atan of 0/0 below
  float r, theta;
  if (std::abs(o.x) > std::abs(o.y)) {
    r = o.x;
    theta = 0.25f * pi * (o.y / o.x);
  } else {
    r = o.y;
    theta = 0.5f * pi - 0.25f * pi * (o.x / o.y);
  }
  return {r * std::cos(theta), r * std::sin(theta)};
}
// Density per unit AREA of the disk: 1 / pi inside the unit disk.
inline float square_to_uniform_disk_concentric_pdf(vec2 p) { return glm::dot(p, p) <= 1.0f ? inv_pi : 0.0f; }
// The inverse (pbrt-v4's InvertUniformDiskConcentricSample).
inline vec2 uniform_disk_concentric_to_square(vec2 p) {
  float theta = std::atan2(p.y, p.x);  // in [-pi, pi]
  const float r = std::sqrt(p.x * p.x + p.y * p.y);
  if (theta < -0.25f * pi) theta += two_pi;  // into [-pi/4, 7pi/4)
  vec2 o;
  if (theta < 0.25f * pi) {  // the right wedge, |x| > |y|, x > 0
    o = {r, r * theta / (0.25f * pi)};
  } else if (theta < 0.75f * pi) {  // top: y > 0
    o = {r * (0.5f * pi - theta) / (0.25f * pi), r};
  } else if (theta < 1.25f * pi) {  // left: x < 0
    o = {-r, -r * (theta - pi) / (0.25f * pi)};
  } else {  // bottom: y < 0
    o = {r * (theta - 1.5f * pi) / (0.25f * pi), -r};
  }
  return 0.5f * (o + vec2(1.0f));
}

// --- uniform sphere
inline vec3 square_to_uniform_sphere(vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = safe_sqrt(1.0f - z * z), phi = two_pi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
// Density per unit solid angle: 1 / (4 pi).
inline float square_to_uniform_sphere_pdf() { return 0.25f * inv_pi; }
inline vec2 uniform_sphere_to_square(const vec3& d) {
  float phi = std::atan2(d.y, d.x);
  if (phi < 0.0f) phi += two_pi;
  return {0.5f * (1.0f - d.z), phi / two_pi};
}

// --- uniform ball: radius cbrt(u0) (the volume inside radius r is r^3 of
// the ball's), direction uniform on the sphere from u.
inline vec3 square_to_uniform_ball(float u0, vec2 u) { return std::cbrt(u0) * square_to_uniform_sphere(u); }
// Density per unit VOLUME: 3 / (4 pi) inside the unit ball.
inline float square_to_uniform_ball_pdf(const vec3& p) {
  return glm::dot(p, p) < 1.0f ? 0.75f * inv_pi : 0.0f;
}
// (u0, u) of a point inside the ball (the origin maps to u0 = 0, u = (0.5, 0)).
inline void uniform_ball_to_cube(const vec3& p, float& u0, vec2& u) {
  const float r = glm::length(p);
  u0 = r * r * r;
  u = r > 0.0f ? uniform_sphere_to_square(p / r) : vec2(0.5f, 0.0f);
}

// --- uniform cone of half-angle theta_max around +z, given as
// one_minus_cos = 1 - cos(theta_max), which stays accurate for narrow cones.
inline vec3 square_to_uniform_cone(vec2 u, float one_minus_cos) {
  const float omc = u.x * one_minus_cos;      // 1 - cos(theta)
  const float z = 1.0f - omc;
  const float r = safe_sqrt(omc * (2.0f - omc));  // sin(theta) without 1 - z^2 cancellation
  const float phi = two_pi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
// Density per unit solid angle: 1 / (2 pi (1 - cos theta_max)) inside the cone.
// 1 - cos theta is taken as (x^2 + y^2) / (1 + z) in the upper hemisphere:
// 1 - z there loses the bits a narrow cone needs (d.z is 1 to within a few
// ulps), and sampled directions near the rim would get density 0.
inline float square_to_uniform_cone_pdf(const vec3& d, float one_minus_cos) {
  const float omc = d.z > 0.0f ? (d.x * d.x + d.y * d.y) / (1.0f + d.z) : 1.0f - d.z;
  return omc <= one_minus_cos ? 1.0f / (two_pi * one_minus_cos) : 0.0f;
}
inline vec2 uniform_cone_to_square(const vec3& d, float one_minus_cos) {
  float phi = std::atan2(d.y, d.x);
  if (phi < 0.0f) phi += two_pi;
  const float omc = (d.x * d.x + d.y * d.y) / (1.0f + d.z);  // 1 - cos, cancellation-free
  return {omc / one_minus_cos, phi / two_pi};
}

// --- linear density on [0, 1] with end values a, b >= 0, a + b > 0 (the
// marginal and conditional of a bilinear density; Hart et al. 2020,
// sec. 4.1, pbrt-v4's SampleLinear): sample, density per unit LENGTH,
// inverse (the CDF). The sample is the CDF's quadratic root in the form
// u (a + b) / (a + sqrt((1 - u) a^2 + u b^2)), which does not cancel for
// a ~ b (where the quadratic's leading coefficient b - a vanishes); clamped
// because rounding may step past [0, 1].
inline double square_to_linear(double u, double a, double b) {
  const double x = u * (a + b) / (a + std::sqrt((1.0 - u) * a * a + u * b * b));
  return std::clamp(x, 0.0, 1.0);
}
inline double square_to_linear_pdf(double x, double a, double b) { return 2.0 * ((1.0 - x) * a + x * b) / (a + b); }
inline double linear_to_square(double x, double a, double b) {
  return std::clamp(x * (a * (2.0 - x) + b * x) / (a + b), 0.0, 1.0);
}

}  // namespace mcrt
