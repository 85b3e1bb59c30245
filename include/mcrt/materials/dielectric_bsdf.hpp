#pragma once
// Glass and other dielectric interfaces, after pbrt-v4 (4th ed.):
//  - dielectric_bsdf, pbrt-v4's DielectricBxDF: smooth (sec. 9.5) when
//    eta == 1 or the distribution is effectively smooth, a pair of delta
//    lobes, specular reflection and refraction chosen with probabilities
//    R / (R + T) and T / (R + T); rough (sec. 9.7) otherwise, microfacet
//    reflection and transmission with the generalized half vector
//    (Walter et al. 2007, "Microfacet Models for Refraction through Rough
//    Surfaces", eqs. 16, 17, 20, 21).
//  - thin_dielectric_bsdf, pbrt-v4's ThinDielectricBxDF (sec. 9.5.1): a thin
//    slab, reflection or straight pass-through, all its internal bounces
//    summed; delta lobes only.
// Conventions of bsdf_sample.hpp. eta is the RELATIVE IOR, inside (below
// the shading normal) over outside; wo below the surface sees 1 / eta.
//
// Rough lobes (pbrt-v4 sec. 9.7; Walter et al. 2007). For wi on wo's side,
// wm = normalize(wo + wi); across the surface, with etap the relative IOR
// along the ray (the index on wi's side over wo's: eta if wo is outside,
// 1 / eta if inside), the generalized half vector wm = normalize(wo + etap wi)
// (Walter et al. eq. 16), faced to +z. Microfacets that face away from wo or
// wi are discarded. With F = fresnel_dielectric(wo . wm, eta):
//   reflection:   f = D(wm) G(wo, wi) F / (4 |cos theta_i cos theta_o|)      (eq. 20)
//                 pdf = D_wo(wm) / (4 |wo . wm|) * R / (R + T)
//   transmission: f = D(wm) G(wo, wi) (1 - F) |wi . wm| |wo . wm|
//                     / (|cos theta_i cos theta_o| (wi . wm + wo . wm / etap)^2)   (eq. 21)
//                     [/ etap^2 in radiance mode, pbrt-v4 sec. 9.5.2]
//                 pdf = D_wo(wm) |wi . wm| / (wi . wm + wo . wm / etap)^2 * T / (R + T)
// where |wi . wm| / (wi . wm + wo . wm / etap)^2 = d(omega_m) / d(omega_i) is
// the Jacobian of the refraction map (eq. 17), and R = F, T = 1 - F at that
// microfacet; pdfs per unit solid angle of wi.
//
// Generalized reciprocity of the transmission lobe (derived in
// tests/test_bsdfs.cpp; Veach 1997, thesis sec. 5.2): with etap = etap(wo -> wi),
//   radiance mode:   f(wi, wo) = etap^2 f(wo, wi),
//   importance mode: f(wi, wo) = f(wo, wi) / etap^2,
//   and f_radiance(wi, wo) = f_importance(wo, wi) (the adjoint BSDF).
#include <algorithm>
#include <cmath>

#include "mcrt/core/math.hpp"
#include "mcrt/materials/bsdf_sample.hpp"
#include "mcrt/materials/fresnel.hpp"
#include "mcrt/materials/shading_frame.hpp"
#include "mcrt/materials/trowbridge_reitz.hpp"

namespace mcrt {

struct dielectric_bsdf {
  float eta = 1.5f;  // relative IOR, inside over outside
  trowbridge_reitz distrib;

  // Delta lobes only: eta == 1 (the interface is invisible: straight
  // pass-through however rough) or a smooth interface.
  bool is_delta() const { return eta == 1.0f || distrib.effectively_smooth(); }

  color eval(const vec3& wo, const vec3& wi, transport_mode mode = transport_mode::radiance) const {
    if (is_delta()) return color(0.0f);
    half_vector h;
    if (!generalized_half_vector(wo, wi, h)) return color(0.0f);
    const float F = fresnel_dielectric(glm::dot(wo, h.wm), eta);
    if (h.reflect) {
      return color(distrib.D(h.wm) * distrib.G(wo, wi) * F / std::abs(4.0f * h.cos_theta_i * h.cos_theta_o));
    }
    const float denom = sqr(glm::dot(wi, h.wm) + glm::dot(wo, h.wm) / h.etap) * h.cos_theta_i * h.cos_theta_o;
    float ft = distrib.D(h.wm) * (1.0f - F) * distrib.G(wo, wi) *
               std::abs(glm::dot(wi, h.wm) * glm::dot(wo, h.wm) / denom);
    // Account for non-symmetry with transmission to a different medium.
    if (mode == transport_mode::radiance) ft /= sqr(h.etap);
    return color(ft);
  }

  // Density of wi per unit SOLID ANGLE over the whole sphere (reflection on
  // wo's side, transmission on the other); 0 for the delta lobes. Does not
  // depend on the mode. With lobes restricted, the density of the
  // restricted sample(): the allowed lobe's probability is 1.
  float pdf(const vec3& wo, const vec3& wi, transport_mode = transport_mode::radiance,
            bsdf_lobes lobes = bsdf_lobes::all) const {
    if (is_delta()) return 0.0f;
    half_vector h;
    if (!generalized_half_vector(wo, wi, h)) return 0.0f;
    const float R = fresnel_dielectric(glm::dot(wo, h.wm), eta), T = 1.0f - R;
    const float pr = lobes == bsdf_lobes::transmission ? 0.0f : R;
    const float pt = lobes == bsdf_lobes::reflection ? 0.0f : T;
    // Guard: no allowed lobe to sample (R + T = 1 always, but a restriction
    // may leave the one with probability 0).
    if (pr == 0.0f && pt == 0.0f) return 0.0f;
    if (h.reflect) return distrib.pdf(wo, h.wm) / (4.0f * std::abs(glm::dot(wo, h.wm))) * pr / (pr + pt);
    const float denom = sqr(glm::dot(wi, h.wm) + glm::dot(wo, h.wm) / h.etap);
    const float dwm_dwi = std::abs(glm::dot(wi, h.wm)) / denom;
    return distrib.pdf(wo, h.wm) * dwm_dwi * pt / (pr + pt);
  }

  // lobes restricts the choice to reflection or transmission (pbrt-v4's
  // sampleFlags): the allowed lobe is then taken with probability 1 where
  // it has any.
  bool sample(const vec3& wo, float uc, vec2 u, bsdf_sample& out, transport_mode mode = transport_mode::radiance,
              bsdf_lobes lobes = bsdf_lobes::all) const {
    out = bsdf_sample{};
    // Guard: wo in the tangent plane has no side (and f has 1 / cos theta_o).
    if (wo.z == 0.0f) return false;
    if (is_delta()) {
      // Perfect specular: Fresnel at the macro normal, the lobe chosen by uc.
      const float R = fresnel_dielectric(cos_theta(wo), eta), T = 1.0f - R;
      const float pr = lobes == bsdf_lobes::transmission ? 0.0f : R;
      const float pt = lobes == bsdf_lobes::reflection ? 0.0f : T;
      if (pr == 0.0f && pt == 0.0f) return false;
      if (uc < pr / (pr + pt)) {
        const vec3 wi(-wo.x, -wo.y, wo.z);
        out.wi = wi;
        out.f = color(R / abs_cos_theta(wi));
        out.pdf = pr / (pr + pt);
        out.delta = true;
        return true;
      }
      vec3 wi;
      float etap = 1.0f;
      // Refraction cannot fail here: T > 0 means no total internal reflection.
      if (!refract(wo, vec3(0.0f, 0.0f, 1.0f), eta, etap, wi)) return false;
      float ft = T / abs_cos_theta(wi);
      if (mode == transport_mode::radiance) ft /= sqr(etap);
      out.wi = wi;
      out.f = color(ft);
      out.pdf = pt / (pr + pt);
      out.delta = true;
      out.transmission = true;
      out.eta = etap;
      return true;
    }
    // Rough: a visible normal, Fresnel at it, then the lobe chosen by uc.
    const vec3 wm = distrib.sample_wm(wo, u);
    const float R = fresnel_dielectric(glm::dot(wo, wm), eta), T = 1.0f - R;
    const float pr = lobes == bsdf_lobes::transmission ? 0.0f : R;
    const float pt = lobes == bsdf_lobes::reflection ? 0.0f : T;
    if (pr == 0.0f && pt == 0.0f) return false;
    if (uc < pr / (pr + pt)) {
      const vec3 wi = reflect(wo, wm);
      if (!same_hemisphere(wo, wi)) return false;  // reflected through the surface: no sample (pbrt-v4)
      out.wi = wi;
      out.pdf = distrib.pdf(wo, wm) / (4.0f * std::abs(glm::dot(wo, wm))) * pr / (pr + pt);
      out.f = color(distrib.D(wm) * distrib.G(wo, wi) * R / (4.0f * cos_theta(wi) * cos_theta(wo)));
      return true;
    }
    vec3 wi;
    float etap = 1.0f;
    const bool tir = !refract(wo, wm, eta, etap, wi);
    // TIR is impossible when T > 0 but for rounding; a refracted direction
    // on wo's side (a steep microfacet) leaves no sample, as in pbrt-v4.
    if (tir || same_hemisphere(wo, wi) || wi.z == 0.0f) return false;
    const float denom = sqr(glm::dot(wi, wm) + glm::dot(wo, wm) / etap);
    const float dwm_dwi = std::abs(glm::dot(wi, wm)) / denom;
    out.wi = wi;
    out.pdf = distrib.pdf(wo, wm) * dwm_dwi * pt / (pr + pt);
    float ft = T * distrib.D(wm) * distrib.G(wo, wi) *
               std::abs(glm::dot(wi, wm) * glm::dot(wo, wm) / (cos_theta(wi) * cos_theta(wo) * denom));
    if (mode == transport_mode::radiance) ft /= sqr(etap);
    out.f = color(ft);
    out.transmission = true;
    out.eta = etap;
    return true;
  }

 private:
  struct half_vector {
    vec3 wm;
    float cos_theta_o, cos_theta_i, etap;
    bool reflect;
  };
  // The generalized half vector of (wo, wi), faced to +z, or false when
  // there is none or the microfacet faces away from wo or wi (pbrt-v4's
  // common prologue of f() and PDF()).
  bool generalized_half_vector(const vec3& wo, const vec3& wi, half_vector& h) const {
    h.cos_theta_o = cos_theta(wo);
    h.cos_theta_i = cos_theta(wi);
    h.reflect = h.cos_theta_i * h.cos_theta_o > 0.0f;
    h.etap = 1.0f;
    if (!h.reflect) h.etap = h.cos_theta_o > 0.0f ? eta : 1.0f / eta;
    vec3 wm = wi * h.etap + wo;
    // Guard: a direction in the tangent plane, or wo + etap wi = 0 (wi
    // opposite wo with etap = 1), has no half vector.
    if (h.cos_theta_i == 0.0f || h.cos_theta_o == 0.0f || glm::dot(wm, wm) == 0.0f) return false;
    wm = glm::normalize(wm);
    if (wm.z < 0.0f) wm = -wm;  // FaceForward(wm, (0, 0, 1))
    // Discard back-facing microfacets.
    if (glm::dot(wm, wi) * h.cos_theta_i < 0.0f || glm::dot(wm, wo) * h.cos_theta_o < 0.0f) return false;
    h.wm = wm;
    return true;
  }
};

// A thin dielectric slab (a window pane) of relative IOR eta, pbrt-v4's
// ThinDielectricBxDF (sec. 9.5.1): light either reflects specularly or
// passes straight through (wi = -wo: the two refractions cancel), with the
// single-interface R = fresnel_dielectric(|cos theta_o|, eta) summed over
// the bounces inside the slab:
//   R' = R + T^2 R / (1 - R^2),  T' = 1 - R'.
// Delta lobes only: eval() and pdf() are 0. The pass-through is not scaled
// by 1 / eta^2 in either mode (the ray ends in the medium it started in).
struct thin_dielectric_bsdf {
  float eta = 1.5f;

  bool is_delta() const { return true; }
  color eval(const vec3&, const vec3&, transport_mode = transport_mode::radiance) const { return color(0.0f); }
  float pdf(const vec3&, const vec3&, transport_mode = transport_mode::radiance) const { return 0.0f; }

  bool sample(const vec3& wo, float uc, vec2 /*u*/, bsdf_sample& out,
              transport_mode = transport_mode::radiance) const {
    out = bsdf_sample{};
    if (wo.z == 0.0f) return false;  // guard: f = R / |cos theta| would be infinite
    float R = fresnel_dielectric(abs_cos_theta(wo), eta), T = 1.0f - R;
    // Account for the bounces inside the slab (a geometric series); R = 1
    // (only at grazing) would divide 0 by 0.
    if (R < 1.0f) {
      R += sqr(T) * R / (1.0f - sqr(R));
      T = 1.0f - R;
    }
    if (R == 0.0f && T == 0.0f) return false;
    out.delta = true;
    if (uc < R / (R + T)) {
      out.wi = vec3(-wo.x, -wo.y, wo.z);
      out.f = color(R / abs_cos_theta(out.wi));
      out.pdf = R / (R + T);
      return true;
    }
    out.wi = -wo;
    out.f = color(T / abs_cos_theta(out.wi));
    out.pdf = T / (R + T);
    out.transmission = true;
    return true;
  }
};

}  // namespace mcrt
