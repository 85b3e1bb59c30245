// Cost of solid-angle sampling of a rectangle (spherical rectangle map of
// Urena et al. 2013 with its area fallback): sample plus pdf per call, on the
// observers and the light of BM_SampleRectArea (bench_samplers_area.cpp).
// The counter fast_path is the fraction of those observers served by the
// sampler's fast path (spherical_rectangle.hpp). BM_SampleRectSolidAngleExact
// times spherical_rectangle alone, the exact path, on the same observers.
#include <benchmark/benchmark.h>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "observers.hpp"

namespace {

void BM_SampleRectSolidAngle(benchmark::State& state) {
  const mcrt::rect_solid_angle_sampler sampler{mcrt::bench::cornell_rect_light()};
  const std::vector<mcrt::vec3> obs = mcrt::bench::observers_around(sampler.shape);
  mcrt::bench::run_sample_and_pdf(state, sampler, obs);
  std::size_t fast = 0;
  for (const mcrt::vec3& o : obs) fast += sampler.fast_path(o);
  state.counters["fast_path"] = double(fast) / double(obs.size());
}
BENCHMARK(BM_SampleRectSolidAngle);

void BM_SampleRectSolidAngleExact(benchmark::State& state) {
  const mcrt::rect shape = mcrt::bench::cornell_rect_light();
  const std::vector<mcrt::vec3> obs = mcrt::bench::observers_around(shape);
  mcrt::pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const mcrt::vec3& o = obs[i++ & (obs.size() - 1)];
    const mcrt::spherical_rectangle sr(shape, o);
    if (!sr.valid()) continue;
    const mcrt::dvec3 v = sr.sample_offset(rng.uniform2());
    const mcrt::dvec3 dir = v / glm::length(v);
    // pdf(o, dir) sets up the observer again, as rect_solid_angle_sampler::pdf does.
    const mcrt::spherical_rectangle sr2(shape, o);
    double t;
    if (sr2.intersect(dir, t)) benchmark::DoNotOptimize(sr2.pdf_offset(t * dir));
    benchmark::DoNotOptimize(v);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SampleRectSolidAngleExact);

}  // namespace
