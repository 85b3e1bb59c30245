// Cost of the sphere strategies: sample plus pdf per call of the projected
// solid angle sampler (Urena & Georgiev 2018, radial map), the cone sampler
// (uniform solid angle) and the visible-cap area sampler, on the same
// (observer, normal) pairs.
//
// The set: a sphere of radius 65 at the Cornell box's centre, 4096 observers
// at distances 1.2 to 6 radii in all directions, each with a random unit
// normal, kept in a fixed mix: half with the sphere wholly above the
// receiving plane (h / r >= 1: the cap above the horizon, closed-form map),
// half with the cap crossing the horizon (-1 < h / r < 1), of which a third
// with the centre below the plane (h < 0, lune only). BM_*Above and
// BM_*Crossing time the two halves apart.
#include <benchmark/benchmark.h>

#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/sampling/projected_spherical_cap.hpp"
#include "mcrt/sampling/sphere_area.hpp"
#include "mcrt/sampling/sphere_cone.hpp"

namespace {

using mcrt::vec3;

mcrt::sphere bench_sphere() {
  mcrt::sphere s{};
  s.center = vec3(278.0f, 278.0f, 279.5f);
  s.radius = 65.0f;
  return s;
}

struct receiver {
  vec3 o, n;
};

enum class mix { both, above, crossing };

// 4096 (observer, normal) pairs (see the header comment), or 4096 of one kind.
std::vector<receiver> receivers(mix m) {
  const mcrt::sphere sp = bench_sphere();
  constexpr std::size_t count = 4096;
  std::vector<receiver> above, cross_up, cross_down;
  mcrt::pcg32 rng(7, 13);
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
  std::vector<receiver> cross = cross_up;
  cross.insert(cross.end(), cross_down.begin(), cross_down.end());
  if (m == mix::above) return above;
  if (m == mix::crossing) return cross;
  std::vector<receiver> out;
  for (std::size_t i = 0; i < count / 2; ++i) {
    out.push_back(above[2 * i]);
    out.push_back(cross[2 * i]);
  }
  // Interleave pseudo-randomly so the branch predictor does not learn the kind.
  for (std::size_t i = out.size() - 1; i > 0; --i) std::swap(out[i], out[rng.next_u32() % uint32_t(i + 1)]);
  return out;
}

template <class Sampler>
void run(benchmark::State& state, const Sampler& sampler, mix m) {
  const std::vector<receiver> rs = receivers(m);
  mcrt::pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const receiver& r = rs[i++ & (rs.size() - 1)];
    mcrt::light_sample s;
    if constexpr (requires { sampler.sample(r.o, r.n, rng.uniform2(), s); }) {
      if (sampler.sample(r.o, r.n, rng.uniform2(), s)) benchmark::DoNotOptimize(sampler.pdf(r.o, r.n, s.dir));
    } else {
      if (sampler.sample(r.o, rng.uniform2(), s)) benchmark::DoNotOptimize(sampler.pdf(r.o, s.dir));
    }
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_SampleSphereCone(benchmark::State& state) { run(state, mcrt::sphere_cone_sampler{bench_sphere()}, mix::both); }
BENCHMARK(BM_SampleSphereCone);

void BM_SampleSphereProjectedSolidAngle(benchmark::State& state) {
  run(state, mcrt::sphere_projected_solid_angle_sampler{bench_sphere()}, mix::both);
}
BENCHMARK(BM_SampleSphereProjectedSolidAngle);

void BM_SampleSphereArea(benchmark::State& state) { run(state, mcrt::sphere_area_sampler{bench_sphere()}, mix::both); }
BENCHMARK(BM_SampleSphereArea);

void BM_SampleSphereProjectedSolidAngleAbove(benchmark::State& state) {
  run(state, mcrt::sphere_projected_solid_angle_sampler{bench_sphere()}, mix::above);
}
BENCHMARK(BM_SampleSphereProjectedSolidAngleAbove);

void BM_SampleSphereProjectedSolidAngleCrossing(benchmark::State& state) {
  run(state, mcrt::sphere_projected_solid_angle_sampler{bench_sphere()}, mix::crossing);
}
BENCHMARK(BM_SampleSphereProjectedSolidAngleCrossing);

}  // namespace
