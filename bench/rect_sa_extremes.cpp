// The extreme cases of solid-angle rectangle sampling for the README: for
// each configuration, the exact solid angle S (50-digit Van Oosterom-Strackee,
// Boost.Multiprecision), the relative error of the estimate E[1/pdf] over
// 10^6 samples against it with its standard error, the path taken by
// rect_solid_angle_sampler (its fast path, or spherical_rectangle's map, map
// with Newton polish, or area fallback) and the worst round-trip error
// |invert(sample(u)) - u| of spherical_rectangle's map. Prints a markdown
// table.
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"

namespace {

using namespace mcrt;

double reference_solid_angle(const rect& r, const vec3& o) {
  using mp = boost::multiprecision::cpp_bin_float_50;
  struct v3 {
    mp x, y, z;
  };
  const auto dot = [](const v3& a, const v3& b) { return mp(a.x * b.x + a.y * b.y + a.z * b.z); };
  const auto cross = [](const v3& a, const v3& b) {
    return v3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  };
  const auto tri = [&](const v3& a, const v3& b, const v3& c) {
    const mp la = sqrt(dot(a, a)), lb = sqrt(dot(b, b)), lc = sqrt(dot(c, c));
    return mp(2 * atan2(abs(dot(a, cross(b, c))), la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la));
  };
  const v3 a{mp(r.corner.x) - o.x, mp(r.corner.y) - o.y, mp(r.corner.z) - o.z};
  const v3 b{a.x + r.e1.x, a.y + r.e1.y, a.z + r.e1.z}, d{a.x + r.e2.x, a.y + r.e2.y, a.z + r.e2.z};
  const v3 f{b.x + r.e2.x, b.y + r.e2.y, b.z + r.e2.z};
  return static_cast<double>(tri(a, b, f) + tri(a, f, d));
}

struct extreme_case {
  std::string name;
  rect shape;
  vec3 o;
};

}  // namespace

int main() {
  const rect unit = xy_rect(-0.5f, 0.5f, -0.5f, 0.5f, 0.0f);
  const rect square2 = xy_rect(-1.0f, 1.0f, -1.0f, 1.0f, 0.0f);
  const rect strip = xy_rect(-5000.0f, 5000.0f, -0.5f, 0.5f, 0.0f);
  std::vector<extreme_case> cases;
  // One per decade: a unit square seen obliquely (45 degrees off its axis)
  // from the distance that gives S ~ 10^-k.
  for (int k = 12; k >= 0; --k) {
    const double s = std::pow(10.0, -k);
    const double d = std::sqrt(0.7071 / s);  // S ~ A cos / d^2
    if (k > 8 && k != 10 && k != 12) continue;
    cases.push_back({"S ~ 1e-" + std::to_string(k) + " (oblique)", unit, vec3(float(0.7071 * d), 0.1f, float(0.7071 * d))});
  }
  cases.push_back({"2 pi - S ~ 1e-6 (h = 1e-7 above)", square2, {0.1f, -0.2f, 1e-7f}});
  cases.push_back({"2 pi - S ~ 1e-5 (h = 1e-6 above)", square2, {0.3f, -0.2f, 1e-6f}});
  cases.push_back({"grazing 1e-6, just outside an edge", square2, {0.3f, -1.000001f, 1e-6f}});
  cases.push_back({"grazing 1e-6, outside (sliver)", square2, {2.5f, 0.4f, 1e-6f}});
  cases.push_back({"grazing 1e-7, outside (sliver)", square2, {2.5f, 0.4f, 1e-7f}});
  cases.push_back({"aspect 1e4, overhead", strip, {0.0f, 0.0f, 1.0f}});
  cases.push_back({"aspect 1e4, side, grazing 1e-6", strip, {0.0f, -1.5f, 1e-6f}});
  cases.push_back({"aspect 1e4, end-on from 1e5", strip, {1e5f, 0.1f, 300.0f}});
  cases.push_back({"Cornell light from the floor", xz_rect(213, 343, 227, 332, 554, true), {278.0f, 1.0f, 279.5f}});
  cases.push_back({"unit square, 45 degrees, 10 sizes", unit, {7.071f, 0.1f, 7.071f}});

  constexpr int n = 1'000'000;
  std::printf("| configuration | exact S (sr) | path | rel. error of E[1/pdf] | std. error | max round trip |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const extreme_case& c : cases) {
    const double exact = reference_solid_angle(c.shape, c.o);
    const rect_solid_angle_sampler smp{c.shape};
    const spherical_rectangle sr(c.shape, c.o);
    pcg32 rng(1, 2);
    double sum = 0.0, sum2 = 0.0, rt = 0.0;
    int failed = 0;
    for (int i = 0; i < n; ++i) {
      const vec2 u = rng.uniform2();
      light_sample s;
      if (!smp.sample(c.o, u, s)) {
        ++failed;
        continue;
      }
      const double w = 1.0 / double(s.pdf);
      sum += w;
      sum2 += w * w;
      if (sr.uses_map() && i < 100'000) {
        const dvec2 v = sr.invert_offset(sr.sample_offset(u));
        rt = std::max({rt, std::abs(v.x - u.x), std::abs(v.y - u.y)});
      }
    }
    const double mean = sum / n, se = std::sqrt(std::max(sum2 / n - mean * mean, 0.0) / (n - 1));
    const char* path = smp.fast_path(c.o) ? "fast map" : !sr.uses_map() ? "area (exact pdf)" : sr.refines() ? "map + Newton" : "map";
    char rts[32] = "-";
    if (sr.uses_map()) std::snprintf(rts, sizeof rts, "%.1e", rt);
    std::printf("| %s | %.6e | %s | %+.1e | %.1e | %s |%s\n", c.name.c_str(), exact, path, mean / exact - 1.0,
                se / exact, rts, failed ? " (samples refused)" : "");
  }
  return 0;
}
