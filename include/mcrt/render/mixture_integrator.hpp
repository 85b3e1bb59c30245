#pragma once
// Shirley's estimator ("The Rest of Your Life", sec. 10-12), iterative:
// emission where a path meets a light's front side; at each diffuse bounce
// one direction from the 50/50 mixture of the lights' pdf and the cosine pdf
// (render/pdf.hpp), weighted by scattering pdf / mixture pdf; specular
// materials follow their ray. Every light of the scene takes part in the
// mixture, emitting or not (book 3's glass sphere), chosen uniformly.
//
// Dimensions (samplers/layout.hpp) at bounce b: the light-choice number
// picks the component and, rescaled, the light; the light sample feeds the
// light's strategy, the material sample the cosine pdf, whichever was
// chosen. With the independent sampler the numbers are drawn in the order of
// Shirley's code, so its images are those of the original program.
#include "mcrt/render/path.hpp"
#include "mcrt/render/pdf.hpp"

namespace mcrt {

struct mixture_integrator {
  static constexpr const char* name = "mixture";

  template <class Scene, class P>
  static color li(const Scene& sc, ray r, P& ps, const path_settings& set) {
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
      if (depth == set.max_depth) break;
      const int b = layout::bounce(depth);
      if (depth >= set.rr_depth && !survive_roulette(throughput, [&] { return ps.get1d(b + layout::roulette); }))
        break;

      if (const auto* lam = std::get_if<lambertian>(&m)) {
        const vec3 n = rec.facing_normal();
        const vec3 origin = rec.spawn_origin(n);  // the sampled directions leave on the facing side
        const cosine_pdf cos_pdf(n);
        const light_pdf<light> lights(sc.lights, origin, n);
        const mixture_pdf<light> mix(cos_pdf, lights);
        const float u_select = ps.get1d(b + layout::light_choice);
        const bool from_cosine = lights.empty() || u_select < 0.5f;
        const vec2 u = ps.get2d(b + (from_cosine ? layout::material : layout::light));
        vec3 dir;
        float p;
        if (!mix.generate(u_select, u, dir, p)) break;  // zero-valued sample
        const float cos_theta = glm::dot(dir, n);
        // Below the surface the scattering pdf is 0: the path carries nothing more.
        if (!(cos_theta > 0.0f) || !(p > 0.0f)) break;
        throughput *= lam->albedo * (cos_theta * inv_pi / p);
        r = {origin, dir};
        continue;
      }

      specular_scatter sp;
      if (!scatter_specular(m, r, rec, ps, b, sp)) break;
      throughput *= sp.attenuation;
      r = sp.r;
    }
    return radiance;
  }
};

}  // namespace mcrt
