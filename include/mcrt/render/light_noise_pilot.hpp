#pragma once
// How much of a light's noise the image's sample generator leaves: the
// factor kappa of `auto`, measured before rendering, which with the
// emission term's kappa_E (render/noise_pilot.hpp) sets each light's share
// of the image's noise (auto_params::image_variance; README, "Choosing per
// shading point").
//
// `auto`'s rule models a light sample's variance with independent samples
// (v_s). A pixel's N light samples of a quasi-random sequence (stratified,
// Owen-scrambled Sobol: samplers/) integrate the light's smooth part much
// better than N independent ones: with Sobol points the light's own share
// of the error of area sampling was 0.09-0.20 of its independent-sample
// share with direct light of a large rectangle in a box, 0.25-0.34 over a
// floor at 1 light size from the light (README, "What the rule does not
// know"; bench/light_noise_share.sh).
//
// kappa = sum_r N Var_m(mean of N estimates) / sum_r Var(one estimate)
// over the noise pilot's receivers r (the diffuse surfaces its pixels'
// centres see): at each, the light's estimate V cos+(theta) / pdf (its
// direct light over L, V the shadow ray's visibility, with the light's own
// sampler: in the pilot's
// scene, the shape's cheapest strategy) from N = the image's spp points of
// the image's sample generator, in the dimensions a path's first light
// sample takes (samplers/layout.hpp), for M independent scramblings (M
// pseudo-pixels per receiver). Var_m is the unbiased variance of the M
// means, Var(one estimate) the sample variance of all M N estimates (each
// point of a scrambled sequence is uniform, so it estimates the variance
// of one independent sample, up to a relative bias of kappa / (M N)). The
// sums weigh each receiver by its variance, as the image's error does.
// kappa is 1 for independent samples (not measured) and where no receiver
// sees the light.
//
// The same points stratify the rest of a path's first bounce (visibility,
// which kappa includes, and the pixel's footprint), and the path's noise
// V_R (the pilot's, with independent samples) is largely the light's own
// where a light's noise matters at all; so `mcrt render` takes V_R as
// reduced by kappa as well, and only the emission term by its own
// kappa_E: the rule's v_s / v_rest is then the independent-sample one with
// V = V_R + (kappa_E / kappa) V_E (main.cpp). Where the image's noise is
// a light's edges in view (the boxes, direct light) this weighs the edges
// by how much better the sequence resolves them than the light's noise.
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/render/light.hpp"
#include "mcrt/samplers/layout.hpp"
#include "mcrt/samplers/samplers.hpp"
#include "mcrt/sampling/auto_strategy.hpp"

namespace mcrt {

struct light_noise_pilot_settings {
  int receivers = 128;  // at most this many of the pilot's receivers (evenly spaced in its order)
  int scramblings = 4;  // M >= 2 pseudo-pixels per receiver
};

// The pilot `mcrt render` runs for an image of width x height: 2
// scramblings at as many receivers as make 1 % of the image's samples
// (W H / 200), at least 32, at most 128: light samples with their shadow
// rays, a fraction of a path's cost each (4 scramblings at W H / 100 took
// 3-4 % of a 100 x 100 render's time with direct light).
inline light_noise_pilot_settings light_noise_pilot_for(int width, int height) {
  const double r = 0.005 * static_cast<double>(width) * height;
  return {static_cast<int>(std::clamp(r, 32.0, 128.0)), 2};
}

// kappa of the light sc.lights[index] at the receivers rs, for the image's
// samples of type Sampler at spp per pixel. The estimate is 0 where the
// shadow ray towards the sampled point meets anything before it.
template <class Sampler, class Scene>
double light_noise_factor_with(const Scene& sc, std::size_t index, std::span<const auto_receiver> rs, int spp,
                               std::uint64_t seed, const light_noise_pilot_settings& ps = {}) {
  const light& l = sc.lights[index];
  const int m = std::max(ps.scramblings, 2), n = std::max(spp, 1);
  const std::size_t count = std::min(rs.size(), static_cast<std::size_t>(std::max(ps.receivers, 1)));
  // Its own seed ("kappa"): the image's pixels' scramblings are not these.
  const Sampler sampler(seed ^ 0x6b61707061ull, n);
  constexpr int dim = layout::bounce(0) + layout::light;
  double between = 0.0, within = 0.0;
  std::vector<double> means(static_cast<std::size_t>(m));
  for (std::size_t i = 0; i < count; ++i) {
    // Evenly spaced over the receivers, which are in pixel order (rows).
    const auto_receiver& r = rs[i * rs.size() / count];
    double sum = 0.0, sum2 = 0.0;
    for (int j = 0; j < m; ++j) {
      auto px = sampler.start_pixel(static_cast<int>(i), j, static_cast<int>(count));
      double s = 0.0;
      for (int k = 0; k < n; ++k) {
        px.start_sample(k);
        light_sample ls;
        double f = 0.0;
        if (sample(l, r.p, r.n, px.get2d(dim), ls) && ls.pdf > 0.0f) {
          const float c = glm::dot(ls.dir, r.n);
          hit_record rec;
          // Unoccluded: nothing met before the sampled point (the light
          // itself ends the ray a little before it).
          if (c > 0.0f && !sc.hit(ray{r.p, ls.dir}, sc.ray_epsilon, ls.dist * (1.0f - 1e-4f), rec))
            f = c / double(ls.pdf);
        }
        s += f, sum2 += f * f;
      }
      sum += s;
      means[static_cast<std::size_t>(j)] = s / n;
    }
    const double total = double(m) * n;
    if (!(sum > 0.0)) continue;  // the light gives this receiver nothing
    const double mean = sum / total;
    double ss = 0.0;
    for (const double x : means) ss += (x - mean) * (x - mean);
    between += n * ss / (m - 1);
    within += std::max(sum2 - total * mean * mean, 0.0) / (total - 1.0);
  }
  return within > 0.0 ? between / within : 1.0;
}

// With the sample generator named (1 for independent samples, by definition).
template <class Scene>
double light_noise_factor(const Scene& sc, std::size_t index, std::span<const auto_receiver> rs, sampler_kind k,
                          int spp, std::uint64_t seed, const light_noise_pilot_settings& ps = {}) {
  if (k == sampler_kind::independent) return 1.0;
  return with_sampler(k, [&]<class S>() { return light_noise_factor_with<S>(sc, index, rs, spp, seed, ps); });
}

}  // namespace mcrt
