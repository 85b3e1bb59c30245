#pragma once
// The independent sampler: every pixel has its own PCG32 stream, seeded from
// (seed, pixel index) by a 64-bit mix, and every draw takes the next numbers
// of that stream whatever its dimension. The pixel position alone is
// stratified: the first floor(sqrt(spp))^2 samples jitter one per cell of a
// square grid, the rest are uniform in the pixel.
//
// A sampler (this one, stratified_sampler, sobol_sampler) is made once per
// render and shared read-only by the threads; start_pixel gives the
// per-pixel generator a thread uses:
//
//   P p = sampler.start_pixel(x, y, width);
//   for i in [0, spp): p.start_sample(i);
//                      p.pixel()      -> 2-D point in the pixel, dims 0-1
//                      p.get1d(dim)   -> float in [0, 1)
//                      p.get2d(dim)   -> point in [0, 1)^2, dims dim, dim+1
//
// with the dimensions of samplers/layout.hpp. P::sequential says whether
// the draws come from one stream in call order (this sampler: then
// p.stream() is that stream, for the few draws whose count is not fixed,
// such as rejection sampling).
#include <cmath>
#include <cstdint>

#include "mcrt/core/rng.hpp"

namespace mcrt {

// The RNG of one pixel: seed and pixel index decorrelated by a 64-bit mix.
inline pcg32 pixel_rng(std::uint64_t seed, std::uint64_t pixel_index) {
  return pcg32(mix64(pixel_index ^ mix64(seed)), mix64(seed + 0x632be59bd9b4e019ULL));
}

class independent_sampler {
 public:
  independent_sampler(std::uint64_t seed, int spp)
      : seed_(seed), strata_(static_cast<int>(std::sqrt(static_cast<double>(spp)))) {}

  class pixel_sampler {
   public:
    static constexpr bool sequential = true;

    void start_sample(int index) { index_ = index; }

    vec2 pixel() {
      vec2 j = rng_.uniform2();
      if (index_ < strata_ * strata_)
        j = (vec2(static_cast<float>(index_ % strata_), static_cast<float>(index_ / strata_)) + j) * inv_strata_;
      return j;
    }
    float get1d(int /*dim*/) { return rng_.uniform(); }
    vec2 get2d(int /*dim*/) { return rng_.uniform2(); }
    pcg32& stream() { return rng_; }

   private:
    friend class independent_sampler;
    pixel_sampler(pcg32 rng, int strata)
        : rng_(rng), strata_(strata), inv_strata_(1.0f / static_cast<float>(strata > 0 ? strata : 1)) {}
    pcg32 rng_;
    int strata_;
    float inv_strata_;
    int index_ = 0;
  };

  pixel_sampler start_pixel(int x, int y, int width) const {
    const std::uint64_t index = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(width) + static_cast<std::uint64_t>(x);
    return {pixel_rng(seed_, index), strata_};
  }

 private:
  std::uint64_t seed_;
  int strata_;
};

}  // namespace mcrt
