#pragma once
// The materials of Shirley's books ("In One Weekend" sec. 8-10, "The Rest of
// Your Life" sec. 10), as plain value types dispatched statically through
// std::variant: a scene stores only the materials it names.
#include <cstdint>
#include <variant>
#include <vector>

#include "mcrt/core/ray.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/geometry/hit_record.hpp"
#include "mcrt/materials/diffuse_transmission_material.hpp"
#include "mcrt/materials/layered_materials.hpp"
#include "mcrt/materials/microfacet_materials.hpp"
#include "mcrt/materials/mix_material.hpp"
#include "mcrt/materials/thin_dielectric_material.hpp"
#include "mcrt/materials/texture.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

// Ideal diffuse reflector: scattering pdf cos(theta)/pi (per unit solid angle).
struct lambertian {
  color albedo{0.5f};
};

// Mirror plus a random offset of up to `fuzz` in a unit ball.
struct metal {
  color albedo{0.8f};
  float fuzz = 0.0f;
};

// Glass: refraction by Snell's law, reflection with Schlick's Fresnel term.
struct dielectric {
  float ior = 1.5f;
};

// A diffuse reflector whose albedo is a texture (pbrt-v4's "diffuse"
// material with a textured reflectance): sampled and lit as a lambertian
// with the albedo the texture has at the hit's (u, v).
struct textured_diffuse {
  texture reflectance;
};

// Emits `emit` from its front side (from both sides when `twosided`, pbrt-v4's
// area light "twosided"). A light of Shirley's scenes scatters nothing;
// a light of a pbrt-v4 scene also reflects with its surface's material, the
// material with index `surface` (pbrt-v4's emitting shapes keep their
// material), where that is not no_surface.
struct diffuse_light {
  static constexpr std::uint32_t no_surface = 0xffffffffu;
  color emit{1.0f};
  bool twosided = false;
  std::uint32_t surface = no_surface;
};

// pbrt-v4's conductor and dielectric (microfacet_materials.hpp),
// diffusetransmission (diffuse_transmission_material.hpp), thindielectric
// (thin_dielectric_material.hpp), coateddiffuse and coatedconductor
// (layered_materials.hpp) and mix (mix_material.hpp) come last: Shirley's
// scenes pay nothing for them.
using material =
    std::variant<lambertian, metal, dielectric, diffuse_light, textured_diffuse, conductor_material,
                 dielectric_material, diffuse_transmission_material, thin_dielectric_material,
                 coated_diffuse_material, coated_conductor_material, mix_material>;

// Every scene's material list pays for the largest alternative: the big
// ones (the coats) hold their parameters by pointer, so that a material
// stays within the conductor's 88 bytes and the variant's index.
static_assert(sizeof(material) <= 96, "a material alternative grew the variant: hold its parameters by pointer");

// The material a hit sees: m itself, or, for a mix (mix_material.hpp), the
// one it chooses there, mixes within mixes resolved in turn. wo points
// towards the ray's origin (-r.d). A scene without mixes pays one test of
// the variant's index.
#if defined(__GNUC__) || defined(__clang__)
[[gnu::noinline]]
#endif
inline const material&
resolve_mix_chain(const std::vector<material>& materials, const material& m, const hit_record& rec, const vec3& wo) {
  const material* p = &m;
  while (const auto* mx = std::get_if<mix_material>(p)) p = &materials[mx->choose(rec, wo)];
  return *p;
}
// The test inline, the choice out of line: the integrators' loop stays as
// it was for scenes without mixes.
inline const material& resolve_mix(const std::vector<material>& materials, const material& m, const hit_record& rec,
                                   const vec3& wo) {
  if (!std::holds_alternative<mix_material>(m)) [[likely]]
    return m;
  return resolve_mix_chain(materials, m, rec, wo);
}

// The materials that make a BSDF at a hit (each has at(rec)): pbrt-v4's
// conductor, dielectric, diffusetransmission, thindielectric,
// coateddiffuse and coatedconductor. has_bsdf and with_bsdf both read this
// one list.
template <class... Ms>
struct material_list {};
using bsdf_materials =
    material_list<conductor_material, dielectric_material, diffuse_transmission_material, thin_dielectric_material,
                  coated_diffuse_material, coated_conductor_material>;

// Whether m has a BSDF (with_bsdf calls its f): a test the integrators can
// make before leaving their inlined loop for with_bsdf.
inline bool has_bsdf(const material& m) {
  return []<class... Ms>(const material& mm, material_list<Ms...>) {
    return (std::holds_alternative<Ms>(mm) || ...);
  }(m, bsdf_materials{});
}

// The BSDF of m at a hit, passed to f, where m has one; false for the
// others (Shirley's materials, diffuse ones and lights).
template <class F>
inline bool with_bsdf(const material& m, const hit_record& rec, F&& f) {
  return [&]<class... Ms>(material_list<Ms...>) {
    return ([&] {
      const auto* x = std::get_if<Ms>(&m);
      if (x) f(x->at(rec));
      return x != nullptr;
    }() || ...);
  }(bsdf_materials{});
}

// The albedo of a diffuse material at a hit (lambertian or textured);
// false for every other material.
inline bool diffuse_albedo(const material& m, const hit_record& rec, color& albedo) {
  if (const auto* lam = std::get_if<lambertian>(&m)) {
    albedo = lam->albedo;
    return true;
  }
  if (const auto* td = std::get_if<textured_diffuse>(&m)) {
    // pbrt-v4's DiffuseMaterial clamps its reflectance to [0, 1]: an image
    // or a scale may give more (or less), which would not conserve energy.
    albedo = glm::clamp(td->reflectance.eval(rec.uv), color(0.0f), color(1.0f));
    return true;
  }
  return false;
}

// What a specular material does with an incoming ray.
struct specular_scatter {
  ray r;
  color attenuation;
};

inline color emitted(const material& m, const hit_record& rec) {
  if (const auto* l = std::get_if<diffuse_light>(&m)) return rec.front_face || l->twosided ? l->emit : color(0.0f);
  return color(0.0f);
}

// Schlick's approximation of the Fresnel reflectance.
inline float schlick(float cosine, float ior) {
  float r0 = (1.0f - ior) / (1.0f + ior);
  r0 *= r0;
  const float m = 1.0f - cosine;
  return r0 + (1.0f - r0) * (m * m) * (m * m) * m;
}

// A point uniform in the unit ball by rejection from the cube [-1, 1]^3
// (Shirley, "In One Weekend", sec. 8): what the independent sampler's
// stream gives a metal's fuzz (samplers with a fixed dimension layout use
// square_to_uniform_ball instead, whose count of numbers is fixed).
inline vec3 random_in_unit_ball(pcg32& rng) {
  while (true) {
    const vec3 p{2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f};
    if (glm::dot(p, p) < 1.0f) return p;
  }
}

// Metal: reflection about the facing normal plus fuzz; absorbed when the
// fuzzed direction points into the surface. ball() gives a point uniform in
// the unit ball; it is called only when the metal has fuzz.
template <class Ball>
inline bool scatter(const metal& m, const ray& in, const hit_record& rec, Ball&& ball, specular_scatter& out) {
  const vec3 n = rec.facing_normal();
  vec3 d = glm::reflect(glm::normalize(in.d), n);
  if (m.fuzz > 0.0f) d += m.fuzz * ball();
  out.r = {rec.spawn_origin(d), d};
  out.attenuation = m.albedo;
  return glm::dot(d, n) > 0.0f;
}

// Dielectric: refract or reflect, choosing by the Fresnel reflectance. u()
// gives a number uniform in [0, 1) for that choice; it is called only when
// there is a choice (not under total internal reflection).
template <class U>
inline bool scatter(const dielectric& m, const ray& in, const hit_record& rec, U&& u, specular_scatter& out) {
  const float eta = rec.front_face ? (1.0f / m.ior) : m.ior;
  const vec3 unit = glm::normalize(in.d);
  const vec3 n = rec.facing_normal();
  const float cos_t = std::min(glm::dot(-unit, n), 1.0f);
  const float sin2_t = 1.0f - cos_t * cos_t;
  vec3 d;
  if (eta * eta * sin2_t > 1.0f || schlick(cos_t, m.ior) > u()) {
    d = glm::reflect(unit, n);
  } else {
    // Snell: perpendicular and parallel parts of the refracted direction.
    const vec3 perp = eta * (unit + cos_t * n);
    d = perp - safe_sqrt(1.0f - glm::dot(perp, perp)) * n;
  }
  out.r = {rec.spawn_origin(d), d};
  out.attenuation = color(1.0f);
  return true;
}

}  // namespace mcrt
