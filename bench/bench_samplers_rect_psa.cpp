// Cost of the cosine-aware rectangle strategies against the spherical
// rectangle, sample plus pdf per call, on the light and observers of
// BM_SampleRectSolidAngle (bench/observers.hpp: the Cornell ceiling light,
// 4096 observers 0.2 to 5 light sizes away in front of it):
//
//  BM_RectPSA_SolidAngle       rect_solid_angle_sampler (ignores the normal)
//  BM_RectPSA_Exact<normals>   rect_projected_solid_angle_sampler
//  BM_RectPSA_Bilinear<normals> rect_bilinear_solid_angle_sampler
//  BM_RectPSA_FloorPeters21<normals> Peters 2021 as published (see below)
//  BM_RectPSA_FloorPeters21WithPdf<normals> the same, its pdf charged as a second call's
//  BM_RectPSA_Peters21Exact[WithPdf]<normals> the same made exact: double, iterated to mcrt's tolerance
//
// Receiver normals: "Up", n = (0, 1, 0) for every observer (a floor under
// the light: the light is wholly above every horizon, no clipping);
// "Random", per observer a unit normal uniform on the hemisphere around the
// direction to the light's centre (fixed seed; the horizon clips the light
// for the fraction given by the counter "clipped"). The same observer,
// normal and u sequence for every strategy. Interleaved A/B:
//   build/mcrt_bench_samplers --benchmark_filter=RectPSA
//     --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/bilinear_spherical_rectangle.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "observers.hpp"

namespace {

using namespace mcrt;

enum class normals { up, random };

std::vector<vec3> receiver_normals(const rect& light, const std::vector<vec3>& obs, normals kind) {
  std::vector<vec3> out;
  out.reserve(obs.size());
  pcg32 rng(5, 3);
  for (const vec3& o : obs) {
    if (kind == normals::up) {
      out.emplace_back(0.0f, 1.0f, 0.0f);
      continue;
    }
    const vec3 to_light = glm::normalize(light.center() - o);
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

// The fraction of observers whose horizon cuts the light.
double clipped_fraction(const rect& r, const std::vector<vec3>& obs, const std::vector<vec3>& ns) {
  std::size_t clipped = 0;
  const vec3 p[4] = {r.corner, r.corner + r.e1, r.corner + r.e2, r.corner + r.e1 + r.e2};
  for (std::size_t i = 0; i < obs.size(); ++i) {
    int below = 0;
    for (const vec3& q : p) below += glm::dot(q - obs[i], ns[i]) <= 0.0f;
    clipped += below > 0;
  }
  return double(clipped) / double(obs.size());
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

void BM_RectPSA_SolidAngle(benchmark::State& state) {
  const rect_solid_angle_sampler sampler{bench::cornell_rect_light()};
  bench::run_sample_and_pdf(state, sampler, bench::observers_around(sampler.shape));
}
BENCHMARK(BM_RectPSA_SolidAngle);

template <normals N>
void BM_RectPSA_Exact(benchmark::State& state) {
  const rect_projected_solid_angle_sampler sampler{bench::cornell_rect_light()};
  const std::vector<vec3> obs = bench::observers_around(sampler.shape);
  const std::vector<vec3> ns = receiver_normals(sampler.shape, obs, N);
  run_with_normals(state, sampler, obs, ns);
  state.counters["clipped"] = clipped_fraction(sampler.shape, obs, ns);
}
BENCHMARK(BM_RectPSA_Exact<normals::up>)->Name("BM_RectPSA_Exact/Up");
BENCHMARK(BM_RectPSA_Exact<normals::random>)->Name("BM_RectPSA_Exact/Random");

template <normals N>
void BM_RectPSA_Bilinear(benchmark::State& state) {
  const rect_bilinear_solid_angle_sampler sampler{bench::cornell_rect_light()};
  const std::vector<vec3> obs = bench::observers_around(sampler.shape);
  const std::vector<vec3> ns = receiver_normals(sampler.shape, obs, N);
  run_with_normals(state, sampler, obs, ns);
  state.counters["clipped"] = clipped_fraction(sampler.shape, obs, ns);
}
BENCHMARK(BM_RectPSA_Bilinear<normals::up>)->Name("BM_RectPSA_Bilinear/Up");
BENCHMARK(BM_RectPSA_Bilinear<normals::random>)->Name("BM_RectPSA_Bilinear/Random");


// ---------------------------------------------------------------- floor
// Peters 2021, "BRDF Importance Sampling for Polygonal Lights" (ACM TOG
// 40(4)), projected-solid-angle sampling of a polygon as published with the
// paper (the author's GLSL, MomentsInGraphics/vulkan_renderer,
// src/shaders/polygon_sampling.glsl: prepare_projected_solid_angle_polygon_
// sampling and sample_projected_solid_angle_polygon with its default two
// iterations; clipping at the horizon as polygon_clipping.glsl), ported to
// C++ in float with the C library's atan, sin, cos: the rectangle's corners
// in the receiver's frame, clipped, the polygon set up and sampled, the
// direction taken back to world space. The pdf cos / Omega_proj comes free
// with the sample. None of the library's guards (float throughout, no
// fallback, Lambert's sum as is), so this bounds from below what the
// published algorithm costs per sample plus pdf on these observers.
namespace peters21 {
using real = float;
using rvec2 = glm::vec2;
using rvec3 = glm::vec3;
constexpr int iterations = 2;           // the published default
constexpr real relative_tolerance = 0;  // no early stop: the fixed count
#include "peters21_port.inc"
}  // namespace peters21

// The same algorithm made exact the way mcrt's sampler is: double
// throughout, and the solver iterated until the residual area is at most
// 1e-12 of the projected solid angle (projected_polygon.hpp's
// newton_tolerance), at most 16 iterations. What Peters' method costs when
// it is asked for what mcrt's exact sampler delivers.
namespace peters21_exact {
using real = double;
using rvec2 = glm::dvec2;
using rvec3 = glm::dvec3;
constexpr int iterations = 16;
constexpr real relative_tolerance = 1e-12;
#include "peters21_port.inc"
}  // namespace peters21_exact

// sample + pdf of Peters 2021 as published (see above) on the observers.
// With charge_pdf (BM_RectPSA_FloorPeters21WithPdf) the pdf of the sampled
// direction is charged as a second call from the same receiver would pay it,
// as the library's pdf() does: the clip and the polygon's set-up again (its
// projected solid angle), then cos / Omega_proj. Not the published usage (a
// shader prepares once per shading point and reuses the set-up for the light
// sample and the BSDF direction's pdf), but the like-for-like counterpart of
// sample() + pdf() through a stateless interface. Api: peters21::api (as
// published) or peters21_exact::api (double, iterated to mcrt's tolerance);
// the counter "evals" is the solver's area evaluations per sample.
// Self-check of the exact port before its first benchmark: on every 16th
// observer, both normal sets, 16 samples each, its projected solid angle
// against mcrt's exact one (cos / pdf of mcrt's sampler, 1e-5 relative: the
// float pdf), each sample's direction unit, above the horizon and through
// the light, and no solver out of iterations. Empty if all holds.
std::string peters21_exact_self_check() {
  const rect light = bench::cornell_rect_light();
  const std::vector<vec3> obs = bench::observers_around(light);
  const rect_projected_solid_angle_sampler mcrt_psa{light};
  pcg32 rng(7, 9);
  peters21_exact::unconverged = 0;
  double worst = 0.0;
  for (const normals kind : {normals::up, normals::random}) {
    const std::vector<vec3> ns = receiver_normals(light, obs, kind);
    for (std::size_t k = 0; k < obs.size(); k += 16) {
      const peters21_exact::frame f{glm::normalize(glm::dvec3(ns[k]))};  // unit in double
      glm::dvec3 v[peters21_exact::max_vertices];
      const int count = peters21_exact::clip(light, glm::dvec3(obs[k]), f, v);
      if (count == 0) continue;
      const peters21_exact::polygon p = peters21_exact::prepare(count, v);
      for (int j = 0; j < 16; ++j) {
        const glm::dvec3 dir = f.to_world(peters21_exact::sample(p, glm::dvec2(rng.uniform2())));
        const vec3 d(dir);
        const double cz = glm::dot(dir, f.n);
        const float pdf = mcrt_psa.pdf(obs[k], ns[k], d);
        hit_record rec;
        const bool hits = light.hit(ray{obs[k], d}, 1e-4f, infinity, rec);
        if (!(std::abs(glm::length(dir) - 1.0) <= 1e-9) || !(cz >= -1e-9) || !hits || !(pdf > 0.0f)) {
          char msg[200];
          std::snprintf(msg, sizeof msg, "Peters 2021 exact port, observer %zu: |dir| %.12f, cos %.3g, hits %d, pdf %g", k,
                        glm::length(dir), cz, int(hits), double(pdf));
          return msg;
        }
        const double rel = std::abs(p.psa - cz / pdf) / p.psa;
        worst = std::max(worst, rel);
        if (!(rel <= 1e-5)) {
          char msg[200];
          std::snprintf(msg, sizeof msg, "Peters 2021 exact port, observer %zu: Omega_proj %.9g, mcrt's %.9g", k, p.psa,
                        cz / pdf);
          return msg;
        }
      }
    }
  }
  if (peters21_exact::unconverged) return "Peters 2021 exact port: a solver ran out of iterations";
  std::fprintf(stderr, "Peters 2021 exact port self-check passed: Omega_proj within %.2g of mcrt's\n", worst);
  return {};
}

template <class Api, normals N, bool charge_pdf>
void BM_RectPSA_FloorPeters21(benchmark::State& state) {
  if constexpr (std::is_same_v<Api, peters21_exact::api>) {
    static const std::string error = peters21_exact_self_check();
    if (!error.empty()) {
      state.SkipWithError(error.c_str());
      return;
    }
  }
  using V3 = typename Api::vec3_type;
  using V2 = typename Api::vec2_type;
  const rect light = bench::cornell_rect_light();
  const std::vector<vec3> obs = bench::observers_around(light);
  const std::vector<vec3> ns = receiver_normals(light, obs, N);
  pcg32 rng(1, 2);
  std::size_t i = 0;
  long long samples = 0;
  Api::evaluations() = 0;
  // The normals in the port's precision (unit to double precision for the
  // exact port: its frame must be orthonormal to that precision).
  std::vector<V3> nv;
  for (const vec3& n : ns) nv.push_back(std::is_same_v<V3, vec3> ? V3(n) : glm::normalize(V3(n)));
  for (auto _ : state) {
    const std::size_t k = i++ & (obs.size() - 1);
    const typename Api::frame_type f{nv[k]};
    V3 v[Api::vertices];
    const int count = Api::clip_rect(light, V3(obs[k]), f, v);
    if (count == 0) continue;
    const typename Api::polygon_type p = Api::prepare_polygon(count, v);
    const V3 local = Api::sample_polygon(p, V2(rng.uniform2()));
    const V3 dir = f.to_world(local);
    ++samples;
    benchmark::DoNotOptimize(dir);
    if constexpr (charge_pdf) {
      const typename Api::frame_type f2{nv[k]};
      V3 v2[Api::vertices];
      const int count2 = Api::clip_rect(light, V3(obs[k]), f2, v2);
      if (count2 == 0) continue;
      const typename Api::polygon_type p2 = Api::prepare_polygon(count2, v2);
      benchmark::DoNotOptimize(glm::dot(dir, nv[k]) / p2.psa);
    } else {
      benchmark::DoNotOptimize(local.z / p.psa);
    }
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["evals"] = samples ? double(Api::evaluations()) / double(samples) : 0.0;
}
BENCHMARK(BM_RectPSA_FloorPeters21<peters21::api, normals::up, false>)->Name("BM_RectPSA_FloorPeters21/Up");
BENCHMARK(BM_RectPSA_FloorPeters21<peters21::api, normals::random, false>)->Name("BM_RectPSA_FloorPeters21/Random");
BENCHMARK(BM_RectPSA_FloorPeters21<peters21::api, normals::up, true>)->Name("BM_RectPSA_FloorPeters21WithPdf/Up");
BENCHMARK(BM_RectPSA_FloorPeters21<peters21::api, normals::random, true>)->Name("BM_RectPSA_FloorPeters21WithPdf/Random");
BENCHMARK(BM_RectPSA_FloorPeters21<peters21_exact::api, normals::up, false>)->Name("BM_RectPSA_Peters21Exact/Up");
BENCHMARK(BM_RectPSA_FloorPeters21<peters21_exact::api, normals::random, false>)->Name("BM_RectPSA_Peters21Exact/Random");
BENCHMARK(BM_RectPSA_FloorPeters21<peters21_exact::api, normals::up, true>)->Name("BM_RectPSA_Peters21ExactWithPdf/Up");
BENCHMARK(BM_RectPSA_FloorPeters21<peters21_exact::api, normals::random, true>)->Name("BM_RectPSA_Peters21ExactWithPdf/Random");

}  // namespace
