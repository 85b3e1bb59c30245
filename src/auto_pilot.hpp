#pragma once
// The pilots of `--light-sampling auto` in the executable (docs/auto.md):
// the image's noise and the emission term's factor kappa_E
// (render/noise_pilot.hpp), and each light's settling at the fixed point of
// the image's noise and time (render/choice_gain_pilot.hpp). Each is
// compiled in a translation unit of its own (auto_noise_pilot.cpp,
// auto_settle.cpp): they instantiate the integrators and samplers again,
// and beside main.cpp they made the longest unit of the build.
#include <vector>

#include "mcrt/mcrt.hpp"

namespace mcrt::cli {

// The noise pilot with the emission term taken from the image's own
// samples: noise.seconds includes both parts.
struct image_noise {
  noise_pilot_result noise;
  double edge_factor = 1.0;  // kappa_E
  double noise_seconds = 0.0, emission_seconds = 0.0;
};
image_noise measure_image_noise(const scene& sc, const camera& cam, const render_settings& rs);

// settle_auto_lights over the choice gain pilot's pixels of the image.
std::vector<auto_light_settlement> settle_lights(scene& sc, const camera& cam, const render_settings& rs,
                                                 const noise_pilot_result& noise, bool rest_cost_from_pilot);

}  // namespace mcrt::cli
