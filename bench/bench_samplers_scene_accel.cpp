// Where a scene's hierarchy starts to pay (render/scene.hpp's list_limit):
// closest hits of random rays through scenes of N random triangles and
// spheres in a unit box, tested one by one (the lists) or through the BVH
// (build_accelerator with limit 0). Run with
//   build/mcrt_bench_samplers --benchmark_filter=SceneAccel
// and compare the two at each N: the crossover sets list_limit.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "mcrt/mcrt.hpp"

using namespace mcrt;

namespace {

scene random_scene(int n, bool accelerate) {
  pcg32 rng(11, 5);
  scene sc;
  sc.materials.push_back(lambertian{});
  auto mesh = std::make_shared<triangle_mesh>();
  for (int i = 0; i < n; ++i) {
    const vec3 c{rng.uniform(), rng.uniform(), rng.uniform()};
    if (i % 2 == 0) {
      sc.add(sphere{c, 0.05f}, 0);
    } else {
      const auto k = static_cast<std::uint32_t>(mesh->p.size());
      for (int v = 0; v < 3; ++v)
        mesh->p.push_back(c + 0.1f * vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
      mesh->indices.insert(mesh->indices.end(), {k, k + 1, k + 2});
    }
  }
  for (const triangle& t : triangles_of(mesh)) sc.add(t, 0);
  if (accelerate) sc.build_accelerator(0);
  return sc;
}

void run(benchmark::State& state, bool accelerate) {
  const scene sc = random_scene(static_cast<int>(state.range(0)), accelerate);
  pcg32 rng(3, 9);
  std::vector<ray> rays;
  for (int i = 0; i < 4096; ++i)
    rays.push_back({{rng.uniform(), rng.uniform(), rng.uniform()}, square_to_uniform_sphere(rng.uniform2())});
  std::size_t i = 0;
  for (auto _ : state) {
    hit_record rec;
    benchmark::DoNotOptimize(sc.hit(rays[i++ & 4095], 1e-4f, infinity, rec));
  }
}

void BM_SceneAccelLists(benchmark::State& state) { run(state, false); }
void BM_SceneAccelBvh(benchmark::State& state) { run(state, true); }

}  // namespace

BENCHMARK(BM_SceneAccelLists)->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Arg(16)->Arg(32)->Arg(64);
BENCHMARK(BM_SceneAccelBvh)->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Arg(16)->Arg(32)->Arg(64);
