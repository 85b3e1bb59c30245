#pragma once
// Lambertian reflection and Lambertian transmission, pbrt-v4's
// DiffuseTransmissionBxDF (src/pbrt/bxdfs.h; 4th ed., sec. 9.2 for the
// diffuse lobe): a thin translucent sheet (leaves, paper, lamp shades).
//   f(wo, wi) = R / pi   for wi on wo's side,
//               T / pi   for wi on the other side.
// Sampling picks reflection with probability pr / (pr + pt), pr and pt the
// largest channel of R and of T (pbrt-v4's choice), then a cosine-weighted
// direction on the chosen side. Conventions of bsdf_sample.hpp (local
// frame, f without the cosine). Both lobes are symmetric in (wo, wi): the
// BSDF is reciprocal, and the same in radiance and importance modes (no
// refraction, so no 1/eta^2). Directional albedo: R + T per channel.
#include "mcrt/core/math.hpp"
#include "mcrt/materials/bsdf_sample.hpp"
#include "mcrt/materials/shading_frame.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

struct diffuse_transmission_bsdf {
  color R{0.25f};  // hemispherical reflectance, each channel in [0, 1]
  color T{0.25f};  // hemispherical transmittance, each channel in [0, 1]; R + T <= 1 conserves energy

  bool is_delta() const { return false; }

  color eval(const vec3& wo, const vec3& wi, transport_mode = transport_mode::radiance) const {
    // wo or wi in the tangent plane: neither side (pdf() is 0 there too).
    if (wo.z == 0.0f || wi.z == 0.0f) return color(0.0f);
    return (same_hemisphere(wo, wi) ? R : T) * inv_pi;
  }

  // Density of wi per unit SOLID ANGLE: the chosen side's probability times
  // the cosine-weighted density |cos theta_i| / pi; 0 when R and T are
  // both 0 (sample() gives nothing then).
  float pdf(const vec3& wo, const vec3& wi, transport_mode = transport_mode::radiance) const {
    const float pr = max_component(R), pt = max_component(T);
    if (!(pr + pt > 0.0f) || wo.z == 0.0f || wi.z == 0.0f) return 0.0f;
    return (same_hemisphere(wo, wi) ? pr : pt) / (pr + pt) * abs_cos_theta(wi) * inv_pi;
  }

  // uc chooses the side (reflection below pr / (pr + pt)), u the direction
  // by the cosine-weighted hemisphere map of warp.hpp (pbrt-v4 uses the
  // concentric disk map: the same density).
  bool sample(const vec3& wo, float uc, vec2 u, bsdf_sample& out, transport_mode = transport_mode::radiance) const {
    const float pr = max_component(R), pt = max_component(T);
    // Guards: nothing to scatter; wo in the tangent plane has no side.
    if (!(pr + pt > 0.0f) || wo.z == 0.0f) return false;
    const bool reflect = uc < pr / (pr + pt);
    vec3 wi = square_to_cosine_hemisphere(u);  // wi.z >= 2^-12 > 0 for u.x < 1
    if ((wo.z < 0.0f) == reflect) wi.z = -wi.z;
    out = bsdf_sample{};
    out.wi = wi;
    out.f = (reflect ? R : T) * inv_pi;
    out.pdf = (reflect ? pr : pt) / (pr + pt) * abs_cos_theta(wi) * inv_pi;
    out.transmission = !reflect;
    // eta stays 1: the sheet does not bend the ray.
    return true;
  }

 private:
  static float max_component(const color& c) { return std::max(c.r, std::max(c.g, c.b)); }
};

}  // namespace mcrt
