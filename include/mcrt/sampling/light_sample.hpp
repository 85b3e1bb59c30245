#pragma once
// The result of sampling a direction towards a shape from an observer, and
// the interface every shape-sampling strategy offers (Shirley, "The Rest of
// Your Life", sec. 9-10: hittable::random and hittable::pdf_value):
//
//   bool  sample(const vec3& o, vec2 u, light_sample& s) const;
//           u in [0,1)^2 -> direction; false (and no sample) where the
//           strategy has nothing to offer o, e.g. o behind a one-sided light.
//   float pdf(const vec3& o, const vec3& dir) const;
//           density of sample() per unit SOLID ANGLE at o for the unit
//           direction dir; 0 where the ray misses the shape or sample()
//           would return false.
//   bool  faces(const vec3& o) const;
//           whether sample() can return a direction for o at all.
//
// A cosine-aware strategy (one that samples by projected solid angle, or
// weighs by the cosine at the receiver) takes the receiving surface's unit
// normal n as well:
//   bool  sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const;
//   float pdf(const vec3& o, const vec3& n, const vec3& dir) const;
// with the same meaning (pdf still per unit SOLID ANGLE), false / 0 also
// where the light lies wholly below the horizon of n. The renderer calls
// every strategy through the free functions sample(l, o, n, u, s) and
// pdf(l, o, n, dir) of render/light.hpp, which drop n for the strategies
// that ignore it (area, solid angle).
#include <string_view>

#include "mcrt/core/math.hpp"

namespace mcrt {

struct light_sample {
  vec3 dir{0.0f};    // unit direction from the observer
  float dist = 0.0f; // distance to the sampled point of the shape
  float pdf = 0.0f;  // per unit solid angle
};

// Which strategy a light is sampled with; --light-sampling chooses one for
// every light of a scene.
//   area                  uniform on the light's surface (for a sphere: on
//                         the part of its surface the observer sees);
//   solid_angle           uniform in the solid angle the light subtends;
//   projected_solid_angle proportional to cos theta at the receiver within
//                         that solid angle (exact for rectangles and
//                         spheres; for ellipses exact where the map is
//                         well conditioned, the bilinear pre-warp
//                         elsewhere: projected_spherical_ellipse.hpp);
//   bilinear_solid_angle  the solid-angle map pre-warped by a bilinear
//                         approximation of cos theta on its unit square
//                         (Hart et al. 2020, as pbrt-v4), a comparison
//                         strategy for rectangles, ellipses and triangles;
//   pbrt                  what pbrt-v4 ships for each shape, thresholds
//                         included (pbrt_strategy.hpp).
// automatic: `auto`, one of the first three chosen per light and shading
// point (auto_strategy.hpp).
enum class light_sampling { area, solid_angle, projected_solid_angle, bilinear_solid_angle, automatic, pbrt };

// The command line's and the scene format's name of a strategy.
constexpr std::string_view to_string(light_sampling s) {
  switch (s) {
    case light_sampling::area: return "area";
    case light_sampling::solid_angle: return "solid-angle";
    case light_sampling::projected_solid_angle: return "projected-solid-angle";
    case light_sampling::bilinear_solid_angle: return "bilinear-solid-angle";
    case light_sampling::automatic: return "auto";
    case light_sampling::pbrt: return "pbrt";
  }
  return "?";
}

// Area density -> solid-angle density (Shirley, "The Rest of Your Life",
// sec. 9; Veach 1997, eq. 8.10): p_w = p_A d^2 / |cos theta_light|.
inline float area_to_solid_angle(float pdf_area, float dist2, float abs_cos_light) {
  return pdf_area * dist2 / abs_cos_light;
}

}  // namespace mcrt
