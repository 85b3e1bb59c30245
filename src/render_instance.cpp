// One (integrator, sampler) pair of the executable's renderer, compiled once
// per pair with MCRT_INTEGRATOR and MCRT_SAMPLER defined to their names (see
// render_instances.hpp for why each pair has a unit of its own).
#include "render_instances.hpp"

// Token pasting of the macros' values (two levels, so they expand first).
#define MCRT_JOIN_(a, b, c, d) a##b##c##d
#define MCRT_JOIN(a, b, c, d) MCRT_JOIN_(a, b, c, d)

namespace mcrt::cli {

render_result MCRT_JOIN(render_, MCRT_INTEGRATOR, _, MCRT_SAMPLER)(const scene& sc, const camera& cam,
                                                                   const render_settings& rs,
                                                                   const progress_callback& progress) {
  using integrator = MCRT_JOIN(, MCRT_INTEGRATOR, _, integrator);
  using sampler = MCRT_JOIN(, MCRT_SAMPLER, _, sampler);
  return render_with<integrator, sampler>(sc, cam, rs, progress);
}

}  // namespace mcrt::cli
