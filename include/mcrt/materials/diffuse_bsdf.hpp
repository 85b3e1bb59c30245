#pragma once
// Lambertian reflection, pbrt-v4's DiffuseBxDF (4th ed., sec. 9.2):
// f = R / pi for wi on the same side as wo, 0 otherwise. Two-sided: wi is
// sampled on wo's side of the surface, whichever that is. Conventions of
// bsdf_sample.hpp (local frame, f without the cosine).
#include "mcrt/core/math.hpp"
#include "mcrt/materials/bsdf_sample.hpp"
#include "mcrt/materials/shading_frame.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

struct diffuse_bsdf {
  color R{0.5f};  // hemispherical reflectance, each channel in [0, 1]

  bool is_delta() const { return false; }

  color eval(const vec3& wo, const vec3& wi, transport_mode = transport_mode::radiance) const {
    if (!same_hemisphere(wo, wi)) return color(0.0f);
    return R * inv_pi;
  }

  // Density of wi per unit SOLID ANGLE: |cos theta_i| / pi on wo's side
  // (0 when only transmission is asked for: there is none).
  float pdf(const vec3& wo, const vec3& wi, transport_mode = transport_mode::radiance,
            bsdf_lobes lobes = bsdf_lobes::all) const {
    if (!same_hemisphere(wo, wi) || lobes == bsdf_lobes::transmission) return 0.0f;
    return abs_cos_theta(wi) * inv_pi;
  }

  // Cosine-weighted hemisphere on wo's side (Malley's method; pbrt-v4 uses
  // the concentric disk map, this the polar one of warp.hpp: the same
  // density, another pairing of u with wi). uc is unused.
  bool sample(const vec3& wo, float /*uc*/, vec2 u, bsdf_sample& out, transport_mode = transport_mode::radiance,
              bsdf_lobes lobes = bsdf_lobes::all) const {
    // Guard: wo in the tangent plane has no side; eval() and pdf() are 0 for
    // it, so a sample would not match them (pbrt-v4 samples the upper side).
    if (wo.z == 0.0f || lobes == bsdf_lobes::transmission) return false;
    vec3 wi = square_to_cosine_hemisphere(u);  // wi.z >= 2^-12 > 0 for u.x < 1
    if (wo.z < 0.0f) wi.z = -wi.z;
    out = bsdf_sample{};
    out.wi = wi;
    out.f = R * inv_pi;
    out.pdf = abs_cos_theta(wi) * inv_pi;
    return true;
  }
};

template <>
inline constexpr bool reflects_only<diffuse_bsdf> = true;

}  // namespace mcrt
