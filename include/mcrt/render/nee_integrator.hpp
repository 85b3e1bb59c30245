#pragma once
// Next-event estimation (pbrt-v4's PathIntegrator without the BSDF-side
// weight; Veach 1997, sec. 9.2 and 10.3): at each diffuse bounce one light
// sample, checked by a shadow ray, gives the direct light, and the path
// continues with a sample of the material's pdf. Emission that continuation
// meets is not counted again; camera rays and specular bounces, which no
// light sample can reproduce, still see emission.
//
// The loop is written once, as next_event_integrator<Weights>, for this
// estimator and for mis_integrator.hpp: both are multiple importance
// sampling of two techniques (the light sample and the material's sample)
// with different weights. Here the light sample takes weight 1 wherever it
// could have drawn the direction, and the material's sample takes the rest:
// weight 1 only where no light sample reaches (an emitter that is not in the
// scene's list of lights, a direction where every light's pdf is 0), so the
// estimate stays unbiased whatever the scene holds.
//
// The shadow ray is a closest-hit query and the light sample counts the
// radiance of whatever front side of an emitter it meets first, divided by
// the density of the whole technique p_L (light_selection.hpp): correct with
// several lights, one in front of another.
//
// Dimensions (samplers/layout.hpp) at bounce b: the light choice (drawn
// only when the scene has more than one emitter), the light sample, the
// roulette, then the material sample.
#include <memory>
#include <type_traits>

#include "mcrt/render/path.hpp"

namespace mcrt {

// Weights of plain next-event estimation: the light sample where it can
// reach, the material's sample elsewhere.
struct light_sample_weights {
  // The material's sample counts emission only where no light sample reaches.
  static constexpr bool material_counts_listed_lights = false;
  static float light(const path_settings&, float p_light, float /*p_material*/) { return p_light > 0.0f ? 1.0f : 0.0f; }
  static float material(const path_settings&, float /*p_material*/, float p_light) { return p_light > 0.0f ? 0.0f : 1.0f; }
};

// One light sample from the diffuse point p (facing normal n, albedo)
// towards the light chosen by sel: the radiance it brings, times the
// lambertian BSDF and the cosine, over the technique's density, with the
// light technique's weight. Zero when nothing is chosen, the sample is
// below the surface or the shadow ray meets no emitter's front side.
template <class Weights, class Scene, class P>
color sample_direct_light(const Scene& sc, const vec3& p, const vec3& n, const color& albedo,
                          const light_selection& sel, P& ps, int b, const path_settings& set) {
  if (sel.empty()) return color(0.0f);
  float prob = 0.0f;
  const std::ptrdiff_t k = sel.pick(sel.needs_choice() ? ps.get1d(b + layout::light_choice) : 0.0f, prob);
  if (k < 0) return color(0.0f);
  light_sample s;
  if (!sample(sc.lights[static_cast<std::size_t>(k)], p, n, ps.get2d(b + layout::light), s, sel.footprint()))
    return color(0.0f);
  const float cos_theta = glm::dot(s.dir, n);
  if (!(cos_theta > 0.0f)) return color(0.0f);
  const float p_light = sel.pdf(s.dir, k, s.pdf);
  if (!(p_light > 0.0f) || !std::isfinite(p_light)) return color(0.0f);
  const color le = shadow_ray_radiance(sc, p, s.dir);
  if (le == color(0.0f)) return color(0.0f);
  const float w = Weights::light(set, p_light, cos_theta * inv_pi);
  return le * albedo * (cos_theta * inv_pi * w / p_light);
}

// One light sample from a point with a BSDF (pbrt-v4's conductor and
// dielectric, not delta): the same technique as sample_direct_light, with
// the BSDF's value f(wo, wi) |cos theta_i| in the shading frame fr and its
// own pdf in the weight; directions on either side of the surface (a rough
// dielectric transmits). The shadow ray leaves rec's point on the side of
// the direction (hit_record::spawn_origin).
template <class Weights, class Scene, class P, class Bsdf>
color sample_direct_light_bsdf(const Scene& sc, const hit_record& rec, const shading_frame& fr, const vec3& wo,
                               const Bsdf& bsdf, const light_selection& sel, P& ps, int b, const path_settings& set) {
  if (sel.empty()) return color(0.0f);
  float prob = 0.0f;
  const std::ptrdiff_t k = sel.pick(sel.needs_choice() ? ps.get1d(b + layout::light_choice) : 0.0f, prob);
  if (k < 0) return color(0.0f);
  light_sample s;
  if (!sample(sc.lights[static_cast<std::size_t>(k)], sel.point(), sel.normal(), ps.get2d(b + layout::light), s,
              sel.footprint()))
    return color(0.0f);
  const vec3 wi = fr.to_local(s.dir);
  const color f = bsdf.eval(wo, wi) * std::abs(wi.z);
  if (f == color(0.0f)) return color(0.0f);
  const float p_light = sel.pdf(s.dir, k, s.pdf);
  if (!(p_light > 0.0f) || !std::isfinite(p_light)) return color(0.0f);
  const color le = shadow_ray_radiance(sc, rec.spawn_origin(s.dir), s.dir);
  if (le == color(0.0f)) return color(0.0f);
  // The BSDF's pdf only where the weight reads it (a layered BSDF's is a
  // random walk of its own).
  const float p_material = Weights::material_counts_listed_lights ? bsdf.pdf(wo, wi) : 0.0f;
  const float w = Weights::light(set, p_light, p_material);
  return le * f * (w / p_light);
}

template <class Weights>
struct next_event_integrator {
  // What a path carries from one vertex to the next.
  struct path_state {
    color radiance{0.0f}, throughput{1.0f};
    // After a non-delta bounce: the light selection at that point and the
    // density of the direction the material sampled, for the weight of the
    // emission the direction meets.
    bool after_diffuse = false;
    light_selection prev_sel;  // read only after_diffuse, which assigns it
    float prev_p_material = 0.0f;

    // The light selection at this vertex, built where the previous vertex's
    // was: that one is read only by the emission this vertex's ray met,
    // which comes before. A selection carries bvh's memo (hundreds of
    // bytes), so it is built in place rather than copied at each vertex.
    template <class Scene>
    const light_selection& select_lights(const Scene& sc, const vec3& o, const vec3& n, light_choice how,
                                         bool both_sides = false) {
      static_assert(std::is_trivially_destructible_v<light_selection>);
      light_selection& sel = *std::construct_at(&prev_sel, sc, o, n, how, both_sides);
      sel.set_footprint(footprint);
      return sel;
    }
    // The pixel's footprint while the path is at its camera ray's first
    // surface (renderer.hpp), then nullptr.
    const auto_footprint* footprint = nullptr;
  };

  template <class Scene, class P>
  static color li(const Scene& sc, ray r, P& ps, const path_settings& set, const auto_footprint* fp = nullptr) {
    path_state st;
    st.footprint = fp;
    for (int depth = 0;; ++depth) {
      if (depth == 1) st.footprint = nullptr;
      hit_record rec;
      if (!sc.hit(r, 0.0f, infinity, rec)) {
        st.radiance += st.throughput * sc.background;
        break;
      }
      const material* mp = &sc.materials[rec.material];
      if (const auto* l = std::get_if<diffuse_light>(mp)) {
        if (rec.front_face || l->twosided) {
          const float w = st.after_diffuse ? Weights::material(set, st.prev_p_material, st.prev_sel.pdf(r.d)) : 1.0f;
          st.radiance += st.throughput * l->emit * w;
        }
        // A light of Shirley's scenes ends the path; one of a pbrt-v4 scene
        // reflects with its surface's material.
        if (l->surface == diffuse_light::no_surface) break;
        mp = &sc.materials[l->surface];
      }
      const material& m = resolve_mix(sc.materials, *mp, rec, -r.d);
      if (depth == set.max_depth) break;
      const int b = layout::bounce(depth);

      color albedo;
      if (diffuse_albedo(m, rec, albedo)) {
        const vec3 n = rec.facing_shading_normal(r.d);
        // Light samples and the continuation leave on the facing side.
        const vec3 p = rec.spawn_origin(n);
        const light_selection& sel = st.select_lights(sc, p, n, set.choose);
        st.radiance += st.throughput * sample_direct_light<Weights>(sc, p, n, albedo, sel, ps, b, set);
        if (depth >= set.rr_depth && !survive_roulette(st.throughput, [&] { return ps.get1d(b + layout::roulette); }))
          break;
        // The last scattering event of a plain next-event estimator: the
        // continuation could only meet the background or an emitter no
        // light sample reaches; when the scene has neither, it is not traced.
        if constexpr (!Weights::material_counts_listed_lights)
          if (depth + 1 == set.max_depth && sc.background == color(0.0f) && sc.unsampled_emitters == 0) break;
        const vec3 dir = cosine_pdf(n).generate(ps.get2d(b + layout::material));
        const float cos_theta = glm::dot(dir, n);
        if (!(cos_theta > 0.0f)) break;
        // f cos / p = (albedo / pi) cos / (cos / pi)
        st.throughput *= albedo;
        st.after_diffuse = true;  // st.prev_sel is sel
        st.prev_p_material = cos_theta * inv_pi;
        r = {p, dir};
        continue;
      }

      if (has_bsdf(m)) {
        if (!bsdf_vertex(sc, m, rec, depth, ps, set, st, r)) break;
        continue;
      }

      if (depth >= set.rr_depth && !survive_roulette(st.throughput, [&] { return ps.get1d(b + layout::roulette); }))
        break;
      specular_scatter sp;
      if (!scatter_specular(m, r, rec, ps, b, sp)) break;
      st.throughput *= sp.attenuation;
      st.after_diffuse = false;
      r = sp.r;
    }
    return st.radiance;
  }

  // A vertex on pbrt-v4's conductor or dielectric (has_bsdf(m)): a light
  // sample where the BSDF is not a delta, then the BSDF's own sample, which
  // becomes r. False when the path ends there (roulette, absorption).
  // Kept out of li (GCC's and Clang's noinline): the loop of Shirley's
  // materials stays small enough for its own calls to be inlined.
  template <class Scene, class P>
#if defined(__GNUC__) || defined(__clang__)
  [[gnu::noinline]]
#endif
  static bool bsdf_vertex(const Scene& sc, const material& m, const hit_record& rec, int depth, P& ps,
                          const path_settings& set, path_state& st, ray& r) {
    const int b = layout::bounce(depth);
    bool alive = false;
    with_bsdf(m, rec, [&](const auto& bsdf) {
      const shading_frame fr = shading_frame::from_normal_tangent(rec.shading_normal(), rec.dpdu);
      const vec3 wo = fr.to_local(-glm::normalize(r.d));
      // The light technique's density with the shading normal on wo's
      // side, from the point moved off the surface to the side the ray
      // came from: on an emitter's own surface, its plane's side decides
      // by more than rounding whether its own light faces the point.
      // A surface that transmits takes light from both sides of its horizon.
      constexpr bool transmits = !reflects_only<std::decay_t<decltype(bsdf)>>;
      const light_selection& sel =
          st.select_lights(sc, rec.spawn_origin(-r.d), wo.z < 0.0f ? -fr.z : fr.z, set.choose, transmits);
      if (!bsdf.is_delta())
        st.radiance += st.throughput * sample_direct_light_bsdf<Weights>(sc, rec, fr, wo, bsdf, sel, ps, b, set);
      if (depth >= set.rr_depth && !survive_roulette(st.throughput, [&] { return ps.get1d(b + layout::roulette); }))
        return;
      bsdf_sample bs;
      if (!bsdf.sample(wo, ps.get1d(b + layout::material_choice), ps.get2d(b + layout::material), bs) ||
          !(bs.pdf > 0.0f) || bs.f == color(0.0f))
        return;
      const vec3 wi = glm::normalize(fr.to_world(bs.wi));
      st.throughput *= bs.f * (std::abs(bs.wi.z) / bs.pdf);
      st.after_diffuse = !bs.delta;  // st.prev_sel is sel
      // The weight of the emission wi meets takes the BSDF's pdf, the one
      // the light sample's weight took (layered_bsdf.hpp: a walk's own pdf
      // is not the density of wi).
      if (!bs.delta)
        st.prev_p_material =
            bs.pdf_is_proportional && Weights::material_counts_listed_lights ? bsdf.pdf(wo, bs.wi) : bs.pdf;
      r = {rec.spawn_origin(wi), wi};
      alive = true;
    });
    return alive;
  }
};

struct nee_integrator : next_event_integrator<light_sample_weights> {
  static constexpr const char* name = "nee";
};

}  // namespace mcrt
