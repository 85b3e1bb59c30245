// Cost of choosing a light among N: one light_selection at a receiver, a
// pick() and the density pdf() of the technique at the chosen light's
// sampled direction (what next-event estimation with MIS pays per light
// sample; the chosen triangle's own area sample, about 40 ns, included),
// per selection:
//   BM_LightSelect/<choice>/<N>   choice 0 power, 1 uniform, 2 bvh,
//                                 3 pbrt-bvh; N = 100, 10^4, 10^5 small
//                                 triangles (area-sampled) scattered over
//                                 a 18 x 3 x 18 box facing down, receivers
//                                 on the floor below, normal up.
//   BM_LightBvhBuild/<N>          building the light BVH over those N
//                                 lights' bounds (light_bvh's constructor,
//                                 its proxies included).
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "mcrt/mcrt.hpp"

namespace {

struct many {
  std::shared_ptr<mcrt::triangle_mesh> mesh = std::make_shared<mcrt::triangle_mesh>();
  mcrt::light_list lights;
  std::vector<mcrt::emitter> emitters;
  std::vector<mcrt::light_bounds> items;
  mcrt::light_bvh tree;
  std::vector<mcrt::vec3> receivers;
};

const many& scene_of(int n) {
  static std::vector<std::unique_ptr<many>> cache(8);
  const int slot = n <= 100 ? 0 : n <= 10000 ? 1 : 2;
  if (cache[static_cast<std::size_t>(slot)]) return *cache[static_cast<std::size_t>(slot)];
  auto s = std::make_unique<many>();
  mcrt::pcg32 rng(5, 5);
  const float size = 0.3f / std::sqrt(static_cast<float>(n) / 10.0f);
  for (int i = 0; i < n; ++i) {
    const mcrt::vec3 c{18.0f * (rng.uniform() - 0.5f), 0.05f + 3.0f * rng.uniform(), 18.0f * (rng.uniform() - 0.5f)};
    const auto base = static_cast<std::uint32_t>(s->mesh->p.size());
    // Counter-clockwise seen from above: the normal -y after the swap below.
    s->mesh->p.push_back(c + mcrt::vec3{-size, 0.0f, -size});
    s->mesh->p.push_back(c + mcrt::vec3{0.0f, 0.1f * size, size});
    s->mesh->p.push_back(c + mcrt::vec3{size, 0.0f, -size});
    s->mesh->indices.insert(s->mesh->indices.end(), {base, base + 1, base + 2});
  }
  for (const mcrt::triangle& t : mcrt::triangles_of(s->mesh)) {
    const bool down = t.normal().y < 0.0f;
    mcrt::light l = mcrt::triangle_area_sampler{t, !down};
    const float radiance = std::pow(10.0f, 3.0f * rng.uniform() - 1.0f);
    s->emitters.push_back({static_cast<std::uint32_t>(s->lights.size()), mcrt::pi * t.area() * radiance});
    s->lights.push_back(l);
  }
  for (const mcrt::emitter& e : s->emitters) s->items.push_back(mcrt::bounds_of(s->lights[e.light], e.power));
  s->tree = mcrt::light_bvh(s->items);
  for (int i = 0; i < 1024; ++i) s->receivers.push_back({18.0f * (rng.uniform() - 0.5f), 0.0f, 18.0f * (rng.uniform() - 0.5f)});
  cache[static_cast<std::size_t>(slot)] = std::move(s);
  return *cache[static_cast<std::size_t>(slot)];
}

void BM_LightSelect(benchmark::State& state) {
  const mcrt::light_choice how = static_cast<mcrt::light_choice>(state.range(0));
  const many& s = scene_of(static_cast<int>(state.range(1)));
  const mcrt::vec3 n{0.0f, 1.0f, 0.0f};
  mcrt::pcg32 rng(9, 9);
  std::size_t i = 0;
  for (auto _ : state) {
    const mcrt::vec3& o = s.receivers[i++ & 1023];
    const mcrt::light_selection sel(s.lights, s.emitters, &s.tree, o, n, how);
    float prob = 0.0f;
    const std::ptrdiff_t k = sel.pick(rng.uniform(), prob);
    float p = 0.0f;
    if (k >= 0) {
      mcrt::light_sample ls;
      if (mcrt::sample(s.lights[static_cast<std::size_t>(k)], o, n, rng.uniform2(), ls)) p = sel.pdf(ls.dir, k, ls.pdf);
    }
    benchmark::DoNotOptimize(p);
  }
}
BENCHMARK(BM_LightSelect)->ArgsProduct({{0, 1, 2, 3}, {100, 10000, 100000}});

void BM_LightBvhBuild(benchmark::State& state) {
  const many& s = scene_of(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const mcrt::light_bvh tree(s.items);
    benchmark::DoNotOptimize(tree.nodes().data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(s.items.size()));
}
BENCHMARK(BM_LightBvhBuild)->Arg(100)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace
