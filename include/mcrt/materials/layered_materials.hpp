#pragma once
// pbrt-v4's "coateddiffuse" and "coatedconductor" materials (src/pbrt/
// materials.h and materials.cpp, CoatedDiffuseMaterial and
// CoatedConductorMaterial::GetBxDF): a dielectric coat over a diffuse or a
// conductor base, the random-walk BSDF of layered_bsdf.hpp.
//
// Shared parameters, each possibly a texture, evaluated at the hit:
// thickness (default 0.01), the medium's albedo (default 0: no medium,
// clamped to [0, 1]) and g (default 0, clamped to [-1, 1]), maxdepth (10)
// and nsamples (1); roughness as microfacet_materials.hpp (remaproughness).
// One IOR for the three channels (mcrt renders no dispersion; a spectrum's
// value at 550 nm, as for "dielectric"); an IOR of 0 is taken as 1 as
// pbrt-v4 takes it.
#include <limits>
#include <memory>

#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/materials/conductor_bsdf.hpp"
#include "mcrt/materials/dielectric_bsdf.hpp"
#include "mcrt/materials/diffuse_bsdf.hpp"
#include "mcrt/materials/layered_bsdf.hpp"
#include "mcrt/materials/microfacet_materials.hpp"
#include "mcrt/materials/texture.hpp"

namespace mcrt {

// What coateddiffuse and coatedconductor share: the slab and its walk.
struct layer_parameters {
  std::shared_ptr<const texture> thickness, albedo, g;  // null: 0.01, 0, 0
  int max_depth = 10, n_samples = 1;

  template <class Top, class Bottom>
  void apply(const hit_record& rec, layered_bsdf<Top, Bottom>& b) const {
    // pbrt-v4's LayeredBxDF keeps the thickness at least FLT_MIN (a slab of
    // 0 would make the transmittance's 0 / 0).
    b.thickness = std::max(thickness ? thickness->eval(rec.uv).r : 0.01f, std::numeric_limits<float>::min());
    b.albedo = albedo ? glm::clamp(albedo->eval(rec.uv), color(0.0f), color(1.0f)) : color(0.0f);
    b.g = g ? std::clamp(g->eval(rec.uv).r, -1.0f, 1.0f) : 0.0f;
    b.max_depth = max_depth;
    b.n_samples = n_samples;
  }
};

using coated_diffuse_bsdf = layered_bsdf<dielectric_bsdf, diffuse_bsdf>;
using coated_conductor_bsdf = layered_bsdf<dielectric_bsdf, conductor_bsdf>;
// Neither base transmits: light leaves through the coat only.
template <>
inline constexpr bool reflects_only<coated_diffuse_bsdf> = true;
template <>
inline constexpr bool reflects_only<coated_conductor_bsdf> = true;

// Plastic, varnished wood, paint: a dielectric coat (eta, default 1.5;
// roughness default 0) over a Lambertian base of `reflectance` (default
// 0.5, clamped to [0, 1]).
struct coated_diffuse_parameters {
  std::shared_ptr<const texture> reflectance;  // null: 0.5
  float eta = 1.5f;
  microfacet_roughness roughness;
  layer_parameters layer;
};

// Lacquered metal: a dielectric coat (interface.eta, default 1.5;
// interface.*roughness, default 0) over a conductor (conductor.eta and
// conductor.k, default copper, or `reflectance`; conductor.*roughness,
// default 0). The conductor's IOR is relative to the coat: pbrt-v4 divides
// eta and k by the coat's eta.
struct coated_conductor_parameters {
  float interface_eta = 1.5f;
  microfacet_roughness interface_roughness;
  conductor_material conductor;  // its eta, k or reflectance and roughness
  layer_parameters layer;
};

// The materials hold their parameters by pointer: a material is an
// alternative of one variant (material.hpp), whose size is its largest
// alternative's, and every scene's materials would otherwise pay for the
// two dozen words of these. A null pointer is pbrt-v4's defaults (a
// coated conductor then needs its conductor's IOR).
struct coated_diffuse_material {
  std::shared_ptr<const coated_diffuse_parameters> p;

  coated_diffuse_bsdf at(const hit_record& rec) const {
    static const coated_diffuse_parameters defaults;
    const coated_diffuse_parameters& q = p ? *p : defaults;
    coated_diffuse_bsdf b;
    b.top.eta = q.eta;
    b.top.distrib = q.roughness.at(rec);
    b.bottom.R = q.reflectance ? glm::clamp(q.reflectance->eval(rec.uv), color(0.0f), color(1.0f)) : color(0.5f);
    q.layer.apply(rec, b);
    return b;
  }
};

struct coated_conductor_material {
  std::shared_ptr<const coated_conductor_parameters> p;

  coated_conductor_bsdf at(const hit_record& rec) const {
    static const coated_conductor_parameters defaults;
    const coated_conductor_parameters& q = p ? *p : defaults;
    coated_conductor_bsdf b;
    b.top.eta = q.interface_eta;
    b.top.distrib = q.interface_roughness.at(rec);
    b.bottom = q.conductor.at(rec);
    b.bottom.eta /= q.interface_eta;
    b.bottom.k /= q.interface_eta;
    q.layer.apply(rec, b);
    return b;
  }
};

}  // namespace mcrt
