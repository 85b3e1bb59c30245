#pragma once
// What a light, or a node of the light hierarchy (accel/light_bvh.hpp), is
// worth to a shading point: the importance by which render/light_selection.hpp
// chooses among many lights. Two measures:
//
//  * pbrt-v4's (LightBounds::Importance, lightsamplers.cpp; Conty Estevez &
//    Kulla 2018, eq. 3), as it ships: phi cos(theta') / d^2 times the
//    receiver's cos(theta'_i), with d the distance to the box's centre
//    clamped below by half its diagonal's length, theta' the smallest angle
//    the node's normals' cone leaves between a normal and the direction to
//    the point, theta'_i that between the point's normal and the box (|cos|:
//    a receiver of either side), both widened by the angle theta_b the box
//    subtends (its bounding sphere's). An upper bound of the cosines over
//    the node, an estimate of its distance.
//
//  * the exact one of a single light: its luminance times pi times its
//    projected solid angle above the receiver's horizon, the integral of
//    cos+ over the directions it covers (Lambert's formula for a polygon
//    clipped to the horizon; the visible cap for a sphere): the light's
//    whole unoccluded contribution to a diffuse receiver, up to the albedo.
//    For a distant light it is pbrt-v4's importance of that light (phi cos
//    cos_i / d^2); near one, where the contributions that dominate the
//    noise are, it is the true value, where pbrt-v4's overestimates a light
//    partly below the horizon and misjudges a large one by its centre. A
//    receiver that transmits counts both sides of its horizon.
//
// Both are in the same unit (pi L Omega_proj ~ phi cos cos_i / d^2 for a
// small light), so a node's estimate and a light's exact value can be
// compared at one split.
#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include "mcrt/accel/light_bvh.hpp"
#include "mcrt/core/fast_math.hpp"
#include "mcrt/render/light.hpp"

namespace mcrt {

// cos(max(0, a - b)) and sin(max(0, a - b)) from the sines and cosines of
// angles a, b in [0, pi] (pbrt-v4's cosSubClamped / sinSubClamped).
inline float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 1.0f;
  return cos_a * cos_b + sin_a * sin_b;
}
inline float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 0.0f;
  return sin_a * cos_b - cos_a * sin_b;
}

// pbrt-v4's importance of the bounds b at the point p with unit normal n (n
// zero: no receiver term). two_sided_receiver: pbrt-v4's |cos theta_i|;
// false: cos+ (a receiver that only reflects gets nothing from a node wholly
// below its horizon).
inline float bounds_importance(const light_bounds& b, const vec3& p, const vec3& n, bool two_sided_receiver = true) {
  using light_bvh_detail::safe_sqrt;
  const vec3 pc = b.box.centroid();
  const vec3 to_p = p - pc;
  float d2 = glm::dot(to_p, to_p);
  // pbrt-v4's clamp of the distance at half the diagonal (in its units, as
  // it ships: the length, not its square).
  d2 = std::max(d2, 0.5f * glm::length(b.box.hi - b.box.lo));
  // Directions: from the box's centre to p. At the centre itself the
  // direction is undefined; the box then subtends every direction
  // (cos_theta_b = -1 below), which makes theta' 0 whatever cos_theta_w is.
  const float len = std::sqrt(glm::dot(to_p, to_p));
  const vec3 wi = len > 0.0f ? to_p / len : vec3(0.0f, 0.0f, 1.0f);
  const float cos_w = glm::dot(b.normals.w, wi);
  const float sin_w = safe_sqrt(1.0f - cos_w * cos_w);
  // theta_b: the half-angle of the cone from p holding the box's bounding
  // sphere (pbrt-v4's BoundSubtendedDirections); every direction inside it.
  const vec3 half = 0.5f * (b.box.hi - b.box.lo);
  const float r2 = glm::dot(half, half);
  const float dc2 = glm::dot(to_p, to_p);
  float cos_b = -1.0f;
  if (dc2 > r2) cos_b = safe_sqrt(1.0f - r2 / dc2);
  const float sin_b = safe_sqrt(1.0f - cos_b * cos_b);
  // theta' = max(0, theta_w - theta_o - theta_b).
  const float cos_o = b.normals.cos_theta, sin_o = safe_sqrt(1.0f - cos_o * cos_o);
  const float cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
  const float sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
  const float cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
  if (cos_p <= b.cos_theta_e) return 0.0f;
  float importance = b.phi * cos_p / d2;
  if (n != vec3(0.0f)) {
    // The receiver: theta_i between n and the direction to the box's centre.
    const float c = -glm::dot(wi, n);
    const float cos_i = two_sided_receiver ? std::abs(c) : c;
    const float sin_i = safe_sqrt(1.0f - cos_i * cos_i);
    importance *= std::max(cos_sub_clamped(sin_i, cos_i, sin_b, cos_b), 0.0f);
  }
  return std::max(importance, 0.0f);
}

namespace light_importance_detail {

// Lambert's formula for the integral of cos+ (cosine to n) over the
// directions from o to a convex polygon of `count` <= 4 vertices, clipped to
// the half-space in front of o's horizon (Sutherland & Hodgman, one plane):
// Omega_proj = |sum_i gamma_i n . (r_i x r_{i+1}) / |r_i x r_{i+1}|| / 2,
// gamma_i the angle between consecutive unit vectors r_i to the clipped
// vertices (Lambert 1760; Arvo 1995, "Applications of Irradiance Tensors",
// eq. 2). In double, the angles by fast_math::atan2_upper.
inline double clipped_polygon_projected_solid_angle(const vec3* v, int count, const vec3& o, const vec3& n) {
  const dvec3 od(o), nd(n);
  std::array<dvec3, 5> r{};
  int m = 0;
  for (int i = 0; i < count; ++i) {
    const dvec3 a = dvec3(v[i]) - od, b = dvec3(v[(i + 1) % count]) - od;
    const double ha = glm::dot(a, nd), hb = glm::dot(b, nd);
    if (ha >= 0.0) r[static_cast<std::size_t>(m++)] = a;
    if ((ha > 0.0 && hb < 0.0) || (ha < 0.0 && hb > 0.0)) r[static_cast<std::size_t>(m++)] = a + (b - a) * (ha / (ha - hb));
  }
  if (m < 3) return 0.0;
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const dvec3 &a = r[static_cast<std::size_t>(i)], &b = r[static_cast<std::size_t>((i + 1) % m)];
    const double la = glm::length(a), lb = glm::length(b);
    // A vertex at o itself subtends nothing it could be weighed by.
    if (!(la > 0.0) || !(lb > 0.0)) continue;
    const dvec3 c = glm::cross(a, b);
    const double s = glm::length(c);
    if (!(s > 0.0)) continue;  // an edge seen end-on
    sum += fast_math::atan2_upper(s, glm::dot(a, b)) * (glm::dot(nd, c) / s);
  }
  return std::abs(0.5 * sum);
}

template <class S>
inline double projected_solid_angle_of(const S& s, const vec3& o, const vec3& n) {
  using Shape = std::decay_t<decltype(s.shape)>;
  if constexpr (std::is_same_v<Shape, triangle>) {
    const std::array<vec3, 3> v{s.shape.vertex(0), s.shape.vertex(1), s.shape.vertex(2)};
    return clipped_polygon_projected_solid_angle(v.data(), 3, o, n);
  } else if constexpr (std::is_same_v<Shape, rect>) {
    const rect& r = s.shape;
    const std::array<vec3, 4> v{r.corner, r.corner + r.e1, r.corner + r.e1 + r.e2, r.corner + r.e2};
    return clipped_polygon_projected_solid_angle(v.data(), 4, o, n);
  } else if constexpr (std::is_same_v<Shape, sphere>) {
    sphere_projected_view view;
    return view.make(s.shape, o, n, false) ? view.cap.omega : 0.0;
  } else {
    return -1.0;  // no closed form here (disks): the caller takes the bounds' estimate
  }
}

}  // namespace light_importance_detail

// The bounds of one light as the hierarchy keeps them: its shape's box, its
// emitting normal (the side faces() accepts; every direction for a sphere),
// lambertian emission (theta_e = pi/2) and the flux phi.
template <light_handle L>
light_bounds bounds_of(const L& l, float phi) {
  return dispatch(l, [&](const auto& s) {
    using Shape = std::decay_t<decltype(s.shape)>;
    light_bounds b;
    b.box = s.shape.bounds();
    b.phi = phi;
    b.cos_theta_e = 0.0f;
    if constexpr (std::is_same_v<Shape, sphere>) {
      b.normals = direction_cone::entire_sphere();
      b.centre = s.shape.center;
    } else {
      if constexpr (std::is_same_v<Shape, triangle>)
        b.centre = (s.shape.vertex(0) + s.shape.vertex(1) + s.shape.vertex(2)) / 3.0f;
      else if constexpr (std::is_same_v<Shape, rect>)
        b.centre = s.shape.corner + 0.5f * (s.shape.e1 + s.shape.e2);
      else
        b.centre = s.shape.center;
      vec3 ng;
      if constexpr (std::is_same_v<Shape, triangle>)
        ng = s.shape.normal();
      else
        ng = s.shape.n;
      // The side the strategy samples (a two-sided light's back is a light
      // of its own): the one whose far point faces() accepts.
      const vec3 c = b.box.centroid();
      const float reach = 1.0f + glm::length(b.box.hi - b.box.lo) + glm::length(c);
      b.normals = {s.faces(c + reach * ng) ? ng : -ng, 1.0f};
    }
    return b;
  });
}

// pi L Omega_proj+ of the light l at o (normal n), L its radiance's
// luminance (phi over pi times its area), Omega_proj+ the integral of cos+
// (or of |cos| where both_sides) over the directions it covers; 0 where it
// does not face o. Negative where the light's shape has no closed form here
// (disks), for the caller to take bounds_importance instead.
template <light_handle L>
double exact_importance(const L& l, float phi, const vec3& o, const vec3& n, bool both_sides) {
  return dispatch(l, [&](const auto& s) -> double {
    if (!s.faces(o)) return 0.0;
    double omega = light_importance_detail::projected_solid_angle_of(s, o, n);
    if (omega < 0.0) return -1.0;
    if (both_sides) omega += light_importance_detail::projected_solid_angle_of(s, o, -n);
    return double(phi) / double(surface_area(s.shape)) * omega;
  });
}

}  // namespace mcrt
