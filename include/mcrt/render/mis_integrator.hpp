#pragma once
// Next-event estimation with multiple importance sampling (Veach & Guibas
// 1995; Veach 1997, sec. 9.2; pbrt-v4's PathIntegrator, Mitsuba 3's path):
// at each diffuse bounce the light sample and the material's sample both
// count the direct light, each weighted by the heuristic of its density
// against the other technique's density for the same direction (power
// heuristic, beta = 2, by default; balance on request: mis.hpp). Both
// densities are per unit solid angle: the light technique's is that of the
// whole choice-then-sample (light_selection.hpp), evaluated through each
// strategy's pdf, so every light strategy takes part as it samples.
//
// The loop is next_event_integrator (nee_integrator.hpp); only the weights
// differ.
#include "mcrt/render/nee_integrator.hpp"

namespace mcrt {

struct heuristic_weights {
  static constexpr bool material_counts_listed_lights = true;
  static float light(const path_settings& set, float p_light, float p_material) {
    return mis_weight(set.heuristic, p_light, p_material);
  }
  static float material(const path_settings& set, float p_material, float p_light) {
    return mis_weight(set.heuristic, p_material, p_light);
  }
};

struct mis_integrator : next_event_integrator<heuristic_weights> {
  static constexpr const char* name = "mis";
};

}  // namespace mcrt
