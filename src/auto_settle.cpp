#include "auto_pilot.hpp"

namespace mcrt::cli {

std::vector<auto_light_settlement> settle_lights(scene& sc, const camera& cam, const render_settings& rs,
                                                 const noise_pilot_result& noise, bool rest_cost_from_pilot) {
  return settle_auto_lights(sc, cam, rs, noise, choice_gain_pixels_for(rs.width, rs.height), rest_cost_from_pilot);
}

}  // namespace mcrt::cli
