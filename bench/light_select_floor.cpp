// How far each light selection is from the best that a selection blind to
// visibility can do: the variance of the direct light's estimate at diffuse
// receivers, with visibility, the lights' own samplers and (for mis) the
// material's sample, under
//   - power, pbrt-bvh and bvh, the renderer's selections (render/
//     light_selection.hpp), and
//   - exact: P_k = c_k / sum_j c_j, c_k light k's exact unoccluded
//     contribution (pi L_k Omega_proj+, render/light_importance.hpp), the
//     selection that makes next-event estimation's choice of light noise-
//     free where nothing is occluded (bench/light_select_variance.cpp: its
//     V is 0). It costs O(N) per point and per density, so it is a floor
//     to compare with, not a selection to render with.
//   - exact-m2: P_k proportional to the square root of light k's own
//     second moment (Veach 1997, sec. 9.2), which weighs each light's own
//     sampling noise as well as its contribution: the best one-sample
//     selection for nee blind to visibility;
//   - exact-mis: the `exact` P_k re-chosen, for the 32 largest, to minimise
//     the unoccluded variance of mis's light and material samples together
//     (optimise_mis below): a selection that gives a light the material's
//     samples already cover less of the light's.
// With equal samples, the ratio of power's variance to a selection's is the
// efficiency that selection would gain over power if it cost no more: for
// the exact ones, about the most a selection blind to visibility can gain.
//
// The estimators are the renderer's (render/nee_integrator.hpp) at one
// vertex: nee takes one light sample, f cos / (pi p_L(dir)), p_L the
// density of the whole technique (sum_k P_k p_k); mis adds one cosine-
// weighted material sample, both weighted by the power heuristic as
// `--integrator mis` does. A white lambertian receiver, so each estimate is
// the radiance it reflects.
//
//   build/mcrt_light_select_floor SCENE.pbrt [--points P] [--samples S]
//       [--seed K] [--light-sampling area|solid-angle]
//       [--receivers floor|camera]
//
// Receivers (bench/receivers.hpp): points uniform on the floor y = 0
// within |x|, |z| < 9, normal +y (bench/many_lights.py's scenes; the
// default), or the surfaces the file's camera sees; points whose every estimate is 0
// (under a box) are left out. Prints per integrator and selection the mean
// over points of the variance of one estimate, its ratio to power's, and
// the mean estimate (the same for every selection up to noise: a check).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "pbrt/builder.hpp"
#include "receivers.hpp"

using namespace mcrt;

namespace {

double channel_mean(const color& c) { return (double(c.r) + c.g + c.b) / 3.0; }

// A seed for the numbers drawn at the receiver o (its position, hashed).
std::uint64_t point_hash(const vec3& o) { return std::uint64_t(std::abs(o.x) * 1e6f + std::abs(o.z) * 1e3f); }

// One sample of a light's own sampler at o (normal n), unoccluded: its
// estimate f / p_k = L cos+ / (pi p_k) and p_b / p_k, p_b = cos+ / pi the
// material's cosine density; both 0 where the sampler offers nothing or the
// direction is below the horizon.
struct light_draw {
  double f_over_p = 0.0, pb_over_p = 0.0;
};

// side x side stratified samples of light l (side = floor(sqrt(samples))),
// radiance its luminance.
std::vector<light_draw> light_draws(light_ref l, double radiance, const vec3& o, const vec3& n, int samples,
                                    pcg32& rng) {
  const int side = std::max(1, static_cast<int>(std::sqrt(double(samples))));
  std::vector<light_draw> out;
  out.reserve(static_cast<std::size_t>(side * side));
  for (int a = 0; a < side; ++a)
    for (int b = 0; b < side; ++b) {
      const vec2 u{(float(a) + rng.uniform()) / float(side), (float(b) + rng.uniform()) / float(side)};
      light_sample ls;
      light_draw d;
      if (sample(l, o, n, u, ls) && ls.pdf > 0.0f) {
        const double cs = glm::dot(ls.dir, n);
        if (cs > 0.0) d = {radiance * cs * inv_pi / double(ls.pdf), cs * inv_pi / double(ls.pdf)};
      }
      out.push_back(d);
    }
  return out;
}

// The exact selection at a point: P_k over the scene's lights (index as in
// sc.lights), its CDF over the emitters with P_k > 0.
struct exact_selection {
  std::vector<double> prob;  // by light index
  std::vector<std::size_t> lights;
  std::vector<double> cdf;

  // second_moment: P_k proportional to the square root of the second moment
  // of light k's own unoccluded estimate L cos+ / (pi p_k) (from
  // `m2_samples` of its sampler's stratified samples, light_draws), the
  // selection that minimises the one-sample estimate's variance when each
  // light's own noise counts (Veach 1997, sec. 9.2: p_k ~ sqrt(E[f_k^2 /
  // p_k])). radiance_of: each light's luminance, as exact_importance takes it.
  exact_selection(const scene& sc, const vec3& o, const vec3& n, const std::vector<double>& radiance_of,
                  bool second_moment = false, int m2_samples = 64)
      : prob(sc.lights.size(), 0.0) {
    double total = 0.0;
    pcg32 m2_rng(0x9e3779b97f4a7c15ull ^ point_hash(o), 5);
    for (const emitter& e : sc.emitters) {
      double c = std::max(exact_importance(sc.lights[e.light], e.power, o, n, false), 0.0);
      if (second_moment && c > 0.0) {
        const std::vector<light_draw> d = light_draws(sc.lights[e.light], radiance_of[e.light], o, n, m2_samples, m2_rng);
        double m2 = 0.0;
        for (const light_draw& x : d) m2 += x.f_over_p * x.f_over_p;
        c = std::sqrt(m2 / double(d.size()));
      }
      if (!(c > 0.0)) continue;
      prob[e.light] += c;
      lights.push_back(e.light);
      total += c;
      cdf.push_back(total);
    }
    if (!(total > 0.0)) return;
    for (double& p : prob) p /= total;
    for (double& c : cdf) c /= total;
  }

  // mis: re-chooses the `top` largest P_k to minimise the one-sample mis
  // estimate's unoccluded variance, sum_k V_k(P_k) with
  //   V_k(P) = E_{p_k}[(f w_l / p_k)^2] / P + E_{p_b}[1_k (L w_b)^2],
  // w_l = (P p_k)^2 / ((P p_k)^2 + p_b^2) and w_b = 1 - w_l (power
  // heuristic, lights apart in direction), p_b = cos / pi, both expectations
  // from `samples` of light k's sampler (the second by p_b / p_k). The
  // others keep their share. Lagrange: V_k'(P_k) = -lambda, by bisection on
  // lambda and a search on log P per light.
  void optimise_mis(const scene& sc, const vec3& o, const vec3& n, const std::vector<double>& radiance_of,
                    int top = 32, int samples = 256) {
    if (lights.empty()) return;
    std::vector<std::size_t> order = lights;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return prob[a] > prob[b]; });
    order.resize(std::min<std::size_t>(order.size(), static_cast<std::size_t>(top)));
    double budget = 0.0;
    for (const std::size_t k : order) budget += prob[k];
    std::vector<std::vector<light_draw>> t(order.size());
    pcg32 rng(0x51ed27u ^ point_hash(o), 9);
    for (std::size_t i = 0; i < order.size(); ++i)
      t[i] = light_draws(sc.lights[order[i]], radiance_of[order[i]], o, n, samples, rng);
    const auto v = [&](std::size_t i, double P) {
      const double l2 = radiance_of[order[i]] * radiance_of[order[i]];
      double s = 0.0;
      for (const light_draw& x : t[i]) {
        if (x.f_over_p == 0.0) continue;
        // w_l = P^2 / (P^2 + r^2), r = p_b / p_k.
        const double r = x.pb_over_p, w = P * P / (P * P + r * r);
        s += x.f_over_p * x.f_over_p * w * w / P + l2 * (1.0 - w) * (1.0 - w) * r;
      }
      return s / double(t[i].size());
    };
    const auto best_p = [&](std::size_t i, double lambda) {
      double lo = std::log(1e-7), hi = std::log(budget);
      for (int it = 0; it < 60; ++it) {
        const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
        const double f1 = v(i, std::exp(m1)) + lambda * std::exp(m1), f2 = v(i, std::exp(m2)) + lambda * std::exp(m2);
        if (f1 < f2) hi = m2; else lo = m1;
      }
      return std::exp(0.5 * (lo + hi));
    };
    double llo = 1e-12, lhi = 1e12;
    std::vector<double> p(order.size());
    for (int it = 0; it < 60; ++it) {
      const double lambda = std::sqrt(llo * lhi);
      double sum = 0.0;
      for (std::size_t i = 0; i < order.size(); ++i) sum += (p[i] = best_p(i, lambda));
      if (sum > budget) llo = lambda; else lhi = lambda;
    }
    double sum = 0.0;
    for (const double x : p) sum += x;
    for (std::size_t i = 0; i < order.size(); ++i) prob[order[i]] = p[i] * budget / sum;
    double c = 0.0;
    for (std::size_t i = 0; i < lights.size(); ++i) cdf[i] = (c += prob[lights[i]]);
    for (double& x : cdf) x /= c;
  }
  bool empty() const { return lights.empty(); }
  std::ptrdiff_t pick(double u, double& p) const {
    const auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
    const std::size_t i = std::min(static_cast<std::size_t>(it - cdf.begin()), lights.size() - 1);
    p = prob[lights[i]];
    return static_cast<std::ptrdiff_t>(lights[i]);
  }
  // p_L(dir) = sum_k P_k p_k(o, dir), over every light (brute force).
  double pdf(const scene& sc, const vec3& o, const vec3& n, const vec3& dir) const {
    double s = 0.0;
    for (const std::size_t k : lights) s += prob[k] * double(mcrt::pdf(sc.lights[k], o, n, dir));
    return s;
  }
};

// A selection: the renderer's (how) or an exact one (exact = true;
// second_moment: by each light's own second moment; mis_optimal: re-chosen
// for mis, optimise_mis).
struct selector {
  const char* name;
  light_choice how;
  bool exact;
  bool second_moment = false;
  bool mis_optimal = false;
};

struct moments {
  double n = 0, sum = 0, sum2 = 0;
  void add(double x) { n += 1, sum += x, sum2 += x * x; }
  double mean() const { return sum / n; }
  double variance() const { return n > 1 ? std::max(0.0, (sum2 - sum * sum / n) / (n - 1)) : 0.0; }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: %s SCENE.pbrt [--points P] [--samples S] [--seed K] [--light-sampling area|solid-angle] [--receivers floor|camera]\n",
                 argv[0]);
    return 2;
  }
  int points = 128, samples = 256;
  std::uint64_t seed = 1;
  std::string kind = "floor";
  pbrt::build_options options;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--points") points = std::atoi(value.c_str());
    else if (flag == "--samples") samples = std::atoi(value.c_str());
    else if (flag == "--seed") seed = std::strtoull(value.c_str(), nullptr, 10);
    else if (flag == "--light-sampling" && value == "solid-angle") options.strategy = light_sampling::solid_angle;
    else if (flag == "--light-sampling" && value == "area") options.strategy = light_sampling::area;
    else if (flag == "--receivers" && (value == "floor" || value == "camera")) kind = value;
    else {
      std::fprintf(stderr, "%s: unknown option %s %s\n", argv[0], flag.c_str(), value.c_str());
      return 2;
    }
  }
  const pbrt::built_scene b = pbrt::load_pbrt_file(argv[1], options);
  const scene& sc = b.world;
  std::printf("%s: %zu emitters, %d receivers (%s), %d samples each\n", argv[1], sc.emitters.size(), points,
              kind.c_str(), samples);
  const selector selectors[] = {{"power", light_choice::power, false},
                                {"pbrt-bvh", light_choice::pbrt_bvh, false},
                                {"bvh", light_choice::bvh, false},
                                {"exact", light_choice::power, true},
                                {"exact-m2", light_choice::power, true, true},
                                {"exact-mis", light_choice::power, true, false, true}};
  constexpr int ns = 6;
  // Per integrator (0 nee, 1 mis) and selection: summed over points.
  double var_sum[2][ns] = {}, mean_sum[2][ns] = {};
  double seconds[ns] = {};
  int used = 0;
  std::vector<double> radiance_of(sc.lights.size(), 0.0);  // luminance by light (exact_importance's)
  for (const emitter& e : sc.emitters)
    radiance_of[e.light] =
        double(e.power) / (pi * dispatch(sc.lights[e.light], [](const auto& l) { return double(surface_area(l.shape)); }));
  pcg32 point_rng(seed, 7);
  const std::vector<bench::receiver> receivers = bench::make_receivers(b, kind, points, point_rng, 1e-4f);
  for (int i = 0; i < static_cast<int>(receivers.size()); ++i) {
    const vec3 o = receivers[static_cast<std::size_t>(i)].o, n = receivers[static_cast<std::size_t>(i)].n;
    const onb frame(n);  // the material's samples about n
    moments m[2][ns];
    for (int q = 0; q < ns; ++q) {
      const auto start = std::chrono::steady_clock::now();
      const selector& s = selectors[q];
      pcg32 rng(seed * 1000003u + static_cast<std::uint64_t>(i), 11);  // the same numbers for every selection
      const light_selection sel(sc, o, n, s.how);
      std::optional<exact_selection> ex;
      if (s.exact) ex.emplace(sc, o, n, radiance_of, s.second_moment);
      if (s.mis_optimal) ex->optimise_mis(sc, o, n, radiance_of);
      const auto p_light = [&](const vec3& dir, std::ptrdiff_t k, float pk) {
        return ex ? ex->pdf(sc, o, n, dir) : double(sel.pdf(dir, k, pk));
      };
      for (int j = 0; j < samples; ++j) {
        const float u0 = rng.uniform();
        const vec2 ul{rng.uniform(), rng.uniform()}, ub{rng.uniform(), rng.uniform()};
        double f_light = 0.0, f_light_mis = 0.0, f_material = 0.0;
        // The light sample.
        double prob = 0.0;
        float probf = 0.0f;
        std::ptrdiff_t k = -1;
        if (ex) {
          if (!ex->empty()) k = ex->pick(u0, prob);
        } else if (!sel.empty()) {
          k = sel.pick(sel.needs_choice() ? u0 : 0.0f, probf);
        }
        light_sample ls;
        if (k >= 0 && sample(sc.lights[static_cast<std::size_t>(k)], o, n, ul, ls)) {
          const float c = glm::dot(ls.dir, n);
          const double pl = c > 0.0f ? p_light(ls.dir, k, ls.pdf) : 0.0;
          if (pl > 0.0 && std::isfinite(pl)) {
            const double le = channel_mean(shadow_ray_radiance(sc, o, ls.dir));
            const double f = le * c * inv_pi;
            f_light = f / pl;
            f_light_mis = f * power_heuristic(float(pl), c * inv_pi) / pl;
          }
        }
        // The material's sample (cosine-weighted), for mis.
        const vec3 dir = glm::normalize(frame.to_world(square_to_cosine_hemisphere(ub)));
        hit_record rec;
        if (sc.hit(ray{o, dir}, 0.0f, infinity, rec)) {
          const double le = channel_mean(emitted(sc.materials[rec.material], rec));
          if (le > 0.0) {
            const float pb = square_to_cosine_hemisphere_pdf(frame.to_local(dir));
            const double pl = p_light(dir, -1, 0.0f);
            f_material = le * power_heuristic(pb, float(pl));
          }
        }
        m[0][q].add(f_light);
        m[1][q].add(f_light_mis + f_material);
      }
      seconds[q] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    if (!(m[0][0].mean() > 0.0 || m[1][0].mean() > 0.0)) continue;
    ++used;
    for (int t = 0; t < 2; ++t)
      for (int q = 0; q < ns; ++q) var_sum[t][q] += m[t][q].variance(), mean_sum[t][q] += m[t][q].mean();
  }
  std::printf("%d receivers lit\n\n", used);
  std::printf("| integrator | selection | mean variance of one estimate | power / this | mean estimate | seconds |\n");
  std::printf("|---|---|---:|---:|---:|---:|\n");
  const char* integrators[] = {"nee", "mis"};
  for (int t = 0; t < 2; ++t)
    for (int q = 0; q < ns; ++q)
      std::printf("| %s | %s | %.4g | %.2f | %.5g | %.2f |\n", integrators[t], selectors[q].name, var_sum[t][q] / used,
                  var_sum[t][0] / var_sum[t][q], mean_sum[t][q] / used, seconds[q]);
  return 0;
}
