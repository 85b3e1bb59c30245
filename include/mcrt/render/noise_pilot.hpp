#pragma once
// The image's noise, measured before rendering: the mean over pixels of the
// variance of one pixel sample (radiance^2, averaged over the channels),
// the V of `auto` (sampling/auto_strategy.hpp, auto_params::image_variance).
//
// A pilot renders a stratified subset of the image's own pixels (one pixel
// drawn uniformly in each stride x stride block, the stride chosen to give
// about `pixels` blocks), at the image's resolution, so that each pixel's
// footprint, and with it the noise of edges (a light seen by the camera),
// is the image's; each pixel takes `spp` independent samples with the
// scene's integrator, and its variance is the unbiased sample variance of
// those. The mean over the blocks, each weighted by its area (the last
// row and column of blocks may be narrower), is then an unbiased estimate
// of the image's mean variance per sample with independent samples
// (quasi-random samples converge faster where the integrand is smooth;
// the pilot does not model that). A fixed grid of pixels would not be:
// where its lines fall decides which of a few thin features (a light's
// edge in view, a shadow's) it meets, and no seed averages that out. It also
// takes the mean squared albedo of the diffuse surfaces the pixels' centres
// see (the channels' mean): the light's contribution to a pixel is the
// surface's albedo times a white surface's, which `auto` takes on average.
//
// The emitters the camera sees. Where a pixel straddles the edge of an
// emitter (or of the background) in view, the radiance the camera ray meets
// first jumps, and with two samples that pixel's sample variance is either
// 0 or large: a few such pixels made the pilot's V swing by 6-20x between
// seeds (the Cornell boxes' ceiling lights). So a sample X is split into E,
// the radiance the camera ray meets first (emission, or background), and
// R = X - E, what the surface there reflects: V is the mean of s2(R) (the
// two samples') over the pilot's blocks plus the mean of s2_K(E), the
// sample variance of E over K more camera rays (hit tests only) uniform in
// the pixel. The pixels on an emitter's edge are few (a line of them) and
// carry most of the image's variance where the camera sees a light (with
// a fixed grid of every stride-th pixel, V differed 1000-fold between the
// 400- and the 1024-pixel pilots of the Cornell box with the seed's
// light), so s2_K(E) is measured on blocks of half the side (rounded up),
// four times as many pixels, with the same number of rays in all (K
// pixels / pixels_E per pixel, at least 2). Both terms are unbiased and
// never negative; their sum falls short of the variance of X by the mean
// of 2 cov(E, R) over a pixel, small where E and R do not vary together (a
// light's edge: where a ray meets the emitter it reflects nothing). The
// unbiased s2(X) - s2(E) + s2_K(E) of each pixel keeps that cross term,
// which at an edge pixel with two samples is +-|E1 - E2| |R1 - R2|, the
// light's radiance times the reflected one, offset only by the same
// pixel's s2_K(E): with s2_K(E) measured on other pixels (commit 8c914c8)
// the mean fell below 0 (V = 0 at 2 of 8 pilots of a box with a disk
// light, size_disk_1of4, global).
//
// The diffuse surfaces the pixels' centres see are kept too (in pixel
// order, whichever thread met them), as the receivers at which `auto`
// weighs what its per-point choice gains against what it costs
// (auto_sampler::table_gain).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <span>
#include <thread>
#include <variant>
#include <vector>

#include "mcrt/render/camera.hpp"
#include "mcrt/render/renderer.hpp"
#include "mcrt/sampling/auto_strategy.hpp"
#include "mcrt/samplers/independent.hpp"
#include "mcrt/samplers/samplers.hpp"

namespace mcrt {

struct noise_pilot_settings {
  int pixels = 1024;       // about this many pixels of the image (all, for smaller images)
  int spp = 2;             // samples per pixel (>= 2: a sample variance needs two)
  int emission_rays = 8;   // K: camera rays per measured pixel, spread over the finer blocks, for the
                           // variance of what they meet first (header; < 2: none)
};

// The pilot `mcrt render` runs for an image of width x height at spp: 1024
// pixels, or fewer where that would exceed 1 % of the image's samples (at
// least 64), with 2 samples each and 8 emission rays (hit tests) per
// measured pixel, cast on the finer blocks.
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

// A pixel of the finer blocks whose K emission rays did not all meet the
// same radiance (an emitter's edge, most likely), with its block's weight.
struct edge_pixel {
  int x, y;
  double weight;
};

struct noise_pilot_result {
  double image_variance = 0.0;  // mean variance of one pixel sample, radiance^2
  double edge_variance = 0.0;   // of which the mean of s2_K(E): what the camera rays meet first (header)
  double mean_albedo2 = 1.0;    // mean squared albedo (of the channels' mean) the camera sees on diffuse surfaces
  double seconds = 0.0;         // wall-clock time of the pilot
  int pixels = 0;               // pixels measured
  int stride = 1;
  std::vector<auto_receiver> receivers;  // the diffuse surfaces the measured pixels' centres see
  std::vector<edge_pixel> edge_pixels;   // the finer blocks' pixels with s2_K(E) > 0, in row order
};

// The side of the pilot's blocks (one pixel measured in each), stride =
// floor(sqrt(W H / pixels)) (at least 1).
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
  const int k = out.stride;
  const int nx = (rs.width + k - 1) / k, ny = (rs.height + k - 1) / k;
  // The finer blocks of the emission term (header) and its rays per pixel.
  const int k_rays = ps.emission_rays >= 2 ? ps.emission_rays : 0;
  const int ke = (k + 1) / 2;
  const int nxe = k_rays ? (rs.width + ke - 1) / ke : 0, nye = k_rays ? (rs.height + ke - 1) / ke : 0;
  const int ke_rays =
      k_rays ? std::max(2, static_cast<int>(std::lround(double(k_rays) * nx * ny / (double(nxe) * nye)))) : 0;
  // Their own seeds: the pilot's samples are not the image's, nor are its
  // emission rays its paths', nor its choices of pixels.
  const independent_sampler sampler(rs.seed ^ 0x70696c6f74ull, m);       // "pilot"
  const independent_sampler edge_sampler(rs.seed ^ 0x6564676573ull, 1);  // "edges"
  const independent_sampler pixel_chooser(rs.seed ^ 0x7069636bull, 1);   // "pick"
  // The pixel drawn in block (i, j) of side b (nb blocks a row; `salt`
  // tells the two sets of blocks apart), and the block's area over b^2.
  struct block_pixel {
    int x, y;
    double weight;
  };
  auto pick = [&](int i, int j, int b, int nb, int salt) {
    const int bw = std::min(b, rs.width - i * b), bh = std::min(b, rs.height - j * b);
    auto px = pixel_chooser.start_pixel(i, 2 * j + salt, nb);
    px.start_sample(0);
    const vec2 u = px.stream().uniform2();
    return block_pixel{i * b + std::min(static_cast<int>(u.x * float(bw)), bw - 1),
                       j * b + std::min(static_cast<int>(u.y * float(bh)), bh - 1), double(bw) * bh / (double(b) * b)};
  };
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  const path_settings set = rs.path();

  unsigned n = rs.threads ? rs.threads : std::max(1u, std::thread::hardware_concurrency());
  // A thread per 512 measured pixels at most: starting a thread (~0.1 ms
  // here) costs more than it saves on a pilot of a few hundred pixels (a
  // 100 x 100 image at 8 spp: 400 pixels, 0.23 ms on one thread, 0.35 ms
  // on two).
  const unsigned measured = static_cast<unsigned>(nx) * static_cast<unsigned>(ny);
  n = std::max(1u, std::min({n, static_cast<unsigned>(ny), measured / 512u}));
  // Per row (the pilot's rows, then the finer grid's), summed in row order
  // afterwards: the result does not depend on which thread took which row
  // (the choices of `auto` depend on it).
  const int rows = ny + nye;
  std::atomic<int> next_row{0};
  std::vector<double> row_sums(static_cast<std::size_t>(rows), 0.0), row_weights(static_cast<std::size_t>(rows), 0.0),
      row_albedo2(static_cast<std::size_t>(ny), 0.0);
  std::vector<int> row_counts(static_cast<std::size_t>(ny), 0), row_diffuse(static_cast<std::size_t>(ny), 0);
  std::vector<std::vector<auto_receiver>> row_receivers(static_cast<std::size_t>(ny));
  std::vector<std::vector<edge_pixel>> row_edges(static_cast<std::size_t>(nye));
  auto worker = [&] {
    std::vector<glm::dvec3> c(static_cast<std::size_t>(m)), e(static_cast<std::size_t>(m)),
        ek(static_cast<std::size_t>(std::max(ke_rays, 1)));
    for (int j; (j = next_row.fetch_add(1, std::memory_order_relaxed)) < rows;) {
      double sum = 0.0, weights = 0.0;
      int count = 0;
      if (j >= ny) {
        // A row of the finer blocks: s2_K(E) of each one's pixel.
        for (int i = 0; i < nxe; ++i) {
          const block_pixel b = pick(i, j - ny, ke, nxe, 1);
          auto px = edge_sampler.start_pixel(b.x, b.y, rs.width);
          px.start_sample(0);
          for (int r = 0; r < ke_rays; ++r)
            ek[static_cast<std::size_t>(r)] =
                glm::dvec3(radiance_met_first(sc, pixel_ray(cam, b.x, b.y, px.stream().uniform2(), inv_w, inv_h)));
          const double s2 = sample_variance(ek.data(), ke_rays);
          if (s2 > 0.0) row_edges[static_cast<std::size_t>(j - ny)].push_back({b.x, b.y, b.weight});
          sum += b.weight * s2;
          weights += b.weight;
        }
        row_sums[static_cast<std::size_t>(j)] = sum;
        row_weights[static_cast<std::size_t>(j)] = weights;
        continue;
      }
      double albedo2 = 0.0;
      int diffuse = 0;
      for (int i = 0; i < nx; ++i) {
        const block_pixel b = pick(i, j, k, nx, 0);
        const int x = b.x, y = b.y;
        // The surface at the pixel's centre: its albedo, if diffuse.
        hit_record rec;
        if (sc.hit(pixel_ray(cam, x, y, vec2(0.5f), inv_w, inv_h), sc.ray_epsilon, infinity, rec))
          if (const auto* l = std::get_if<lambertian>(&sc.materials[rec.material])) {
            const double a = (double(l->albedo.r) + l->albedo.g + l->albedo.b) / 3.0;
            albedo2 += a * a;
            ++diffuse;
            row_receivers[static_cast<std::size_t>(j)].push_back({rec.p, rec.facing_normal()});
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
        // What the camera rays meet first taken out of each sample (its
        // variance comes from the finer blocks: header).
        if (k_rays)
          for (int i = 0; i < finite; ++i) c[static_cast<std::size_t>(i)] -= e[static_cast<std::size_t>(i)];
        sum += b.weight * sample_variance(c.data(), finite);
        weights += b.weight;
        ++count;
      }
      row_sums[static_cast<std::size_t>(j)] = sum;
      row_weights[static_cast<std::size_t>(j)] = weights;
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
  double sum = 0.0, weights = 0.0, albedo2 = 0.0, edge_sum = 0.0, edge_weights = 0.0;
  int diffuse = 0;
  for (std::size_t j = 0; j < static_cast<std::size_t>(ny); ++j) {
    sum += row_sums[j], weights += row_weights[j], out.pixels += row_counts[j];
    albedo2 += row_albedo2[j], diffuse += row_diffuse[j];
    out.receivers.insert(out.receivers.end(), row_receivers[j].begin(), row_receivers[j].end());
  }
  for (std::size_t j = static_cast<std::size_t>(ny); j < static_cast<std::size_t>(rows); ++j) {
    edge_sum += row_sums[j], edge_weights += row_weights[j];
    const auto& edges = row_edges[j - static_cast<std::size_t>(ny)];
    out.edge_pixels.insert(out.edge_pixels.end(), edges.begin(), edges.end());
  }
  out.edge_variance = edge_weights > 0.0 ? edge_sum / edge_weights : 0.0;
  if (weights > 0.0) out.image_variance = sum / weights + out.edge_variance;
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

// The pilot's result with its emission term as the image's samples leave
// it (kappa_E from edge_noise_factor below): V and its emission term.
inline void scale_emission_term(noise_pilot_result& r, double kappa_e) {
  r.image_variance -= (1.0 - kappa_e) * r.edge_variance;
  r.edge_variance *= kappa_e;
}

// What the image's sample generator leaves of the emission term: kappa_E
// = sum_x w_x N Var_m(mean of E over N camera rays) / sum_x w_x Var(E of
// one ray), over the pilot's edge pixels x (at most `pixels` of them,
// evenly spaced in its list), each with M independent scramblings of the
// image's own samples at its spp (the pixel dimensions, samplers/
// layout.hpp), Var(E of one ray) the sample variance of all M N rays.
// An edge crossing a pixel is a discontinuity in the pixel's two
// dimensions, which stratified and Sobol points resolve better than
// independent ones: with N of them the variance of a pixel's mean falls
// about as N^-1.5, not N^-1 (Owen 1997; Pharr et al. 2019, "Efficient
// generation of points that satisfy two-dimensional elementary
// intervals", for the pixel's edges); the pilot's s2_K(E) (independent
// rays) times kappa_E is the emission term's share of the image's noise
// with the image's samples. A ratio at the pixels where E varied, applied
// to s2_K(E), which stays unbiased over all pixels (a pixel whose K rays
// all met the same radiance adds nothing to either). Hit tests only.
// 1 for independent samples, and where no edge pixel was found.
template <class Sampler, class Scene>
double edge_noise_factor_with(const Scene& sc, const camera& cam, const render_settings& rs,
                              std::span<const edge_pixel> edges, int scramblings = 2, int pixels = 512) {
  const int m = std::max(scramblings, 2), n = std::max(rs.spp, 1);
  const std::size_t count = std::min(edges.size(), static_cast<std::size_t>(std::max(pixels, 1)));
  std::vector<Sampler> samplers;
  // Their own seeds ("edgeq" and j): not the image's scramblings.
  for (int j = 0; j < m; ++j) samplers.emplace_back(mix64(rs.seed ^ 0x6564676571ull) + std::uint64_t(j), n);
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  double between = 0.0, within = 0.0;
  std::vector<glm::dvec3> means(static_cast<std::size_t>(m)), rays(static_cast<std::size_t>(m) * n);
  for (std::size_t i = 0; i < count; ++i) {
    const edge_pixel& e = edges[i * edges.size() / count];
    for (int j = 0; j < m; ++j) {
      auto px = samplers[static_cast<std::size_t>(j)].start_pixel(e.x, e.y, rs.width);
      glm::dvec3 s(0.0);
      for (int k = 0; k < n; ++k) {
        px.start_sample(k);
        const glm::dvec3 v(radiance_met_first(sc, camera_ray(cam, px, e.x, e.y, inv_w, inv_h)));
        rays[static_cast<std::size_t>(j) * n + k] = v;
        s += v;
      }
      means[static_cast<std::size_t>(j)] = s / double(n);
    }
    between += e.weight * double(n) * sample_variance(means.data(), m);
    within += e.weight * sample_variance(rays.data(), m * n);
  }
  return within > 0.0 ? between / within : 1.0;
}

// With the image's sample generator (rs.sampler); 1 for independent samples.
template <class Scene>
double edge_noise_factor(const Scene& sc, const camera& cam, const render_settings& rs,
                         std::span<const edge_pixel> edges, int scramblings = 2, int pixels = 512) {
  if (rs.sampler == sampler_kind::independent) return 1.0;
  return with_sampler(rs.sampler, [&]<class S>() {
    return edge_noise_factor_with<S>(sc, cam, rs, edges, scramblings, pixels);
  });
}

}  // namespace mcrt
