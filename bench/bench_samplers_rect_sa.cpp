// Cost of solid-angle sampling of a rectangle (spherical rectangle map of
// Urena et al. 2013 with its area fallback): sample plus pdf per call, on the
// observers and the light of BM_SampleRectArea (bench_samplers_area.cpp).
#include <benchmark/benchmark.h>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "observers.hpp"

namespace {

void BM_SampleRectSolidAngle(benchmark::State& state) {
  const mcrt::rect_solid_angle_sampler sampler{mcrt::xz_rect(213, 343, 227, 332, 554, true)};
  const std::vector<mcrt::vec3> obs =
      mcrt::bench::observers_around(sampler.shape.center(), sampler.shape.n, 130.0f);
  mcrt::pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const mcrt::vec3& o = obs[i++ & (obs.size() - 1)];
    mcrt::light_sample s;
    if (sampler.sample(o, rng.uniform2(), s)) benchmark::DoNotOptimize(sampler.pdf(o, s.dir));
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SampleRectSolidAngle);

}  // namespace
