// The extreme cases of solid-angle triangle sampling, three implementations
// of Arvo's map side by side (the same map: A = p0, B = p1, C = p2):
//   mcrt     triangle_solid_angle_sampler (spherical_triangle.hpp: closed
//            forms in double, float direction out)
//   pbrt-v4  SampleSphericalTriangle as published, in float
//            (pbrt_spherical_triangle_port.inc; pbrt-v4 itself falls back to
//            area sampling below 3e-4 sr and above 6.22 sr: this is the map
//            it would use there)
//   Peters   Peters 2021's "variant of Arvo's method" for polygons as
//            published, in float (peters21_sa_port.inc)
//   Peters, double  the same in double, its direction rounded to float
// For each configuration: the exact solid angle S (50-digit Van
// Oosterom-Strackee, Boost.Multiprecision) and, per implementation, the
// relative error of its 1/pdf against S (what biases every estimate), the
// share of N samples that are NaN or whose direction misses the triangle
// (a double ray test), and the largest angle between its direction and
// Arvo's map evaluated in 50 digits at the same u (first 1000 samples),
// over the triangle's angular size sqrt(S). Prints a markdown table.
//
//   build/mcrt_triangle_sa_extremes [N]     (default 100000)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "pbrt_spherical_triangle_port.inc"
#include "peters21_sa_port.inc"
#include "support/spherical_triangle_reference.hpp"

namespace {

using namespace mcrt;

using test::arvo_reference;
using test::reference_solid_angle;

double angle_between(const dvec3& a, const dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

struct tri_case {
  std::string name;
  vec3 p0, p1, p2, o;
};

struct stats {
  double omega_error = 0.0;  // 1/pdf over S, minus 1 (from the first valid sample)
  bool have_omega = false;
  long long bad = 0;         // NaN, Inf or a zero pdf
  long long missed = 0;      // finite directions that miss the triangle
  double max_dir_error = 0.0;
};

std::string percent(long long k, long long n) {
  char buf[32];
  if (k == 0) return "0";
  std::snprintf(buf, sizeof buf, "%.2g %%", 100.0 * double(k) / double(n));
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  const long long n = argc > 1 ? std::atoll(argv[1]) : 100000;
  constexpr int n_dir = 1000;
  constexpr int kinds = 4;  // mcrt, pbrt-v4, Peters, Peters in double

  // A triangle of area ~1 (front +z), the test battery's sliver (aspect
  // 1e4) and size-3 triangle; solid angles by decade seen along the z axis,
  // where a float direction keeps its relative precision.
  const vec3 t0(-0.5f, -0.5f, 0), t1(1, -0.5f, 0), t2(-0.5f, 0.8f, 0);
  const vec3 q0(-1, -1, 0), q1(2, -1, 0), q2(-1, 2, 0);
  const vec3 s0(-0.5f, 0, 0), s1(0.5f, 0, 0), s2(0.1f, 1e-4f, 0);
  std::vector<tri_case> cases;
  for (int k : {12, 10, 8, 6, 4, 3, 2, 0}) {
    const double d = std::sqrt(0.975 / std::pow(10.0, -k));  // S ~ A / d^2 overhead
    cases.push_back({"S ~ 1e-" + std::to_string(k) + ", overhead", t0, t1, t2, {0.1f, 0.2f, float(d)}});
  }
  cases.push_back({"S ~ 1e-8, oblique (45 deg)", t0, t1, t2, {7000.0f, 0.2f, 7000.0f}});
  cases.push_back({"2 pi - S ~ 6e-7 (h = 1e-7 inside)", q0, q1, q2, {0.1f, -0.2f, 1e-7f}});
  cases.push_back({"2 pi - S ~ 6e-6 (h = 1e-6 inside)", q0, q1, q2, {0.1f, -0.2f, 1e-6f}});
  cases.push_back({"h = 3e-6 of the size, beyond an edge", q0, q1, q2, {0.3f, -1.000002f, 3e-6f}});
  cases.push_back({"h = 3e-6 of the size, beyond a vertex", q0, q1, q2, {-1.000002f, -1.000002f, 3e-6f}});
  cases.push_back({"h = 3e-6 of the size, outside", q0, q1, q2, {3.0f, 0.5f, 3e-6f}});
  cases.push_back({"sliver 1e4, overhead", s0, s1, s2, {0, 0, 0.3f}});
  cases.push_back({"sliver 1e4, overhead (order 1, 2, 0)", s1, s2, s0, {0, 0, 0.3f}});
  cases.push_back({"sliver 1e4, grazing 1e-6", s0, s1, s2, {0, -0.2f, 1e-6f}});
  cases.push_back({"sliver 1e4, end-on", s0, s1, s2, {2.0f, 0, 0.01f}});
  cases.push_back({"sliver 1e4, far (30 sizes)", s0, s1, s2, {0, 0, 30.0f}});
  cases.push_back({"Cornell half light from the floor", {343, 554, 332}, {213, 554, 227}, {343, 554, 227}, {278, 1, 279.5f}});

  std::printf("N = %lld samples per case and implementation (pcg32, seed 1); direction error over the first %d\n\n",
              n, n_dir);
  std::printf(
      "| configuration | exact S (sr) | 1/pdf ÷ S − 1: mcrt | pbrt-v4 | Peters | Peters, double | NaN or missed: mcrt | "
      "pbrt-v4 | Peters | Peters, double | max direction error / √S: mcrt | pbrt-v4 | Peters | Peters, double |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const tri_case& c : cases) {
    const dvec3 o(c.o), d0(c.p0), d1(c.p1), d2(c.p2);
    const double exact = reference_solid_angle(o, d0, d1, d2);
    const spherical_triangle st(o, d0, d1, d2);  // the double ray test
    auto mesh = std::make_shared<triangle_mesh>();
    mesh->p = {c.p0, c.p1, c.p2};
    mesh->indices = {0, 1, 2};
    triangle_solid_angle_sampler smp{triangle{mesh, 0}};
    if (!smp.faces(c.o)) smp = triangle_solid_angle_sampler{triangle{mesh, 0}, true};
    const auto peters = bench::peters21_sa::prepare<float>(c.p1, c.p0, c.p2, c.o);
    const auto peters_d = bench::peters21_sa::prepare<double>(d1, d0, d2, o);

    stats s[kinds];
    double t_hit;
    pcg32 rng(1, 2);
    for (long long i = 0; i < n; ++i) {
      const vec2 u = rng.uniform2();
      vec3 dir[kinds];
      float pdf[kinds];
      light_sample ls;
      const bool ok = smp.sample(c.o, u, ls);
      dir[0] = ok ? ls.dir : vec3(std::nanf(""));
      pdf[0] = ok ? ls.pdf : 0.0f;
      dir[1] = bench::pbrt_port::sample_spherical_triangle(c.p0, c.p1, c.p2, c.o, u, pdf[1]);
      dir[2] = bench::peters21_sa::sample<float>(peters, u);
      pdf[2] = 1.0f / peters.solid_angle;
      dir[3] = vec3(bench::peters21_sa::sample<double>(peters_d, dvec2(u)));
      pdf[3] = float(1.0 / peters_d.solid_angle);
      const dvec3 ref = i < n_dir ? arvo_reference(o, d0, d1, d2, double(u.x), double(u.y)) : dvec3(0.0);
      for (int m = 0; m < kinds; ++m) {
        const dvec3 d(dir[m]);
        if (!std::isfinite(d.x + d.y + d.z) || !(pdf[m] > 0.0f) || !std::isfinite(pdf[m])) {
          ++s[m].bad;
          continue;
        }
        if (!s[m].have_omega) s[m].omega_error = 1.0 / (double(pdf[m]) * exact) - 1.0, s[m].have_omega = true;
        if (!st.hits(d, t_hit)) ++s[m].missed;
        if (i < n_dir) s[m].max_dir_error = std::max(s[m].max_dir_error, angle_between(glm::normalize(d), ref));
      }
    }
    std::printf("| %s | %.6e |", c.name.c_str(), exact);
    for (int m = 0; m < kinds; ++m) {
      if (s[m].bad == n) std::printf(" none |");
      else std::printf(" %+.1e |", s[m].omega_error);
    }
    for (int m = 0; m < kinds; ++m) std::printf(" %s |", percent(s[m].bad + s[m].missed, n).c_str());
    for (int m = 0; m < kinds; ++m) {
      if (s[m].bad == n) std::printf(" – |");
      else std::printf(" %.1e |", s[m].max_dir_error / std::sqrt(exact));
    }
    std::printf("\n");
  }
  return 0;
}
