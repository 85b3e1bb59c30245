#pragma once
// pbrt-v4's "conductor" and "dielectric" materials (src/pbrt/materials.h):
// their parameters, each possibly a texture, and the BSDF they make at a
// hit (conductor_bsdf.hpp, dielectric_bsdf.hpp) in the hit's shading frame.
// Roughness: pbrt-v4's uroughness / vroughness (default `roughness`, 0),
// turned into the Trowbridge-Reitz alphas by sqrt when remaproughness is
// true (TrowbridgeReitzDistribution::RoughnessToAlpha), taken as alphas
// otherwise.
#include <memory>

#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/materials/conductor_bsdf.hpp"
#include "mcrt/materials/dielectric_bsdf.hpp"
#include "mcrt/materials/shading_frame.hpp"
#include "mcrt/materials/texture.hpp"

namespace mcrt {

struct microfacet_roughness {
  std::shared_ptr<const texture> u, v;  // float textures (their red channel)
  bool remap = true;

  trowbridge_reitz at(const hit_record& rec) const {
    // A roughness texture below 0 (an image, a scale) is taken as 0:
    // roughness_to_alpha is a square root.
    float au = u ? std::max(u->eval(rec.uv).r, 0.0f) : 0.0f, av = v ? std::max(v->eval(rec.uv).r, 0.0f) : 0.0f;
    if (remap) {
      au = trowbridge_reitz::roughness_to_alpha(au);
      av = trowbridge_reitz::roughness_to_alpha(av);
    }
    return trowbridge_reitz(au, av);
  }
};

// A metal: the complex IOR eta + i k per channel, or pbrt-v4's artist-
// friendly `reflectance` r, which it turns into eta = 1, k = 2 sqrt(r) /
// sqrt(1 - r) (normal-incidence reflectance r).
struct conductor_material {
  std::shared_ptr<const texture> eta, k;       // used when reflectance is null
  std::shared_ptr<const texture> reflectance;  // or null
  microfacet_roughness roughness;

  conductor_bsdf at(const hit_record& rec) const {
    conductor_bsdf b;
    b.distrib = roughness.at(rec);
    if (reflectance) {
      // Clamped below 1, where k would be infinite (pbrt-v4 clamps to 0.9999).
      const color r = glm::clamp(reflectance->eval(rec.uv), color(0.0f), color(0.9999f));
      b.eta = color(1.0f);
      b.k = 2.0f * glm::sqrt(r) / glm::sqrt(color(1.0f) - r);
    } else {
      // An IOR texture below 0 (an image, a scale) is taken as 0: the
      // conductor's eta and k are non-negative.
      b.eta = glm::max(eta->eval(rec.uv), color(0.0f));
      b.k = glm::max(k->eval(rec.uv), color(0.0f));
    }
    return b;
  }
};

// Glass and other dielectric interfaces: eta is the IOR inside (behind the
// surface's front side) over outside.
struct dielectric_material {
  float eta = 1.5f;
  microfacet_roughness roughness;

  dielectric_bsdf at(const hit_record& rec) const {
    dielectric_bsdf b;
    b.eta = eta;
    b.distrib = roughness.at(rec);
    return b;
  }
};

}  // namespace mcrt
