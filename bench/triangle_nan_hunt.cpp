// The NaN hunt of the triangle light strategies: N samples per strategy
// (default 10^9) from random configurations, eight samples each: a
// triangle of aspect up to 10^4 and size 10^-5 to 1 times its distance
// from the origin (at least 1), placed up to 10^4 from it; an observer in
// front of it at a height of 10^-7 to 10^3 times its size, over its
// interior or near it; a receiver normal uniform on the hemisphere towards
// the light. Each sample goes through the strategy's sample() and then
// pdf() of the direction returned. Counts per strategy: samples returned,
// NaN or infinite directions, distances or pdfs, returned pdfs that are not
// positive, and returned directions whose pdf() is 0 (directions that miss
// the triangle once rounded to float), the last also by the observer's
// height over the triangle's plane in decades of its size (where float
// directions miss: observers all but in the plane, whose directions graze
// it, so that a direction's rounding moves its hit point by more than the
// triangle's size). Seeded: the same N and seed give the same counts.
// Prints markdown tables; exit status 1 if any NaN or infinity was met.
//
//   build/mcrt_triangle_nan_hunt [N] [seed] [strategies: sa,psa,bilinear,pbrt,area]
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <memory>
#include <string>

#include "mcrt/core/onb.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/render/light.hpp"
#include "mcrt/sampling/bilinear_spherical_triangle.hpp"
#include "mcrt/sampling/pbrt_strategy.hpp"
#include "mcrt/sampling/projected_triangle.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"

namespace {

using namespace mcrt;

// Decades of the observer's height / the triangle's size: 1e-7 .. 1e3.
constexpr int decades = 10, lowest_decade = -7;

struct counts {
  std::uint64_t draws = 0, returned = 0, nonfinite = 0, bad_pdf = 0, zero_pdf_of_returned = 0;
  std::uint64_t returned_by[decades] = {}, zero_by[decades] = {};
};

struct configuration {
  triangle t;
  vec3 o, n;
  int decade = 0;  // of height / size
};

vec3 unit_vector(pcg32& rng) {
  const float z = 2.0f * rng.uniform() - 1.0f, phi = two_pi * rng.uniform();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

configuration random_configuration(pcg32& rng) {
  const float aspect = std::pow(10.0f, 4.0f * rng.uniform());
  const vec3 centre = unit_vector(rng) * (std::pow(10.0f, 4.0f * rng.uniform()) * (rng.uniform() < 0.25f ? 0.0f : 1.0f));
  // At least 1e-5 of the coordinates' magnitude: a smaller triangle is
  // below their float resolution (its vertices round together).
  const float size = std::max(1.0f, glm::length(centre)) * std::pow(10.0f, -5.0f * rng.uniform());
  const onb f(unit_vector(rng));
  const vec3 u = f.u, v = f.v;
  auto m = std::make_shared<triangle_mesh>();
  const float w = size, h = size / aspect;
  m->p = {centre, centre + w * u, centre + (rng.uniform() * w) * u + h * v};
  m->indices = {0, 1, 2};
  configuration c{triangle{m, 0}, vec3(0.0f), vec3(0.0f)};
  const vec3 nrm = c.t.normal();
  const float exponent = -7.0f + 10.0f * rng.uniform();
  const float height = size * std::pow(10.0f, exponent);
  vec3 foot;
  if (rng.uniform() < 0.5f) {
    const vec2 b = square_to_triangle(rng.uniform2());
    foot = b.x * m->p[0] + b.y * m->p[1] + (1.0f - b.x - b.y) * m->p[2];
  } else {
    foot = centre + (rng.uniform() - 0.5f) * 4.0f * size * u + (rng.uniform() - 0.5f) * 4.0f * size * v;
  }
  c.o = foot + height * nrm;
  c.decade = std::clamp(int(std::floor(exponent)) - lowest_decade, 0, decades - 1);
  // A receiver normal uniform on the hemisphere towards the light.
  vec3 d = unit_vector(rng);
  if (glm::dot(d, centre - c.o) < 0.0f) d = -d;
  c.n = d;
  return c;
}

template <class Sampler>
void draw(const Sampler& s, const configuration& c, vec2 u, counts& k) {
  ++k.draws;
  light_sample ls;
  // The free functions of render/light.hpp: the normal reaches the
  // strategies that use it.
  if (!mcrt::sample(s, c.o, c.n, u, ls)) return;
  ++k.returned;
  ++k.returned_by[c.decade];
  if (!std::isfinite(ls.pdf) || !all_finite(ls.dir) || !std::isfinite(ls.dist)) {
    ++k.nonfinite;
    return;
  }
  if (!(ls.pdf > 0.0f)) ++k.bad_pdf;
  const float p = mcrt::pdf(s, c.o, c.n, ls.dir);
  if (!std::isfinite(p)) ++k.nonfinite;
  if (p == 0.0f) ++k.zero_pdf_of_returned, ++k.zero_by[c.decade];
}

}  // namespace

int main(int argc, char** argv) {
  const std::uint64_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1'000'000'000ull;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  const std::string which = argc > 3 ? argv[3] : "sa,psa,bilinear,pbrt,area";
  const auto has = [&](const std::string& name) {
    for (std::size_t b = 0; b <= which.size();) {
      const std::size_t e = std::min(which.find(',', b), which.size());
      if (which.compare(b, e - b, name) == 0) return true;
      b = e + 1;
    }
    return false;
  };
  counts sa, psa, bil, pb, area;
  pcg32 rng(seed, 17);
  const auto start = std::chrono::steady_clock::now();
  // Eight samples per configuration: the set-up's cost is shared, every
  // configuration still meets each strategy.
  for (std::uint64_t i = 0; i < n; i += 8) {
    const configuration c = random_configuration(rng);
    const triangle_solid_angle_sampler s_sa(c.t);
    const triangle_projected_solid_angle_sampler s_psa(c.t);
    const triangle_bilinear_solid_angle_sampler s_bil(c.t);
    const triangle_pbrt_sampler s_pb(c.t);
    const triangle_area_sampler s_area(c.t);
    for (int j = 0; j < 8; ++j) {
      const vec2 u = rng.uniform2();
      if (has("sa")) draw(s_sa, c, u, sa);
      if (has("psa")) draw(s_psa, c, u, psa);
      if (has("bilinear")) draw(s_bil, c, u, bil);
      if (has("pbrt")) draw(s_pb, c, u, pb);
      if (has("area")) draw(s_area, c, u, area);
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("| strategy | draws | returned | NaN/Inf | pdf <= 0 | pdf() 0 on a returned direction |\n|---|---:|---:|---:|---:|---:|\n");
  const auto row = [](const char* name, const counts& k) {
    if (k.draws == 0) return;
    std::printf("| %s | %llu | %llu | %llu | %llu | %llu |\n", name, (unsigned long long)k.draws,
                (unsigned long long)k.returned, (unsigned long long)k.nonfinite, (unsigned long long)k.bad_pdf,
                (unsigned long long)k.zero_pdf_of_returned);
  };
  row("solid-angle", sa);
  row("projected-solid-angle", psa);
  row("bilinear-solid-angle", bil);
  row("pbrt", pb);
  row("area", area);
  std::printf("\nShare of returned directions whose pdf() is 0, by the observer's height over the plane / the "
              "triangle's size:\n\n| strategy |");
  for (int d = 0; d < decades; ++d) std::printf(" 1e%d-1e%d |", d + lowest_decade, d + lowest_decade + 1);
  std::printf("\n|---|");
  for (int d = 0; d < decades; ++d) std::printf("---:|");
  std::printf("\n");
  const auto shares = [](const char* name, const counts& k) {
    if (k.draws == 0) return;
    std::printf("| %s |", name);
    for (int d = 0; d < decades; ++d)
      std::printf(" %.3g %% |", k.returned_by[d] ? 100.0 * double(k.zero_by[d]) / double(k.returned_by[d]) : 0.0);
    std::printf("\n");
  };
  shares("solid-angle", sa);
  shares("projected-solid-angle", psa);
  shares("bilinear-solid-angle", bil);
  shares("pbrt", pb);
  shares("area", area);
  std::printf("\n%llu samples per strategy, seed %llu, %.1f s\n", (unsigned long long)n, (unsigned long long)seed, secs);
  return sa.nonfinite + psa.nonfinite + bil.nonfinite + pb.nonfinite + area.nonfinite == 0 ? 0 : 1;
}
