// Cost floors of the two solid-angle maps: the least work any faithful
// implementation of each published algorithm does per sample, timed on the
// lights and observers of the other sampler benchmarks. They are not
// samplers of the library (none of them is exact at the extremes); they bound
// from below what the cost targets ask of one.
//
// BM_FloorRectSolidAngleUFK13: the spherical-rectangle sampler exactly as
//   Urena, Fajardo & King 2013 list it (sec. 4, "Algorithm 1" set-up and
//   sample), in float with the C library's float functions, with none of the
//   library's guards: no double precision, S = sum gamma_i - 2 pi (which
//   cancels for small rectangles), no fallback. The pdf 1/S comes free with
//   the sample (the pdf of a later direction from the same observer is not
//   charged), so this is sample plus pdf at its cheapest.
// BM_FloorRectSolidAngleSkeleton: the same, with acos, sin and cos replaced
//   by one-operation stand-ins: only the algorithm's square roots, divisions
//   and multiply-adds remain, a lower bound for any implementation of the
//   map whatever its elementary functions cost. Its values are meaningless.
// BM_FloorEllipseSolidAngle: what any exact map of the spherical ellipse
//   through the closed form computes per sample, with the cone reduction, the
//   Newton refinement, the map to the ellipse and the pdf's set-up counted as
//   free: Omega (complete integrals, by the AGM) and one incomplete integral
//   (one fused Carlson R_F, R_J evaluation) at the sample's first guess.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "observers.hpp"

namespace {

using namespace mcrt;

// The elementary functions of the rectangle's floors: libm's, or stand-ins.
struct libm_functions {
  static float acos(float x) { return std::acos(x); }
  static float sin(float x) { return std::sin(x); }
  static float cos(float x) { return std::cos(x); }
};
struct stand_in_functions {
  static float acos(float x) { return 1.5707964f - x; }
  static float sin(float x) { return x; }
  static float cos(float x) { return 1.0f - 0.5f * x * x; }
};

struct ufk13_rect {
  vec3 s, ex, ey, ez;
  float exl, eyl;
  explicit ufk13_rect(const rect& r)
      : s(r.corner), ex(glm::normalize(r.e1)), ey(glm::normalize(r.e2)), ez(glm::cross(ex, ey)),
        exl(glm::length(r.e1)), eyl(glm::length(r.e2)) {}
};

// Set-up of UFK13's Algorithm 1 for a rectangle with unit edge directions
// ex, ey, lengths exl, eyl, corner s, from observer o, and its sample, with
// the elementary functions F.
template <class F>
void ufk13_sample(const ufk13_rect& q, const vec3& o, vec2 u, light_sample& ls) {
  // Set-up: the local reference system and the four inner normals.
  vec3 z = q.ez;
  const vec3 d = q.s - o;
  const float x0 = glm::dot(d, q.ex), y0 = glm::dot(d, q.ey);
  float z0 = glm::dot(d, z);
  if (z0 > 0.0f) {
    z0 = -z0;
    z = -z;
  }
  const float x1 = x0 + q.exl, y1 = y0 + q.eyl;
  const vec3 v00{x0, y0, z0}, v01{x0, y1, z0}, v10{x1, y0, z0}, v11{x1, y1, z0};
  const vec3 n0 = glm::normalize(glm::cross(v00, v10)), n1 = glm::normalize(glm::cross(v10, v11));
  const vec3 n2 = glm::normalize(glm::cross(v11, v01)), n3 = glm::normalize(glm::cross(v01, v00));
  const float g0 = F::acos(-glm::dot(n0, n1)), g1 = F::acos(-glm::dot(n1, n2));
  const float g2 = F::acos(-glm::dot(n2, n3)), g3 = F::acos(-glm::dot(n3, n0));
  const float b0 = n0.z, b1 = n2.z, b0sq = b0 * b0;
  const float k = 2.0f * std::numbers::pi_v<float> - g2 - g3;
  const float solid_angle = g0 + g1 - k;
  // Sample: the u coordinate ...
  const float au = u.x * solid_angle + k;
  const float fu = (F::cos(au) * b0 - b1) / F::sin(au);
  float cu = 1.0f / std::sqrt(fu * fu + b0sq) * (fu > 0.0f ? 1.0f : -1.0f);
  cu = std::clamp(cu, -1.0f, 1.0f);
  float xu = -(cu * z0) / std::sqrt(1.0f - cu * cu);
  xu = std::clamp(xu, x0, x1);
  // ... then v.
  const float dd = std::sqrt(xu * xu + z0 * z0);
  const float h0 = y0 / std::sqrt(dd * dd + y0 * y0), h1 = y1 / std::sqrt(dd * dd + y1 * y1);
  const float hv = h0 + u.y * (h1 - h0), hv2 = hv * hv;
  const float yv = hv2 < 1.0f - 1e-6f ? hv * dd / std::sqrt(1.0f - hv2) : y1;
  // Direction, distance and pdf, as every light sample carries them.
  const vec3 v = xu * q.ex + yv * q.ey + z0 * z;
  ls.dist = glm::length(v);
  ls.dir = v / ls.dist;
  ls.pdf = 1.0f / solid_angle;
}

template <class F>
void floor_rect(benchmark::State& state) {
  const rect shape = bench::cornell_rect_light();
  const ufk13_rect q(shape);
  const std::vector<vec3> obs = bench::observers_around(shape);
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    light_sample ls;
    ufk13_sample<F>(q, obs[i++ & (obs.size() - 1)], rng.uniform2(), ls);
    benchmark::DoNotOptimize(ls);
  }
  state.SetItemsProcessed(state.iterations());
}
void BM_FloorRectSolidAngleUFK13(benchmark::State& st) { floor_rect<libm_functions>(st); }
void BM_FloorRectSolidAngleSkeleton(benchmark::State& st) { floor_rect<stand_in_functions>(st); }
BENCHMARK(BM_FloorRectSolidAngleUFK13);
BENCHMARK(BM_FloorRectSolidAngleSkeleton);

void BM_FloorEllipseSolidAngle(benchmark::State& state) {
  const std::vector<spherical_ellipse> cones = bench::canonical_cones(bench::cornell_disk_light());
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const spherical_ellipse& se = cones[i++ & (cones.size() - 1)];
    const double omega = spherical_ellipse_area(se);
    // The slice of the planar first guess psi = pi/4 (2 u - 1) (the closed
    // form's cost hardly depends on where it is evaluated).
    spherical_ellipse_slice sl;
    const double psi = 0.25 * std::numbers::pi * (2.0 * rng.uniform() - 1.0);
    fast_math::sincos_quadrant(std::abs(psi), sl.s, sl.c);
    sl.s = std::copysign(sl.s, psi);
    benchmark::DoNotOptimize(omega);
    benchmark::DoNotOptimize(spherical_ellipse_half_partial_area(se, sl));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FloorEllipseSolidAngle);

}  // namespace
