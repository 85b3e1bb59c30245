#pragma once
// What the image's sample generator leaves of what `auto`'s choice gains,
// measured per light before rendering; with it each light's rule sees the
// image's noise as the image's own samples leave it (docs/auto.md).
//
// The rule models a light sample's variance with independent samples (v_s),
// and the pilot's V (render/noise_pilot.hpp) is an independent-sample
// variance too, except for its emission term (kappa_E). A pixel's N light
// samples from a stratified or Owen-scrambled Sobol sequence integrate the
// light's smooth part far better than N independent ones: with Sobol points
// the light's own share of the error of area sampling is 0.09-0.20 of its
// independent-sample share with direct light of a large rectangle in a box,
// 0.25-0.34 over a floor at one light size from the light
// (bench/light_noise_share.sh). Measured at a fixed receiver point the
// factor is far smaller still (0.014 over a floor at 0.3 light sizes, where
// the image keeps about 0.3): within a pixel the receiver moves with the
// pixel's own dimensions, and the light's estimate varies with it.
//
// So it is measured where the image takes it, at pixels, on the
// difference of the two estimates the choice is between:
//   kappa = sum_x w_x N Var_m(mean of d) / sum_x w_x Var(d of one sample),
// d = f_c - f_a, the light's direct light estimate with the cheapest
// strategy (c) minus that with the choice (a), both from the same point of
// the square. At each pixel x, M independent scramblings of the image's
// own samples, N = its spp each: the camera ray from the pixel's
// dimensions, and at the diffuse surface it meets the two estimates
// (shadow rays, albedo / pi, over the pdf) from the first bounce's light
// dimensions (samplers/layout.hpp). Both estimate the same integral at
// each point, so d is the light's sampling noise alone: what the pixel's
// footprint and the edges it crosses add to each cancels from it. Var_m is
// the unbiased variance of the M pixel means of d, Var(d of one sample) the
// sample variance of all M N values (each point of a scrambled sequence is
// uniform, so it estimates one independent sample's variance): kappa is 1
// for independent samples. The pixels are the pilot's whose centre's
// receiver the choice samples by a dearer strategy (elsewhere d = 0), at
// most `pixels` of them, evenly spaced.
//
// The light's own noise with its cheapest strategy is a share s of V: the
// pilot's light_variance over V, or the rule's model of it at the pilot's
// receivers (auto_sampler::noise_share), the larger (each alone varies 0.1-1.7
// and 0.5-7 between seeds over a floor at 0.3 light sizes, area sampling's
// noise near a light being heavy-tailed; taking the larger errs towards the
// choice), at most the share of V's reflected part, 1 - V_E / V: V_E, V's
// emission term (what camera rays meet first, at its size with the image's
// samples: noise_pilot_result::edge_variance), holds none of a light sample's
// noise. The image's samples leave kappa of it: the image's noise is
// V (1 - (1 - kappa) s), and the choice gains kappa of what the rule models.
// Near s = 1 V_l is steep in s (dV_l / ds = -V (1 - kappa) / kappa, -6 V at
// kappa = 0.14), and at s = 1 kappa cancels (V_l = V). Capped at 1 only, s
// would take V_l to V on a box under a disk light covering most of its ceiling
// with direct light (size_disk_x8, 8 and 32 spp), where V_E is 9-22 % of V, and
// the choice would lose to area sampling everywhere (0.83x); with the cap (s =
// 0.78-0.87 where it sets s) V_l is 1.8-6.8 V there. The rule of the light then
// sees V_l = V (1 - (1 - kappa) s) / kappa (auto_params::image_variance): its
// scores v_s / v_rest = kappa D^2 v_s / (V (1 - (1 - kappa) s)) are the
// modelled gains with the image's samples against the image's noise with them.
// V <= V_l <= V / kappa: V where the light's noise is all of the image's,
// V / kappa where it is none of it. The path's noise beyond the light's is left
// at its independent size: an overestimate, so the choice is weighed against
// more noise than the image has, never less.
//
// The pixels' light samples are the first bounce's; with global light a
// light sample at a deeper bounce sits on dimensions the sequence
// stratifies less (the light's share 0.8-0.9 of independent in the same box
// with global light), so the kappa the rule takes is f kappa_1 + (1 - f),
// kappa_1 measured on the first bounce and f the share of the pilot's light
// samples taken there (noise_pilot_result::first_bounce_share; 1 with
// direct light alone). With kappa_1 for every light sample the strip
// light of the mixed scene (cornell_two_lights, global light) would get
// V_l = 6 V and area sampling, 0.36x the best fixed strategy.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "mcrt/render/camera.hpp"
#include "mcrt/render/light.hpp"
#include "mcrt/render/noise_pilot.hpp"
#include "mcrt/render/renderer.hpp"
#include "mcrt/render/rest_cost.hpp"
#include "mcrt/samplers/independent.hpp"
#include "mcrt/samplers/layout.hpp"
#include "mcrt/samplers/samplers.hpp"

namespace mcrt {

// The pilot `mcrt render` runs: at most W H / 300 pixels (at least 32, at
// most 256) with 2 scramblings each of the image's samples; each camera
// sample a camera ray, two light samples and two shadow rays (about 1.5 %
// of the image's samples' time with direct light).
inline int choice_gain_pixels_for(int width, int height) {
  return static_cast<int>(std::clamp(static_cast<double>(width) * height / 300.0, 32.0, 256.0));
}

// kappa (header) of the auto light s at the pixels given, for M =
// scramblings sets of samples of type Sampler (seeded from `seed`); 1 where
// the difference never varies (no pixel, or the two strategies agree).
template <class Sampler, class Scene, class Auto>
double choice_gain_factor_with(const Scene& sc, const camera& cam, const render_settings& rs, const Auto& s,
                               std::span<const edge_pixel> pixels, std::uint64_t seed, int scramblings = 2) {
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  constexpr int dim = layout::bounce(0) + layout::light;
  // d at one camera sample: 0 where its ray meets no diffuse surface.
  return sequence_noise_factor<Sampler>(rs, pixels, seed, scramblings, [&](auto& px, int x, int y) {
    hit_record rec;
    if (!sc.hit(camera_ray(cam, px, x, y, inv_w, inv_h), 0.0f, infinity, rec)) return 0.0;
    const auto* lam = std::get_if<lambertian>(&sc.materials[rec.material]);
    if (!lam) return 0.0;
    const vec3 nf = rec.facing_normal();
    const vec3 p = rec.spawn_origin(nf);
    const vec2 u = px.get2d(dim);
    light_sample lc, la;
    const double fc = light_estimate(sc, s.sample_cheapest(p, u, lc), lc, p, nf);
    const double fa = light_estimate(sc, s.sample(p, nf, u, la), la, p, nf);
    return (double(lam->albedo.r) + lam->albedo.g + lam->albedo.b) / 3.0 * inv_pi * (fc - fa);
  }, 1024);  // two light samples and shadow rays each: about 250 ns
}

// With the image's sample generator (rs.sampler); 1 for independent samples.
template <class Scene, class Auto>
double choice_gain_factor(const Scene& sc, const camera& cam, const render_settings& rs, const Auto& s,
                          std::span<const edge_pixel> pixels, int scramblings = 2) {
  if (rs.sampler == sampler_kind::independent || pixels.empty()) return 1.0;
  // Their own seeds ("gainq" and j): not the image's scramblings.
  return with_sampler(rs.sampler, [&]<class S>() {
    return choice_gain_factor_with<S>(sc, cam, rs, s, pixels, rs.seed ^ 0x6761696e71ull, scramblings);
  });
}

// What settle_auto_lights found for one light sampled by `auto`.
struct auto_light_settlement {
  std::size_t light = 0;        // index in the scene's lights
  double kappa = 1.0;           // what the image's samples leave of the choice's gain (header)
  double kappa_first_bounce = 1.0;  // of which at the first bounce's light samples
  double kappa_seconds = 0.0;   // the time its measurement took (0 where it was not measured)
  double noise_share = 0.0;     // s: the light's own noise with its cheapest strategy, over V
  double noise_share_measured = 0.0, noise_share_model = 0.0;
  double image_variance = 0.0;  // V_l: the V its rule sees
  double rest_cost = 0.0;       // c_rest its rule took, ns per light sample
  bool cheapest = false;        // its choice did not pay at the receivers: its cheapest strategy everywhere
};

// For each light of the scene sampled by `auto` (built with V, the pilot's
// image variance, in its params): kappa at the pilot's pixels whose
// receiver it samples by a dearer strategy, its noise share s, and its
// rule rebuilt with V_l = V (1 - (1 - kappa) s) / kappa; then, where that
// rule's choice does not pay at the pilot's receivers
// (use_cheapest_where_choice_does_not_pay), its cheapest strategy.
template <class Scene>
std::vector<auto_light_settlement> settle_auto_lights(Scene& sc, const camera& cam, const render_settings& rs,
                                                      const noise_pilot_result& noise, int pixels,
                                                      bool model_rest_cost = true) {
  std::vector<auto_light_settlement> out;
  for (std::size_t i = 0; i < sc.lights.size(); ++i) {
    std::optional<light> rebuilt;
    // The rule's models at the pilot's receivers: the light's and the
    // points' alone, so one evaluation serves every params weighed below.
    std::vector<auto_choice> models;
    auto_light_settlement a;
    a.light = i;
    bool screened = false;  // the rule's first test takes the cheapest strategy at every receiver
    std::visit(
        [&]<class S>(const S& s) {
          if constexpr (strategy_of<S>() == light_sampling::automatic) {
            auto_params p = s.params;
            // c_rest from the pilot's counted rays and paths per light
            // sample (render/rest_cost.hpp).
            if (model_rest_cost && noise.rays_per_light_sample > 0.0)
              p.rest_cost = modelled_rest_cost(noise.rays_per_light_sample, noise.paths_per_light_sample,
                                               intersection_cost_per_ray(sc), light_shape_cost<decltype(s.shape)>());
            a.rest_cost = p.rest_cost;
            const S with_cost = s.with_params(p);
            a.image_variance = p.image_variance;
            // kappa <= 1 only weighs the choice's gain down (V_l >= V): where
            // the choice does not pay with V, it is not measured.
            if (with_cost.cheapest_at_every(noise.receivers)) {
              screened = true;
              return;
            }
            models = with_cost.receiver_models(noise.receivers);
            if (!(with_cost.table_gain(noise.receivers, models) > 0.0f)) {
              rebuilt = with_cost;
              return;
            }
            std::vector<edge_pixel> dearer;
            for (std::size_t k = 0; k < noise.receivers.size(); ++k)
              if (with_cost.choice(noise.receivers[k].p, noise.receivers[k].n) != s.cheapest())
                dearer.push_back(noise.receiver_pixels[k]);
            const std::vector<edge_pixel> chosen = evenly_spaced(dearer, pixels);
            // Measured on the first bounce's light samples; at deeper
            // bounces the sequence leaves about all of the light's noise
            // (header), so over a path's light samples kappa is the
            // first bounce's share of them times kappa plus the rest.
            const auto kappa_start = std::chrono::steady_clock::now();
            a.kappa_first_bounce = choice_gain_factor(sc, cam, rs, with_cost, chosen);
            a.kappa_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - kappa_start).count();
            const double f = std::clamp(noise.first_bounce_share, 0.0, 1.0);
            a.kappa = f * a.kappa_first_bounce + (1.0 - f);
            const double v = s.params.image_variance;
            const double measured = i < noise.light_variance.size() && v > 0.0 ? noise.light_variance[i] / v : 0.0;
            a.noise_share_measured = measured;
            a.noise_share_model = s.noise_share(models);
            // At most V's reflected part (header).
            const double reflected = v > 0.0 ? std::clamp(1.0 - noise.edge_variance / v, 0.0, 1.0) : 1.0;
            a.noise_share = std::clamp(std::max(measured, a.noise_share_model), 0.0, reflected);
            a.image_variance = a.kappa > 0.0 ? v * (1.0 - (1.0 - a.kappa) * a.noise_share) / a.kappa
                                             : double(std::numeric_limits<float>::max());
            p.image_variance = static_cast<float>(std::min(a.image_variance, double(std::numeric_limits<float>::max())));
            rebuilt = s.with_params(p);
          }
        },
        sc.lights[i]);
    if (screened) {
      a.cheapest = use_cheapest(sc.lights[i]);
      out.push_back(a);
      continue;
    }
    if (!rebuilt) continue;
    sc.lights[i] = std::move(*rebuilt);
    a.cheapest = use_cheapest_where_choice_does_not_pay(sc.lights[i], noise.receivers, models);
    out.push_back(a);
  }
  return out;
}

}  // namespace mcrt
