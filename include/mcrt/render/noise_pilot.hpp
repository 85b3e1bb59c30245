#pragma once
// The image's noise, measured before rendering: the mean over pixels of the
// variance of one pixel sample (radiance^2, averaged over the channels),
// the V of `auto` (sampling/auto_strategy.hpp, auto_params::image_variance).
//
// A pilot renders a regular subset of the image's own pixels (every
// stride-th pixel in x and y, the stride chosen to give about `pixels` of
// them), at the image's resolution, so that each pixel's footprint, and
// with it the noise of edges (a light seen by the camera), is the image's;
// each pixel takes `spp` independent samples with the scene's integrator,
// and its variance is the unbiased sample variance of those. The mean over
// the pixels is then an unbiased estimate of the image's mean variance per
// sample with independent samples (quasi-random samples converge faster
// where the integrand is smooth; the pilot does not model that). It also
// takes the mean squared albedo of the diffuse surfaces the pixels' centres
// see (the channels' mean): the light's contribution to a pixel is the
// surface's albedo times a white surface's, which `auto` takes on average.
//
// The emitters the camera sees. Where a pixel straddles the edge of an
// emitter (or of the background) in view, the radiance the camera ray meets
// first jumps, and with two samples that pixel's sample variance is either
// 0 or large: a few such pixels made the pilot's V swing by 6-20x between
// seeds (the Cornell boxes' ceiling lights). So each pixel's variance is
// s2(X) - s2(E) + s2_K(E), with E the radiance the camera ray meets first
// (emission, or background): the part of the two samples' variance that
// comes from E is taken out and put back as measured by K more camera rays
// (hit tests only) uniform in the pixel. Each term is an unbiased sample
// variance of uniform pixel positions, so the sum stays unbiased for the
// variance of X, with far less spread.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <thread>
#include <variant>
#include <vector>

#include "mcrt/render/camera.hpp"
#include "mcrt/render/renderer.hpp"
#include "mcrt/samplers/independent.hpp"

namespace mcrt {

struct noise_pilot_settings {
  int pixels = 1024;       // about this many pixels of the image (all, for smaller images)
  int spp = 2;             // samples per pixel (>= 2: a sample variance needs two)
  int emission_rays = 8;   // K camera rays per pixel for the variance of what they meet first (< 2: none)
};

// The pilot `mcrt render` runs for an image of width x height at spp: 1024
// pixels, or fewer where that would exceed 1 % of the image's samples (at
// least 64), with 2 samples and 8 emission rays (hit tests) each.
inline noise_pilot_settings noise_pilot_for(int width, int height, int spp) {
  const double budget = 0.01 * static_cast<double>(width) * height * spp / 2.0;  // pixels at 2 samples
  return {static_cast<int>(std::clamp(budget, 64.0, 1024.0)), 2, 8};
}

// The radiance a camera ray meets first: the emission of the surface it
// hits (front side; 0 for a surface that does not emit), or the background.
template <class Scene>
color radiance_met_first(const Scene& sc, const ray& r) {
  hit_record rec;
  if (!sc.hit(r, sc.ray_epsilon, infinity, rec)) return sc.background;
  return emitted(sc.materials[rec.material], rec);
}

// The unbiased sample variance of n >= 2 values, averaged over the channels.
inline double sample_variance(const glm::dvec3* v, int n) {
  glm::dvec3 mean(0.0), ss(0.0);
  for (int i = 0; i < n; ++i) mean += v[i];
  mean /= static_cast<double>(n);
  for (int i = 0; i < n; ++i) ss += (v[i] - mean) * (v[i] - mean);
  return (ss.x + ss.y + ss.z) / (3.0 * (n - 1));
}

struct noise_pilot_result {
  double image_variance = 0.0;  // mean variance of one pixel sample, radiance^2
  double mean_albedo2 = 1.0;    // mean squared albedo (of the channels' mean) the camera sees on diffuse surfaces
  double seconds = 0.0;         // wall-clock time of the pilot
  int pixels = 0;               // pixels measured
  int stride = 1;
};

// Every stride-th pixel in each direction, stride = floor(sqrt(W H / pixels))
// (at least 1), starting half a stride in.
inline int noise_pilot_stride(int width, int height, int pixels) {
  const double k = std::sqrt(static_cast<double>(width) * height / std::max(pixels, 1));
  return std::max(1, static_cast<int>(k));
}

template <class Integrator, class Scene>
noise_pilot_result estimate_image_variance_with(const Scene& sc, const camera& cam, const render_settings& rs,
                                                const noise_pilot_settings& ps = {}) {
  noise_pilot_result out;
  const int m = std::max(ps.spp, 2);
  out.stride = noise_pilot_stride(rs.width, rs.height, ps.pixels);
  const int k = out.stride, x0 = k / 2, y0 = k / 2;
  const int nx = (rs.width - x0 + k - 1) / k, ny = (rs.height - y0 + k - 1) / k;
  // Its own seed: the pilot's samples are not the image's.
  const independent_sampler sampler(rs.seed ^ 0x70696c6f74ull, m);  // "pilot"
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  const path_settings set = rs.path();

  unsigned n = rs.threads ? rs.threads : std::max(1u, std::thread::hardware_concurrency());
  n = std::max(1u, std::min<unsigned>(n, static_cast<unsigned>(ny)));
  // Per row, summed in row order afterwards: the result does not depend on
  // which thread took which row (the choices of `auto` depend on it).
  std::atomic<int> next_row{0};
  std::vector<double> row_sums(static_cast<std::size_t>(ny), 0.0), row_albedo2(static_cast<std::size_t>(ny), 0.0);
  std::vector<int> row_counts(static_cast<std::size_t>(ny), 0), row_diffuse(static_cast<std::size_t>(ny), 0);
  const int k_rays = ps.emission_rays >= 2 ? ps.emission_rays : 0;
  auto worker = [&] {
    std::vector<glm::dvec3> c(static_cast<std::size_t>(m)), e(static_cast<std::size_t>(m)),
        ek(static_cast<std::size_t>(std::max(k_rays, 1)));
    for (int j; (j = next_row.fetch_add(1, std::memory_order_relaxed)) < ny;) {
      const int y = y0 + j * k;
      double sum = 0.0, albedo2 = 0.0;
      int count = 0, diffuse = 0;
      for (int i = 0; i < nx; ++i) {
        const int x = x0 + i * k;
        // The surface at the pixel's centre: its albedo, if diffuse.
        hit_record rec;
        if (sc.hit(pixel_ray(cam, x, y, vec2(0.5f), inv_w, inv_h), sc.ray_epsilon, infinity, rec))
          if (const auto* l = std::get_if<lambertian>(&sc.materials[rec.material])) {
            const double a = (double(l->albedo.r) + l->albedo.g + l->albedo.b) / 3.0;
            albedo2 += a * a;
            ++diffuse;
          }
        auto px = sampler.start_pixel(x, y, rs.width);
        int finite = 0;
        for (int s = 0; s < m; ++s) {
          px.start_sample(s);
          const ray r = camera_ray(cam, px, x, y, inv_w, inv_h);
          const color v = Integrator::li(sc, r, px, set);
          if (!all_finite(v)) continue;
          c[static_cast<std::size_t>(finite)] = glm::dvec3(v);
          if (k_rays) e[static_cast<std::size_t>(finite)] = glm::dvec3(radiance_met_first(sc, r));
          ++finite;
        }
        if (finite < 2) continue;
        double var = sample_variance(c.data(), finite);
        if (k_rays) {
          // What the camera rays meet first: its two-sample variance out,
          // its K-ray variance in (header).
          for (int i = 0; i < k_rays; ++i)
            ek[static_cast<std::size_t>(i)] =
                glm::dvec3(radiance_met_first(sc, pixel_ray(cam, x, y, px.stream().uniform2(), inv_w, inv_h)));
          var += sample_variance(ek.data(), k_rays) - sample_variance(e.data(), finite);
        }
        sum += var;
        ++count;
      }
      row_sums[static_cast<std::size_t>(j)] = sum;
      row_counts[static_cast<std::size_t>(j)] = count;
      row_albedo2[static_cast<std::size_t>(j)] = albedo2;
      row_diffuse[static_cast<std::size_t>(j)] = diffuse;
    }
  };

  const auto start = std::chrono::steady_clock::now();
  {
    std::vector<std::jthread> pool;
    for (unsigned t = 1; t < n; ++t) pool.emplace_back(worker);
    worker();
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  double sum = 0.0, albedo2 = 0.0;
  int diffuse = 0;
  for (std::size_t j = 0; j < static_cast<std::size_t>(ny); ++j) {
    sum += row_sums[j], out.pixels += row_counts[j];
    albedo2 += row_albedo2[j], diffuse += row_diffuse[j];
  }
  // (A mean of unbiased terms, one of them subtracted: clamped at 0.)
  out.image_variance = out.pixels ? std::max(sum / out.pixels, 0.0) : 0.0;
  if (diffuse > 0) out.mean_albedo2 = albedo2 / diffuse;
  return out;
}

// With the integrator named in rs (the pilot's sampler is always independent).
template <class Scene>
noise_pilot_result estimate_image_variance(const Scene& sc, const camera& cam, const render_settings& rs,
                                           const noise_pilot_settings& ps = {}) {
  return with_integrator(rs.integrator,
                         [&]<class I>() { return estimate_image_variance_with<I>(sc, cam, rs, ps); });
}

}  // namespace mcrt
