#pragma once
// The path tracer's estimators, one per header, selectable by name:
//   mixture (mixture_integrator.hpp)  Shirley's 50/50 mixture of the lights'
//                                     pdf and the material's pdf;
//   nee     (nee_integrator.hpp)      next-event estimation: a light sample
//                                     and a shadow ray at each diffuse bounce;
//   mis     (mis_integrator.hpp)      both techniques, weighted by the power
//                                     (or balance) heuristic.
// All three estimate the same image. An integrator is a type with
//   template <class Scene, class P> static color li(const Scene&, ray, P&, const path_settings&);
// the radiance along the camera ray, P a pixel sampler (samplers/).
#include <string_view>

#include "mcrt/render/mis_integrator.hpp"
#include "mcrt/render/mixture_integrator.hpp"
#include "mcrt/render/nee_integrator.hpp"

namespace mcrt {

enum class integrator_kind { mixture, nee, mis };

// Calls f.template operator()<Integrator>() for the integrator named by k.
template <class F>
decltype(auto) with_integrator(integrator_kind k, F&& f) {
  switch (k) {
    case integrator_kind::nee: return f.template operator()<nee_integrator>();
    case integrator_kind::mis: return f.template operator()<mis_integrator>();
    default: return f.template operator()<mixture_integrator>();
  }
}

constexpr std::string_view to_string(integrator_kind k) {
  return k == integrator_kind::nee ? "nee" : k == integrator_kind::mis ? "mis" : "mixture";
}

}  // namespace mcrt
