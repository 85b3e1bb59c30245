#pragma once
// What every BSDF of mcrt/materials/ shares: the transport mode, the sample
// record, and the conventions (after pbrt-v4, 4th ed., sec. 9.1):
//
//  - Directions are in the LOCAL shading frame (shading_frame.hpp): z is the
//    shading normal, x the tangent (dpdu), along which a microfacet
//    distribution's alpha_x applies. wo and wi point away from the surface
//    and are unit length. wo is the direction light leaves along (towards
//    the camera in radiance mode), wi the one it arrives from.
//  - f excludes the cosine factor |cos theta_i|: the estimator's weight is
//    f |cos theta_i| / pdf.
//  - pdf is per unit SOLID ANGLE of wi, for every non-delta lobe.
//  - Delta (specular) lobes follow pbrt-v4 exactly: f = F / |cos theta_i|,
//    pdf = the discrete probability of choosing that lobe and delta = true,
//    so that f |cos theta_i| / pdf is the weight. eval() and pdf() of a delta
//    lobe return 0: no other strategy can find its direction.
//
// Each BSDF offers the triplet
//   bool  sample(wo, uc, u, bsdf_sample& out, mode) const;
//   color eval(wo, wi, mode) const;
//   float pdf(wo, wi, mode) const;
//   bool  is_delta() const;
// with mode defaulted to transport_mode::radiance. sample() returns false
// when it produces no direction (wo in the tangent plane, a reflected
// direction below the surface, total internal reflection on the chosen
// microfacet); the caller then ends the path, as pbrt-v4 does with an empty
// optional.
#include "mcrt/core/math.hpp"

namespace mcrt {

// pbrt-v4's TransportMode (4th ed., sec. 9.5.2): radiance when the path
// started at the camera, importance when it started at a light. Only
// refraction depends on it: radiance is compressed by 1/eta'^2 when it enters
// a denser medium (sec. 9.5.2), importance is not.
enum class transport_mode { radiance, importance };

// The other mode: the one light travelling the opposite way carries
// (pbrt-v4's !mode). A layered BSDF samples the exit side of its walk from
// wi, against the flow of light.
inline transport_mode adjoint(transport_mode m) {
  return m == transport_mode::radiance ? transport_mode::importance : transport_mode::radiance;
}

// The lobes a sample may choose and a pdf counts (pbrt-v4's
// BxDFReflTransFlags): all, or only those leaving on wo's side
// (reflection), or only those crossing the surface (transmission). The
// interfaces of a layered BSDF (layered_bsdf.hpp) are asked for one kind.
// A restricted pdf is the density of the restricted sample(): the chosen
// lobe's probability is renormalised over the allowed lobes.
enum class bsdf_lobes { all, reflection, transmission };

// Whether a BSDF type scatters only to wo's side of the surface (a
// renderer then looks for light on that side only): specialised true
// beside each reflection-only BSDF.
template <class Bsdf>
inline constexpr bool reflects_only = false;

struct bsdf_sample {
  vec3 wi{0.0f};        // sampled incident direction, local frame, unit
  color f{0.0f};        // BSDF value for (wo, wi), without the cosine
  float pdf = 0;        // solid-angle density, or the lobe probability if delta
  bool delta = false;   // a specular lobe: pdf is a discrete probability
  bool transmission = false;  // wi on the other side of the surface than wo
  float eta = 1;        // relative IOR along the ray for transmission (pbrt-v4's etap), else 1
  // pbrt-v4's pdfIsProportional: f and pdf are those of one random path
  // (layered_bsdf.hpp), so f / pdf is an unbiased weight, but pdf is not
  // the density of wi; a multiple-importance weight takes the BSDF's
  // pdf(wo, wi) instead.
  bool pdf_is_proportional = false;
};

}  // namespace mcrt
