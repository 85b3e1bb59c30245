// Where the time of a sample plus pdf goes: sample() alone and pdf() alone
// (for a direction the sampler produced, so pdf does its whole work) for the
// rectangle and ellipse samplers, and the parts of the ellipse's solid-angle
// sampler: the cone set-up with Omega, Omega alone, the area-equation solver
// alone. Same lights and observers as the other sampler benchmarks.
#include <benchmark/benchmark.h>

#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"
#include "observers.hpp"

namespace {

using namespace mcrt;

const rect bench_rect = bench::cornell_rect_light();
const ellipse bench_ellipse = bench::cornell_disk_light();

template <class Sampler>
void sample_only(benchmark::State& state, const Sampler& s, const std::vector<vec3>& obs) {
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    light_sample ls;
    benchmark::DoNotOptimize(s.sample(obs[i++ & (obs.size() - 1)], rng.uniform2(), ls));
    benchmark::DoNotOptimize(ls);
  }
  state.SetItemsProcessed(state.iterations());
}

template <class Sampler>
void pdf_only(benchmark::State& state, const Sampler& s, const std::vector<vec3>& obs) {
  pcg32 rng(1, 2);
  std::vector<vec3> dirs(obs.size(), vec3(0.0f));
  for (std::size_t k = 0; k < obs.size(); ++k) {
    light_sample ls;
    if (s.sample(obs[k], rng.uniform2(), ls)) dirs[k] = ls.dir;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & (obs.size() - 1);
    benchmark::DoNotOptimize(s.pdf(obs[k], dirs[k]));
  }
  state.SetItemsProcessed(state.iterations());
}

std::vector<vec3> rect_observers() { return bench::observers_around(bench_rect); }
std::vector<vec3> ellipse_observers() { return bench::observers_around(bench_ellipse); }

// Half of the Cornell light, as bench_samplers_triangle_sa.cpp.
triangle bench_triangle() {
  auto m = std::make_shared<triangle_mesh>();
  m->p = {{343, 554, 332}, {213, 554, 227}, {343, 554, 227}};
  m->indices = {0, 1, 2};
  return {m, 0};
}
std::vector<vec3> triangle_observers() {
  const triangle t = bench_triangle();
  return bench::observers_around((t.vertex(0) + t.vertex(1) + t.vertex(2)) / 3.0f, t.normal(), 130.0f);
}
void BM_TriangleSolidAngleSampleOnly(benchmark::State& st) {
  sample_only(st, triangle_solid_angle_sampler{bench_triangle()}, triangle_observers());
}
void BM_TriangleSolidAnglePdfOnly(benchmark::State& st) {
  pdf_only(st, triangle_solid_angle_sampler{bench_triangle()}, triangle_observers());
}
// The spherical triangle's set-up alone (Omega and the map's constants).
void BM_TriangleSolidAngleSetup(benchmark::State& state) {
  const std::vector<vec3> obs = triangle_observers();
  const triangle t = bench_triangle();
  const dvec3 p0(t.vertex(0)), p1(t.vertex(1)), p2(t.vertex(2));
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(spherical_triangle(dvec3(obs[i++ & (obs.size() - 1)]), p0, p1, p2));
  state.SetItemsProcessed(state.iterations());
}

void BM_RectAreaSampleOnly(benchmark::State& st) { sample_only(st, rect_area_sampler{bench_rect}, rect_observers()); }
void BM_RectAreaPdfOnly(benchmark::State& st) { pdf_only(st, rect_area_sampler{bench_rect}, rect_observers()); }
void BM_RectSolidAngleSampleOnly(benchmark::State& st) {
  sample_only(st, rect_solid_angle_sampler{bench_rect}, rect_observers());
}
void BM_RectSolidAnglePdfOnly(benchmark::State& st) {
  pdf_only(st, rect_solid_angle_sampler{bench_rect}, rect_observers());
}
void BM_EllipseAreaSampleOnly(benchmark::State& st) {
  sample_only(st, ellipse_area_sampler{bench_ellipse}, ellipse_observers());
}
void BM_EllipseAreaPdfOnly(benchmark::State& st) { pdf_only(st, ellipse_area_sampler{bench_ellipse}, ellipse_observers()); }
void BM_EllipseSolidAngleSampleOnly(benchmark::State& st) {
  sample_only(st, ellipse_solid_angle_sampler{bench_ellipse}, ellipse_observers());
}
void BM_EllipseSolidAnglePdfOnly(benchmark::State& st) {
  pdf_only(st, ellipse_solid_angle_sampler{bench_ellipse}, ellipse_observers());
}

// The cone set-up of the ellipse sampler (frame, Jacobi, Omega by the AGM).
void BM_EllipseConeSetup(benchmark::State& state) {
  const std::vector<vec3> obs = ellipse_observers();
  const ellipse_frame f(bench_ellipse);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(make_ellipse_cone(bench_ellipse, f, obs[i++ & (obs.size() - 1)]));
  state.SetItemsProcessed(state.iterations());
}

// Omega of the canonical cone alone (AGM).
void BM_EllipseSolidAngleOmega(benchmark::State& state) {
  const std::vector<spherical_ellipse> cones = bench::canonical_cones(bench_ellipse);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(spherical_ellipse_area(cones[i++ & (cones.size() - 1)]));
  state.SetItemsProcessed(state.iterations());
}

// The parallel map's area-equation solver alone (Omega precomputed).
void BM_EllipseSolidAngleSolver(benchmark::State& state) {
  const std::vector<spherical_ellipse> cones = bench::canonical_cones(bench_ellipse);
  std::vector<double> omegas;
  for (const spherical_ellipse& se : cones) omegas.push_back(spherical_ellipse_area(se));
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & (cones.size() - 1);
    benchmark::DoNotOptimize(newton_carlson_solver::invert(cones[k], omegas[k], rng.uniform()));
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_RectAreaSampleOnly);
BENCHMARK(BM_RectAreaPdfOnly);
BENCHMARK(BM_RectSolidAngleSampleOnly);
BENCHMARK(BM_RectSolidAnglePdfOnly);
BENCHMARK(BM_EllipseAreaSampleOnly);
BENCHMARK(BM_EllipseAreaPdfOnly);
BENCHMARK(BM_EllipseSolidAngleSampleOnly);
BENCHMARK(BM_EllipseSolidAnglePdfOnly);
BENCHMARK(BM_EllipseConeSetup);
BENCHMARK(BM_EllipseSolidAngleOmega);
BENCHMARK(BM_EllipseSolidAngleSolver);
BENCHMARK(BM_TriangleSolidAngleSampleOnly);
BENCHMARK(BM_TriangleSolidAnglePdfOnly);
BENCHMARK(BM_TriangleSolidAngleSetup);

}  // namespace
