// Cost of the sample generators (samplers/independent.hpp, stratified.hpp,
// sobol_sampler.hpp) as a renderer uses them: 64 samples per pixel
// (start_pixel once per 64 samples, then start_sample for each), and per
// sample the draws of a path of three bounces in the layout of
// samplers/layout.hpp: pixel() and, per bounce, light choice (1-D), light
// (2-D), material choice (1-D), material (2-D), roulette (1-D) -- 16 draws,
// 7 of them 2-D.
//
//   BM_SamplerPath<S>   one iteration = one path (16 draws); "per_draw" is
//                       the time divided by 16
//   BM_SamplerGet2D<S>  one iteration = one get2d, cycling over the path's
//                       7 pairs (start_sample / start_pixel amortised in)
//   BM_SamplerGet1D<S>  one iteration = one get1d, cycling over the 9 1-D
//                       dimensions
// and the building blocks alone: nested_uniform_scramble, permute (Kensler),
// sobol_sample of a generic dimension (loop over the index bits).
#include <benchmark/benchmark.h>

#include <cstdint>

#include "mcrt/core/rng.hpp"
#include "mcrt/samplers/hash.hpp"
#include "mcrt/samplers/independent.hpp"
#include "mcrt/samplers/layout.hpp"
#include "mcrt/samplers/owen_scrambling.hpp"
#include "mcrt/samplers/sobol.hpp"
#include "mcrt/samplers/sobol_sampler.hpp"
#include "mcrt/samplers/stratified.hpp"

namespace {

using namespace mcrt;

constexpr int bench_spp = 64;
constexpr int bench_bounces = 3;
constexpr int draws_per_path = 1 + 5 * bench_bounces;
constexpr int image_width = 640;

// Pixel and sample bookkeeping of a render loop: a new pixel every bench_spp
// samples.
template <class Sampler>
struct pixel_walker {
  const Sampler& sampler;
  decltype(sampler.start_pixel(0, 0, 1)) p;
  int x = 0, y = 0, sample = 0;
  explicit pixel_walker(const Sampler& s) : sampler(s), p(s.start_pixel(0, 0, image_width)) { p.start_sample(0); }
  void next_sample() {
    if (++sample == bench_spp) {
      sample = 0;
      if (++x == image_width) x = 0, ++y;
      p = sampler.start_pixel(x, y, image_width);
    }
    p.start_sample(sample);
  }
};

template <class Sampler>
void BM_SamplerPath(benchmark::State& state) {
  const Sampler sampler(7, bench_spp);
  pixel_walker<Sampler> w(sampler);
  for (auto _ : state) {
    auto& p = w.p;
    vec2 acc = p.pixel();
    for (int k = 0; k < bench_bounces; ++k) {
      const int b = layout::bounce(k);
      acc.x += p.get1d(b + layout::light_choice);
      acc += p.get2d(b + layout::light);
      acc.y += p.get1d(b + layout::material_choice);
      acc += p.get2d(b + layout::material);
      acc.x += p.get1d(b + layout::roulette);
    }
    benchmark::DoNotOptimize(acc);
    w.next_sample();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["per_draw"] =
      benchmark::Counter(draws_per_path, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

template <class Sampler>
void BM_SamplerGet2D(benchmark::State& state) {
  const Sampler sampler(7, bench_spp);
  pixel_walker<Sampler> w(sampler);
  int dims[1 + 2 * bench_bounces] = {layout::pixel};
  for (int k = 0; k < bench_bounces; ++k) {
    dims[1 + 2 * k] = layout::bounce(k) + layout::light;
    dims[2 + 2 * k] = layout::bounce(k) + layout::material;
  }
  int d = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(w.p.get2d(dims[d]));
    if (++d == 1 + 2 * bench_bounces) d = 0, w.next_sample();
  }
  state.SetItemsProcessed(state.iterations());
}

template <class Sampler>
void BM_SamplerGet1D(benchmark::State& state) {
  const Sampler sampler(7, bench_spp);
  pixel_walker<Sampler> w(sampler);
  int dims[3 * bench_bounces];
  for (int k = 0; k < bench_bounces; ++k) {
    dims[3 * k] = layout::bounce(k) + layout::light_choice;
    dims[3 * k + 1] = layout::bounce(k) + layout::material_choice;
    dims[3 * k + 2] = layout::bounce(k) + layout::roulette;
  }
  int d = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(w.p.get1d(dims[d]));
    if (++d == 3 * bench_bounces) d = 0, w.next_sample();
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK_TEMPLATE(BM_SamplerPath, independent_sampler);
BENCHMARK_TEMPLATE(BM_SamplerPath, stratified_sampler);
BENCHMARK_TEMPLATE(BM_SamplerPath, sobol_sampler);
BENCHMARK_TEMPLATE(BM_SamplerGet2D, independent_sampler);
BENCHMARK_TEMPLATE(BM_SamplerGet2D, stratified_sampler);
BENCHMARK_TEMPLATE(BM_SamplerGet2D, sobol_sampler);
BENCHMARK_TEMPLATE(BM_SamplerGet1D, independent_sampler);
BENCHMARK_TEMPLATE(BM_SamplerGet1D, stratified_sampler);
BENCHMARK_TEMPLATE(BM_SamplerGet1D, sobol_sampler);

// ------------------------------------------------------------ building blocks

void BM_NestedUniformScramble(benchmark::State& state) {
  std::uint32_t x = 12345u, seed = 0x9e3779b9u;
  for (auto _ : state) {
    x = nested_uniform_scramble(x, seed);  // dependent chain: latency
    benchmark::DoNotOptimize(x);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_NestedUniformScramble);

void BM_KenslerPermute(benchmark::State& state) {
  const auto l = static_cast<std::uint32_t>(state.range(0));
  std::uint32_t i = 0, seed = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(permute(i, l, seed));
    if (++i == l) i = 0, ++seed;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_KenslerPermute)->Arg(64)->Arg(100);

void BM_SobolSampleGenericDim(benchmark::State& state) {
  std::uint32_t i = 0;
  int d = 2;
  (void)sobol_matrices();  // the table is built on first use, outside the timing
  for (auto _ : state) {
    benchmark::DoNotOptimize(sobol_sample(i & 1023u, d));  // 10 index bits, as for spp = 1024
    ++i;
    if (++d == 40) d = 2;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SobolSampleGenericDim);

}  // namespace
