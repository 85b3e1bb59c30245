#pragma once
// The lights of a scene: every shape that is sampled directly, each with its
// sampling strategy, in one std::variant so a scene holds exactly the
// strategies it uses and dispatch is a few compares, not a virtual call.
#include <variant>

#include "mcrt/core/dispatch.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "mcrt/sampling/sphere_cone.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_ellipse_polar.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"

namespace mcrt {

using light = std::variant<rect_area_sampler, rect_solid_angle_sampler, ellipse_area_sampler,
                           ellipse_solid_angle_sampler, ellipse_polar_solid_angle_sampler, sphere_cone_sampler>;

// The free functions light_pdf (render/pdf.hpp) calls: the strategy's own
// members for a plain strategy, a static dispatch for the variant.
template <class S>
bool faces(const S& s, const vec3& o) { return s.faces(o); }
template <class S>
bool sample(const S& s, const vec3& o, vec2 u, light_sample& out) { return s.sample(o, u, out); }
template <class S>
float pdf(const S& s, const vec3& o, const vec3& dir) { return s.pdf(o, dir); }

inline bool faces(const light& l, const vec3& o) {
  return dispatch(l, [&](const auto& s) { return s.faces(o); });
}
inline bool sample(const light& l, const vec3& o, vec2 u, light_sample& out) {
  return dispatch(l, [&](const auto& s) { return s.sample(o, u, out); });
}
inline float pdf(const light& l, const vec3& o, const vec3& dir) {
  return dispatch(l, [&](const auto& s) { return s.pdf(o, dir); });
}

// Surface area of a light's shape (the whole sphere for a sphere).
inline float surface_area(const rect& r) { return r.area; }
inline float surface_area(const ellipse& e) { return e.area; }
inline float surface_area(const sphere& s) { return 2.0f * two_pi * s.radius * s.radius; }
inline float surface_area(const light& l) {
  return dispatch(l, [](const auto& s) { return surface_area(s.shape); });
}

// Luminance of a linear Rec. 709 colour (ITU-R BT.709 Y weights).
inline float luminance(const color& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

}  // namespace mcrt
