// Cost of solid-angle sampling of a triangle (Arvo 1995, in the closed forms
// of sampling/spherical_triangle.hpp) against uniform area sampling of the
// same triangle (sampling/triangle_area.hpp): sample plus pdf per call, on
// the observers of the samplers' benchmark (bench/observers.hpp) around one
// half of the Cornell box light, front -y.
#include <benchmark/benchmark.h>

#include <memory>

#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"
#include "observers.hpp"

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

}  // namespace
