#pragma once
// The BSDFs pbrt-v4 scenes need, in the local shading frame (conventions in
// bsdf_sample.hpp): Lambertian, conductor (smooth mirror or rough
// Torrance-Sparrow), dielectric (smooth or rough, reflection and
// transmission) and thin dielectric, with the Fresnel terms, the
// Trowbridge-Reitz distribution and the shading frame they are built on;
// Lambertian reflection with Lambertian transmission; two interfaces with
// a scattering slab between them (layered_bsdf.hpp), whose triplet is
// estimated by random walks.
#include "mcrt/materials/bsdf_sample.hpp"
#include "mcrt/materials/conductor_bsdf.hpp"
#include "mcrt/materials/dielectric_bsdf.hpp"
#include "mcrt/materials/diffuse_bsdf.hpp"
#include "mcrt/materials/diffuse_transmission_bsdf.hpp"
#include "mcrt/materials/fresnel.hpp"
#include "mcrt/materials/henyey_greenstein.hpp"
#include "mcrt/materials/layered_bsdf.hpp"
#include "mcrt/materials/shading_frame.hpp"
#include "mcrt/materials/trowbridge_reitz.hpp"
