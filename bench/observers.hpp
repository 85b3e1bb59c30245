#pragma once
// What the sampler benchmarks share: the two lights (the Cornell box's
// ceiling rectangle and a disk of the same size), observer positions spread
// around a light, so every sampler is timed on the same set of points, and
// the timed loop itself (one sample plus its pdf per iteration).
#include <benchmark/benchmark.h>

#include <cmath>
#include <utility>
#include <vector>

#include "mcrt/core/math.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"

namespace mcrt::bench {

// The benchmark lights: the ceiling light of Shirley's Cornell box (130 x
// 105, facing down) and a disk of radius 65 at its centre.
inline rect cornell_rect_light() { return xz_rect(213, 343, 227, 332, 554, true); }
inline ellipse cornell_disk_light() { return ellipse::make({278, 554, 279.5}, {65, 0, 0}, {0, 0, 65}); }

// n points in front of a light centred at `center` with unit front normal
// `n`, at distances from 0.2 to 5 times `size`, in all directions of the
// front half-space.
inline std::vector<vec3> observers_around(const vec3& center, const vec3& n, float size,
                                          std::size_t count = 4096) {
  std::vector<vec3> out;
  out.reserve(count);
  pcg32 rng(7, 11);
  while (out.size() < count) {
    const vec3 d{2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f};
    const float l2 = glm::dot(d, d);
    if (l2 > 1.0f || l2 < 1e-4f) continue;
    vec3 dir = d / std::sqrt(l2);
    if (glm::dot(dir, n) < 0.05f) dir = glm::reflect(dir, n);
    if (glm::dot(dir, n) < 0.05f) continue;
    const float dist = size * (0.2f + 4.8f * rng.uniform());
    out.push_back(center + dist * dir);
  }
  return out;
}

// The observers every benchmark of a light uses.
inline std::vector<vec3> observers_around(const rect& r) { return observers_around(r.center(), r.n, 130.0f); }
inline std::vector<vec3> observers_around(const ellipse& e) { return observers_around(e.center, e.n, 130.0f); }

// The canonical cones of e from its observers, for the benchmarks of the
// spherical ellipse's parts (set up outside their timed loops).
inline std::vector<spherical_ellipse> canonical_cones(const ellipse& e) {
  std::vector<spherical_ellipse> out;
  for (const vec3& o : observers_around(e)) out.push_back(make_ellipse_cone(e, o).se);
  return out;
}

// The projected-spherical-cap benchmarks' sphere (radius 65 at the Cornell
// box's centre) and receivers (bench_samplers_psc.cpp and its floor): 4096
// (observer, normal) pairs at 1.2 to 6 radii with random normals, half with
// the cap above the horizon (h / r >= 1), half crossing it (-1 < h / r < 1;
// a third of those with the centre below the plane), interleaved
// pseudo-randomly so the branch predictor does not learn the kind; or 4096
// of one kind.
inline sphere psc_sphere() {
  sphere s{};
  s.center = vec3(278.0f, 278.0f, 279.5f);
  s.radius = 65.0f;
  return s;
}
struct sphere_receiver {
  vec3 o, n;
};
enum class cap_mix { both, above, crossing };
inline std::vector<sphere_receiver> sphere_receivers(cap_mix m) {
  const sphere sp = psc_sphere();
  constexpr std::size_t count = 4096;
  std::vector<sphere_receiver> above, cross_up, cross_down;
  pcg32 rng(7, 13);
  auto unit = [&rng] {
    for (;;) {
      const vec3 d{2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f};
      const float l2 = glm::dot(d, d);
      if (l2 <= 1.0f && l2 > 1e-4f) return d / std::sqrt(l2);
    }
  };
  while (above.size() < count || cross_up.size() + cross_down.size() < count) {
    const vec3 o = sp.center + sp.radius * (1.2f + 4.8f * rng.uniform()) * unit();
    const vec3 n = unit();
    const float mu = glm::dot(sp.center - o, n) / sp.radius;
    if (mu >= 1.0f) {
      if (above.size() < count) above.push_back({o, n});
    } else if (mu >= 0.0f) {
      if (cross_up.size() < 2 * count / 3) cross_up.push_back({o, n});
    } else if (mu > -1.0f) {
      if (cross_down.size() < count - 2 * count / 3) cross_down.push_back({o, n});
    }
  }
  std::vector<sphere_receiver> cross = cross_up;
  cross.insert(cross.end(), cross_down.begin(), cross_down.end());
  if (m == cap_mix::above) return above;
  if (m == cap_mix::crossing) return cross;
  std::vector<sphere_receiver> out;
  for (std::size_t i = 0; i < count / 2; ++i) {
    out.push_back(above[2 * i]);
    out.push_back(cross[2 * i]);
  }
  for (std::size_t i = out.size() - 1; i > 0; --i) std::swap(out[i], out[rng.next_u32() % uint32_t(i + 1)]);
  return out;
}

// Times sampler.sample plus sampler.pdf for the sampled direction, cycling
// through the observers (their count must be a power of two).
template <class Sampler>
void run_sample_and_pdf(benchmark::State& state, const Sampler& sampler, const std::vector<vec3>& obs) {
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const vec3& o = obs[i++ & (obs.size() - 1)];
    light_sample s;
    if (sampler.sample(o, rng.uniform2(), s)) benchmark::DoNotOptimize(sampler.pdf(o, s.dir));
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations());
}

}  // namespace mcrt::bench
