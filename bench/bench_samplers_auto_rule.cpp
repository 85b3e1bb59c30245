// What `auto`'s rule costs where a receiver is close to a planar light and
// g peaks between the fine rule's points (sampling/auto_strategy.hpp): the
// fine rule's model there (its sums, the exact projected solid angle and
// v_area integrated about the peak), and the peak integral alone
// (planar_rule::peak_v_area), against the fine rule's model where it
// resolves g. The receivers: walls 0.5-40 units below the benchmark
// lights' plane and 20-60 units beside their edge, facing across the
// light, and floors 0.5-40 units under their middle, facing them (the
// Cornell box's walls and ceiling light, scaled as its lights are).
#include <benchmark/benchmark.h>

#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/auto_strategy.hpp"
#include "observers.hpp"

namespace {

using namespace mcrt;

struct receiver {
  vec3 o, n;
};

// Receivers near the light of centre c, half-extent `half` along x, facing
// down (the benchmark lights): half on walls beside it, half under it.
std::vector<receiver> near_receivers(const vec3& c, float half) {
  std::vector<receiver> out;
  pcg32 rng(3, 5);
  for (int i = 0; i < 64; ++i) {
    const float below = 0.5f + 39.5f * rng.uniform();
    if (i % 2 == 0)
      out.push_back({c + vec3(half + 20.0f + 40.0f * rng.uniform(), -below, 60.0f * (rng.uniform() - 0.5f)), vec3(-1, 0, 0)});
    else
      out.push_back({c + vec3(half * (rng.uniform() - 0.5f), -below, half * (rng.uniform() - 0.5f)), vec3(0, 1, 0)});
  }
  return out;
}
// Receivers the fine rule resolves: 2-5 light sizes below its middle.
std::vector<receiver> far_receivers(const vec3& c, float half) {
  std::vector<receiver> out;
  pcg32 rng(7, 9);
  for (int i = 0; i < 64; ++i)
    out.push_back({c + vec3(half * (rng.uniform() - 0.5f), -half * (4.0f + 6.0f * rng.uniform()), 0.0f), vec3(0, 1, 0)});
  return out;
}

const rect bench_rect = bench::cornell_rect_light();
const ellipse bench_ellipse = bench::cornell_disk_light();

// f(rule, receiver) per iteration, over the receivers in turn.
template <class Shape, class F>
void over_receivers(benchmark::State& state, const Shape& s, const std::vector<receiver>& rs, F f) {
  const planar_rule rule(s);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(f(rule, rs[i++ & 63]));
  state.SetItemsProcessed(state.iterations());
}
template <class Shape>
void fine_model(benchmark::State& state, const Shape& s, const std::vector<receiver>& rs) {
  over_receivers(state, s, rs, [](const planar_rule& rule, const receiver& r) { return rule.fine(r.o, r.n).v_area(); });
}
template <class Shape>
void peak_integral(benchmark::State& state, const Shape& s, const std::vector<receiver>& rs) {
  over_receivers(state, s, rs, [](const planar_rule& rule, const receiver& r) { return rule.peak_v_area(r.o, r.n); });
}

void BM_AutoRuleRectNear(benchmark::State& st) { fine_model(st, bench_rect, near_receivers(bench_rect.center(), 65.0f)); }
void BM_AutoRuleRectFar(benchmark::State& st) { fine_model(st, bench_rect, far_receivers(bench_rect.center(), 65.0f)); }
void BM_AutoPeakIntegralRect(benchmark::State& st) {
  peak_integral(st, bench_rect, near_receivers(bench_rect.center(), 65.0f));
}
void BM_AutoRuleEllipseNear(benchmark::State& st) {
  fine_model(st, bench_ellipse, near_receivers(bench_ellipse.center, 65.0f));
}
void BM_AutoRuleEllipseFar(benchmark::State& st) {
  fine_model(st, bench_ellipse, far_receivers(bench_ellipse.center, 65.0f));
}
void BM_AutoPeakIntegralEllipse(benchmark::State& st) {
  peak_integral(st, bench_ellipse, near_receivers(bench_ellipse.center, 65.0f));
}

}  // namespace

BENCHMARK(BM_AutoRuleRectNear);
BENCHMARK(BM_AutoRuleRectFar);
BENCHMARK(BM_AutoPeakIntegralRect);
BENCHMARK(BM_AutoRuleEllipseNear);
BENCHMARK(BM_AutoRuleEllipseFar);
BENCHMARK(BM_AutoPeakIntegralEllipse);
