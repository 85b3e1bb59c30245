#include "pbrt/materials.hpp"

#include <cmath>
#include <memory>
#include <utility>

namespace mcrt::pbrt {
namespace {

// pbrt-v4's roughness parameters: uroughness and vroughness, each
// `roughness` (default 0) where absent; remaproughness (default true).
microfacet_roughness roughness(params& p, values& v) {
  microfacet_roughness r;
  const std::shared_ptr<const texture> both = v.float_texture(p, "roughness", 0.0f);
  r.u = p.find("uroughness") ? v.float_texture(p, "uroughness", 0.0f) : both;
  r.v = p.find("vroughness") ? v.float_texture(p, "vroughness", 0.0f) : both;
  r.remap = p.boolean("remaproughness", true);
  // A roughness below 0 has no meaning (alpha is its square root); a
  // texture below 0 is taken as 0 where it is evaluated.
  for (const char* name : {"roughness", "uroughness", "vroughness"})
    if (const param* q = p.find(name); q && q->type == "float" && q->numbers.size() == 1 && q->numbers[0] < 0.0)
      p.fail(*q, "must be >= 0");
  return r;
}

// A dielectric's IOR `eta`: a float or a spectrum (default 1.5). One IOR for
// the three channels: a named glass's at 550 nm, a sampled spectrum's at
// 532 nm (mcrt renders no dispersion).
float ior(params& p, values& v) {
  float eta = 1.5f;
  if (const param* e = p.find("eta")) {
    if (e->type == "float") {
      eta = static_cast<float>(p.real("eta", 1.5));
    } else if (e->type == "spectrum") {
      eta = v.spectrum(p, "eta", spectrum_use::unbounded)->g;
    } else {
      p.fail(*e, "must be a float or a spectrum (textured IORs are not supported)");
    }
    if (!(eta > 0.0f) || !std::isfinite(eta)) p.fail(*e, "must be > 0");
  }
  return eta;
}

}  // namespace

std::optional<mcrt::material> make_material(const std::string& directive_name, const std::string& type, params& p,
                                            values& v) {
  // pbrt-v4's MaterialHandle::Create: "interface" (and the deprecated "none")
  // is no material at all.
  if (type == "interface" || type == "none") return std::nullopt;
  mcrt::material m;
  if (type == "diffuse") {
    const std::shared_ptr<const texture> r = v.spectrum_texture(p, "reflectance", color(0.5f));
    if (r->is_constant())
      m = lambertian{glm::clamp(r->value, color(0.0f), color(1.0f))};
    else
      m = textured_diffuse{*r};
  } else if (type == "conductor") {
    conductor_material c;
    const bool has_ior = p.find("eta") || p.find("k");
    if (p.find("reflectance")) {
      if (has_ior) p.fail("gives both reflectance and eta/k (pbrt-v4 refuses that too)");
      c.reflectance = v.spectrum_texture(p, "reflectance", color(0.0f));
    } else {
      // pbrt-v4's default conductor is copper.
      std::string why;
      c.eta = v.spectrum_texture(p, "eta", *named_spectrum_rgb("metal-Cu-eta", spectrum_use::unbounded, why),
                               spectrum_use::unbounded);
      c.k = v.spectrum_texture(p, "k", *named_spectrum_rgb("metal-Cu-k", spectrum_use::unbounded, why),
                             spectrum_use::unbounded);
      // A conductor's complex IOR eta + i k has eta >= 0 and k >= 0 (a
      // texture below 0 is taken as 0 where it is evaluated).
      for (const auto& [name, tex] : {std::pair{"eta", c.eta}, std::pair{"k", c.k}})
        if (tex->is_constant() && glm::any(glm::lessThan(tex->value, color(0.0f))))
          p.fail(*p.find(name), "must not be negative");
    }
    c.roughness = roughness(p, v);
    m = c;
  } else if (type == "dielectric") {
    dielectric_material g;
    g.eta = ior(p, v);
    g.roughness = roughness(p, v);
    m = g;
  } else if (type == "thindielectric") {
    // pbrt-v4's ThinDielectricMaterial::Create: eta (float or spectrum,
    // default 1.5); no roughness (a thin slab is smooth).
    m = thin_dielectric_material{ior(p, v)};
  } else if (type == "diffusetransmission") {
    // pbrt-v4's DiffuseTransmissionMaterial::Create: reflectance and
    // transmittance 0.25 by default, scale 1; scale times each is clamped
    // to [0, 1] at the hit (a negative scale makes the sheet black, as in
    // pbrt-v4).
    diffuse_transmission_material t;
    t.reflectance = v.spectrum_texture(p, "reflectance", color(0.25f));
    t.transmittance = v.spectrum_texture(p, "transmittance", color(0.25f));
    t.scale = static_cast<float>(p.real("scale", 1.0));
    m = t;
  } else {
    refuse(p.loc(), directive_name + " " + quoted(type) +
                        ": not supported (supported: diffuse, conductor, dielectric, thindielectric, diffusetransmission, interface)");
  }
  return m;
}

}  // namespace mcrt::pbrt
