// Derived from PSCMaps.h of C. Urena and I. Georgiev (Apache License 2.0;
// THIRD_PARTY.md has the licence's text and lists the changes). Its notice:
//
// *********************************************************************
// **
// ** Projected Spherical Cap Maps
// ** template class 'PSCMaps' (class and aux funcs declaration)
// **
// ** Copyright (C) 2018 Carlos Ureña and Iliyan Georgiev
// **
// ** Licensed under the Apache License, Version 2.0 (the "License");
// ** you may not use this file except in compliance with the License.
// ** You may obtain a copy of the License at
// **
// **    http://www.apache.org/licenses/LICENSE-2.0
// **
// ** Unless required by applicable law or agreed to in writing, software
// ** distributed under the License is distributed on an "AS IS" BASIS,
// ** WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
// ** See the License for the specific language governing permissions and
// ** limitations under the License.

// Cost floor of projected-solid-angle sphere sampling: the sampler of Urena
// & Georgiev 2018, "Stratified Sampling of Projected Spherical Caps" (EGSR
// 2018, CGF 37(4)), below [UG18], as its authors published it
// (github.com/carlos-urena/psc-sampler, PSCMaps.h, Apache-2.0), sample plus
// pdf per call on the receivers and u sequence of bench_samplers_psc.cpp
// (copied): BM_FloorSphereUG18{Above,Crossing,} against its
// BM_SampleSphereProjectedSolidAngle{Above,Crossing,}. Interleaved:
//   build/mcrt_bench_samplers --benchmark_filter=Sphere
//     --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
//
// Timed: what a renderer runs per sample following the README's usage example
// with PSCMaps<float> and the radial map, re-written as a compact C++ port
// (float, the C library's float functions): the caller's frame (vz the unit
// normal, vx the unit part of c - o orthogonal to it, vy = vz x vx), alpha =
// asin(r / d), beta = asin(h / d), h = (c - o) . n; initialize(alpha, beta,
// true); eval_map = rad_map (above the horizon varphi = pi u in the ellipse's
// disk; crossing, eval_Ar_inverse: analytic past the tangency ray, the
// parabola for lunes with L < 1e-5, else InverseNSB, Newton with a bisection
// safeguard on the area normalised by F / 2, tolerance 1e-4, at most 20
// iterations; then eval_rmin_rmax); the direction x vx + y vy + z vz, z =
// sqrt(max(0, 1 - x^2 - y^2)); the pdf z / F, F = get_area() = Omega_p (the
// projected solid angle is the area of the projection in the unit disk). The
// pdf is that one division: the pdf of a later direction is NOT recomputed
// ("pdf free", as in the rectangle floors); mcrt's benchmark calls sample()
// then pdf(), which redoes the set-up.
// Left out, each making the floor cheaper, i.e. conservative: the do_checks
// asserts (debugging aids; the header ships with do_checks = true), the
// std::function wrappers of the area and its derivative (inlined lambdas),
// the Vars<T> statics (constants), normalising n (unit, as the README's caller
// has it), the distance to the sphere (mcrt returns one, the README none).
// Kept: the clamps outside the asserts, the promotions to double (M_PI * u,
// M_PI - atan). Checked off-line against PSCMaps.h (PSCMaps<float>, -DNDEBUG,
// 8192 receivers x 4 u): F and (x, y) bit-identical with -ffp-contract=off;
// with FMA contraction F identical, (x, y) within the Newton tolerance's reach.
//
// Self-check before the first floor (SkipWithError), 205 receivers of each
// kind x 64 u, against a wrong, cheaper algorithm: the port in double, F
// against mcrt's exact Omega_p (1e-5 relative), the map against mcrt's, the
// same radial map (1e-5 sin alpha above the horizon; crossing, 5e-2, and 1e-2
// for 99% of the samples, the Newton tolerance's reach; lunes under the
// published parabola shortcut, an approximation, not compared); the float
// port: F above the horizon (1e-3), directions unit, above the horizon,
// within alpha + 1e-3 of the axis. Its F of crossing caps is only reported:
// the published float code is off by a few % for centres near the horizon
// (cos phi_l as sqrt(1 - sin^2 phi_l), phi_l -> pi/2, in eval_ArC), by orders
// of magnitude for thin lunes (L = ArC - ArE cancels).
// Counters: area_evals, InverseNSB area evaluations per sample (0 for the
// closed forms and the parabola); newton_share, the share of samples running
// InverseNSB (8 samples per receiver, the timed u sequence).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/sampling/projected_spherical_cap.hpp"
#include "observers.hpp"

namespace {

using mcrt::vec2;
using mcrt::vec3;

// The sphere and receiver sets: bench/observers.hpp (shared with bench_samplers_psc.cpp).
using mcrt::bench::cap_mix;
using mcrt::bench::sphere_receiver;

// ------------------------------------------------------------ the UG18 port
// Names in comments are PSCMaps.h's. T = float when timed (double in the
// self-check). Probe: called per area evaluation of InverseNSB (a counter in
// the statistics, a no-op when timed).
namespace ug18 {

constexpr double pi_d = std::numbers::pi;  // M_PI

// InverseNSB: t in [0, t_max] with area(t) = a_obj, area' = dens > 0, from the
// linear guess; a Newton step leaving [lo, hi] is replaced by the midpoint
// after the bracket is cut at t. Ends at |area - a| <= 1e-4 (ini_iN_tolerance)
// or after 21 steps (ini_iN_max_iters = 20).
template <class T, class Area, class Dens>
T inverse_nsb(const Area& area, const Dens& dens, T t_max, T a_obj, T a_max) {
  const T a = std::max(T(0), std::min(a_obj, a_max));
  T t = (a / a_max) * t_max, lo = 0, hi = t_max;
  for (int iters = 0;;) {
    const T diff = area(t) - a;
    if (std::abs(diff) <= T(1e-4)) break;
    T next = t + -diff / dens(t);
    if (std::isnan(next) || next < lo || hi < next) {
      (0.0 < diff ? hi : lo) = t;
      next = T(0.5) * hi + T(0.5) * lo;
    }
    t = next;
    if (20 < ++iters) break;
  }
  return t;
}

// PSCMaps<T> initialised with use_radial = true.
template <class T>
struct cap {
  static constexpr T pi = T(pi_d), half_pi = T(0.5) * pi;
  bool fully_visible = false, partially_visible = false, invisible = false, center_below_hor = false;
  T E = 0, L = 0, F = 0, sin_beta_abs = 0, cos_beta_sq = 0, xe = 0, ax = 0, ay = 0, axay2 = 0, xe_sq = 0;
  T phi_l = 0, AE_phi_l = 0;

  static T clamp(T v, T hi) { return std::max(T(0), std::min(v, hi)); }  // as check_theta

  // initialize(alpha, beta, true) with compute_ELF_xlyl_phi_l.
  void initialize(T p_alpha, T p_beta) {
    const T alpha = std::max(T(0), std::min(half_pi, p_alpha)), beta = std::max(-half_pi, std::min(half_pi, p_beta));
    E = L = F = AE_phi_l = 0;
    fully_visible = partially_visible = invisible = false;
    ay = std::sin(alpha);
    const T r1maysq = std::sqrt(T(1) - ay * ay), sin_beta = std::sin(beta);
    sin_beta_abs = std::abs(sin_beta);
    cos_beta_sq = T(1) - sin_beta * sin_beta;
    const T cos_beta = std::sqrt(cos_beta_sq);
    xe = cos_beta * r1maysq;  // the ellipse: centre (xe, 0), semi-axes ax (x), ay (y)
    ax = ay * sin_beta_abs;
    axay2 = ax * ay * T(0.5);
    xe_sq = xe * xe;
    if (ay <= sin_beta) fully_visible = true;
    else if (-ay < sin_beta) partially_visible = true;
    else invisible = true;
    center_below_hor = sin_beta < T(0);
    if (invisible) return;
    if (partially_visible) {  // the tangency point (xl, yl), its angle phi_l, the half lune L
      const T xl = r1maysq / cos_beta, yl = std::sqrt(T(1) - xl * xl);
      phi_l = std::atan2(yl, xl - xe);
      AE_phi_l = area_ellipse(phi_l);
      L = std::max(T(0), area_circle(phi_l) - AE_phi_l);
      if (!center_below_hor) E = pi * axay2;
    } else {
      E = pi * axay2;
    }
    F = T(2) * (E + L);
  }

  // eval_ArE [UG18 eq. 24]: area swept in the ellipse up to the ray at theta.
  T area_ellipse(T theta) const {
    theta = clamp(theta, pi);
    const T a = std::atan(sin_beta_abs * std::abs(std::tan(theta)));
    return theta <= half_pi ? axay2 * a : T(axay2 * (pi_d - a));
  }
  // eval_ArC [UG18 eq. 25, the published asin-saving form], theta <= phi_l.
  T area_circle(T theta) const {
    theta = clamp(theta, phi_l);
    const T z = std::sin(theta), xez = xe * z, z_sq = z * z;
    return T(0.5) *
           (theta - std::asin(xez) + xe_sq * z * std::sqrt(T(1) - z_sq) - xez * std::sqrt(T(1) - xe_sq * z_sq));
  }
  // eval_rEll, eval_rCirc: the ray's length to the ellipse, to the circle.
  T r_ellipse(T theta) const {
    const T s = std::sin(clamp(theta, pi));
    return ax / std::sqrt(T(1) - cos_beta_sq * (s * s));
  }
  T r_circle(T theta) const {
    const T s = std::sin(clamp(theta, phi_l)), s_sq = s * s;
    return std::sqrt(T(1) - xe_sq * s_sq) - xe * std::sqrt(T(1) - s_sq);
  }
  // eval_Ar and eval_rad_integrand: the area swept and its derivative.
  T area(T theta) const {
    if (fully_visible) return area_ellipse(theta);
    if (center_below_hor) return theta <= phi_l ? area_circle(theta) - area_ellipse(theta) : L;
    return theta <= phi_l ? area_circle(theta) : area_ellipse(theta) + L;
  }
  T density(T theta) const {
    if (fully_visible || (!center_below_hor && phi_l <= theta)) {
      const T re = r_ellipse(theta);
      return T(0.5) * re * re;
    }
    if (center_below_hor) {
      if (!(theta <= phi_l)) return T(0);
      const T rc = r_circle(theta), re = r_ellipse(theta);
      return T(0.5) * (rc * rc - re * re);
    }
    const T r = r_circle(theta);
    return T(0.5) * r * r;
  }
  // eval_rmin_rmax
  void radii(T theta, T& rmin, T& rmax) const {
    const T tc = std::min(theta, pi);
    const bool ellipse = fully_visible || (!center_below_hor && phi_l <= tc);
    rmin = !ellipse && center_below_hor ? r_ellipse(tc) : T(0);
    rmax = ellipse ? r_ellipse(tc) : r_circle(tc);
  }
  // eval_ArE_inverse (analytic).
  T area_ellipse_inverse(T ar) const {
    const T ang = clamp(ar, E) / axay2, t = std::atan(std::tan(ang) / sin_beta_abs);
    return ang <= half_pi ? t : pi + t;
  }
  // eval_Ar_inverse
  template <class Probe>
  T area_inverse(T ar, Probe& probe) const {
    const T half = T(0.5) * F;  // Ar_max_value
    ar = clamp(ar, half);
    if (fully_visible) return area_ellipse_inverse(ar);  // (unreachable from rad_map)
    const T frac = ar / half;
    if (!center_below_hor && AE_phi_l + L < ar) return area_ellipse_inverse(ar - L);   // past the tangency
    if (center_below_hor && L < 1e-5) return phi_l * (T(1) - std::sqrt(T(1) - frac));  // small lune: parabola
    const auto area_n = [&](T theta) {
      probe();
      return area(theta) / half;
    };
    const auto density_n = [&](T theta) { return density(theta) / half; };
    const T t_max = center_below_hor ? phi_l : pi;
    return clamp(inverse_nsb(area_n, density_n, t_max, frac, T(1)), t_max);
  }
  // eval_map = rad_map: (s, t) in [0, 1]^2 to (x, y) in the unit disk.
  template <class Probe>
  void map(T s, T t, T& x, T& y, Probe& probe) const {
    const bool neg = t < T(0.5), scaled = fully_visible;  // scaled: in the ellipse's disk
    const T u = neg ? T(1) - T(2) * t : T(2) * t - T(1);
    T varphi = T(pi_d * u), rmin = 0, rmax = 1;
    if (!scaled) {
      varphi = std::max(T(0), std::min(pi, area_inverse(u * T(0.5) * F, probe)));
      radii(varphi, rmin, rmax);
    }
    const T si = neg ? -std::sin(varphi) : std::sin(varphi);
    const T co = std::sqrt(T(1) - si * si) * (varphi <= half_pi ? T(1) : T(-1));
    const T rad = std::sqrt(s * (rmax * rmax) + (T(1) - s) * (rmin * rmin));
    x = scaled ? xe + ax * (rad * co) : xe + rad * co;
    y = scaled ? ay * (rad * si) : rad * si;
  }
};

// The README's usage example, per sample: frame, alpha, beta, initialize,
// eval_map, direction, pdf = z / area; ok false: invisible.
struct result {
  vec3 dir{0.0f};
  float pdf = 0.0f, area = 0.0f;
  bool ok = false;
};
template <class Probe>
result sample(const mcrt::sphere& sp, const vec3& o, const vec3& n, vec2 u, Probe& probe) {
  const vec3 w = sp.center - o;
  const float d = glm::length(w), h = glm::dot(w, n);
  const vec3 vz = n, vx = glm::normalize(w - h * vz), vy = glm::cross(vz, vx);
  cap<float> c;
  c.initialize(std::asin(sp.radius / d), std::asin(h / d));
  if (c.invisible) return {};
  float x, y;
  c.map(u.x, u.y, x, y, probe);
  const float z = std::sqrt(std::max(0.0f, 1.0f - x * x - y * y));
  return {x * vx + y * vy + z * vz, z / c.F, c.F, true};
}

}  // namespace ug18

// ------------------------------------------------------------ the self-check
// (see the header comment). Empty if all holds, else the first failure.
std::string ug18_self_check() {
  const mcrt::sphere sp = mcrt::bench::psc_sphere();
  const mcrt::sphere_projected_solid_angle_sampler exact{sp};
  mcrt::pcg32 rng(3, 5);
  auto probe = [] {};
  double worst_double = 0.0, worst_float[2] = {0.0, 0.0};
  int crossing = 0, crossing_off = 0, samples = 0, samples_off = 0;  // (the last two: crossing caps)
  for (const cap_mix m : {cap_mix::crossing, cap_mix::above}) {
    const std::vector<sphere_receiver> rs = mcrt::bench::sphere_receivers(m);
    const bool above = m == cap_mix::above;
    for (std::size_t i = 0; i < rs.size(); i += 20) {
      const double omega = exact.projected_solid_angle(rs[i].o, rs[i].n);
      const glm::dvec3 w = glm::dvec3(sp.center) - glm::dvec3(rs[i].o), n = glm::normalize(glm::dvec3(rs[i].n));
      const double d = glm::length(w), alpha = std::asin(sp.radius / d), h = glm::dot(w, n);
      const glm::dvec3 ex = glm::normalize(w - h * n), ey = glm::cross(n, ex);
      ug18::cap<double> cd;
      cd.initialize(alpha, std::asin(h / d));
      const double rel_double = std::abs(cd.F - omega) / omega;
      const bool parabola = cd.center_below_hor && cd.L < 1e-5;  // the published approximate map
      for (int k = 0; k < 64; ++k) {
        const vec2 u = k < 4 ? vec2(float(k & 1), float(k >> 1)) : rng.uniform2();  // the corners, then random
        const ug18::result s = ug18::sample(sp, rs[i].o, rs[i].n, u, probe);
        const glm::dvec3 dir(s.dir);
        const double rel = std::abs(s.area - omega) / omega, len = glm::length(dir), cz = glm::dot(dir, n) / len;
        const double angle = std::acos(std::clamp(glm::dot(dir, w) / (len * d), -1.0, 1.0));
        // mcrt's map is the same radial map (same halves, same orientation):
        // the double port's direction against mcrt's, in units of sin alpha.
        double x, y;
        cd.map(double(u.x), double(u.y), x, y, probe);
        const glm::dvec3 dd = x * ex + y * ey + std::sqrt(std::max(0.0, 1.0 - x * x - y * y)) * n;
        mcrt::light_sample ls;
        const bool compare = exact.sample(rs[i].o, rs[i].n, u, ls) && !parabola;
        const double off = compare ? glm::length(dd - glm::dvec3(ls.dir)) * d / sp.radius : 0.0;
        if (!s.ok || !(rel_double <= 1e-5) || (above && !(rel <= 1e-3)) || !(off <= (above ? 1e-5 : 5e-2)) ||
            !(std::abs(len - 1.0) <= 1e-4) || !(cz >= -1e-5) || !(angle <= alpha + 1e-3)) {
          char msg[300];
          std::snprintf(msg, sizeof msg,
                        "UG18 port, receiver %zu (h / r %.4f): F %.6g (double port %.6g) vs Omega_p %.6g, |dir| %.6f, "
                        "cos %.3g, angle - alpha %.3g, off mcrt's map %.3g",
                        i, h / sp.radius, s.area, cd.F, omega, len, cz, angle - alpha, off);
          return msg;
        }
        samples += !above && compare;
        samples_off += !above && off > 1e-2;
        if (k > 0) continue;
        worst_double = std::max(worst_double, rel_double);
        worst_float[above] = std::max(worst_float[above], rel);
        crossing += !above;
        crossing_off += !above && rel > 1e-3;
      }
    }
  }
  if (samples_off > samples / 100) return "UG18 port: > 1% of crossing-cap directions 1e-2 sin alpha off mcrt's";
  std::fprintf(stderr,
               "UG18 port self-check passed. F vs Omega_p, relative: double port <= %.2g; float port <= %.2g above "
               "the horizon,\n  crossing <= %.2g and > 1e-3 on %d of %d caps. Crossing directions (double port) "
               "off mcrt's by > 1e-2 sin alpha: %d of %d\n",
               worst_double, worst_float[1], worst_float[0], crossing_off, crossing, samples_off, samples);
  return {};
}

void floor_sphere_ug18(benchmark::State& state, cap_mix m) {
  static const std::string error = ug18_self_check();
  if (!error.empty()) {
    state.SkipWithError(error.c_str());
    return;
  }
  const mcrt::sphere sp = mcrt::bench::psc_sphere();
  const std::vector<sphere_receiver> rs = mcrt::bench::sphere_receivers(m);
  auto no_probe = [] {};
  mcrt::pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const sphere_receiver& r = rs[i++ & (rs.size() - 1)];
    benchmark::DoNotOptimize(ug18::sample(sp, r.o, r.n, rng.uniform2(), no_probe));
  }
  state.SetItemsProcessed(state.iterations());
  // InverseNSB's statistics, untimed: 8 samples a receiver, the same u.
  long evals = 0, newton = 0, samples = 8 * long(rs.size());
  rng = mcrt::pcg32(1, 2);
  for (long k = 0; k < samples; ++k) {
    const sphere_receiver& r = rs[std::size_t(k) & (rs.size() - 1)];
    long here = 0;
    auto count = [&here] { ++here; };
    ug18::sample(sp, r.o, r.n, rng.uniform2(), count);
    evals += here;
    newton += here > 0;
  }
  state.counters["area_evals"] = double(evals) / double(samples);
  state.counters["newton_share"] = double(newton) / double(samples);
}

void BM_FloorSphereUG18(benchmark::State& st) { floor_sphere_ug18(st, cap_mix::both); }
void BM_FloorSphereUG18Above(benchmark::State& st) { floor_sphere_ug18(st, cap_mix::above); }
void BM_FloorSphereUG18Crossing(benchmark::State& st) { floor_sphere_ug18(st, cap_mix::crossing); }
BENCHMARK(BM_FloorSphereUG18);
BENCHMARK(BM_FloorSphereUG18Above);
BENCHMARK(BM_FloorSphereUG18Crossing);

}  // namespace
