#include "render_instances.hpp"

namespace mcrt::cli {

render_result render_scene(const scene& sc, const camera& cam, const render_settings& rs, const progress_callback& progress) {
#define MCRT_PAIR(I, S) \
  if (rs.integrator == integrator_kind::I && rs.sampler == sampler_kind::S) return render_##I##_##S(sc, cam, rs, progress);
  MCRT_PAIR(mixture, independent)
  MCRT_PAIR(mixture, stratified)
  MCRT_PAIR(mixture, sobol)
  MCRT_PAIR(nee, independent)
  MCRT_PAIR(nee, stratified)
  MCRT_PAIR(nee, sobol)
  MCRT_PAIR(mis, independent)
  MCRT_PAIR(mis, stratified)
  MCRT_PAIR(mis, sobol)
#undef MCRT_PAIR
  throw std::logic_error("render_scene: unknown integrator or sampler");
}

}  // namespace mcrt::cli
