// Cost of the triangle light strategies: sample plus pdf per call, on the
// observers of the samplers' benchmark (bench/observers.hpp) around one
// half of the Cornell box light, front -y:
//  BM_SampleTriangleArea          triangle_area_sampler
//  BM_SampleTriangleSolidAngle    triangle_solid_angle_sampler (Arvo 1995 in
//                                 the closed forms of spherical_triangle.hpp)
//  BM_FloorPbrtSphericalTriangle  pbrt-v4's SampleSphericalTriangle as
//                                 published (float, pbrt_spherical_triangle_
//                                 port.inc), its pdf 1/Omega from the same
//                                 call: the floor of the published algorithm
//  BM_SampleTriangle{ProjectedSolidAngle,Bilinear,Pbrt}/Up
//                                 the cosine-aware ones, receiver normal
//                                 (0, 1, 0) (the light above every horizon)
#include <benchmark/benchmark.h>

#include <memory>

#include "mcrt/sampling/bilinear_spherical_triangle.hpp"
#include "mcrt/sampling/pbrt_strategy.hpp"
#include "mcrt/sampling/projected_triangle.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"
#include "observers.hpp"
#include "pbrt_spherical_triangle_port.inc"
#include "peters21_sa_port.inc"

namespace {

mcrt::triangle cornell_half_triangle() {
  auto m = std::make_shared<mcrt::triangle_mesh>();
  m->p = {{343, 554, 332}, {213, 554, 227}, {343, 554, 227}};
  m->indices = {0, 1, 2};
  return {m, 0};
}

std::vector<mcrt::vec3> triangle_observers(const mcrt::triangle& t) {
  const mcrt::vec3 c = (t.vertex(0) + t.vertex(1) + t.vertex(2)) / 3.0f;
  return mcrt::bench::observers_around(c, t.normal(), 130.0f);
}

void BM_SampleTriangleSolidAngle(benchmark::State& state) {
  const mcrt::triangle t = cornell_half_triangle();
  const mcrt::triangle_solid_angle_sampler sampler{t};
  mcrt::bench::run_sample_and_pdf(state, sampler, triangle_observers(t));
}
BENCHMARK(BM_SampleTriangleSolidAngle);

void BM_SampleTriangleArea(benchmark::State& state) {
  const mcrt::triangle t = cornell_half_triangle();
  const mcrt::triangle_area_sampler sampler{t};
  mcrt::bench::run_sample_and_pdf(state, sampler, triangle_observers(t));
}
BENCHMARK(BM_SampleTriangleArea);

// A published map timed as published: map(p0, p1, p2, o, u) over the
// observers, its direction and density kept from the optimiser.
template <class Map>
void run_floor(benchmark::State& state, Map map) {
  const mcrt::triangle t = cornell_half_triangle();
  const std::vector<mcrt::vec3> obs = triangle_observers(t);
  const mcrt::vec3 p0 = t.vertex(0), p1 = t.vertex(1), p2 = t.vertex(2);
  mcrt::pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    float pdf = 0.0f;
    const mcrt::vec3 d = map(p0, p1, p2, obs[i++ & (obs.size() - 1)], rng.uniform2(), pdf);
    benchmark::DoNotOptimize(d);
    benchmark::DoNotOptimize(pdf);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_FloorPbrtSphericalTriangle(benchmark::State& state) {
  run_floor(state, [](const mcrt::vec3& p0, const mcrt::vec3& p1, const mcrt::vec3& p2, const mcrt::vec3& o,
                      mcrt::vec2 u, float& pdf) {
    return mcrt::bench::pbrt_port::sample_spherical_triangle(p0, p1, p2, o, u, pdf);
  });
}
BENCHMARK(BM_FloorPbrtSphericalTriangle);

// Polygon vertices (p1, p0, p2): Arvo's map with A = p0, B = p1, C = p2.
void BM_FloorPeters21SphericalTriangle(benchmark::State& state) {
  run_floor(state, [](const mcrt::vec3& p0, const mcrt::vec3& p1, const mcrt::vec3& p2, const mcrt::vec3& o,
                      mcrt::vec2 u, float& pdf) {
    const auto s = mcrt::bench::peters21_sa::prepare<float>(p1, p0, p2, o);
    pdf = 1.0f / s.solid_angle;
    return mcrt::bench::peters21_sa::sample<float>(s, u);
  });
}
BENCHMARK(BM_FloorPeters21SphericalTriangle);

// The same in double (the extremes program's fourth column), float in and out.
void BM_Peters21SphericalTriangleDouble(benchmark::State& state) {
  run_floor(state, [](const mcrt::vec3& p0, const mcrt::vec3& p1, const mcrt::vec3& p2, const mcrt::vec3& o,
                      mcrt::vec2 u, float& pdf) {
    const auto s = mcrt::bench::peters21_sa::prepare<double>(mcrt::dvec3(p1), mcrt::dvec3(p0), mcrt::dvec3(p2),
                                                             mcrt::dvec3(o));
    pdf = static_cast<float>(1.0 / s.solid_angle);
    return mcrt::vec3(mcrt::bench::peters21_sa::sample<double>(s, mcrt::dvec2(u)));
  });
}
BENCHMARK(BM_Peters21SphericalTriangleDouble);

// As bench::run_sample_and_pdf, with the receiver normal (0, 1, 0).
template <class Sampler>
void run_up(benchmark::State& state, const Sampler& sampler, const std::vector<mcrt::vec3>& obs) {
  const mcrt::vec3 n(0.0f, 1.0f, 0.0f);
  mcrt::pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const mcrt::vec3& o = obs[i++ & (obs.size() - 1)];
    mcrt::light_sample s;
    if (sampler.sample(o, n, rng.uniform2(), s)) benchmark::DoNotOptimize(sampler.pdf(o, n, s.dir));
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_SampleTriangleProjectedSolidAngle(benchmark::State& state) {
  const mcrt::triangle t = cornell_half_triangle();
  run_up(state, mcrt::triangle_projected_solid_angle_sampler{t}, triangle_observers(t));
}
BENCHMARK(BM_SampleTriangleProjectedSolidAngle)->Name("BM_SampleTriangleProjectedSolidAngle/Up");

void BM_SampleTriangleBilinear(benchmark::State& state) {
  const mcrt::triangle t = cornell_half_triangle();
  run_up(state, mcrt::triangle_bilinear_solid_angle_sampler{t}, triangle_observers(t));
}
BENCHMARK(BM_SampleTriangleBilinear)->Name("BM_SampleTriangleBilinear/Up");

void BM_SampleTrianglePbrt(benchmark::State& state) {
  const mcrt::triangle t = cornell_half_triangle();
  run_up(state, mcrt::triangle_pbrt_sampler{t}, triangle_observers(t));
}
BENCHMARK(BM_SampleTrianglePbrt)->Name("BM_SampleTrianglePbrt/Up");

}  // namespace
