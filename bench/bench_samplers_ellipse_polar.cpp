// Cost of solid-angle sampling of ellipses through the polar map of the
// spherical ellipse (sampling/spherical_ellipse_polar.hpp): sample plus pdf
// per call, on the light and observers of bench_samplers_ellipse_sa.cpp
// (bench/observers.hpp), so the figures compare with BM_SampleEllipseSolidAngle.
#include <benchmark/benchmark.h>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_ellipse_polar.hpp"
#include "observers.hpp"

namespace {

const mcrt::ellipse bench_light = mcrt::ellipse::make({278, 554, 279.5}, {65, 0, 0}, {0, 0, 65});

void BM_SampleEllipseSolidAnglePolar(benchmark::State& state) {
  const mcrt::ellipse_polar_solid_angle_sampler s{bench_light};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape.center, s.shape.n, 130.0f));
}
BENCHMARK(BM_SampleEllipseSolidAnglePolar);

}  // namespace
