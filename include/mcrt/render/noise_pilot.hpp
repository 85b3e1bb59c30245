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
// The emitters the camera sees. Where a pixel straddles the edge of an emitter
// (or of the background) in view, the radiance the camera ray meets first
// jumps, and with two samples that pixel's sample variance is either 0 or
// large: from two samples alone a few such pixels make the pilot's V swing by
// 6-25x between seeds (the Cornell boxes' ceiling lights: size_rect_x4 and
// size_disk_x4, direct light). So a sample X is split into E, the radiance the
// camera ray meets first (emission, or background), and R = X - E, what the
// surface there reflects: V is the mean of s2(R) (the two samples') over the
// pilot's blocks plus the mean of s2_K(E), the sample variance of E over K more
// camera rays (hit tests only) uniform in the pixel. The pixels on an emitter's
// edge are few (a line of them) and carry most of the image's variance where
// the camera sees a light (a fixed grid of every stride-th pixel meets them or
// misses them by where its lines fall: its V is 1000-fold apart between the
// 400- and the 1024-pixel pilots of the Cornell box with the thesis's light). So
// the mean of s2_K(E) is taken over two strata: the emitters' footprint in the
// image (emitter_footprint: where a camera ray may meet a listed light), every
// pixel of it measured with 2 to K rays (a systematic sample of it where it is
// large), and the rest of the image on blocks of half the side (rounded up),
// one random pixel each, where only an emitting background or an emitter the
// lights do not list can add anything (else it is not measured). From random
// pixels of the finer blocks alone the pilot would meet 0 to 5 edge pixels of a
// small ceiling light in view, and V would vary 6000-fold between seeds
// (size_rect_1of4, direct, 100 x 100, 8 and 32 spp: 0.00016 to 1.08); with the
// footprint it meets 8 to 11 of them, and V is 0.48 to 0.80. Both terms are
// unbiased and never negative; their sum falls short of the variance of X by
// the mean of 2 cov(E, R) over a pixel, small where E and R do not vary
// together (a light's edge: where a ray meets the emitter it reflects nothing).
// The unbiased s2(X) - s2(E) + s2_K(E) of each pixel would keep that cross
// term, but at an edge pixel with two samples it is +-|E1 - E2| |R1 - R2|, the
// light's radiance times the reflected one, offset only by the same pixel's
// s2_K(E): with s2_K(E) measured on other pixels its mean falls below 0 (V = 0
// at 2 of 8 pilots of a box with a disk light, size_disk_1of4, global), so it
// is not used.
//
// The diffuse surfaces the pixels' centres see are kept too (in pixel
// order, whichever thread met them), as the receivers at which `auto`
// weighs what its per-point choice gains against what it costs
// (auto_sampler::table_gain), with their pixels (for
// render/choice_gain_pilot.hpp).
//
// Each light's own noise: at the point the first of a pixel's samples
// meets, if diffuse, two more independent samples of each light give
// (f1 - f2)^2 / 2 (with albedo / pi, over the light's choice probability),
// an unbiased estimate of the variance one light sample adds there; its
// mean over the blocks, as V's, is light_variance, the light's part of V
// with its sampler (render/choice_gain_pilot.hpp). And the paths' work:
// their light samples counted (counting_pixel_sampler), and their rays
// (ray_counting_scene), per light sample, give `auto` its c_rest
// (render/rest_cost.hpp); each row's paths are also timed apart from the
// rest of the pilot (seconds_per_light_sample: reported, not used, as a
// check of that model on the machine at hand).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <span>
#include <thread>
#include <variant>
#include <vector>

#include "mcrt/core/worker_errors.hpp"
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
  // Each light's own noise is measured where the scene has at most this
  // many lights (its cost grows with their number: two samples of every
  // light at each pixel); beyond, light_variance is 0 and `auto`'s rule
  // takes the light's share of the noise from its model alone
  // (render/choice_gain_pilot.hpp). With 145 lights (many_lights_n100,
  // 160 x 120, 32 spp) the measurement took 0.053 s of the pilot's 0.057,
  // 12 % of the image's time, and changed no choice.
  std::size_t light_noise_limit = 16;
  // V's reflected part alone: what the camera rays meet first taken out of
  // each sample, and no emission term (no emission rays; edge_variance 0).
  bool reflected_only = false;
};

// A scene that counts the rays traced in it (its hit tests) and otherwise is
// the scene it wraps: what an integrator reads of a scene, by reference.
template <class Scene>
struct ray_counting_scene {
  const Scene& inner;
  std::uint64_t& rays;
  const decltype(Scene::lights)& lights = inner.lights;
  const decltype(Scene::emitters)& emitters = inner.emitters;
  const light_bvh& light_tree = inner.light_tree;
  const decltype(Scene::materials)& materials = inner.materials;
  const color& background = inner.background;
  const std::size_t& unsampled_emitters = inner.unsampled_emitters;

  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    ++rays;
    return inner.hit(r, tmin, tmax, rec);
  }
  bool hit_side(const ray& r, float tmin, float tmax, hit_record& rec) const {
    ++rays;
    return inner.hit_side(r, tmin, tmax, rec);
  }
};

// The pilot `mcrt render` runs for an image of width x height at spp: 1024
// pixels, or fewer where their samples would exceed 0.25 % of the image's
// (at least 64), with 2 samples each and 8 emission rays (hit tests) per
// measured pixel, cast on the finer blocks. A pilot pixel costs about 6-7
// of the image's samples (its two paths, two samples of each light at its
// first point, its centre's ray and its emission rays: 0.73 us of one
// thread against 0.11 us per image sample, size_rect_x4, direct light), so
// that the pilot takes 1-2 % of the image's time on one thread. The budget
// is small because where one fixed strategy is best everywhere `auto` can
// at most match it and still pays its pilot: 1 % of the samples would take
// 6 % of a 100 x 100 render's time at 8 spp, and there `auto` reaches 0.94x
// the best fixed strategy (area sampling everywhere) with 1 % against
// 0.98x with 0.25 % (A/B, direct light, 8 and 32 spp x 4 seeds).
inline noise_pilot_settings noise_pilot_for(int width, int height, int spp) {
  const double budget = 0.0025 * static_cast<double>(width) * height * spp / 2.0;  // pixels at 2 samples
  return {static_cast<int>(std::clamp(budget, 64.0, 1024.0)), 2, 8};
}

// A pixel sampler that counts the light samples a path draws (its 2-D draws
// at a bounce's light dimensions, samplers/layout.hpp; apart, those of the
// first bounce) and otherwise is the sampler it wraps.
template <class P>
struct counting_pixel_sampler {
  static constexpr bool sequential = P::sequential;
  P& inner;
  std::uint64_t& light_samples;
  std::uint64_t& first_bounce_light_samples;

  vec2 pixel() { return inner.pixel(); }
  float get1d(int dim) { return inner.get1d(dim); }
  vec2 get2d(int dim) {
    const int d = dim - layout::bounce(0);
    if (d >= 0 && d % layout::dims_per_bounce == layout::light) {
      ++light_samples;
      if (d == layout::light) ++first_bounce_light_samples;
    }
    return inner.get2d(dim);
  }
  auto& stream() { return inner.stream(); }
};

// The radiance a camera ray meets first: the emission of the surface it
// hits (front side; 0 for a surface that does not emit), or the background.
template <class Scene>
color radiance_met_first(const Scene& sc, const ray& r) {
  hit_record rec;
  if (!sc.hit(r, 0.0f, infinity, rec)) return sc.background;
  return emitted(sc.materials[rec.material], rec);
}

// A light sample's estimate of the direct light at p (facing normal nf) over
// the surface's albedo / pi: the radiance of the emitter's front side the
// shadow ray meets first (the channels' mean), times cos(theta) / pdf; 0
// where the light offered no sample (ok false, pdf 0), below the surface, or
// where the shadow ray meets no emitter's front side. As the integrators'
// sample_direct_light (render/nee_integrator.hpp) with one light, always
// chosen.
template <class Scene>
double light_estimate(const Scene& sc, bool ok, const light_sample& ls, const vec3& p, const vec3& nf) {
  if (!ok || !(ls.pdf > 0.0f) || !std::isfinite(ls.pdf)) return 0.0;
  const float c = glm::dot(ls.dir, nf);
  if (!(c > 0.0f)) return 0.0;
  const color le = shadow_ray_radiance(sc, p, ls.dir);
  return (double(le.r) + le.g + le.b) / 3.0 * c / double(ls.pdf);
}

// The unbiased sample variance of n >= 2 values, averaged over the channels.
inline double sample_variance(const glm::dvec3* v, int n) {
  glm::dvec3 mean(0.0), ss(0.0);
  for (int i = 0; i < n; ++i) mean += v[i];
  mean /= static_cast<double>(n);
  for (int i = 0; i < n; ++i) ss += (v[i] - mean) * (v[i] - mean);
  return (ss.x + ss.y + ss.z) / (3.0 * (n - 1));
}

// Points whose convex hull holds the shape (for its footprint in the image).
inline std::vector<vec3> hull_points(const rect& r) {
  return {r.corner, r.corner + r.e1, r.corner + r.e2, r.corner + r.e1 + r.e2};
}
inline std::vector<vec3> hull_points(const ellipse& e) {
  return {e.center + e.a1 + e.a2, e.center + e.a1 - e.a2, e.center - e.a1 + e.a2, e.center - e.a1 - e.a2};
}
inline std::vector<vec3> hull_points(const triangle& t) { return {t.vertex(0), t.vertex(1), t.vertex(2)}; }
inline std::vector<vec3> hull_points(const sphere& s) {
  std::vector<vec3> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(s.center + s.radius * vec3(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f));
  return v;
}

// The pixels where the camera may see an emitter of the scene's lights: per
// emitter the bounding rectangle of its hull's projection, one pixel wider
// on every side; the whole image for an emitter not wholly in front of the
// camera. A mask of width x height, row order.
template <class Scene>
std::vector<std::uint8_t> emitter_footprint(const Scene& sc, const camera& cam, int width, int height) {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * height, 0);
  for (const emitter& em : sc.emitters) {
    const std::vector<vec3> pts =
        dispatch(sc.lights[em.light], [](const auto& l) { return hull_points(l.shape); });
    float s0 = infinity, s1 = -infinity, t0 = infinity, t1 = -infinity;
    bool front = true;
    for (const vec3& p : pts) {
      float s = 0.0f, t = 0.0f;
      if (!cam.project(p, s, t)) {
        front = false;
        break;
      }
      s0 = std::min(s0, s), s1 = std::max(s1, s), t0 = std::min(t0, t), t1 = std::max(t1, t);
    }
    int x0 = 0, x1 = width - 1, y0 = 0, y1 = height - 1;
    if (front) {
      // Clamped in float first: a point near the eye's plane projects far out.
      auto to_pixel = [](float v, int n) { return static_cast<int>(std::floor(std::clamp(v * n, -2.0f, n + 2.0f))); };
      x0 = std::max(0, to_pixel(s0, width) - 1), x1 = std::min(width - 1, to_pixel(s1, width) + 1);
      y0 = std::max(0, to_pixel(t0, height) - 1), y1 = std::min(height - 1, to_pixel(t1, height) + 1);
    }
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) mask[static_cast<std::size_t>(y) * width + x] = 1;
  }
  return mask;
}

// A pixel the pilot measured, with its block's weight: of the finer blocks
// where its K emission rays did not all meet the same radiance (an
// emitter's edge, most likely), or where its centre sees a receiver.
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
  std::vector<edge_pixel> receiver_pixels;  // their pixels, with their blocks' weights (receivers' order)
  // Per light of the scene: the variance of its own first-bounce estimate
  // (its sampler's noise alone, with independent samples), mean over the
  // pixels as V is: radiance^2 per pixel sample (header).
  std::vector<double> light_variance;
  // The pilot's paths' time (one thread's) per light sample they took: a
  // light sample's share of a path's time with the cheapest strategies and
  // independent samples (0 where they took none). Measured, so it varies
  // from run to run: reported only (render/rest_cost.hpp models it).
  double seconds_per_light_sample = 0.0;
  // The share of those light samples taken at the paths' first bounce (1
  // with direct light alone).
  double first_bounce_share = 1.0;
  // The rays those paths traced (hit tests: camera, continuation and
  // shadow rays) and the paths themselves, per light sample (counted).
  double rays_per_light_sample = 0.0, paths_per_light_sample = 0.0;
  std::vector<edge_pixel> edge_pixels;   // the pixels with s2_K(E) > 0 (footprint, finer blocks), weights in pixels
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
  const int k_rays = ps.emission_rays >= 2 && !ps.reflected_only ? ps.emission_rays : 0;
  const bool split = k_rays > 0 || ps.reflected_only;  // E taken out of each sample
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
  // The emission term's first stratum (header): the pixels where the camera
  // may see an emitter (emitter_footprint), every one of them measured with
  // as many rays as the finer blocks take in all (2 to K each), or, where
  // they are more than half that many rays, a systematic sample of them
  // with 2 rays each (a random start: each pixel's inclusion probability is
  // the same, count / size, and its term is weighted by the inverse). The
  // finer blocks then measure only the pixels outside it.
  std::vector<std::uint8_t> in_footprint;
  std::vector<int> footprint;  // y * width + x
  if (k_rays) {
    in_footprint = emitter_footprint(sc, cam, rs.width, rs.height);
    for (std::size_t i = 0; i < in_footprint.size(); ++i)
      if (in_footprint[i]) footprint.push_back(static_cast<int>(i));
  }
  const double rays_f = double(ke_rays) * nxe * nye;
  std::size_t nf = footprint.size();
  int kf_rays = 2;
  double f_weight = 1.0;  // pixels each measured footprint pixel stands for
  if (nf > 0) {
    if (2.0 * double(nf) <= rays_f) {
      kf_rays = std::clamp(static_cast<int>(rays_f / double(nf)), 2, std::max(k_rays, 2));
    } else {
      nf = static_cast<std::size_t>(rays_f / 2.0);
      f_weight = double(footprint.size()) / double(nf);
    }
  }
  auto footprint_pixel = [&](std::size_t i) {
    auto px = pixel_chooser.start_pixel(0, 0, 1);
    px.start_sample(1);
    const double start = double(px.stream().uniform2().x);
    const auto k = static_cast<std::size_t>((double(i) + start) * f_weight);
    return footprint[std::min(k, footprint.size() - 1)];
  };
  // Outside the footprint a camera ray meets emission only where the
  // background or an emitter the lights do not list emits; elsewhere the
  // finer blocks have nothing to measure (every s2_K(E) there is 0).
  const bool outside = sc.background != color(0.0f) || sc.unsampled_emitters > 0;
  constexpr std::size_t footprint_chunk = 64;
  const int nfe = static_cast<int>((nf + footprint_chunk - 1) / footprint_chunk);
  const int rows = ny + nye + nfe;
  std::atomic<int> next_row{0};
  std::vector<double> row_sums(static_cast<std::size_t>(rows), 0.0), row_weights(static_cast<std::size_t>(rows), 0.0),
      row_albedo2(static_cast<std::size_t>(ny), 0.0);
  std::vector<int> row_counts(static_cast<std::size_t>(ny), 0), row_diffuse(static_cast<std::size_t>(ny), 0);
  std::vector<std::vector<auto_receiver>> row_receivers(static_cast<std::size_t>(ny));
  std::vector<std::vector<edge_pixel>> row_receiver_pixels(static_cast<std::size_t>(ny));
  const std::size_t nl = sc.lights.size() <= ps.light_noise_limit ? sc.lights.size() : 0;
  std::vector<std::vector<double>> row_lights(static_cast<std::size_t>(ny), std::vector<double>(nl, 0.0));
  std::vector<std::vector<edge_pixel>> row_edges(static_cast<std::size_t>(nye + nfe));
  const double block_pixels = double(ke) * ke;  // the pixels a finer block's full weight stands for
  using pilot_pixel_sampler = decltype(sampler.start_pixel(0, 0, 1));
  std::vector<double> row_path_seconds(static_cast<std::size_t>(ny), 0.0);
  std::vector<std::uint64_t> row_light_samples(static_cast<std::size_t>(ny), 0),
      row_first_light_samples(static_cast<std::size_t>(ny), 0), row_rays(static_cast<std::size_t>(ny), 0);
  auto worker = [&] {
    std::vector<block_pixel> blocks;
    std::vector<pilot_pixel_sampler> pixel_samplers;
    blocks.reserve(static_cast<std::size_t>(nx)), pixel_samplers.reserve(static_cast<std::size_t>(nx));
    std::vector<ray> path_rays(static_cast<std::size_t>(nx) * m);
    std::vector<color> path_values(static_cast<std::size_t>(nx) * m);
    std::vector<glm::dvec3> c(static_cast<std::size_t>(m)), e(static_cast<std::size_t>(m)),
        ek(static_cast<std::size_t>(std::max({ke_rays, kf_rays, 1})));
    // s2_K(E) of pixel (x, y) from n rays.
    auto emission_variance = [&](int x, int y, int n) {
      auto px = edge_sampler.start_pixel(x, y, rs.width);
      px.start_sample(0);
      for (int r = 0; r < n; ++r)
        ek[static_cast<std::size_t>(r)] =
            glm::dvec3(radiance_met_first(sc, pixel_ray(cam, x, y, px.stream().uniform2(), inv_w, inv_h)));
      return sample_variance(ek.data(), n);
    };
    for (int j; (j = next_row.fetch_add(1, std::memory_order_relaxed)) < rows;) {
      double sum = 0.0, weights = 0.0;
      int count = 0;
      if (j >= ny + nye) {
        // A chunk of the footprint's pixels (sums in pixels).
        const std::size_t i0 = static_cast<std::size_t>(j - ny - nye) * footprint_chunk;
        for (std::size_t i = i0; i < std::min(nf, i0 + footprint_chunk); ++i) {
          const int p = footprint_pixel(i), x = p % rs.width, y = p / rs.width;
          const double s2 = emission_variance(x, y, kf_rays);
          if (s2 > 0.0) row_edges[static_cast<std::size_t>(j - ny)].push_back({x, y, f_weight});
          sum += f_weight * s2;
        }
        row_sums[static_cast<std::size_t>(j)] = sum;
        continue;
      }
      if (j >= ny) {
        // A row of the finer blocks: s2_K(E) of each one's pixel, outside
        // the footprint (sums in pixels).
        for (int i = 0; i < nxe && outside; ++i) {
          const block_pixel b = pick(i, j - ny, ke, nxe, 1);
          if (!in_footprint.empty() && in_footprint[static_cast<std::size_t>(b.y) * rs.width + b.x]) continue;
          const double s2 = emission_variance(b.x, b.y, ke_rays);
          if (s2 > 0.0) row_edges[static_cast<std::size_t>(j - ny)].push_back({b.x, b.y, b.weight * block_pixels});
          sum += b.weight * block_pixels * s2;
        }
        row_sums[static_cast<std::size_t>(j)] = sum;
        continue;
      }
      double albedo2 = 0.0;
      int diffuse = 0;
      // The row's paths first, timed apart from the rest of the pilot's
      // work, counting their light samples (the time per light sample).
      blocks.clear(), pixel_samplers.clear();
      for (int i = 0; i < nx; ++i) {
        blocks.push_back(pick(i, j, k, nx, 0));
        pixel_samplers.push_back(sampler.start_pixel(blocks.back().x, blocks.back().y, rs.width));
      }
      std::uint64_t light_samples = 0, first_light_samples = 0, rays = 0;
      const ray_counting_scene<Scene> counting{sc, rays};
      const auto paths_start = std::chrono::steady_clock::now();
      for (int i = 0; i < nx; ++i) {
        auto& px = pixel_samplers[static_cast<std::size_t>(i)];
        counting_pixel_sampler<pilot_pixel_sampler> counted{px, light_samples, first_light_samples};
        for (int s = 0; s < m; ++s) {
          px.start_sample(s);
          const ray r = camera_ray(cam, px, blocks[static_cast<std::size_t>(i)].x, blocks[static_cast<std::size_t>(i)].y,
                                   inv_w, inv_h);
          path_rays[static_cast<std::size_t>(i * m + s)] = r;
          path_values[static_cast<std::size_t>(i * m + s)] = Integrator::li(counting, r, counted, set);
        }
      }
      row_path_seconds[static_cast<std::size_t>(j)] =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - paths_start).count();
      row_light_samples[static_cast<std::size_t>(j)] = light_samples;
      row_first_light_samples[static_cast<std::size_t>(j)] = first_light_samples;
      row_rays[static_cast<std::size_t>(j)] = rays;
      for (int i = 0; i < nx; ++i) {
        const block_pixel b = blocks[static_cast<std::size_t>(i)];
        const int x = b.x, y = b.y;
        // The surface at the pixel's centre: its albedo, if diffuse.
        hit_record rec;
        if (sc.hit(pixel_ray(cam, x, y, vec2(0.5f), inv_w, inv_h), 0.0f, infinity, rec))
          if (const auto* l = std::get_if<lambertian>(&sc.materials[rec.material])) {
            const double a = (double(l->albedo.r) + l->albedo.g + l->albedo.b) / 3.0;
            albedo2 += a * a;
            ++diffuse;
            row_receivers[static_cast<std::size_t>(j)].push_back({rec.p, rec.facing_normal()});
            row_receiver_pixels[static_cast<std::size_t>(j)].push_back({x, y, b.weight});
          }
        auto& px = pixel_samplers[static_cast<std::size_t>(i)];
        int finite = 0;
        for (int s = 0; s < m; ++s) {
          const ray r = path_rays[static_cast<std::size_t>(i * m + s)];
          const color v = path_values[static_cast<std::size_t>(i * m + s)];
          if (!all_finite(v)) continue;
          c[static_cast<std::size_t>(finite)] = glm::dvec3(v);
          if (split) e[static_cast<std::size_t>(finite)] = glm::dvec3(radiance_met_first(sc, r));
          ++finite;
          // Each light's own noise at the surface the camera ray meets:
          // two independent samples of it there, (f1 - f2)^2 / 2 (its
          // variance given the point), over P(light) as the estimator
          // divides by it.
          if (nl == 0 || s > 0) continue;  // at the first sample's point of each pixel
          hit_record rec1;
          if (!sc.hit(r, 0.0f, infinity, rec1)) continue;
          const auto* lam = std::get_if<lambertian>(&sc.materials[rec1.material]);
          if (!lam) continue;
          const vec3 nf = rec1.facing_normal();
          const vec3 p1 = rec1.spawn_origin(nf);
          const light_selection sel(sc, p1, nf, set.choose);
          const double a = (double(lam->albedo.r) + lam->albedo.g + lam->albedo.b) / 3.0 * inv_pi;
          for (std::size_t l = 0; l < nl; ++l) {
            const double prob = sel.probability(l);
            if (!(prob > 0.0)) continue;
            light_sample s1, s2;
            const bool ok1 = sample(sc.lights[l], p1, nf, px.stream().uniform2(), s1);
            const double f1 = light_estimate(sc, ok1, s1, p1, nf);
            const bool ok2 = sample(sc.lights[l], p1, nf, px.stream().uniform2(), s2);
            const double f2 = light_estimate(sc, ok2, s2, p1, nf);
            row_lights[static_cast<std::size_t>(j)][l] += b.weight * a * a * 0.5 * (f1 - f2) * (f1 - f2) / prob;
          }
        }
        if (finite < 2) continue;
        // What the camera rays meet first taken out of each sample (its
        // variance comes from the finer blocks: header).
        if (split)
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
    worker_errors errors;  // an exception of a worker thread reaches the caller
    {
      std::vector<std::jthread> pool;
      for (unsigned t = 1; t < n; ++t) pool.emplace_back([&] { errors.run(worker); });
      errors.run(worker);
    }
    errors.rethrow_if_failed();
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  double sum = 0.0, weights = 0.0, albedo2 = 0.0, edge_sum = 0.0;
  int diffuse = 0;
  for (std::size_t j = 0; j < static_cast<std::size_t>(ny); ++j) {
    sum += row_sums[j], weights += row_weights[j], out.pixels += row_counts[j];
    albedo2 += row_albedo2[j], diffuse += row_diffuse[j];
    out.receivers.insert(out.receivers.end(), row_receivers[j].begin(), row_receivers[j].end());
    out.receiver_pixels.insert(out.receiver_pixels.end(), row_receiver_pixels[j].begin(),
                               row_receiver_pixels[j].end());
    out.light_variance.resize(nl, 0.0);
    for (std::size_t l = 0; l < nl; ++l) out.light_variance[l] += row_lights[j][l];
  }
  for (std::size_t j = static_cast<std::size_t>(ny); j < static_cast<std::size_t>(rows); ++j) {
    edge_sum += row_sums[j];
    const auto& edges = row_edges[j - static_cast<std::size_t>(ny)];
    out.edge_pixels.insert(out.edge_pixels.end(), edges.begin(), edges.end());
  }
  out.edge_variance = edge_sum / (double(rs.width) * rs.height);
  if (weights > 0.0) out.image_variance = sum / weights + out.edge_variance;
  out.light_variance.resize(nl, 0.0);
  for (double& v : out.light_variance) v = weights > 0.0 ? v / weights : 0.0;
  double path_seconds = 0.0;
  std::uint64_t light_samples = 0, first_light_samples = 0, rays = 0;
  for (std::size_t j = 0; j < static_cast<std::size_t>(ny); ++j)
    path_seconds += row_path_seconds[j], light_samples += row_light_samples[j],
        first_light_samples += row_first_light_samples[j], rays += row_rays[j];
  if (light_samples > 0) {
    out.seconds_per_light_sample = path_seconds / double(light_samples);
    out.first_bounce_share = double(first_light_samples) / double(light_samples);
    out.rays_per_light_sample = double(rays) / double(light_samples);
    out.paths_per_light_sample = double(nx) * ny * m / double(light_samples);
  }
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

// What a sample generator leaves of the noise of a per-sample value at the
// given pixels: sum_x w_x N Var_m(mean of the value over N samples) /
// sum_x w_x Var(the value of one sample), with M independent scramblings of
// N = rs.spp samples of type Sampler per pixel (seeded mix64(seed) + j),
// Var(one) the sample variance of all M N values (each point of a scrambled
// sequence is uniform, so it estimates one independent sample's variance;
// the ratio is about 1 for independent samples). value(px, x, y) takes the
// pixel sampler after start_sample and returns the sample's value (its
// channels averaged by sample_variance). Per pixel its terms, summed in
// pixel order afterwards (the result does not depend on the threads), on
// up to two threads where the samples are parallel_from or more: starting
// a thread costs about 0.1 ms here, more than it saves on less than about
// 0.3 ms of work (the choice gain pilot's 528 samples of a 100 x 100 image
// at 8 spp: 0.15 ms on one thread, 0.26 ms on two; its 2112 at 32 spp:
// 0.5-0.7 ms and 0.35 ms). 1 where nothing varies.
template <class Sampler, class Value>
double sequence_noise_factor(const render_settings& rs, std::span<const edge_pixel> pixels, std::uint64_t seed,
                             int scramblings, Value&& value, std::size_t parallel_from) {
  const int m = std::max(scramblings, 2), n = std::max(rs.spp, 1);
  std::vector<Sampler> samplers;
  for (int j = 0; j < m; ++j) samplers.emplace_back(mix64(seed) + std::uint64_t(j), n);
  std::vector<double> between_x(pixels.size(), 0.0), within_x(pixels.size(), 0.0);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    std::vector<glm::dvec3> means(static_cast<std::size_t>(m)), values(static_cast<std::size_t>(m) * n);
    for (std::size_t xi; (xi = next.fetch_add(1, std::memory_order_relaxed)) < pixels.size();) {
      const edge_pixel& x = pixels[xi];
      for (int j = 0; j < m; ++j) {
        auto px = samplers[static_cast<std::size_t>(j)].start_pixel(x.x, x.y, rs.width);
        glm::dvec3 sum(0.0);
        for (int k = 0; k < n; ++k) {
          px.start_sample(k);
          const glm::dvec3 v(value(px, x.x, x.y));
          values[static_cast<std::size_t>(j) * n + k] = v;
          sum += v;
        }
        means[static_cast<std::size_t>(j)] = sum / double(n);
      }
      between_x[xi] = x.weight * double(n) * sample_variance(means.data(), m);
      within_x[xi] = x.weight * sample_variance(values.data(), m * n);
    }
  };
  unsigned threads = rs.threads ? rs.threads : std::max(1u, std::thread::hardware_concurrency());
  if (pixels.size() * std::size_t(m) * std::size_t(n) < parallel_from) threads = 1;
  {
    worker_errors errors;  // an exception of a worker thread reaches the caller
    {
      std::vector<std::jthread> pool;
      for (unsigned t = 1; t < std::min(threads, 2u); ++t) pool.emplace_back([&] { errors.run(worker); });
      errors.run(worker);
    }
    errors.rethrow_if_failed();
  }
  double between = 0.0, within = 0.0;
  for (std::size_t i = 0; i < pixels.size(); ++i) between += between_x[i], within += within_x[i];
  return within > 0.0 ? between / within : 1.0;
}

// At most `count` (>= 1) of the pixels, evenly spaced in their list.
inline std::vector<edge_pixel> evenly_spaced(std::span<const edge_pixel> pixels, int count) {
  const std::size_t n = std::min(pixels.size(), static_cast<std::size_t>(std::max(count, 1)));
  std::vector<edge_pixel> chosen;
  for (std::size_t i = 0; i < n; ++i) chosen.push_back(pixels[i * pixels.size() / n]);
  return chosen;
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
// Here with samples of type Sampler (sequence_noise_factor above): the
// value is E, what the camera ray meets first (hit tests only).
template <class Sampler, class Scene>
double edge_noise_factor_with(const Scene& sc, const camera& cam, const render_settings& rs,
                              std::span<const edge_pixel> edges, int scramblings = 2, int pixels = 512) {
  const std::vector<edge_pixel> chosen = evenly_spaced(edges, pixels);
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  // Their own seeds ("edgeq" and j): not the image's scramblings.
  return sequence_noise_factor<Sampler>(rs, chosen, rs.seed ^ 0x6564676571ull, scramblings,
                                        [&](auto& px, int x, int y) {
                                          return radiance_met_first(sc, camera_ray(cam, px, x, y, inv_w, inv_h));
                                        },
                                        4096);  // a hit test each: about 60 ns
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
