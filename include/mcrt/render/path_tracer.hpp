#pragma once
// Shirley's path tracer ("The Rest of Your Life", sec. 10-12), iterative:
// emission where a path meets a light's front side; at each diffuse bounce
// the next direction is drawn from the 50/50 mixture of the lights' pdf and
// the cosine pdf, and weighted by scattering pdf / mixture pdf; specular
// materials follow their ray. No heap allocation per bounce.
#include "mcrt/core/dispatch.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/render/pdf.hpp"
#include "mcrt/render/scene.hpp"

namespace mcrt {

struct path_settings {
  int max_depth = 50;  // maximum number of scattering events along a path
  // Russian roulette (Arvo & Kirk 1990) from this many scattering events on,
  // on the path's throughput as pbrt-v4 does (from the second scattering):
  // see trace_path. Unbiased; a value >= max_depth turns it off.
  int rr_depth = 1;
};

template <class Scene>
color trace_path(const Scene& sc, ray r, pcg32& rng, const path_settings& ps) {
  color radiance(0.0f), throughput(1.0f);
  for (int depth = 0;; ++depth) {
    hit_record rec;
    if (!sc.hit(r, sc.ray_epsilon, infinity, rec)) {
      radiance += throughput * sc.background;
      break;
    }
    const material& m = sc.materials[rec.material];
    if (const auto* l = std::get_if<diffuse_light>(&m)) {
      if (rec.front_face) radiance += throughput * l->emit;
      break;
    }
    if (depth == ps.max_depth) break;
    if (depth >= ps.rr_depth) {
      // Russian roulette on the throughput (as pbrt-v4): a path whose
      // throughput is below 1 survives with that probability; one at or
      // above 1 always continues, so the roulette never raises a path's
      // weight above 1 and adds no fireflies.
      const float q = std::max({throughput.r, throughput.g, throughput.b});
      if (q < 1.0f) {
        if (!(rng.uniform() < q)) break;
        throughput /= q;
      }
    }

    if (const auto* lam = std::get_if<lambertian>(&m)) {
      const vec3 n = rec.facing_normal();
      const cosine_pdf cos_pdf(n);
      const light_pdf<light> lights(sc.lights, rec.p);
      const mixture_pdf<light> mix(cos_pdf, lights);
      const float u_select = rng.uniform();
      vec3 dir;
      float p;
      if (!mix.generate(u_select, rng.uniform2(), dir, p)) break;  // zero-valued sample
      const float cos_theta = glm::dot(dir, n);
      // Below the surface the scattering pdf is 0: the path carries nothing more.
      if (!(cos_theta > 0.0f) || !(p > 0.0f)) break;
      throughput *= lam->albedo * (cos_theta * inv_pi / p);
      r = {rec.p, dir};
      continue;
    }

    specular_scatter sp;
    const bool scattered = dispatch(m, [&](const auto& mat) -> bool {
          using M = std::decay_t<decltype(mat)>;
          if constexpr (std::is_same_v<M, metal> || std::is_same_v<M, dielectric>)
            return scatter(mat, r, rec, rng, sp);
          else
            return false;
        });
    if (!scattered) break;
    throughput *= sp.attenuation;
    r = sp.r;
  }
  return radiance;
}

}  // namespace mcrt
