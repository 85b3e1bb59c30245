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
      if (!sc.hit(r, 0.0f, infinity, rec)) {
        radiance += throughput * sc.background;
        break;
      }
      const material* mp = &sc.materials[rec.material];
      if (const auto* l = std::get_if<diffuse_light>(mp)) {
        if (rec.front_face || l->twosided) radiance += throughput * l->emit;
        // A light of Shirley's scenes ends the path; one of a pbrt-v4 scene
        // reflects with its surface's material.
        if (l->surface == diffuse_light::no_surface) break;
        mp = &sc.materials[l->surface];
      }
      const material& m = resolve_mix(sc.materials, *mp, rec, -r.d);
      if (depth == set.max_depth) break;
      const int b = layout::bounce(depth);
      if (depth >= set.rr_depth && !survive_roulette(throughput, [&] { return ps.get1d(b + layout::roulette); }))
        break;

      color albedo;
      if (diffuse_albedo(m, rec, albedo)) {
        const vec3 n = rec.facing_shading_normal(r.d);
        const vec3 origin = rec.spawn_origin(n);  // the sampled directions leave on the facing side
        const cosine_pdf cos_pdf(n);
        const light_pdf lights(sc.lights, origin, n);
        const mixture_pdf mix(cos_pdf, lights);
        const float u_select = ps.get1d(b + layout::light_choice);
        const bool from_cosine = lights.empty() || u_select < 0.5f;
        const vec2 u = ps.get2d(b + (from_cosine ? layout::material : layout::light));
        vec3 dir;
        float p;
        if (!mix.generate(u_select, u, dir, p)) break;  // zero-valued sample
        const float cos_theta = glm::dot(dir, n);
        // Below the surface the scattering pdf is 0: the path carries nothing more.
        if (!(cos_theta > 0.0f) || !(p > 0.0f)) break;
        throughput *= albedo * (cos_theta * inv_pi / p);
        r = {origin, dir};
        continue;
      }

      // pbrt-v4's conductor and dielectric: the mixture of the lights' pdf
      // and the BSDF's own (50/50), or the BSDF alone where it is a delta.
      bool scattered = false, absorbed = false;
      with_bsdf(m, rec, [&](const auto& bsdf) {
        scattered = true;
        const shading_frame fr = shading_frame::from_normal_tangent(rec.shading_normal(), rec.dpdu);
        const vec3 wo = fr.to_local(-glm::normalize(r.d));
        const vec3 n = wo.z < 0.0f ? -fr.z : fr.z;
        // From the point moved off the surface to the side the ray came from
        // (as nee_integrator.hpp's light selection).
        const light_pdf lights(sc.lights, rec.spawn_origin(-r.d), n);
        const float u_select = ps.get1d(b + layout::light_choice);
        vec3 wi_local;
        color f;
        float p;
        if (bsdf.is_delta() || lights.empty() || u_select < 0.5f) {
          bsdf_sample bs;
          if (!bsdf.sample(wo, ps.get1d(b + layout::material_choice), ps.get2d(b + layout::material), bs) ||
              !(bs.pdf > 0.0f)) {
            absorbed = true;
            return;
          }
          wi_local = bs.wi;
          f = bs.f;
          if (lights.empty() || bsdf.is_delta()) {
            p = bs.pdf;
          } else if (bs.delta) {
            // A delta lobe of a BSDF that also has others (a smooth coat's
            // reflection over a layered base): only this branch, taken
            // with probability 1/2, finds its direction.
            p = 0.5f * bs.pdf;
          } else if (bs.pdf_is_proportional) {
            // A walk's f / pdf is the unbiased weight but its pdf is not the
            // density of wi: one-sample MIS with the balance heuristic on
            // the BSDF's pdf p~, the one the light branch divides by
            // (layered_bsdf.hpp): (f / pdf)_walk p~ / (0.5 (p~ + p_light)).
            const float pt = bsdf.pdf(wo, bs.wi);
            f *= pt / bs.pdf;
            p = 0.5f * (pt + lights.value(fr.to_world(bs.wi)));
          } else {
            p = 0.5f * (bs.pdf + lights.value(fr.to_world(bs.wi)));
          }
        } else {
          light_sample s;
          const std::ptrdiff_t k = lights.generate(2.0f * u_select - 1.0f, ps.get2d(b + layout::light), s);
          if (k < 0) {
            absorbed = true;
            return;
          }
          wi_local = fr.to_local(s.dir);
          f = bsdf.eval(wo, wi_local);
          p = 0.5f * (bsdf.pdf(wo, wi_local) + lights.value(s.dir, k, s.pdf));
        }
        if (f == color(0.0f) || !(p > 0.0f)) {
          absorbed = true;
          return;
        }
        const vec3 wi = glm::normalize(fr.to_world(wi_local));
        throughput *= f * (std::abs(wi_local.z) / p);
        r = {rec.spawn_origin(wi), wi};
      });
      if (scattered) {
        if (absorbed) break;
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
