#pragma once
// The executable's renderer: the integrator and sample generator named in
// render_settings, each pair compiled in a translation unit of its own
// (render_instance.cpp, built once per pair by src/CMakeLists.txt). The
// compiler's inlining of one pair then does not depend on which other pairs
// the program holds, and with it neither does the fusion of multiplies and
// adds into FMA instructions: the mixture integrator with the independent
// sampler gives, bit for bit, the images of the program before samplers
// and integrators were selectable (all pairs in one unit did not). With
// link-time optimisation (MCRT_LTO) the link optimises the units together;
// the default image stays bit for bit that of a build without it
// (bench/first_contact.sh compares them).
#include "mcrt/mcrt.hpp"

namespace mcrt::cli {

render_result render_scene(const scene& sc, const camera& cam, const render_settings& rs, const progress_callback& progress);

#define MCRT_DECLARE_RENDER_INSTANCE(I, S) \
  render_result render_##I##_##S(const scene&, const camera&, const render_settings&, const progress_callback&);
MCRT_DECLARE_RENDER_INSTANCE(mixture, independent)
MCRT_DECLARE_RENDER_INSTANCE(mixture, stratified)
MCRT_DECLARE_RENDER_INSTANCE(mixture, sobol)
MCRT_DECLARE_RENDER_INSTANCE(nee, independent)
MCRT_DECLARE_RENDER_INSTANCE(nee, stratified)
MCRT_DECLARE_RENDER_INSTANCE(nee, sobol)
MCRT_DECLARE_RENDER_INSTANCE(mis, independent)
MCRT_DECLARE_RENDER_INSTANCE(mis, stratified)
MCRT_DECLARE_RENDER_INSTANCE(mis, sobol)
#undef MCRT_DECLARE_RENDER_INSTANCE

}  // namespace mcrt::cli
