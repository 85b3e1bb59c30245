#pragma once
// Renders a scene through a camera with one integrator and one sample
// generator: 16x16 tiles handed to all threads from an atomic counter; every
// pixel's numbers depend only on (seed, pixel, sample index, dimension), so
// an image is bit-identical whatever the thread count. Each camera sample
// is a ray through the point of the pixel the sampler gives (dimensions 0
// and 1), drawn from the pixel filter (filter importance sampling, as
// pbrt-v4: render/pixel_filter.hpp), and the pixel's value is the mean of
// its samples, each of weight 1. The default filter, the box of radius 0.5,
// is a point uniform in the pixel.
//
// render_with<Integrator, Sampler> is the statically dispatched core; render()
// picks the pair named in render_settings at run time, so a program pays only
// for one branch per image.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "mcrt/render/camera.hpp"
#include "mcrt/render/image.hpp"
#include "mcrt/render/path_tracer.hpp"
#include "mcrt/render/pixel_filter.hpp"
#include "mcrt/samplers/samplers.hpp"

namespace mcrt {

struct render_settings {
  int width = 600, height = 600;
  int spp = 100;
  int max_depth = 50;
  int rr_depth = 1;  // see path_settings
  std::uint64_t seed = 0;
  unsigned threads = 0;  // 0: all hardware threads
  integrator_kind integrator = integrator_kind::mis;  // as pbrt-v4's and Mitsuba 3's path tracers
  sampler_kind sampler = sampler_kind::sobol;  // the most efficient in the study (docs/results.md)
  light_choice choose = light_choice::power;       // nee, mis (path_settings)
  mis_heuristic heuristic = mis_heuristic::power;  // mis (path_settings)
  pixel_filter filter;  // the box of radius 0.5: each pixel's samples uniform in it

  path_settings path() const { return {max_depth, rr_depth, choose, heuristic}; }
};

struct render_result {
  image img;
  double seconds = 0.0;                 // wall-clock time of the rendering alone
  std::uint64_t nonfinite_samples = 0;  // radiance samples dropped as NaN/Inf
  unsigned threads = 1;
};

// progress(fraction_done, elapsed_seconds) is called from the calling thread
// about every `progress_interval`, and once at the end.
using progress_callback = std::function<void(double, double)>;

// The camera ray through the point j in [0, 1)^2 of pixel (x, y).
inline ray pixel_ray(const camera& cam, int x, int y, vec2 j, float inv_w, float inv_h) {
  return cam.generate((static_cast<float>(x) + j.x) * inv_w, (static_cast<float>(y) + j.y) * inv_h);
}

// The camera ray of one sample of pixel (x, y): through the point the
// filter draws with the sampler's numbers (dimensions 0 and 1); with the
// default box of radius 0.5, the point of the pixel they give. A camera
// with a thin lens also draws its lens point (dimensions layout::lens and
// layout::lens + 1).
template <class PixelSampler>
ray camera_ray(const camera& cam, PixelSampler& ps, int x, int y, float inv_w, float inv_h,
               const pixel_filter& filter = {}) {
  const vec2 p = filter.film_point(x, y, ps.pixel());
  if (cam.has_lens()) return cam.generate(p.x * inv_w, p.y * inv_h, ps.get2d(layout::lens));
  return cam.generate(p.x * inv_w, p.y * inv_h);
}

// One camera sample of pixel (x, y): its camera ray and the radiance along it.
template <class Integrator, class Scene, class PixelSampler>
color camera_sample(const Scene& sc, const camera& cam, PixelSampler& ps, int x, int y, float inv_w, float inv_h,
                    const path_settings& set, const pixel_filter& filter = {}) {
  return Integrator::li(sc, camera_ray(cam, ps, x, y, inv_w, inv_h, filter), ps, set);
}

template <class Integrator, class Scene, class Sampler>
color render_pixel(const Scene& sc, const camera& cam, const render_settings& rs, const Sampler& sampler, int x, int y,
                   std::uint64_t& nonfinite) {
  auto ps = sampler.start_pixel(x, y, rs.width);
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  const path_settings set = rs.path();
  glm::dvec3 sum(0.0);
  for (int s = 0; s < rs.spp; ++s) {
    ps.start_sample(s);
    const color c = camera_sample<Integrator>(sc, cam, ps, x, y, inv_w, inv_h, set, rs.filter);
    if (all_finite(c))
      sum += glm::dvec3(c);
    else
      ++nonfinite;
  }
  return color(sum / static_cast<double>(rs.spp));
}

template <class Integrator, class Sampler, class Scene>
render_result render_with(const Scene& sc, const camera& cam, const render_settings& rs,
                          const progress_callback& progress = {},
                          std::chrono::milliseconds progress_interval = std::chrono::milliseconds(250)) {
  const Sampler sampler(rs.seed, rs.spp);
  constexpr int tile = 16;
  render_result out;
  out.img = image(rs.width, rs.height);
  const int tiles_x = (rs.width + tile - 1) / tile, tiles_y = (rs.height + tile - 1) / tile;
  const int tile_count = tiles_x * tiles_y;
  unsigned n = rs.threads ? rs.threads : std::max(1u, std::thread::hardware_concurrency());
  n = std::min<unsigned>(n, static_cast<unsigned>(tile_count));
  out.threads = n;

  std::atomic<int> next{0}, done{0};
  // The progress reporter waits on this between reports, and the tile that
  // completes the image wakes it: the image's time is not rounded up to
  // the progress interval.
  std::mutex finished_mutex;
  std::condition_variable finished;
  std::atomic<std::uint64_t> nonfinite{0};
  auto worker = [&] {
    std::uint64_t bad = 0;
    for (int t; (t = next.fetch_add(1, std::memory_order_relaxed)) < tile_count;) {
      const int x0 = (t % tiles_x) * tile, y0 = (t / tiles_x) * tile;
      const int x1 = std::min(x0 + tile, rs.width), y1 = std::min(y0 + tile, rs.height);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) out.img.at(x, y) = render_pixel<Integrator>(sc, cam, rs, sampler, x, y, bad);
      if (done.fetch_add(1, std::memory_order_release) + 1 == tile_count) {
        const std::lock_guard<std::mutex> lock(finished_mutex);
        finished.notify_all();
      }
    }
    nonfinite.fetch_add(bad, std::memory_order_relaxed);
  };

  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  std::vector<std::jthread> pool;
  pool.reserve(n);
  for (unsigned i = 0; i + 1 < n; ++i) pool.emplace_back(worker);
  if (progress) {
    // The calling thread reports progress while the pool works.
    pool.emplace_back(worker);
    for (int d; (d = done.load(std::memory_order_acquire)) < tile_count;) {
      progress(static_cast<double>(d) / tile_count, elapsed());
      std::unique_lock<std::mutex> lock(finished_mutex);
      finished.wait_for(lock, progress_interval,
                        [&] { return done.load(std::memory_order_acquire) == tile_count; });
    }
  } else {
    worker();
  }
  pool.clear();  // join
  out.seconds = elapsed();
  out.nonfinite_samples = nonfinite.load();
  if (progress) progress(1.0, out.seconds);
  return out;
}

// The integrator and sampler named in rs, dispatched once per image.
template <class Scene>
render_result render(const Scene& sc, const camera& cam, const render_settings& rs,
                     const progress_callback& progress = {},
                     std::chrono::milliseconds progress_interval = std::chrono::milliseconds(250)) {
  return with_integrator(rs.integrator, [&]<class I>() {
    return with_sampler(rs.sampler, [&]<class S>() { return render_with<I, S>(sc, cam, rs, progress, progress_interval); });
  });
}

}  // namespace mcrt
