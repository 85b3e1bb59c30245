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
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "mcrt/core/worker_errors.hpp"
#include "mcrt/render/camera.hpp"
#include "mcrt/render/image.hpp"
#include "mcrt/render/path_tracer.hpp"
#include "mcrt/render/pixel_filter.hpp"
#include "mcrt/sampling/auto_footprint.hpp"
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

// One camera sample of pixel (x, y): its camera ray and the radiance along
// it; with the pixel's footprint fp where the integrator takes one (nee,
// mis: sampling/auto_footprint.hpp).
template <class Integrator, class Scene, class PixelSampler>
color camera_sample(const Scene& sc, const camera& cam, PixelSampler& ps, int x, int y, float inv_w, float inv_h,
                    const path_settings& set, const pixel_filter& filter = {}, const auto_footprint* fp = nullptr) {
  const ray r = camera_ray(cam, ps, x, y, inv_w, inv_h, filter);
  if constexpr (requires { Integrator::li(sc, r, ps, set, fp); })
    return Integrator::li(sc, r, ps, set, fp);
  else
    return Integrator::li(sc, r, ps, set);
}

// Where the pinhole ray through the film point (x + j.x, y + j.y) first
// meets a surface: its spawn point and facing shading normal. Out of line
// (GCC's and Clang's noinline; about one call per pixel): a corner that
// tile_footprints and pixel_footprint both reach, from the same film point,
// is then the same to the bit, whatever contractions each caller's inlined
// copy would have made.
struct footprint_corner {
  bool hit = false;
  vec3 o{0.0f}, n{0.0f};
};
template <class Scene>
#if defined(__GNUC__) || defined(__clang__)
[[gnu::noinline]]
#endif
footprint_corner corner_seen(const Scene& sc, const camera& cam, int x, int y, vec2 j, float inv_w, float inv_h) {
  const ray r = pixel_ray(cam, x, y, j, inv_w, inv_h);
  hit_record rec;
  if (!sc.hit(r, 0.0f, infinity, rec)) return {};
  const vec3 n = rec.facing_shading_normal(r.d);
  return {true, rec.spawn_origin(n), n};
}

// The footprint of pixel (x, y) on the surfaces it sees (sampling/
// auto_footprint.hpp): where the corners of its filter's support, seen
// through the lens's centre, first meet a surface.
template <class Scene>
auto_footprint pixel_footprint(const Scene& sc, const camera& cam, int x, int y, float inv_w, float inv_h,
                               const pixel_filter& filter) {
  auto_footprint fp;
  const vec2 r = filter.radius();
  for (const vec2 d : {vec2(-r.x, -r.y), vec2(r.x, -r.y), vec2(-r.x, r.y), vec2(r.x, r.y)}) {
    const footprint_corner c = corner_seen(sc, cam, x, y, vec2(0.5f) + d, inv_w, inv_h);
    if (c.hit) fp.add(c.o, c.n);
  }
  return fp;
}

// The footprints of the pixels of a tile [x0, x1) x [y0, y1). Where the
// filter's support is a whole number of pixels wide (2 r: the box's 1,
// the Gaussian's 3, the triangle's 4) the corners of neighbouring pixels
// coincide, and each is traced once: (x1 - x0 + 2 r_x) (y1 - y0 + 2 r_y)
// rays for the tile (289 for 16 x 16 pixels and the box) instead of four
// per pixel.
class tile_footprints {
 public:
  template <class Scene>
  void trace(const Scene& sc, const camera& cam, const pixel_filter& filter, int x0, int y0, int x1, int y1,
             float inv_w, float inv_h) {
    const vec2 r = filter.radius();
    sx_ = static_cast<int>(std::lround(2.0f * r.x)), sy_ = static_cast<int>(std::lround(2.0f * r.y));
    shared_ = std::abs(2.0f * r.x - float(sx_)) < 1e-6f && std::abs(2.0f * r.y - float(sy_)) < 1e-6f;
    x0_ = x0, y0_ = y0, w_ = x1 - x0 + sx_;
    if (!shared_) return;
    const int h = y1 - y0 + sy_;
    corners_.resize(static_cast<std::size_t>(w_) * h);
    // Corner (i, j) is the lower corner of pixel (x0 + i, y0 + j).
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w_; ++i)
        corners_[static_cast<std::size_t>(j) * w_ + i] =
            corner_seen(sc, cam, x0 + i, y0 + j, vec2(0.5f - r.x, 0.5f - r.y), inv_w, inv_h);
  }
  template <class Scene>
  auto_footprint at(const Scene& sc, const camera& cam, const pixel_filter& filter, int x, int y, float inv_w,
                    float inv_h) const {
    if (!shared_) return pixel_footprint(sc, cam, x, y, inv_w, inv_h, filter);
    auto_footprint fp;
    const int i = x - x0_, j = y - y0_;
    for (const auto& [a, b] : {std::pair{0, 0}, {sx_, 0}, {0, sy_}, {sx_, sy_}}) {
      const footprint_corner& c = corners_[static_cast<std::size_t>(j + b) * w_ + i + a];
      if (c.hit) fp.add(c.o, c.n);
    }
    return fp;
  }

 private:
  std::vector<footprint_corner> corners_;
  int x0_ = 0, y0_ = 0, w_ = 0, sx_ = 1, sy_ = 1;
  bool shared_ = false;
};

template <class Integrator, class Scene, class Sampler>
color render_pixel(const Scene& sc, const camera& cam, const render_settings& rs, const Sampler& sampler, int x, int y,
                   std::uint64_t& nonfinite, const auto_footprint* fp = nullptr) {
  auto ps = sampler.start_pixel(x, y, rs.width);
  const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
  const path_settings set = rs.path();
  glm::dvec3 sum(0.0);
  for (int s = 0; s < rs.spp; ++s) {
    ps.start_sample(s);
    const color c = camera_sample<Integrator>(sc, cam, ps, x, y, inv_w, inv_h, set, rs.filter, fp);
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
  // A scene with lights `auto` samples: one choice per pixel at the camera
  // rays' first surfaces (sampling/auto_footprint.hpp).
  const bool footprint = std::any_of(sc.lights.begin(), sc.lights.end(), [](light_ref l) {
    return strategy_of(l) == light_sampling::automatic;
  });
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
  worker_errors errors;
  auto work = [&] {
    std::uint64_t bad = 0;
    const float inv_w = 1.0f / static_cast<float>(rs.width), inv_h = 1.0f / static_cast<float>(rs.height);
    tile_footprints footprints;
    for (int t; !errors.failed() && (t = next.fetch_add(1, std::memory_order_relaxed)) < tile_count;) {
      const int x0 = (t % tiles_x) * tile, y0 = (t / tiles_x) * tile;
      const int x1 = std::min(x0 + tile, rs.width), y1 = std::min(y0 + tile, rs.height);
      if (footprint) footprints.trace(sc, cam, rs.filter, x0, y0, x1, y1, inv_w, inv_h);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          // Only a scene with lights `auto` samples pays for the footprint.
          if (!footprint) {
            out.img.at(x, y) = render_pixel<Integrator>(sc, cam, rs, sampler, x, y, bad);
            continue;
          }
          const auto_footprint fp = footprints.at(sc, cam, rs.filter, x, y, inv_w, inv_h);
          out.img.at(x, y) = render_pixel<Integrator>(sc, cam, rs, sampler, x, y, bad, fp.empty() ? nullptr : &fp);
        }
      if (done.fetch_add(1, std::memory_order_release) + 1 == tile_count) {
        const std::lock_guard<std::mutex> lock(finished_mutex);
        finished.notify_all();
      }
    }
    nonfinite.fetch_add(bad, std::memory_order_relaxed);
  };
  // A worker that throws (std::bad_alloc, say) stops the others and wakes
  // the progress reporter; its exception is rethrown below, after the join.
  auto worker = [&] {
    errors.run(work);
    if (errors.failed()) {
      const std::lock_guard<std::mutex> lock(finished_mutex);
      finished.notify_all();
    }
  };

  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  std::vector<std::jthread> pool;
  pool.reserve(n);
  for (unsigned i = 0; i + 1 < n; ++i) pool.emplace_back(worker);
  if (progress) {
    // The calling thread reports progress while the pool works.
    pool.emplace_back(worker);
    for (int d; (d = done.load(std::memory_order_acquire)) < tile_count && !errors.failed();) {
      progress(static_cast<double>(d) / tile_count, elapsed());
      std::unique_lock<std::mutex> lock(finished_mutex);
      finished.wait_for(lock, progress_interval,
                        [&] { return done.load(std::memory_order_acquire) == tile_count || errors.failed(); });
    }
  } else {
    worker();
  }
  pool.clear();  // join
  errors.rethrow_if_failed();
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
