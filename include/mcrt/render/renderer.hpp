#pragma once
// Renders a scene through a camera: 16x16 tiles handed to all threads from
// an atomic counter; every pixel has its own PCG32 stream seeded from (seed,
// pixel index), so an image is bit-identical whatever the thread count.
// Pixel samples are stratified: the first floor(sqrt(spp))^2 samples jitter
// one per cell of a square grid, the rest are uniform in the pixel.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

#include "mcrt/render/camera.hpp"
#include "mcrt/render/image.hpp"
#include "mcrt/render/path_tracer.hpp"

namespace mcrt {

struct render_settings {
  int width = 600, height = 600;
  int spp = 100;
  int max_depth = 50;
  int rr_depth = 1;  // see path_settings
  std::uint64_t seed = 0;
  unsigned threads = 0;  // 0: all hardware threads
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

// The RNG of one pixel: seed and pixel index decorrelated by a 64-bit mix.
inline pcg32 pixel_rng(std::uint64_t seed, std::uint64_t pixel_index) {
  return pcg32(mix64(pixel_index ^ mix64(seed)), mix64(seed + 0x632be59bd9b4e019ULL));
}

template <class Scene>
color render_pixel(const Scene& sc, const camera& cam, const render_settings& rs, int x, int y,
                   std::uint64_t& nonfinite) {
  pcg32 rng = pixel_rng(rs.seed, static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(rs.width) +
                                     static_cast<std::uint64_t>(x));
  const int strata = static_cast<int>(std::sqrt(static_cast<double>(rs.spp)));
  const float inv_strata = 1.0f / static_cast<float>(std::max(strata, 1));
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  const path_settings ps{rs.max_depth, rs.rr_depth};
  glm::dvec3 sum(0.0);
  for (int s = 0; s < rs.spp; ++s) {
    vec2 j = rng.uniform2();
    if (s < strata * strata) j = (vec2(static_cast<float>(s % strata), static_cast<float>(s / strata)) + j) * inv_strata;
    const ray r = cam.generate((static_cast<float>(x) + j.x) * inv_w, (static_cast<float>(y) + j.y) * inv_h);
    const color c = trace_path(sc, r, rng, ps);
    if (all_finite(c))
      sum += glm::dvec3(c);
    else
      ++nonfinite;
  }
  return color(sum / static_cast<double>(rs.spp));
}

template <class Scene>
render_result render(const Scene& sc, const camera& cam, const render_settings& rs,
                     const progress_callback& progress = {},
                     std::chrono::milliseconds progress_interval = std::chrono::milliseconds(250)) {
  constexpr int tile = 16;
  render_result out;
  out.img = image(rs.width, rs.height);
  const int tiles_x = (rs.width + tile - 1) / tile, tiles_y = (rs.height + tile - 1) / tile;
  const int tile_count = tiles_x * tiles_y;
  unsigned n = rs.threads ? rs.threads : std::max(1u, std::thread::hardware_concurrency());
  n = std::min<unsigned>(n, static_cast<unsigned>(tile_count));
  out.threads = n;

  std::atomic<int> next{0}, done{0};
  std::atomic<std::uint64_t> nonfinite{0};
  auto worker = [&] {
    std::uint64_t bad = 0;
    for (int t; (t = next.fetch_add(1, std::memory_order_relaxed)) < tile_count;) {
      const int x0 = (t % tiles_x) * tile, y0 = (t / tiles_x) * tile;
      const int x1 = std::min(x0 + tile, rs.width), y1 = std::min(y0 + tile, rs.height);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) out.img.at(x, y) = render_pixel(sc, cam, rs, x, y, bad);
      done.fetch_add(1, std::memory_order_release);
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
      std::this_thread::sleep_for(progress_interval);
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

}  // namespace mcrt
