#pragma once
// How each light `auto` samples weighs its choice against the image, before
// rendering (docs/auto.md): the image's noise V_l its rule sees and the
// rest of a path's time per light sample c_rest, at the fixed point of the
// choice they make.
//
// The rule scores a point's change to first order, against the image's
// noise and time per light sample (auto_choice::score). Taken at the
// pilot's (render/noise_pilot.hpp: V with each light's cheapest strategy
// everywhere) they are the image's before the choice, and where the
// light's own noise is much of the image's the first order misjudges the
// choice as a whole: under a sliver of aspect 100 (tri_aspect_a100, direct
// light) area sampling's noise is all of V, a receiver's gain from solid
// angle looks no larger than its cost, and area sampling was kept at most
// receivers, although solid angle everywhere has 1/150 of the error at 1.5x
// the time. The weights the choice should have are the image's with it:
//   V_l = R + s' V,  c_rest' = c_rest + C_c - C_0,
// s' = s N_c / N_0 the light's share of V with the choice (N the means over
// the pilot's receivers of D^2 v / V with the choice and with the cheapest
// strategy, modelled: auto_sampler::modelled_totals), C the mean costs, and
// R the image's noise beyond the light's. Both fall, resp. rise, as the
// choice gets dearer, so iterating from V and c_rest moves them
// monotonically to the fixed point (settle_fixed_point: a few steps).
//
// s, the light's share of V with its cheapest strategy: the pilot's
// light_variance over V, or the rule's model of it (auto_sampler::
// noise_share), the larger (both are heavy-tailed near a light, each
// varying 0.4-12 between seeds over a floor at 0.3 light sizes; the larger
// errs towards the choice), at most V's reflected part, 1 - V_E / V (V_E,
// V's emission term, holds none of a light sample's noise).
//
// R, the image's noise beyond the light's, from a second pilot with every
// light `auto` samples by its lowest-variance strategy, projected solid
// angle (low_variance_pilot, run once for all of them): its reflected
// part (the light's noise left there, from occlusion, the choice cannot
// remove either), plus the first pilot's emission term V_E; at least V b, b the
// BSDF samples' part of the light's estimate with mis (auto_sampler::
// mis_floor, auto_choice::v_bsdf_mis). Not V (1 - s): with the cheapest
// strategy under a sliver the pilot's V is heavy-tailed (tri_aspect_a10000,
// 8 spp: V 0.0057, 0.0047 and 0.00066 at seeds 1-3, while s V stays near
// 0.0028), R = V (1 - s) took the tail in, and at some seeds the choice
// was weighed against several times the image's noise and kept cheaper
// strategies where projected solid angle has a hundredth of their variance
// (4 of the 12 renders of tri_aspect_a1000 and a10000 had 19-170x its
// error; with the second pilot none, and auto went from 0.66-0.74x to
// 0.97-1.05x the best fixed strategy there). With the light's own noise
// small, the rest is steady (under a sliver of aspect 10^4, over 6 pilot
// seeds, R varies 3.1x where V varies 68x). The second pilot is part of
// auto's time.
// Without the floor V b, where the rest is all the light's (a bare floor
// under it) R would be 0, V_l would fall to 0 and projected solid angle
// (modelled variance 0) would be taken everywhere at any cost (2.2x slower
// than solid angle for the same error over a floor at 0.3 light sizes,
// distance_h0.3).
//
// The image's own samples (stratified, Sobol) leave less of a light's noise
// than independent ones, and less of the rest, but not alike: under a small
// light 3 or 10 edges above a floor (tri_distance_h3, h10) Sobol points
// leave 0.004-0.05 of the light's noise and 0.3-0.5 of the rest
// (bench/results/sobol_noise_split). The score weighs a light's noise
// against the image's; with kappa_l and kappa_R what the sequence leaves of
// each, V_l = R kappa_R / kappa_l + s' V in the light's units. So with
// those samples, kappa_l is measured at the fixed point's choice (as nee's
// kappa below, choice_gain_factor), kappa_R is modelled
// (rest_sequence_factor), and where kappa_l < kappa_R the fixed point is
// taken again with R weighed by kappa_R / kappa_l (the floor V b not: it
// is the light's own estimate's noise). Taking the two as cancelling (the
// earlier form) took projected solid angle over most of the floor under
// those lights, where area sampling or solid angle is best (0.67x and
// 0.88x the best fixed strategy).
//
// With nee there is no BSDF floor: a light's samples are all of its
// estimate, s clamped to 1 leaves R = 0, and the fixed point took
// projected solid angle everywhere over a floor at 0.3 light sizes (0.45x
// the first-order rule's efficiency: there the image's noise is mostly not
// the light's, which the sequence removes far better than the rest). nee
// keeps the first-order rule, with kappa, what the image's samples leave
// of the choice's gain, measured per light (choice_gain_factor):
//   kappa = sum_x w_x N Var_m(mean of d) / sum_x w_x Var(d of one sample),
// d = f_c - f_a the light's estimates with the cheapest strategy and the
// choice from the same point of the square, at up to `pixels` of the
// pilot's pixels where the choice is dearer (evenly spaced), M = 2
// scramblings of the image's samples, N = spp each; kappa = f kappa_1 + (1
// - f) over a path's light samples (f the first bounce's share); V_l = V
// (1 - (1 - kappa) s) / kappa, the rest left at its independent size.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
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

// kappa_R (header): what the image's samples leave of the rest of its
// noise, against independent samples; 1 for independent samples, else
// 1/sqrt(spp) and at least 1/3. Not measured: the rest sits in few pixels
// (the edges of what is in view), and measured in the pilot it spread
// 0.005-0.5 between seeds where it is 0.27. A discontinuity across a
// pixel leaves N^-3/2 of its variance to N stratified samples against N^-1
// (1/sqrt(N) of it; Owen 1997); Sobol points left 0.27-0.50 of the rest
// of the triangle members at 8 and 32 spp
// (bench/results/sobol_noise_split), about as much at both.
inline double rest_sequence_factor(const render_settings& rs) {
  if (rs.sampler == sampler_kind::independent) return 1.0;
  return std::max(1.0 / 3.0, 1.0 / std::sqrt(double(std::max(rs.spp, 1))));
}

// The fixed point of a light's V_l and c_rest (header), from V, its noise
// share s, R and c_rest; p holds V_l and c_rest on entry (V and c_rest)
// and the fixed point on return; the steps taken (at most `steps`).
template <class Auto>
int settle_fixed_point(const Auto& s, std::span<const auto_receiver> rs, std::span<const auto_choice> models,
                       double v, double share, double rest_noise, float rest_cost, auto_params& p, int steps = 16) {
  // With the cheapest strategy everywhere: N_0 and C_0.
  const double base_noise = s.noise_share(models), base_cost = s.cheapest_cost();
  if (!(base_noise > 0.0) || !(v > 0.0)) return 0;
  int k = 0;
  for (; k < steps; ++k) {
    const auto with = s.modelled_totals(rs, models, p);
    const double share_after = share * with.noise / base_noise;
    const double vl = rest_noise + share_after * v;
    const float vf = static_cast<float>(std::clamp(vl, double(std::numeric_limits<float>::min()),
                                                   double(std::numeric_limits<float>::max())));
    const float rest = rest_cost + static_cast<float>(with.cost - base_cost);
    if (std::abs(vf - p.image_variance) <= 1e-3f * p.image_variance && std::abs(rest - p.rest_cost) <= 0.5f) break;
    p.image_variance = vf, p.rest_cost = rest;
  }
  return k;
}

// The noise pilot `mcrt render` runs (noise_pilot_for), V's reflected part
// alone (no emission rays, no light's own noise measured), with every
// light `auto` samples by its
// projected-solid-angle sampler (the strategy of least variance, 0 in the
// rule's model: the rule's choice at V -> 0, without its lookups and table
// to fill): the lights are restored on return. No reference into sc.lights
// may be held across the call.
template <class Scene>
noise_pilot_result low_variance_pilot(Scene& sc, const camera& cam, const render_settings& rs) {
  // The auto lights moved out (no copies: many lights are many shared
  // tables' reference counts), their projected samplers in their place.
  std::vector<std::pair<std::size_t, light>> kept;
  kept.reserve(static_cast<std::size_t>(std::count_if(sc.lights.begin(), sc.lights.end(), [](light_ref l) {
    return strategy_of(l) == light_sampling::automatic;
  })));
  for (std::size_t i = 0; i < sc.lights.size(); ++i) {
    std::optional<light> projected;
    dispatch(sc.lights[i], [&]<class S>(const S& s) {
      if constexpr (strategy_of<S>() == light_sampling::automatic) projected = s.projected;
    });
    if (!projected) continue;
    kept.emplace_back(i, sc.lights.take(i));
    sc.lights.set(i, std::move(*projected));
  }
  noise_pilot_settings ps = noise_pilot_for(rs.width, rs.height, rs.spp);
  ps.reflected_only = true;
  ps.light_noise_limit = 0;  // the lights' own noise is not taken out (header)
  noise_pilot_result r = estimate_image_variance(sc, cam, rs, ps);
  for (auto& [i, l] : kept) sc.lights.set(i, std::move(l));
  sc.lights.compact();
  return r;
}

// What settle_auto_lights found for one light sampled by `auto`.
struct auto_light_settlement {
  std::size_t light = 0;        // index in the scene's lights
  double kappa = 1.0;           // nee: what the image's samples leave of the choice's gain (header)
  double kappa_first_bounce = 1.0;  // of which at the first bounce's light samples
  double kappa_seconds = 0.0;   // the time its measurement took (0 where it was not measured)
  double noise_share = 0.0;     // s: the light's own noise with its cheapest strategy, over V
  double noise_share_measured = 0.0, noise_share_model = 0.0;
  double rest_noise = 0.0;      // R: the image's noise beyond the light's (header)
  double rest_weight = 1.0;     // mis, mixture: kappa_R / kappa_l, R's weight in V_l (header; 1: not weighed)
  // R as V_l takes it: the rest beyond the BSDF floor `floor` weighed, at
  // least the floor (the light's own noise, which the sequence reduces as
  // the light's).
  double weighed_rest_noise(double floor, double rest) const { return std::max(rest * rest_weight, floor); }
  double rest_pilot_seconds = 0.0;  // the low-variance pilot's time, on the light that ran it (mis, mixture: header)
  double image_variance = 0.0;  // V_l: the V its rule sees
  double rest_cost = 0.0;       // c_rest its rule took, ns per light sample (with its choice's own cost: header)
  int fixed_point_steps = 0;    // the steps its V_l and c_rest took to their fixed point
  bool cheapest = false;        // its choice did not pay at the receivers: its cheapest strategy everywhere
};

// For each light of the scene sampled by `auto` (built with V, the pilot's
// image variance, in its params): its noise share s, its rule rebuilt with
// V_l and c_rest at their fixed point (header); then, where that rule's
// choice does not pay at the pilot's receivers
// (use_cheapest_where_choice_does_not_pay), its cheapest strategy.
// First, triangles whose rule takes area sampling at every receiver before
// its fine model (auto_sampler::cheapest_at_every) get it without the
// models; then the others are settled, with mis and mixture R measured
// with the first ones as they will be rendered.
template <class Scene>
std::vector<auto_light_settlement> settle_auto_lights(Scene& sc, const camera& cam, const render_settings& rs,
                                                      const noise_pilot_result& noise, int pixels,
                                                      bool model_rest_cost = true) {
  std::optional<noise_pilot_result> low;  // run where a light with mis first needs R
  double low_seconds = 0.0;               // its time, reported on that light
  // c_rest from the pilot's counted rays and paths per light sample
  // (render/rest_cost.hpp), for a light of shape S.
  const float tests_per_ray = intersection_cost_per_ray(sc);
  const auto with_rest_cost = [&]<class S>(const S& s) {
    auto_params p = s.params;
    if (model_rest_cost && noise.rays_per_light_sample > 0.0)
      p.rest_cost = modelled_rest_cost(noise.rays_per_light_sample, noise.paths_per_light_sample, tests_per_ray,
                                       light_shape_cost<decltype(s.shape)>());
    return p;
  };
  std::vector<std::optional<auto_light_settlement>> found(sc.lights.size());
  // The screen.
  const auto_receiver_groups receiver_groups(noise.receivers);
  for (std::size_t i = 0; i < sc.lights.size(); ++i) {
    const bool screened = dispatch(
        sc.lights[i], [&]<class S>(const S& s) {
          if constexpr (strategy_of<S>() == light_sampling::automatic) {
            const auto_params p = with_rest_cost(s);
            if (!s.cheapest_at_every(receiver_groups, p)) return false;
            auto_light_settlement a;
            a.light = i, a.rest_cost = p.rest_cost, a.image_variance = p.image_variance;
            found[i] = a;
            return true;
          }
          return false;
        });
    if (screened) found[i]->cheapest = use_cheapest(sc.lights, i);
  }
  for (std::size_t i = 0; i < sc.lights.size(); ++i) {
    if (found[i]) continue;
    bool need_low = false;
    std::optional<light> rebuilt;
    // The rule's models at the pilot's receivers: the light's and the
    // points' alone, so one evaluation serves every params weighed below.
    std::vector<auto_choice> models;
    auto_light_settlement a;
    a.light = i;
    dispatch(
        sc.lights[i], [&]<class S>(const S& s) {
          if constexpr (strategy_of<S>() == light_sampling::automatic) {
            auto_params p = with_rest_cost(s);
            a.rest_cost = p.rest_cost;
            a.image_variance = p.image_variance;
            const S with_cost = s.with_params(p);
            models = with_cost.receiver_models(noise.receivers);
            const double v = s.params.image_variance;
            const double measured = i < noise.light_variance.size() && v > 0.0 ? noise.light_variance[i] / v : 0.0;
            a.noise_share_measured = measured;
            a.noise_share_model = s.noise_share(models);
            const double reflected = v > 0.0 ? std::clamp(1.0 - noise.edge_variance / v, 0.0, 1.0) : 1.0;
            a.noise_share = std::clamp(std::max(measured, a.noise_share_model), 0.0, reflected);
            // The pilot's pixels where `light` takes a dearer strategy than
            // the cheapest (at most `pixels`, evenly spaced among them).
            const auto dearer_pixels = [&](const S& light) {
              std::vector<edge_pixel> dearer;
              for (std::size_t k = 0; k < noise.receivers.size(); ++k)
                if (light.choice(noise.receivers[k].p, noise.receivers[k].n) != s.cheapest())
                  dearer.push_back(noise.receiver_pixels[k]);
              return evenly_spaced(dearer, pixels);
            };
            // kappa (header) of `light` at those pixels, into a. Measured on
            // the first bounce's light samples; at deeper bounces the
            // sequence leaves about all of the light's noise, so over a
            // path's light samples kappa is the first bounce's share of them
            // times kappa plus the rest.
            const auto measure_kappa = [&](const S& light, std::span<const edge_pixel> at) {
              const auto kappa_start = std::chrono::steady_clock::now();
              a.kappa_first_bounce = choice_gain_factor(sc, cam, rs, light, at);
              a.kappa_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - kappa_start).count();
              const double f = std::clamp(noise.first_bounce_share, 0.0, 1.0);
              a.kappa = f * a.kappa_first_bounce + (1.0 - f);
            };
            if (p.pdf_with_sample) {
              // nee (header): the first-order rule with kappa measured, where
              // the choice pays with V.
              if (!(with_cost.table_gain(noise.receivers, models) > 0.0f)) {
                rebuilt = with_cost;
                return;
              }
              measure_kappa(with_cost, dearer_pixels(with_cost));
              a.rest_noise = v * (1.0 - a.noise_share);
              a.image_variance = a.kappa > 0.0 ? v * (1.0 - (1.0 - a.kappa) * a.noise_share) / a.kappa
                                               : double(std::numeric_limits<float>::max());
              p.image_variance =
                  static_cast<float>(std::min(a.image_variance, double(std::numeric_limits<float>::max())));
              rebuilt = s.with_params(p);
              return;
            }
            // mis and mixture: R from the low-variance pilot (header), at
            // least V b; run once, outside this visit (it swaps the lights).
            if (!low) {
              need_low = true;
              return;
            }
            a.rest_pilot_seconds = low_seconds;
            low_seconds = 0.0;
            a.rest_noise = std::max(low->image_variance + noise.edge_variance, v * s.mis_floor(models));
            const auto_params start = p;
            a.fixed_point_steps = settle_fixed_point(s, noise.receivers, models, v, a.noise_share, a.rest_noise,
                                                     a.rest_cost, p);
            // With stratified or Sobol samples: kappa_l at that fixed
            // point's choice, and the fixed point again with R weighed by
            // kappa_R / kappa_l where the sequence leaves less of the
            // light's noise than of the rest (header).
            if (rs.sampler != sampler_kind::independent) {
              const S settled = s.with_params(p);
              const std::vector<edge_pixel> dearer = dearer_pixels(settled);
              if (!dearer.empty()) {
                measure_kappa(settled, dearer);
                const double kappa_rest = rest_sequence_factor(rs);
                if (a.kappa > 0.0 && a.kappa < kappa_rest) {
                  a.rest_weight = kappa_rest / a.kappa;
                  p = start;
                  const double weighed = a.weighed_rest_noise(v * s.mis_floor(models),
                                                              low->image_variance + noise.edge_variance);
                  a.fixed_point_steps =
                      settle_fixed_point(s, noise.receivers, models, v, a.noise_share, weighed, a.rest_cost, p);
                }
              }
            }
            a.image_variance = p.image_variance;
            a.rest_cost = p.rest_cost;
            rebuilt = s.with_params(p);
          }
        });
    if (need_low) {
      // The low-variance pilot, then this light again.
      const auto start = std::chrono::steady_clock::now();
      low = low_variance_pilot(sc, cam, rs);
      low_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      --i;  // unsigned: wraps at 0, and the loop's ++i brings it back
      continue;
    }
    if (!rebuilt) continue;
    sc.lights.set(i, std::move(*rebuilt));
    a.cheapest = use_cheapest_where_choice_does_not_pay(sc.lights, i, noise.receivers, models);
    found[i] = a;
  }
  sc.lights.compact();  // the holes the lights' new strategies left
  std::vector<auto_light_settlement> out;
  for (const auto& a : found)
    if (a) out.push_back(*a);
  return out;
}

}  // namespace mcrt
