// Cost of solid-angle sampling of ellipses: sample plus pdf per call,
// observers spread around the light (bench/observers.hpp), the same loop as
// BM_SampleEllipseArea. The two solvers of the parallel map's area equation
// side by side (Newton on the Carlson closed form, and the thesis's 10-step
// bisection on a 10-interval Simpson rule), and the polar map.
#include <benchmark/benchmark.h>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_ellipse_polar.hpp"
#include "observers.hpp"

namespace {

const mcrt::ellipse bench_light = mcrt::bench::cornell_disk_light();

void BM_SampleEllipseSolidAngle(benchmark::State& state) {
  const mcrt::ellipse_solid_angle_sampler s{bench_light};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape));
}
BENCHMARK(BM_SampleEllipseSolidAngle);

void BM_SampleEllipseSolidAngleBisectionSimpson(benchmark::State& state) {
  const mcrt::ellipse_solid_angle_sampler_bisection_simpson s{bench_light};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape));
}
BENCHMARK(BM_SampleEllipseSolidAngleBisectionSimpson);

void BM_SampleEllipseSolidAnglePolar(benchmark::State& state) {
  const mcrt::ellipse_polar_solid_angle_sampler s{bench_light};
  mcrt::bench::run_sample_and_pdf(state, s, mcrt::bench::observers_around(s.shape));
}
BENCHMARK(BM_SampleEllipseSolidAnglePolar);

}  // namespace
