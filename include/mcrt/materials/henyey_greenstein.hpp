#pragma once
// The Henyey-Greenstein phase function (Henyey and Greenstein 1941,
// "Diffuse radiation in the galaxy", eq. 3; pbrt-v4, 4th ed., sec. 11.3.1,
// HGPhaseFunction and SampleHenyeyGreenstein of util/sampling.cpp): the
// angular distribution of light scattered by a particle, one parameter g,
// the mean cosine of the scattering angle (g > 0 forward, g < 0 backward,
// 0 isotropic). Used by the medium between a layered BSDF's interfaces
// (layered_bsdf.hpp).
//
// pbrt-v4's convention: wo and wi both point AWAY from the scattering
// point, so forward scattering means wi close to -wo, and with
// cos = wo . wi
//   p(wo, wi) = (1 - g^2) / (4 pi (1 + g^2 + 2 g cos)^(3/2)),
// a density per unit SOLID ANGLE of wi that integrates to 1 over the
// sphere. g is clamped to [-0.99, 0.99] as pbrt-v4 clamps it: near |g| = 1
// the inverse below cancels catastrophically (NaN directions).
#include <algorithm>
#include <cmath>

#include "mcrt/core/math.hpp"
#include "mcrt/materials/shading_frame.hpp"

namespace mcrt {

struct henyey_greenstein {
  float g = 0.0f;

  static float clamped(float g) { return std::clamp(g, -0.99f, 0.99f); }

  // The phase function of the cosine wo . wi.
  static float value(float cos_theta, float g) {
    g = clamped(g);
    const float denom = 1.0f + sqr(g) + 2.0f * g * cos_theta;
    // safe_sqrt: denom >= (1 - |g|)^2 > 0 for |cos| <= 1, but a cosine
    // rounded past -1 may take it a hair below that.
    return (1.0f / (4.0f * pi)) * (1.0f - sqr(g)) / (denom * safe_sqrt(denom));
  }

  float p(const vec3& wo, const vec3& wi) const { return value(glm::dot(wo, wi), g); }

  // Density of wi per unit SOLID ANGLE: the phase function itself (it is
  // sampled exactly).
  float pdf(const vec3& wo, const vec3& wi) const { return p(wo, wi); }

  // wi by inverting the CDF of cos theta (pbrt-v4's SampleHenyeyGreenstein;
  // the isotropic case, |g| < 1e-3, uniform in cos theta), phi = 2 pi u.y
  // about wo. pdf is the density of wi (= p(wo, wi), as the phase
  // function's weight p / pdf is 1).
  void sample(const vec3& wo, vec2 u, vec3& wi, float& pdf_out) const {
    const float gc = clamped(g);
    float cos_theta;
    if (std::abs(gc) < 1e-3f)
      cos_theta = 1.0f - 2.0f * u.x;
    else
      cos_theta = -1.0f / (2.0f * gc) * (1.0f + sqr(gc) - sqr((1.0f - sqr(gc)) / (1.0f + gc - 2.0f * gc * u.x)));
    // The inverse rounds a little outside [-1, 1] near u.x = 0 or 1.
    cos_theta = std::clamp(cos_theta, -1.0f, 1.0f);
    const float sin_theta = safe_sqrt(1.0f - sqr(cos_theta));
    const float phi = two_pi * u.y;
    const shading_frame fr = shading_frame::from_normal(wo);
    wi = fr.to_world(vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta));
    pdf_out = value(cos_theta, gc);
  }
};

}  // namespace mcrt
