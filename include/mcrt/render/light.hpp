#pragma once
// A light: a shape that is sampled directly, with its sampling strategy, as
// one std::variant whose dispatch is a few compares, not a virtual call. A
// scene keeps its lights by strategy (render/light_list.hpp), so that each
// takes its own strategy's bytes and not the variant's.
#include <concepts>
#include <optional>
#include <span>
#include <type_traits>
#include <variant>

#include "mcrt/core/dispatch.hpp"
#include "mcrt/sampling/auto_strategy.hpp"
#include "mcrt/sampling/bilinear_spherical_ellipse.hpp"
#include "mcrt/sampling/bilinear_spherical_rectangle.hpp"
#include "mcrt/sampling/bilinear_spherical_triangle.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/pbrt_strategy.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"
#include "mcrt/sampling/projected_spherical_cap.hpp"
#include "mcrt/sampling/projected_spherical_ellipse.hpp"
#include "mcrt/sampling/projected_triangle.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "mcrt/sampling/sphere_area.hpp"
#include "mcrt/sampling/sphere_cone.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_ellipse_polar.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"

namespace mcrt {

// Every shape x strategy the renderer has. The dispatch (core/dispatch.hpp)
// tests the alternatives in this order, so the strategies of the thesis's
// scenes come first, the cosine-aware ones after them, then the triangles'
// and pbrt-v4's: a scene that does not use a strategy pays for it at most
// one predictable compare.
using light = std::variant<rect_area_sampler, rect_solid_angle_sampler, ellipse_area_sampler,
                           ellipse_solid_angle_sampler, ellipse_polar_solid_angle_sampler, sphere_cone_sampler,
                           rect_projected_solid_angle_sampler, sphere_projected_solid_angle_sampler,
                           ellipse_projected_solid_angle_sampler, sphere_area_sampler,
                           rect_bilinear_solid_angle_sampler, ellipse_bilinear_solid_angle_sampler,
                           rect_auto_sampler, ellipse_auto_sampler, sphere_auto_sampler, triangle_area_sampler,
                           triangle_solid_angle_sampler, triangle_projected_solid_angle_sampler,
                           triangle_bilinear_solid_angle_sampler, triangle_pbrt_sampler, rect_pbrt_sampler,
                           triangle_auto_sampler>;

// What the functions below take as a light: a `light`, or a light of a
// scene's light_list (render/light_list.hpp marks its reference so); each
// reaches the strategy through dispatch().
template <class L>
inline constexpr bool is_light_handle = std::is_same_v<L, light>;
template <class L>
concept light_handle = is_light_handle<L>;

// The strategy a light-sampling class implements (--stats, mcrt samples).
template <class S>
constexpr light_sampling strategy_of() {
  if constexpr (std::is_same_v<S, rect_area_sampler> || std::is_same_v<S, ellipse_area_sampler> ||
                std::is_same_v<S, sphere_area_sampler> || std::is_same_v<S, triangle_area_sampler>)
    return light_sampling::area;
  else if constexpr (std::is_same_v<S, rect_projected_solid_angle_sampler> ||
                     std::is_same_v<S, sphere_projected_solid_angle_sampler> ||
                     std::is_same_v<S, ellipse_projected_solid_angle_sampler> ||
                     std::is_same_v<S, triangle_projected_solid_angle_sampler>)
    return light_sampling::projected_solid_angle;
  else if constexpr (std::is_same_v<S, rect_bilinear_solid_angle_sampler> ||
                     std::is_same_v<S, ellipse_bilinear_solid_angle_sampler> ||
                     std::is_same_v<S, triangle_bilinear_solid_angle_sampler>)
    return light_sampling::bilinear_solid_angle;
  else if constexpr (std::is_same_v<S, triangle_pbrt_sampler> || std::is_same_v<S, rect_pbrt_sampler>)
    return light_sampling::pbrt;
  else if constexpr (std::is_same_v<S, rect_auto_sampler> || std::is_same_v<S, ellipse_auto_sampler> ||
                     std::is_same_v<S, sphere_auto_sampler> || std::is_same_v<S, triangle_auto_sampler>)
    return light_sampling::automatic;
  else
    return light_sampling::solid_angle;
}
template <light_handle L>
light_sampling strategy_of(const L& l) {
  return dispatch(l, []<class S>(const S&) { return strategy_of<S>(); });
}

// The sampler of the cheapest strategy of a light `auto` samples; nullopt
// for any other light.
template <light_handle L>
std::optional<light> cheapest_sampler(const L& l) {
  std::optional<light> cheapest;
  dispatch(l, [&]<class S>(const S& s) {
    if constexpr (strategy_of<S>() == light_sampling::automatic) {
      if (s.cheapest() == light_sampling::area)
        cheapest = s.area;
      else
        cheapest = s.solid_angle;
    }
  });
  return cheapest;
}
// Whether a light `auto` samples gains from its choice per shading point at
// the receivers rs, beyond the choice's own cost (auto_sampler::table_gain);
// true for any other light. models: the light's rule's models at rs
// (auto_sampler::receiver_models), where the caller has them; empty, they
// are evaluated here.
template <light_handle L>
bool choice_pays(const L& l, std::span<const auto_receiver> rs, std::span<const auto_choice> models = {}) {
  bool pays = true;
  dispatch(l, [&]<class S>(const S& s) {
    if constexpr (strategy_of<S>() == light_sampling::automatic)
      pays = (models.empty() ? s.table_gain(rs) : s.table_gain(rs, models)) > 0.0f;
  });
  return pays;
}

// A light sampled by `auto` made its cheapest strategy's sampler (other
// lights are left as they are); returns whether it was.
inline bool use_cheapest(light& l) {
  std::optional<light> cheapest = cheapest_sampler(l);
  if (!cheapest) return false;
  l = std::move(*cheapest);
  return true;
}
// The same where its choice does not pay at rs (choice_pays), with no choice
// per light sample from then on.
inline bool use_cheapest_where_choice_does_not_pay(light& l, std::span<const auto_receiver> rs,
                                                   std::span<const auto_choice> models = {}) {
  return !choice_pays(l, rs, models) && use_cheapest(l);
}

// The free functions light_pdf (render/pdf.hpp) and the integrators call:
// the strategy's own members for a plain strategy, a static dispatch for the
// variant. The receiving surface's unit normal n reaches the strategies that
// use it (cosine-aware ones, with members sample(o, n, u, s) and
// pdf(o, n, dir)); the others (area, solid angle) are called without it.
template <class S>
concept normal_aware_strategy = requires(const S& s, const vec3& v, vec2 u, light_sample& out) {
  { s.sample(v, v, u, out) } -> std::convertible_to<bool>;
  { s.pdf(v, v, v) } -> std::convertible_to<float>;
};

template <class S>
bool faces(const S& s, const vec3& o) { return s.faces(o); }
template <class S>
bool sample(const S& s, const vec3& o, vec2 u, light_sample& out) { return s.sample(o, u, out); }
template <class S>
float pdf(const S& s, const vec3& o, const vec3& dir) { return s.pdf(o, dir); }
template <class S>
bool sample(const S& s, const vec3& o, const vec3& n, vec2 u, light_sample& out) {
  if constexpr (normal_aware_strategy<S>)
    return s.sample(o, n, u, out);
  else
    return s.sample(o, u, out);
}
template <class S>
float pdf(const S& s, const vec3& o, const vec3& n, const vec3& dir) {
  if constexpr (normal_aware_strategy<S>)
    return s.pdf(o, n, dir);
  else
    return s.pdf(o, dir);
}

template <light_handle L>
bool faces(const L& l, const vec3& o) {
  return dispatch(l, [&](const auto& s) { return s.faces(o); });
}
template <light_handle L>
bool sample(const L& l, const vec3& o, const vec3& n, vec2 u, light_sample& out) {
  return dispatch(l, [&](const auto& s) { return mcrt::sample(s, o, n, u, out); });
}
template <light_handle L>
float pdf(const L& l, const vec3& o, const vec3& n, const vec3& dir) {
  return dispatch(l, [&](const auto& s) { return mcrt::pdf(s, o, n, dir); });
}

// Surface area of a light's shape (the whole sphere for a sphere).
// The same at a camera ray's first surface, where the lights `auto`
// samples take one choice over the pixel's footprint fp (nullptr: none;
// sampling/auto_footprint.hpp); every other light as above.
template <light_handle L>
bool sample(const L& l, const vec3& o, const vec3& n, vec2 u, light_sample& out, const auto_footprint* fp) {
  if (!fp) return sample(l, o, n, u, out);
  return dispatch(l, [&]<class S>(const S& s) {
    if constexpr (strategy_of<S>() == light_sampling::automatic)
      return s.sample(o, n, u, out, fp);
    else
      return mcrt::sample(s, o, n, u, out);
  });
}
template <light_handle L>
float pdf(const L& l, const vec3& o, const vec3& n, const vec3& dir, const auto_footprint* fp) {
  if (!fp) return pdf(l, o, n, dir);
  return dispatch(l, [&]<class S>(const S& s) {
    if constexpr (strategy_of<S>() == light_sampling::automatic)
      return s.pdf(o, n, dir, fp);
    else
      return mcrt::pdf(s, o, n, dir);
  });
}

inline float surface_area(const rect& r) { return r.area; }
inline float surface_area(const ellipse& e) { return e.area; }
inline float surface_area(const sphere& s) { return 2.0f * two_pi * s.radius * s.radius; }
inline float surface_area(const triangle& t) { return t.area(); }
template <light_handle L>
float surface_area(const L& l) {
  return dispatch(l, [](const auto& s) { return surface_area(s.shape); });
}

// Luminance of a linear Rec. 709 colour (ITU-R BT.709 Y weights).
inline float luminance(const color& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

}  // namespace mcrt
