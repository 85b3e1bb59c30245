#pragma once
// pbrt-v4's "mix" material (src/pbrt/materials.h, MixMaterial): at each
// hit, one of two materials, the second with probability `amount` (a
// float texture, default 0.5; at or below 0 always the first, at or above
// 1 always the second), chosen by a hash of the hit point, the outgoing
// direction and the two materials (pbrt-v4's ChooseMaterial and HashFloat).
// The choice is a fixed function of the hit, so an image does not depend
// on the thread count or the sampler; mcrt's hash is not pbrt-v4's, so the
// two renderers agree in expectation, not pixel for pixel. A stochastic
// selection and not a blend: the path sees one BSDF, whose light samples
// and weights are its own, and the mean over hits is the mix
// (1 - amount) f_first + amount f_second.
//
// The materials are indices into the scene's list, resolved by
// resolve_mix (material.hpp) before the integrators read the material; a
// mix may hold mixes (pbrt-v4's named materials are defined before they
// are used, so there is no cycle).
#include <bit>
#include <cstdint>
#include <memory>

#include "mcrt/core/rng.hpp"
#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/materials/texture.hpp"

namespace mcrt {

struct mix_material {
  std::uint32_t first = 0, second = 0;    // indices into scene::materials
  std::shared_ptr<const texture> amount;  // probability of `second` (red channel); null: 0.5

  // The index of the material at the hit, wo the direction towards the
  // ray's origin (any length: it is normalised here, so that a ray's
  // direction of any length gives the same choice).
  std::uint32_t choose(const hit_record& rec, const vec3& wo) const {
    const float amt = amount ? amount->eval(rec.uv).r : 0.5f;
    if (!(amt > 0.0f)) return first;  // NaN as 0, as pbrt-v4's amt <= 0 would not
    if (amt >= 1.0f) return second;
    const vec3 w = glm::normalize(wo);
    const auto bits = [](float x) { return static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(x)); };
    std::uint64_t h = mix64(bits(rec.p.x) | (bits(rec.p.y) << 32));
    h = mix64(h ^ (bits(rec.p.z) | (bits(w.x) << 32)));
    h = mix64(h ^ (bits(w.y) | (bits(w.z) << 32)));
    h = mix64(h ^ (static_cast<std::uint64_t>(first) | (static_cast<std::uint64_t>(second) << 32)));
    const float u = static_cast<float>(h >> 40) * 0x1p-24f;  // uniform in [0, 1)
    return amt < u ? first : second;
  }
};

}  // namespace mcrt
