#pragma once
// The sample generators, selectable by name (sampler interface:
// independent.hpp; dimension layout: layout.hpp):
//   independent  a PCG32 stream per pixel;
//   stratified   jittered strata per dimension and dimension pair;
//   sobol        Owen-scrambled Sobol points, one pair of dimensions per 2-D draw.
#include <string_view>

#include "mcrt/samplers/independent.hpp"
#include "mcrt/samplers/sobol_sampler.hpp"
#include "mcrt/samplers/stratified.hpp"

namespace mcrt {

enum class sampler_kind { independent, stratified, sobol };

// Calls f.template operator()<Sampler>() for the sampler named by k.
template <class F>
decltype(auto) with_sampler(sampler_kind k, F&& f) {
  switch (k) {
    case sampler_kind::stratified: return f.template operator()<stratified_sampler>();
    case sampler_kind::sobol: return f.template operator()<sobol_sampler>();
    default: return f.template operator()<independent_sampler>();
  }
}

constexpr std::string_view to_string(sampler_kind k) {
  return k == sampler_kind::stratified ? "stratified" : k == sampler_kind::sobol ? "sobol" : "independent";
}

}  // namespace mcrt
