#pragma once
// The builder's family of materials: pbrt-v4's Material and
// MakeNamedMaterial of a given type, made from the directive's parameters
// into an mcrt material (materials/material.hpp). Each kind's parameters,
// defaults and refusals follow pbrt-v4's materials.cpp (its *Material::
// Create); docs/pbrt.md lists them.
#include <optional>
#include <string>

#include "mcrt/mcrt.hpp"
#include "pbrt/params.hpp"
#include "pbrt/values.hpp"

namespace mcrt::pbrt {

// The material of `type`, or nothing for "interface" (and its deprecated
// name "none"): no surface, a boundary between media that rays pass
// through; refuses (parse_error at the directive) a type mcrt does not
// have. directive_name names the directive in that message. The caller
// refuses displacement and normalmap, and calls p.finish().
std::optional<mcrt::material> make_material(const std::string& directive_name, const std::string& type, params& p,
                                            values& v);

}  // namespace mcrt::pbrt
