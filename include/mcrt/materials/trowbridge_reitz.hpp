#pragma once
// The anisotropic Trowbridge-Reitz (GGX) microfacet distribution with
// Smith's masking, after pbrt-v4's TrowbridgeReitzDistribution (4th ed.,
// sec. 9.6, util/scattering.h). References:
//   [TR75]  Trowbridge and Reitz 1975, "Average irregularity representation
//           of a rough surface for ray reflection";
//   [W07]   Walter et al. 2007, "Microfacet Models for Refraction through
//           Rough Surfaces" (GGX: eqs. 33 and 34);
//   [H14]   Heitz 2014, "Understanding the Masking-Shadowing Function in
//           Microfacet-Based BRDFs" (JCGT 3(2)): the anisotropic GGX D and
//           its Smith Lambda, the height-correlated masking-shadowing G2;
//   [HD14]  Heitz and d'Eon 2014, "Importance Sampling Microfacet-Based
//           BSDFs using the Distribution of Visible Normals" (eq. 2: D_w);
//   [H18]   Heitz 2018, "Sampling the GGX Distribution of Visible Normals"
//           (JCGT 7(4)), its listing in pbrt-v4's hemisphere-projection form.
//
// All vectors are in the local shading frame (shading_frame.hpp): z the
// macro normal, x the tangent along which alpha_x applies. Microfacet
// normals wm are on the upper hemisphere; D(wm) itself is even in wm.z, as
// pbrt-v4's, and callers face-forward half vectors before using it.
#include <algorithm>
#include <cmath>

#include "mcrt/core/math.hpp"
#include "mcrt/materials/shading_frame.hpp"

namespace mcrt {

class trowbridge_reitz {
 public:
  trowbridge_reitz() = default;
  trowbridge_reitz(float alpha_x, float alpha_y)
      : alpha_x_(std::min(alpha_x, max_alpha)), alpha_y_(std::min(alpha_y, max_alpha)) {
    if (!effectively_smooth()) {
      // As pbrt-v4: if one direction has some roughness, the other cannot be
      // (nearly) 0, or x^2 / alpha_x^2 in D() blows up.
      alpha_x_ = std::max(alpha_x_, 1e-4f);
      alpha_y_ = std::max(alpha_y_, 1e-4f);
    }
  }

  // The roughest surface: alpha is clamped to this (roughness 1e8). Its
  // BSDFs reflect O(1/alpha) of the light, and for larger alpha D's
  // denominator (alpha_x alpha_y s^2 for grazing microfacet normals)
  // underflows single precision to NaN weights (seen at alpha 1e15).
  static constexpr float max_alpha = 1e4f;

  float alpha_x() const { return alpha_x_; }
  float alpha_y() const { return alpha_y_; }

  // Below this roughness the BSDFs treat the surface as a perfect specular
  // interface (pbrt-v4's EffectivelySmooth): a lobe this narrow is better
  // sampled as a delta, and its D overflows float.
  bool effectively_smooth() const { return std::max(alpha_x_, alpha_y_) < 1e-3f; }

  // pbrt-v4's RoughnessToAlpha: alpha = sqrt(roughness). (pbrt-v4 notes in
  // mmp/pbrt-v4#479 that roughness^2 would be more perceptually uniform but
  // keeps sqrt so that existing scenes render unchanged; so do we.)
  static float roughness_to_alpha(float roughness) { return std::sqrt(roughness); }

  // Microfacet normal distribution, density of wm per unit solid angle of
  // microfacet normals and per unit macro-surface area, normalized so that
  // integral over the hemisphere of D(wm) cos(theta_m) d(omega_m) = 1
  // ([W07] eq. 33; [H14] for the anisotropic form; pbrt-v4 sec. 9.6.1):
  //   D(wm) = 1 / (pi ax ay cos^4 theta_m (1 + tan^2 theta_m (cos^2 phi_m / ax^2 + sin^2 phi_m / ay^2))^2)
  //         = 1 / (pi ax ay (x^2 / ax^2 + y^2 / ay^2 + z^2)^2)   for unit wm.
  // The second form, used here, needs no tan, cos phi or sin phi: it is the
  // same number without pbrt-v4's cancellation guards (pbrt-v4 returns 0 when
  // cos^4 theta_m < 1e-16; this form gives the continuous value there).
  float D(const vec3& wm) const {
    const float s = sqr(wm.x / alpha_x_) + sqr(wm.y / alpha_y_) + sqr(wm.z);
    return 1.0f / (pi * alpha_x_ * alpha_y_ * sqr(s));
  }

  // Smith's auxiliary function Lambda(w) of the anisotropic GGX distribution
  // ([H14]; [W07] eq. 34 in G1 = 1 / (1 + Lambda) form; pbrt-v4 sec. 9.6.2):
  //   Lambda(w) = (sqrt(1 + alpha(phi)^2 tan^2 theta) - 1) / 2,
  //   alpha(phi)^2 tan^2 theta = (ax^2 x^2 + ay^2 y^2) / z^2.
  // Computed as a / (2 (1 + sqrt(1 + a))) with a = alpha^2 tan^2 theta,
  // which does not cancel near the normal. In the tangent plane (z = 0)
  // Lambda is +inf (G1 = 0); pbrt-v4 returns 0 there, a point every BSDF
  // rejects before it gets here.
  float lambda(const vec3& w) const {
    const float a = (sqr(alpha_x_ * w.x) + sqr(alpha_y_ * w.y)) / sqr(w.z);
    // Tangent-plane guard: a is inf (or NaN for 0 / 0) for w in, or within
    // ~1e-19 of, the tangent plane, and a / (1 + sqrt(a)) would be NaN.
    if (!(a < infinity)) return infinity;
    return a / (2.0f * (1.0f + std::sqrt(1.0f + a)));
  }

  // Smith's masking function G1(w) = 1 / (1 + Lambda(w)) ([H14]; pbrt-v4 sec. 9.6.2).
  float G1(const vec3& w) const { return 1.0f / (1.0f + lambda(w)); }

  // Height-correlated masking-shadowing ([H14]; pbrt-v4 sec. 9.6.3):
  // G(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi)).
  float G(const vec3& wo, const vec3& wi) const { return 1.0f / (1.0f + lambda(wo) + lambda(wi)); }

  // Distribution of normals visible from w ([HD14] eq. 2; pbrt-v4 sec.
  // 9.6.4), density of wm per unit solid angle, normalized over the upper
  // hemisphere of wm:
  //   D_w(wm) = G1(w) max(0, w . wm) D(wm) / cos theta.
  // Two-sided as pbrt-v4's D(w, wm), which uses |w . wm| / |cos theta|: for w
  // below the surface it is the distribution visible from -w, the one
  // sample_wm() draws from. Unlike pbrt-v4 it is 0 for back-facing normals
  // (w . wm of the opposite sign to w.z), so that it is a density; the BSDFs
  // never evaluate it there (a reflection half vector always faces wo, and
  // the dielectric discards back-facing microfacets first), so no BSDF value
  // changes.
  float D(const vec3& w, const vec3& wm) const {
    const float cos_m = glm::dot(w, wm) * std::copysign(1.0f, w.z);
    if (!(cos_m > 0.0f)) return 0.0f;  // back-facing microfacet, or w in the tangent plane
    return G1(w) / abs_cos_theta(w) * D(wm) * cos_m;
  }

  // The density sample_wm() draws wm with, per unit solid angle of wm.
  float pdf(const vec3& w, const vec3& wm) const { return D(w, wm); }

  // A microfacet normal drawn from D_w (two-sided: from D_{-w} if w.z < 0),
  // by [H18] in pbrt-v4's form (Sample_wm): stretch w to the configuration
  // where the distribution is the unit hemisphere (alpha = 1), sample the
  // projected area the hemisphere shows to wh (a disk plus a half ellipse)
  // uniformly, lift the point onto the hemisphere and unstretch its normal.
  vec3 sample_wm(const vec3& w, vec2 u) const {
    // Transform w to the hemispherical configuration (alpha = 1).
    vec3 wh = glm::normalize(vec3(alpha_x_ * w.x, alpha_y_ * w.y, w.z));
    if (wh.z < 0.0f) wh = -wh;
    // Orthonormal basis around wh; at the pole cross(z, wh) vanishes, and
    // any tangent will do ([H18] uses (1, 0, 0) likewise).
    const vec3 t1 = wh.z < 0.99999f ? glm::normalize(glm::cross(vec3(0.0f, 0.0f, 1.0f), wh)) : vec3(1.0f, 0.0f, 0.0f);
    const vec3 t2 = glm::cross(wh, t1);
    // Uniform point on the unit disk (polar map, pbrt-v4's SampleUniformDiskPolar).
    const float r = std::sqrt(u.x), phi = two_pi * u.y;
    vec2 p(r * std::cos(phi), r * std::sin(phi));
    // Warp the disk to the hemisphere's projection seen from wh: the lower
    // half disk is squeezed to a half ellipse of semi-axis wh.z ([H18]).
    const float h = std::sqrt(1.0f - sqr(p.x));
    const float s = 0.5f * (1.0f + wh.z);
    p.y = (1.0f - s) * h + s * p.y;
    // Reproject onto the hemisphere; max guards 1 - |p|^2 rounding below 0.
    const float pz = std::sqrt(std::max(0.0f, 1.0f - glm::dot(p, p)));
    const vec3 nh = p.x * t1 + p.y * t2 + pz * wh;
    // Back to the ellipsoid configuration (normals transform with the
    // inverse transpose of the stretch). The 1e-6 floor on z, as pbrt-v4,
    // keeps wm off the tangent plane, where D and the BSDFs degenerate.
    return glm::normalize(vec3(alpha_x_ * nh.x, alpha_y_ * nh.y, std::max(1e-6f, nh.z)));
  }

 private:
  float alpha_x_ = 0.0f, alpha_y_ = 0.0f;
};

}  // namespace mcrt
