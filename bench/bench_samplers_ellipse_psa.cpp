// Cost of the cosine-aware ellipse strategies against the spherical
// ellipse's parallel map, sample plus pdf per call, on the light and
// observers of BM_SampleEllipseSolidAngle (bench/observers.hpp: the Cornell
// disk light, 4096 observers 0.2 to 5 light sizes away in front of it):
//
//  BM_EllipsePSA_SolidAngle          ellipse_solid_angle_sampler (ignores the normal)
//  BM_EllipsePSA_Exact<normals>      ellipse_projected_solid_angle_sampler
//  BM_EllipsePSA_Bilinear<normals>   ellipse_bilinear_solid_angle_sampler
//
// Receiver normals: "Up", n = (0, 1, 0) for every observer (a floor under
// the light: the light is wholly above every horizon, no clipping);
// "Random", per observer a unit normal uniform on the hemisphere around the
// direction to the light's centre (fixed seed; the horizon clips the light
// for the fraction given by the counter "clipped"; the counter "exact" is
// the fraction of observers on which the exact sampler runs its own map
// rather than its bilinear fallback). The same observer, normal and u
// sequence for every strategy. Interleaved A/B:
//   build/mcrt_bench_samplers --benchmark_filter=EllipsePSA
//     --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/bilinear_spherical_ellipse.hpp"
#include "mcrt/sampling/projected_spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "observers.hpp"

namespace {

using namespace mcrt;

enum class normals { up, random };

std::vector<vec3> receiver_normals(const ellipse& light, const std::vector<vec3>& obs, normals kind) {
  std::vector<vec3> out;
  out.reserve(obs.size());
  pcg32 rng(5, 3);
  for (const vec3& o : obs) {
    if (kind == normals::up) {
      out.emplace_back(0.0f, 1.0f, 0.0f);
      continue;
    }
    const vec3 to_light = glm::normalize(light.center - o);
    for (;;) {
      const vec3 d{2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f};
      const float l2 = glm::dot(d, d);
      if (l2 > 1.0f || l2 < 1e-4f) continue;
      const vec3 n = d / std::sqrt(l2);
      out.push_back(glm::dot(n, to_light) >= 0.0f ? n : -n);
      break;
    }
  }
  return out;
}

// The fraction of observers whose horizon cuts the light (its lowest point
// below the horizon).
double clipped_fraction(const ellipse& e, const std::vector<vec3>& obs, const std::vector<vec3>& ns) {
  std::size_t clipped = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const dvec3 n(ns[i]);
    const double low = glm::dot(n, dvec3(e.center) - dvec3(obs[i])) -
                       std::hypot(glm::dot(n, dvec3(e.a1)), glm::dot(n, dvec3(e.a2)));
    clipped += low < 0.0;
  }
  return double(clipped) / double(obs.size());
}

double exact_fraction(const ellipse_projected_solid_angle_sampler& s, const std::vector<vec3>& obs,
                      const std::vector<vec3>& ns) {
  std::size_t exact = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) exact += s.setup(obs[i], ns[i]).mode == projected_ellipse_mode::exact;
  return double(exact) / double(obs.size());
}

// As bench::run_sample_and_pdf, with the receiver's normal.
template <class Sampler>
void run_with_normals(benchmark::State& state, const Sampler& sampler, const std::vector<vec3>& obs,
                      const std::vector<vec3>& ns) {
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & (obs.size() - 1);
    light_sample s;
    if (sampler.sample(obs[k], ns[k], rng.uniform2(), s)) benchmark::DoNotOptimize(sampler.pdf(obs[k], ns[k], s.dir));
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations());
}

const ellipse bench_light = bench::cornell_disk_light();

void BM_EllipsePSA_SolidAngle(benchmark::State& state) {
  const ellipse_solid_angle_sampler sampler{bench_light};
  bench::run_sample_and_pdf(state, sampler, bench::observers_around(sampler.shape));
}
BENCHMARK(BM_EllipsePSA_SolidAngle);

template <normals N>
void BM_EllipsePSA_Exact(benchmark::State& state) {
  const ellipse_projected_solid_angle_sampler sampler{bench_light};
  const std::vector<vec3> obs = bench::observers_around(sampler.shape);
  const std::vector<vec3> ns = receiver_normals(sampler.shape, obs, N);
  run_with_normals(state, sampler, obs, ns);
  state.counters["clipped"] = clipped_fraction(sampler.shape, obs, ns);
  state.counters["exact"] = exact_fraction(sampler, obs, ns);
}
BENCHMARK(BM_EllipsePSA_Exact<normals::up>)->Name("BM_EllipsePSA_Exact/Up");
BENCHMARK(BM_EllipsePSA_Exact<normals::random>)->Name("BM_EllipsePSA_Exact/Random");

template <normals N>
void BM_EllipsePSA_Bilinear(benchmark::State& state) {
  const ellipse_bilinear_solid_angle_sampler sampler{bench_light};
  const std::vector<vec3> obs = bench::observers_around(sampler.shape);
  const std::vector<vec3> ns = receiver_normals(sampler.shape, obs, N);
  run_with_normals(state, sampler, obs, ns);
  state.counters["clipped"] = clipped_fraction(sampler.shape, obs, ns);
}
BENCHMARK(BM_EllipsePSA_Bilinear<normals::up>)->Name("BM_EllipsePSA_Bilinear/Up");
BENCHMARK(BM_EllipsePSA_Bilinear<normals::random>)->Name("BM_EllipsePSA_Bilinear/Random");

}  // namespace
