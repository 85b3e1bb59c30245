#pragma once
// pbrt-v4's "diffusetransmission" material (src/pbrt/materials.h,
// DiffuseTransmissionMaterial): reflectance and transmittance, each
// possibly a texture (default 0.25 each), times `scale` (default 1), each
// product clamped to [0, 1] per channel at the hit as pbrt-v4 clamps it,
// make the BSDF of diffuse_transmission_bsdf.hpp.
#include <memory>

#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/materials/diffuse_transmission_bsdf.hpp"
#include "mcrt/materials/texture.hpp"

namespace mcrt {

struct diffuse_transmission_material {
  std::shared_ptr<const texture> reflectance, transmittance;  // null: pbrt-v4's default, 0.25
  float scale = 1.0f;

  diffuse_transmission_bsdf at(const hit_record& rec) const {
    const color r = reflectance ? reflectance->eval(rec.uv) : color(0.25f);
    const color t = transmittance ? transmittance->eval(rec.uv) : color(0.25f);
    diffuse_transmission_bsdf b;
    b.R = glm::clamp(scale * r, color(0.0f), color(1.0f));
    b.T = glm::clamp(scale * t, color(0.0f), color(1.0f));
    return b;
  }
};

}  // namespace mcrt
