#include "pbrt/materials.hpp"

#include <cmath>
#include <memory>
#include <utility>

namespace mcrt::pbrt {
namespace {

// pbrt-v4's roughness parameters: uroughness and vroughness, each
// `roughness` (default 0) where absent, each name after `prefix`
// ("interface." and "conductor." for coatedconductor); remaproughness
// (default true).
microfacet_roughness roughness(params& p, values& v, const std::string& prefix = "") {
  microfacet_roughness r;
  const std::string both_name = prefix + "roughness", u_name = prefix + "uroughness", v_name = prefix + "vroughness";
  const std::shared_ptr<const texture> both = v.float_texture(p, both_name, 0.0f);
  r.u = p.find(u_name) ? v.float_texture(p, u_name, 0.0f) : both;
  r.v = p.find(v_name) ? v.float_texture(p, v_name, 0.0f) : both;
  r.remap = p.boolean("remaproughness", true);
  // A roughness below 0 has no meaning (alpha is its square root); a
  // texture below 0 is taken as 0 where it is evaluated.
  for (const std::string& name : {both_name, u_name, v_name})
    if (const param* q = p.find(name); q && q->type == "float" && q->numbers.size() == 1 && q->numbers[0] < 0.0)
      p.fail(*q, "must be >= 0");
  return r;
}

// A dielectric's IOR `name` (eta, interface.eta): a float or a spectrum
// (default 1.5). One IOR for the three channels: a named glass's at 550 nm,
// a sampled spectrum's at 532 nm (mcrt renders no dispersion).
float ior(params& p, values& v, const std::string& name = "eta") {
  float eta = 1.5f;
  if (const param* e = p.find(name)) {
    if (e->type == "float") {
      eta = static_cast<float>(p.real(name, 1.5));
    } else if (e->type == "spectrum") {
      eta = v.spectrum(p, name, spectrum_use::unbounded)->g;
    } else {
      p.fail(*e, "must be a float or a spectrum (textured IORs are not supported)");
    }
    if (!(eta > 0.0f) || !std::isfinite(eta)) p.fail(*e, "must be > 0");
  }
  return eta;
}

// A conductor's IOR: `reflectance`, or eta and k (names after `prefix`),
// copper by default; and its roughness.
conductor_material conductor(params& p, values& v, const std::string& prefix = "") {
  conductor_material c;
  const std::string eta_name = prefix + "eta", k_name = prefix + "k";
  const bool has_ior = p.find(eta_name) || p.find(k_name);
  if (p.find("reflectance")) {
    if (has_ior) p.fail("gives both reflectance and " + eta_name + "/" + k_name + " (pbrt-v4 refuses that too)");
    c.reflectance = v.spectrum_texture(p, "reflectance", color(0.0f));
  } else {
    // pbrt-v4's default conductor is copper.
    std::string why;
    c.eta = v.spectrum_texture(p, eta_name, *named_spectrum_rgb("metal-Cu-eta", spectrum_use::unbounded, why),
                               spectrum_use::unbounded);
    c.k = v.spectrum_texture(p, k_name, *named_spectrum_rgb("metal-Cu-k", spectrum_use::unbounded, why),
                             spectrum_use::unbounded);
    // A conductor's complex IOR eta + i k has eta >= 0 and k >= 0 (a
    // texture below 0 is taken as 0 where it is evaluated).
    for (const auto& [name, tex] : {std::pair{eta_name, c.eta}, std::pair{k_name, c.k}})
      if (tex->is_constant() && glm::any(glm::lessThan(tex->value, color(0.0f))))
        p.fail(*p.find(name), "must not be negative");
  }
  c.roughness = roughness(p, v, prefix);
  return c;
}

// What coateddiffuse and coatedconductor share (pbrt-v4's defaults):
// thickness 0.01, albedo 0, g 0, maxdepth 10, nsamples 1.
layer_parameters layer(params& p, values& v) {
  layer_parameters l;
  l.thickness = v.float_texture(p, "thickness", 0.01f);
  l.albedo = v.spectrum_texture(p, "albedo", color(0.0f));
  l.g = v.float_texture(p, "g", 0.0f);
  // Bounds pbrt-v4 does not check: nsamples 0 would divide by 0, and the
  // cost of every estimate grows with both (1000 walks of 1000 events per
  // evaluation is already hours a frame).
  l.max_depth = p.integer("maxdepth", 10);
  l.n_samples = p.integer("nsamples", 1);
  if (l.max_depth < 0 || l.max_depth > 1000) p.fail(*p.find("maxdepth"), "must be in [0, 1000]");
  if (l.n_samples < 1 || l.n_samples > 1000) p.fail(*p.find("nsamples"), "must be in [1, 1000]");
  if (const param* q = p.find("thickness"); q && q->type == "float" && !(q->numbers.at(0) >= 0.0))
    p.fail(*q, "must be >= 0");
  return l;
}

}  // namespace

std::optional<mcrt::material> make_material(const std::string& directive_name, const std::string& type, params& p,
                                            values& v, const std::map<std::string, std::uint32_t>& named) {
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
    m = conductor(p, v);
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
  } else if (type == "coateddiffuse") {
    // pbrt-v4's CoatedDiffuseMaterial::Create.
    auto c = std::make_shared<coated_diffuse_parameters>();
    c->reflectance = v.spectrum_texture(p, "reflectance", color(0.5f));
    c->eta = ior(p, v);
    c->roughness = roughness(p, v);
    c->layer = layer(p, v);
    m = coated_diffuse_material{c};
  } else if (type == "coatedconductor") {
    // pbrt-v4's CoatedConductorMaterial::Create.
    auto c = std::make_shared<coated_conductor_parameters>();
    c->interface_eta = ior(p, v, "interface.eta");
    c->interface_roughness = roughness(p, v, "interface.");
    c->conductor = conductor(p, v, "conductor.");
    c->layer = layer(p, v);
    m = coated_conductor_material{c};
  } else if (type == "mix") {
    // pbrt-v4's MixMaterial: "materials", two named materials defined
    // before (not interface), and "amount" (default 0.5), the second's
    // probability.
    const param* q = p.find("materials");
    if (!q) p.fail("has no \"string materials\" (two named materials)");
    p.expect_type(*q, {"string"});
    if (q->strings.size() != 2) p.fail(*q, "must name two materials");
    mix_material mx;
    for (int i = 0; i < 2; ++i) {
      const auto it = named.find(q->strings[i]);
      if (it == named.end()) p.fail(*q, "names no material " + quoted(q->strings[i]) + " (MakeNamedMaterial before)");
      if (it->second == interface_material)
        p.fail(*q, quoted(q->strings[i]) + " is an interface material, which a mix cannot hold (as in pbrt-v4)");
      (i == 0 ? mx.first : mx.second) = it->second;
    }
    mx.amount = v.float_texture(p, "amount", 0.5f);
    m = mx;
  } else {
    refuse(p.loc(), directive_name + " " + quoted(type) +
                        ": not supported (supported: diffuse, conductor, dielectric, thindielectric, "
                        "diffusetransmission, coateddiffuse, coatedconductor, mix, interface)");
  }
  return m;
}

}  // namespace mcrt::pbrt
