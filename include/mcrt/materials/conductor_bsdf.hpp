#pragma once
// Metal, pbrt-v4's ConductorBxDF (4th ed., sec. 9.4 for the smooth case,
// sec. 9.6.5 for the rough one): a perfect mirror with the exact conductor
// Fresnel term when the distribution is effectively smooth, otherwise the
// Torrance-Sparrow microfacet BRDF with the Trowbridge-Reitz distribution,
// sampled by its visible normals. Two-sided, as pbrt-v4's: wo below the
// surface reflects below it. Conventions of bsdf_sample.hpp.
//
// Rough lobe (Walter et al. 2007, eq. 20; pbrt-v4 sec. 9.6.5):
//   f(wo, wi) = D(wm) F(|wo . wm|) G(wo, wi) / (4 |cos theta_i| |cos theta_o|),
//   wm = normalize(wo + wi)  (the reflection half vector),
//   pdf(wi)   = D_wo(wm) / (4 |wo . wm|)   per unit solid angle of wi,
// 1 / (4 |wo . wm|) being the Jacobian d(omega_m) / d(omega_i) of the
// reflection map (Walter et al. 2007, eq. 14).
#include <cmath>

#include "mcrt/core/math.hpp"
#include "mcrt/materials/bsdf_sample.hpp"
#include "mcrt/materials/fresnel.hpp"
#include "mcrt/materials/shading_frame.hpp"
#include "mcrt/materials/trowbridge_reitz.hpp"

namespace mcrt {

struct conductor_bsdf {
  trowbridge_reitz distrib;
  color eta{1.0f}, k{0.0f};  // complex relative IOR eta + i k per RGB channel

  bool is_delta() const { return distrib.effectively_smooth(); }

  color eval(const vec3& wo, const vec3& wi, transport_mode = transport_mode::radiance) const {
    if (!same_hemisphere(wo, wi)) return color(0.0f);
    if (distrib.effectively_smooth()) return color(0.0f);  // delta lobe
    const float cos_theta_o = abs_cos_theta(wo), cos_theta_i = abs_cos_theta(wi);
    if (cos_theta_i == 0.0f || cos_theta_o == 0.0f) return color(0.0f);
    vec3 wm = wi + wo;
    // Guard: wi = -wo has no half vector (impossible on the same side, but
    // kept as pbrt-v4 keeps it).
    if (glm::dot(wm, wm) == 0.0f) return color(0.0f);
    wm = glm::normalize(wm);
    const color F = fresnel_complex(std::abs(glm::dot(wo, wm)), eta, k);
    return distrib.D(wm) * F * distrib.G(wo, wi) / (4.0f * cos_theta_i * cos_theta_o);
  }

  // Density of wi per unit SOLID ANGLE: D_wo(wm) / (4 |wo . wm|) with the
  // half vector faced to +z; 0 for the delta (smooth) lobe, and when only
  // transmission is asked for (there is none).
  float pdf(const vec3& wo, const vec3& wi, transport_mode = transport_mode::radiance,
            bsdf_lobes lobes = bsdf_lobes::all) const {
    if (!same_hemisphere(wo, wi) || lobes == bsdf_lobes::transmission) return 0.0f;
    if (distrib.effectively_smooth()) return 0.0f;
    vec3 wm = wo + wi;
    if (glm::dot(wm, wm) == 0.0f) return 0.0f;
    wm = glm::normalize(wm);
    if (wm.z < 0.0f) wm = -wm;  // FaceForward(wm, (0, 0, 1))
    return distrib.pdf(wo, wm) / (4.0f * std::abs(glm::dot(wo, wm)));
  }

  bool sample(const vec3& wo, float /*uc*/, vec2 u, bsdf_sample& out, transport_mode = transport_mode::radiance,
              bsdf_lobes lobes = bsdf_lobes::all) const {
    out = bsdf_sample{};
    if (lobes == bsdf_lobes::transmission) return false;  // a conductor transmits nothing
    // Guard: in the tangent plane the mirror's f = F / |cos| and the rough
    // lobe's 1 / (4 cos_i cos_o) are infinite (pbrt-v4 rejects the rough
    // case only).
    if (wo.z == 0.0f) return false;
    if (distrib.effectively_smooth()) {
      // Perfect specular reflection: f = F / |cos theta_i|, probability 1.
      const vec3 wi(-wo.x, -wo.y, wo.z);
      out.wi = wi;
      out.f = fresnel_complex(abs_cos_theta(wi), eta, k) / abs_cos_theta(wi);
      out.pdf = 1.0f;
      out.delta = true;
      return true;
    }
    // Rough: a visible normal, then mirror wo about it.
    const vec3 wm = distrib.sample_wm(wo, u);
    const vec3 wi = reflect(wo, wm);
    if (!same_hemisphere(wo, wi)) return false;  // reflected below the surface: no sample (pbrt-v4)
    const float cos_theta_o = abs_cos_theta(wo), cos_theta_i = abs_cos_theta(wi);
    if (cos_theta_i == 0.0f || cos_theta_o == 0.0f) return false;
    out.wi = wi;
    out.pdf = distrib.pdf(wo, wm) / (4.0f * std::abs(glm::dot(wo, wm)));
    const color F = fresnel_complex(std::abs(glm::dot(wo, wm)), eta, k);
    out.f = distrib.D(wm) * F * distrib.G(wo, wi) / (4.0f * cos_theta_i * cos_theta_o);
    return true;
  }
};

template <>
inline constexpr bool reflects_only<conductor_bsdf> = true;

}  // namespace mcrt
