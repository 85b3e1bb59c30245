#pragma once
// c_rest, the time per light sample of everything in a path but the light's
// sampler (auto_params::rest_cost), modelled from what the noise pilot
// counts (render/noise_pilot.hpp) and the scene's primitives, so that
// `auto`'s choices, and the image, do not depend on how fast one run
// happened to be.
//
// The pilot's paths' time per light sample, less the cheapest strategy's
// modelled cost (auto_costs), is modelled as
//   c_rest = c_ray (R - P) / L + (R / L) sum_t n_t c_t + c_sample + c_light,
// R the rays the paths traced, P the paths (their camera rays), L their
// light samples: each ray after the camera's (shadow and continuation rays)
// costs c_ray with the work at its ends (light selection, shading, the
// BSDF's sample); every ray tests each of the scene's n_t primitives of
// type t (the scene is a list, render/scene.hpp) at c_t each; a light
// sample costs c_sample beyond its strategy and its rays; and a light of a
// shape whose sample costs more in a path than its sampler alone (the
// ellipse's and the sphere's records and pdfs at the shadow ray's end)
// c_light more.
//
// The constants are a least-squares fit to the pilot's measured time per
// light sample (the fastest of 5 runs) over 102 scene and depth settings:
// the thesis's Cornell scenes, the study's size and distance families and
// four scenes with 12 further primitives of each type, direct and global
// light, nee, this machine (bench/rest_cost.py, which prints the fit and
// the residuals of these constants: 10 % rms, at most 25-29 %, the
// distance family, a large floor with few primitives, measured up to 25 %
// cheaper than modelled). A time measured in each run varies by up to 2x
// between runs of the same command (a 100 x 100 pilot takes a few ms:
// distance_h1, direct light, 78-149 ns per light sample), and with it
// which pixels kappa would be measured at, kappa and some choices: the
// same command would give different images. Modelled, they do not.
#include <algorithm>
#include <cstddef>
#include <tuple>
#include <type_traits>

#include "mcrt/geometry/box.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/render/scene.hpp"

namespace mcrt {

struct rest_cost_model {
  static constexpr float ray = 49.9f;     // c_ray: ns per ray after the camera's
  static constexpr float sample = 22.5f;  // c_sample: ns per light sample
  // c_t: ns per intersection test of a primitive (a miss, mostly).
  static constexpr float axis_rect = 1.45f, rect = 1.33f, ellipse = 1.31f, sphere = 1.75f, box = 3.52f;
  // Triangles are not in the fit: the rectangle's c_t times their cost
  // ratio in bench/bench_samplers_intersect.cpp, BM_IntersectTriangle /
  // BM_IntersectRect = 3.7 (where the sphere's ratio, 1.29, matches its
  // fitted 1.32).
  static constexpr float triangle = 1.33f * 3.7f;
  // c_light: ns per light sample of a light of this shape beyond a rectangle's.
  static constexpr float ellipse_light = 32.7f, sphere_light = 6.0f;
};

// c_t of a primitive type (a shape the scene lists apart).
template <class Shape>
constexpr float intersection_test_cost() {
  if constexpr (std::is_same_v<Shape, rect>) return rest_cost_model::rect;
  else if constexpr (std::is_same_v<Shape, ellipse>) return rest_cost_model::ellipse;
  else if constexpr (std::is_same_v<Shape, sphere>) return rest_cost_model::sphere;
  else if constexpr (std::is_same_v<Shape, triangle>) return rest_cost_model::triangle;
  else {
    static_assert(std::is_same_v<Shape, box>, "a primitive type without a measured test cost");
    return rest_cost_model::box;
  }
}

// sum_t n_t c_t: the modelled time of one ray's intersection tests, ns.
template <class... Shapes>
float intersection_cost_per_ray(const basic_scene<Shapes...>& sc) {
  float c = rest_cost_model::axis_rect * static_cast<float>(sc.axis_rects.size());
  std::apply([&](const auto&... v) {
    ((c += intersection_test_cost<decltype(std::decay_t<decltype(v)>::value_type::shape)>() *
           static_cast<float>(v.size())), ...);
  }, sc.objects);
  return c;
}

// c_light of a light's shape.
template <class Shape>
constexpr float light_shape_cost() {
  if constexpr (std::is_same_v<Shape, ellipse>) return rest_cost_model::ellipse_light;
  else if constexpr (std::is_same_v<Shape, sphere>) return rest_cost_model::sphere_light;
  else return 0.0f;
}

// c_rest (header) from the pilot's rays and paths per light sample, the
// scene's intersection cost per ray and the light's c_light, ns.
inline float modelled_rest_cost(double rays_per_light_sample, double paths_per_light_sample, float tests_per_ray,
                                float light_cost) {
  const double c = rest_cost_model::ray * (rays_per_light_sample - paths_per_light_sample) +
                   rays_per_light_sample * tests_per_ray + rest_cost_model::sample + light_cost;
  return static_cast<float>(std::max(c, 0.0));
}

}  // namespace mcrt
