// The cost of one intersection test of each primitive type, a miss mostly
// (the case that dominates a scene's per-ray work): rays from random points
// of a box around the shape in random directions. The ratio of a type's
// cost to the rectangle's scales the rectangle's fitted c_t of
// render/rest_cost.hpp for a type the fit does not cover (triangles).
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "mcrt/mcrt.hpp"

using namespace mcrt;

namespace {

std::vector<ray> random_rays(int n) {
  pcg32 rng(3, 7);
  std::vector<ray> rays;
  for (int i = 0; i < n; ++i)
    rays.push_back({{rng.uniform() * 4 - 2, rng.uniform() * 4 - 2, rng.uniform() * 4 - 2},
                    square_to_uniform_sphere(rng.uniform2())});
  return rays;
}

template <class Shape>
void run(benchmark::State& state, const Shape& shape) {
  const std::vector<ray> rays = random_rays(4096);
  std::size_t i = 0;
  for (auto _ : state) {
    float t;
    benchmark::DoNotOptimize(shape.intersect(rays[i++ & 4095], 1e-3f, infinity, t));
  }
}

void BM_IntersectRect(benchmark::State& state) {
  run(state, rect::make({-0.5f, 0.1f, -0.4f}, {1.0f, 0.2f, 0.0f}, {0.0f, 0.0f, 0.8f}));
}
void BM_IntersectTriangle(benchmark::State& state) {
  auto mesh = std::make_shared<triangle_mesh>();
  mesh->p = {{-0.5f, 0.1f, -0.4f}, {0.5f, 0.3f, -0.4f}, {0.0f, 0.1f, 0.4f}};
  mesh->indices = {0, 1, 2};
  run(state, triangle{mesh, 0});
}
void BM_IntersectSphere(benchmark::State& state) { run(state, sphere{{0.1f, 0.2f, -0.1f}, 0.5f}); }

}  // namespace

BENCHMARK(BM_IntersectRect);
BENCHMARK(BM_IntersectTriangle);
BENCHMARK(BM_IntersectSphere);
