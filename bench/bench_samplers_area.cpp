// Cost of the area samplers: sample plus pdf per call, observers spread
// around the light (bench/observers.hpp).
#include <benchmark/benchmark.h>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "observers.hpp"

namespace {

void BM_SampleRectArea(benchmark::State& state) {
  const mcrt::rect_area_sampler s{mcrt::xz_rect(213, 343, 227, 332, 554, true)};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape.center(), s.shape.n, 130.0f));
}
BENCHMARK(BM_SampleRectArea);

void BM_SampleEllipseArea(benchmark::State& state) {
  const mcrt::ellipse_area_sampler s{mcrt::ellipse::make({278, 554, 279.5}, {65, 0, 0}, {0, 0, 65})};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape.center, s.shape.n, 130.0f));
}
BENCHMARK(BM_SampleEllipseArea);

}  // namespace
