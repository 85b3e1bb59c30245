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

}  // namespace mcrt
