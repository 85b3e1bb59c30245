// Cost of the area samplers: sample plus pdf per call, observers spread
// around the light (bench/observers.hpp).
#include <benchmark/benchmark.h>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "observers.hpp"

namespace {

void BM_SampleRectArea(benchmark::State& state) {
  const mcrt::rect_area_sampler s{mcrt::bench::cornell_rect_light()};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape));
}
BENCHMARK(BM_SampleRectArea);

void BM_SampleEllipseArea(benchmark::State& state) {
  const mcrt::ellipse_area_sampler s{mcrt::bench::cornell_disk_light()};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape));
}
BENCHMARK(BM_SampleEllipseArea);

}  // namespace
