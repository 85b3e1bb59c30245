#pragma once
// Spectrum- and texture-valued parameters, shared by the builder's families:
// a spectrum as linear sRGB (spectrum.hpp), and a parameter that may name a
// texture of the file (Texture directives, kept here by name) or give a
// constant.
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "mcrt/mcrt.hpp"
#include "pbrt/params.hpp"
#include "pbrt/spectrum.hpp"

namespace mcrt::pbrt {

// A texture in the file: spectrum or float, by name.
struct texture_entry {
  std::shared_ptr<const texture> tex;
  bool is_float = false;
};

class values {
 public:
  std::map<std::string, texture_entry> spectrum_textures, float_textures;

  // A spectrum-valued parameter as linear sRGB: rgb as it is, blackbody
  // normalised to luminance 1 (spectrum.hpp), spectrum values by their
  // conversion there.
  std::optional<color> spectrum(params& p, const std::string& name, spectrum_use use) {
    const param* q = p.find(name);
    if (!q) return std::nullopt;
    if (q->type == "rgb" || q->type == "color") {
      const color c(float(q->numbers[0]), float(q->numbers[1]), float(q->numbers[2]));
      if (use != spectrum_use::unbounded && (c.r < 0.0f || c.g < 0.0f || c.b < 0.0f)) p.fail(*q, "must not be negative");
      return c;
    }
    if (q->type == "blackbody") {
      if (q->numbers.size() != 1 || !(q->numbers[0] > 0.0)) p.fail(*q, "must be one temperature > 0 (kelvin)");
      return blackbody_rgb(q->numbers[0]);
    }
    if (q->type == "spectrum") {
      std::string why;
      const std::optional<color> c = q->strings.empty() ? sampled_spectrum_rgb(q->numbers, use, why)
                                                        : named_spectrum_rgb(q->strings[0], use, why);
      if (!c) p.fail(*q, why);
      return c;
    }
    p.fail(*q, "must be of type rgb, blackbody or spectrum");
  }

  // A material parameter that may be a texture: its texture, or a constant
  // one from the value (def where the parameter is absent).
  std::shared_ptr<const texture> spectrum_texture(params& p, const std::string& name, const color& def,
                                                  spectrum_use use = spectrum_use::albedo) {
    const param* q = p.find(name);
    if (q && q->type == "texture") {
      const auto it = spectrum_textures.find(q->strings.at(0));
      if (it != spectrum_textures.end()) return it->second.tex;
      const auto fit = float_textures.find(q->strings.at(0));
      if (fit != float_textures.end()) return fit->second.tex;  // a float texture as a grey spectrum
      p.fail(*q, "names no texture " + quoted(q->strings.at(0)));
    }
    return std::make_shared<texture>(texture::constant(spectrum(p, name, use).value_or(def)));
  }
  std::shared_ptr<const texture> float_texture(params& p, const std::string& name, float def) {
    const param* q = p.find(name);
    if (q && q->type == "texture") {
      const auto it = float_textures.find(q->strings.at(0));
      if (it == float_textures.end()) p.fail(*q, "names no float texture " + quoted(q->strings.at(0)));
      return it->second.tex;
    }
    const float v = static_cast<float>(p.real(name, def));
    return std::make_shared<texture>(texture::constant(color(v)));
  }
};

}  // namespace mcrt::pbrt
