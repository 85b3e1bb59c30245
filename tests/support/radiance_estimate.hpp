#pragma once
// The radiance a fixed ray brings back through a scene, estimated by one
// integrator fed by one sample generator, with a standard error from
// independent replicates: the references of the closed-form render tests.
//
// Replicate r is pixel (point_id, r) of the sample generator, so for the
// stratified and Sobol generators each replicate is an independent
// scrambling; the standard error is that of the mean of the replicate
// means (the samples of one stratified or Sobol pixel are not independent).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "mcrt/mcrt.hpp"

namespace mcrt::test {

struct estimate {
  double mean, stderr_;
};

// fp: a pixel's footprint for the lights `auto` samples at the ray's first
// surface (sampling/auto_footprint.hpp), where the integrator takes one.
template <class I, class S>
estimate radiance_along(const scene& sc, const ray& r, const path_settings& set, int replicates, int samples,
                        int point_id, std::uint64_t seed, const auto_footprint* fp = nullptr) {
  const S sampler(seed, samples);
  double s = 0.0, s2 = 0.0;
  for (int k = 0; k < replicates; ++k) {
    auto ps = sampler.start_pixel(point_id, k, 1024);
    double sum = 0.0;
    for (int i = 0; i < samples; ++i) {
      ps.start_sample(i);
      if constexpr (requires { I::li(sc, r, ps, set, fp); })
        sum += I::li(sc, r, ps, set, fp).r;
      else
        sum += I::li(sc, r, ps, set).r;
    }
    const double m = sum / samples;
    s += m;
    s2 += m * m;
  }
  const double mean = s / replicates;
  const double var = std::max(s2 / replicates - mean * mean, 0.0) * replicates / (replicates - 1);
  return {mean, std::sqrt(var / replicates)};
}

// The same with the integrator and the sample generator chosen at run time.
inline estimate radiance_along(const scene& sc, const ray& r, const path_settings& set, integrator_kind ik,
                               sampler_kind sk, int replicates, int samples, int point_id, std::uint64_t seed,
                               const auto_footprint* fp = nullptr) {
  return with_integrator(ik, [&]<class I>() {
    return with_sampler(sk, [&]<class S>() {
      return radiance_along<I, S>(sc, r, set, replicates, samples, point_id, seed, fp);
    });
  });
}

}  // namespace mcrt::test
