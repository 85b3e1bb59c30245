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
#include "observers.hpp"

namespace {

using namespace mcrt;

using bench::cap_mix;
using bench::sphere_receiver;

template <class Sampler>
void run(benchmark::State& state, const Sampler& sampler, cap_mix m) {
  const std::vector<sphere_receiver> rs = bench::sphere_receivers(m);
  mcrt::pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const sphere_receiver& r = rs[i++ & (rs.size() - 1)];
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

void BM_SampleSphereCone(benchmark::State& state) { run(state, mcrt::sphere_cone_sampler{bench::psc_sphere()}, cap_mix::both); }
BENCHMARK(BM_SampleSphereCone);

void BM_SampleSphereProjectedSolidAngle(benchmark::State& state) {
  run(state, mcrt::sphere_projected_solid_angle_sampler{bench::psc_sphere()}, cap_mix::both);
}
BENCHMARK(BM_SampleSphereProjectedSolidAngle);

void BM_SampleSphereArea(benchmark::State& state) { run(state, mcrt::sphere_area_sampler{bench::psc_sphere()}, cap_mix::both); }
BENCHMARK(BM_SampleSphereArea);

void BM_SampleSphereProjectedSolidAngleAbove(benchmark::State& state) {
  run(state, mcrt::sphere_projected_solid_angle_sampler{bench::psc_sphere()}, cap_mix::above);
}
BENCHMARK(BM_SampleSphereProjectedSolidAngleAbove);

void BM_SampleSphereProjectedSolidAngleCrossing(benchmark::State& state) {
  run(state, mcrt::sphere_projected_solid_angle_sampler{bench::psc_sphere()}, cap_mix::crossing);
}
BENCHMARK(BM_SampleSphereProjectedSolidAngleCrossing);

}  // namespace
