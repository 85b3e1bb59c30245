// The variance a light selection leaves at a receiver, without noise: for a
// diffuse receiver at x, light k contributes c_k (its unoccluded direct
// light: pi L_k Omega_proj+, the exact importance of render/
// light_importance.hpp), and next-event estimation that chooses k with
// probability P_k and then samples it perfectly (by projected solid angle)
// has relative variance
//     V = sum_k c_k^2 / P_k / (sum_k c_k)^2 - 1
// (0 for P_k proportional to c_k). A light with c_k > 0 and P_k = 0 is left
// to the material's sample (its share is reported as "missed").
//
//   build/mcrt_light_select_variance SCENE.pbrt [points] [seed]
//       [--receivers floor|camera]
//
// Receivers (bench/receivers.hpp): points uniform on the floor y = 0 within
// |x|, |z| < 9, normal +y (bench/many_lights.py's scenes; the default), or
// the surfaces the file's camera sees. Prints, per selection, the mean of V
// and the geometric mean over points of V / V_pbrt-bvh, and the missed share.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "pbrt/builder.hpp"
#include "receivers.hpp"

using namespace mcrt;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.pbrt [points] [seed] [--receivers floor|camera]\n", argv[0]);
    return 2;
  }
  int points = 256;
  std::uint64_t seed = 1;
  std::string kind = "floor";
  int positional = 0;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--receivers" && i + 1 < argc && (std::string(argv[i + 1]) == "floor" || std::string(argv[i + 1]) == "camera")) {
      kind = argv[++i];
    } else if (a.rfind("--", 0) != 0 && positional < 2) {
      if (positional++ == 0)
        points = std::atoi(a.c_str());
      else
        seed = std::strtoull(a.c_str(), nullptr, 10);
    } else {
      std::fprintf(stderr, "%s: unknown argument %s\n", argv[0], a.c_str());
      return 2;
    }
  }
  const pbrt::built_scene b = pbrt::load_pbrt_file(argv[1]);
  const scene& sc = b.world;
  const std::size_t n = sc.emitters.size();
  std::printf("%s: %zu emitters, %d receivers (%s)\n", argv[1], n, points, kind.c_str());
  struct choice {
    const char* name;
    light_choice how;
  };
  const choice choices[] = {{"power", light_choice::power}, {"pbrt-bvh", light_choice::pbrt_bvh}, {"bvh", light_choice::bvh}};
  std::vector<double> sum_v(3, 0.0), sum_log_ratio(3, 0.0), missed(3, 0.0);
  pcg32 rng(seed, 3);
  const std::vector<bench::receiver> receivers = bench::make_receivers(b, kind, points, rng);
  int used = 0;
  std::vector<double> c(n);
  for (const bench::receiver& rc : receivers) {
    const vec3 o = rc.o, nrm = rc.n;
    double total = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const emitter& e = sc.emitters[k];
      c[k] = std::max(exact_importance(sc.lights[e.light], e.power, o, nrm, false), 0.0);
      total += c[k];
    }
    if (!(total > 0.0)) continue;
    ++used;
    double v[3];
    for (int q = 0; q < 3; ++q) {
      const light_selection sel(sc, o, nrm, choices[q].how);
      double s2 = 0.0, miss = 0.0;
      for (std::size_t k = 0; k < n; ++k) {
        if (!(c[k] > 0.0)) continue;
        const double p = sel.probability(sc.emitters[k].light);
        if (p > 0.0)
          s2 += c[k] * c[k] / p;
        else
          miss += c[k];
      }
      const double covered = total - miss;
      v[q] = covered > 0.0 ? s2 / (covered * covered) - 1.0 : 0.0;
      sum_v[static_cast<std::size_t>(q)] += v[q];
      missed[static_cast<std::size_t>(q)] += miss / total;
    }
    for (int q = 0; q < 3; ++q) sum_log_ratio[static_cast<std::size_t>(q)] += std::log(std::max(v[q], 1e-12) / std::max(v[1], 1e-12));
  }
  std::printf("| selection | mean V | geometric mean of V / V_pbrt-bvh | missed share |\n|---|---:|---:|---:|\n");
  for (int q = 0; q < 3; ++q)
    std::printf("| %s | %.4g | %.3f | %.2e |\n", choices[q].name, sum_v[static_cast<std::size_t>(q)] / used,
                std::exp(sum_log_ratio[static_cast<std::size_t>(q)] / used), missed[static_cast<std::size_t>(q)] / used);
  return 0;
}
