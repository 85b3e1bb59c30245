#pragma once
// What the integrators (mixture_integrator.hpp, nee_integrator.hpp,
// mis_integrator.hpp) share: the settings of a path, a shadow ray's
// radiance, Russian roulette, and the specular materials' scattering fed
// from a sampler on the dimensions of samplers/layout.hpp.
#include <algorithm>

#include "mcrt/core/dispatch.hpp"
#include "mcrt/materials/material.hpp"
#include "mcrt/render/light_selection.hpp"
#include "mcrt/render/pdf.hpp"
#include "mcrt/render/mis.hpp"
#include "mcrt/samplers/layout.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

struct path_settings {
  // Maximum number of scattering events along a path; 1 renders direct
  // lighting only (light met by the camera ray or after one scattering).
  int max_depth = 50;
  // Russian roulette (Arvo & Kirk 1990) from this many scattering events on,
  // on the path's throughput as pbrt-v4 does (from the second scattering):
  // see survive_roulette. Unbiased; a value >= max_depth turns it off.
  int rr_depth = 1;
  // nee, mis: how a light is chosen among several (light_selection.hpp).
  light_choice choose = light_choice::power;
  // mis: the heuristic of the weights (mis.hpp).
  mis_heuristic heuristic = mis_heuristic::power;
};

// The radiance a shadow ray from p along dir brings back: that of the
// front side of the emitter it meets first; 0 where it meets nothing (the
// background is not a light a light sample can choose) or a surface that
// does not emit.
template <class Scene>
color shadow_ray_radiance(const Scene& sc, const vec3& p, const vec3& dir) {
  hit_record rec;
  if (!sc.hit_side(ray{p, dir}, 0.0f, infinity, rec)) return color(0.0f);
  return emitted(sc.materials[rec.material], rec);
}

// Russian roulette on the throughput (as pbrt-v4): a path whose throughput
// is below 1 survives with that probability, and its throughput is divided
// by it; one at or above 1 always continues, so the roulette never raises a
// path's weight above 1 and adds no fireflies. u is drawn only when needed.
template <class U>
inline bool survive_roulette(color& throughput, U&& u) {
  const float q = std::max({throughput.r, throughput.g, throughput.b});
  if (q < 1.0f) {
    if (!(u() < q)) return false;
    throughput /= q;
  }
  return true;
}

// A point uniform in the unit ball for a metal's fuzz at the bounce whose
// first dimension is b: from the stream by rejection for a sequential
// sampler (the independent one, whose images thus stay those of Shirley's
// code), else from the material choice and the material sample by the
// ball's map (one fixed count of dimensions).
template <class P>
inline vec3 fuzz_point(P& ps, int b) {
  if constexpr (P::sequential)
    return random_in_unit_ball(ps.stream());
  else
    return square_to_uniform_ball(ps.get1d(b + layout::material_choice), ps.get2d(b + layout::material));
}

// Metal or glass at the bounce whose first dimension is b: the ray they
// scatter to. False for every other material, or when the ray is absorbed.
template <class P>
inline bool scatter_specular(const material& m, const ray& r, const hit_record& rec, P& ps, int b,
                             specular_scatter& sp) {
  return dispatch(m, [&](const auto& mat) -> bool {
    using M = std::decay_t<decltype(mat)>;
    if constexpr (std::is_same_v<M, metal>)
      return scatter(mat, r, rec, [&] { return fuzz_point(ps, b); }, sp);
    else if constexpr (std::is_same_v<M, dielectric>)
      return scatter(mat, r, rec, [&] { return ps.get1d(b + layout::material_choice); }, sp);
    else
      return false;
  });
}

}  // namespace mcrt
