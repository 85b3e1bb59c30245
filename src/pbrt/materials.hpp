#pragma once
// The builder's family of materials: pbrt-v4's Material and
// MakeNamedMaterial of a given type, made from the directive's parameters
// into an mcrt material (materials/material.hpp). Each kind's parameters,
// defaults and refusals follow pbrt-v4's materials.cpp (its *Material::
// Create); docs/pbrt.md lists them.
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "mcrt/mcrt.hpp"
#include "pbrt/params.hpp"
#include "pbrt/values.hpp"

namespace mcrt::pbrt {

// The index the builder gives the material "interface": no surface.
inline constexpr std::uint32_t interface_material = 0xfffffffeu;

// The material of `type`, or nothing for "interface" (and its deprecated
// name "none"): no surface, a boundary between media that rays pass
// through; refuses (parse_error at the directive) a type mcrt does not
// have. directive_name names the directive in that message; `named` maps
// the file's named materials to their indices (a "mix" names two). The
// caller refuses displacement and normalmap, and calls p.finish().
std::optional<mcrt::material> make_material(const std::string& directive_name, const std::string& type, params& p,
                                            values& v, const std::map<std::string, std::uint32_t>& named);

}  // namespace mcrt::pbrt
