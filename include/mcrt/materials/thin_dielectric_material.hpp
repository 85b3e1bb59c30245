#pragma once
// pbrt-v4's "thindielectric" material (src/pbrt/materials.h,
// ThinDielectricMaterial): a thin slab of glass of relative IOR eta
// (default 1.5), whose BSDF (thin_dielectric_bsdf, dielectric_bsdf.hpp)
// reflects or passes light straight through with all its internal bounces
// summed: window panes, soap films without dispersion. One IOR for the
// three channels (mcrt renders no dispersion: a spectrum's value at 550 nm,
// as for "dielectric").
#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/materials/dielectric_bsdf.hpp"

namespace mcrt {

struct thin_dielectric_material {
  float eta = 1.5f;

  thin_dielectric_bsdf at(const hit_record&) const { return thin_dielectric_bsdf{eta}; }
};

}  // namespace mcrt
