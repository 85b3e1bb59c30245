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
// With equal samples, the ratio of power's variance to a selection's is the
// efficiency that selection would gain over power if it cost no more: for
// `exact`, the most any selection blind to visibility can gain.
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

// The exact selection at a point: P_k over the scene's lights (index as in
// sc.lights), its CDF over the emitters with P_k > 0.
struct exact_selection {
  std::vector<double> prob;  // by light index
  std::vector<std::size_t> lights;
  std::vector<double> cdf;

  exact_selection(const scene& sc, const vec3& o, const vec3& n) : prob(sc.lights.size(), 0.0) {
    double total = 0.0;
    for (const emitter& e : sc.emitters) {
      const double c = std::max(exact_importance(sc.lights[e.light], e.power, o, n, false), 0.0);
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

// A selection: the renderer's (how) or the exact one (exact = true).
struct selector {
  const char* name;
  light_choice how;
  bool exact;
};

struct moments {
  double n = 0, sum = 0, sum2 = 0;
  void add(double x) { n += 1, sum += x, sum2 += x * x; }
  double mean() const { return sum / n; }
  double variance() const { return n > 1 ? std::max(0.0, (sum2 - sum * sum / n) / (n - 1)) : 0.0; }
};

double channel_mean(const color& c) { return (double(c.r) + c.g + c.b) / 3.0; }

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
                                {"exact", light_choice::power, true}};
  constexpr int ns = 4;
  // Per integrator (0 nee, 1 mis) and selection: summed over points.
  double var_sum[2][ns] = {}, mean_sum[2][ns] = {};
  double seconds[ns] = {};
  int used = 0;
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
      if (s.exact) ex.emplace(sc, o, n);
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
