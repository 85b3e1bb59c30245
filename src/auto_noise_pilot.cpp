#include <chrono>

#include "auto_pilot.hpp"

namespace mcrt::cli {

image_noise measure_image_noise(const scene& sc, const camera& cam, const render_settings& rs) {
  image_noise out;
  out.noise = estimate_image_variance(sc, cam, rs, noise_pilot_for(rs.width, rs.height, rs.spp));
  out.noise_seconds = out.noise.seconds;
  // The emission term with the image's own samples (render/noise_pilot.hpp).
  const auto start = std::chrono::steady_clock::now();
  out.edge_factor = edge_noise_factor(sc, cam, rs, out.noise.edge_pixels);
  scale_emission_term(out.noise, out.edge_factor);
  out.emission_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.noise.seconds += out.emission_seconds;
  return out;
}

}  // namespace mcrt::cli
