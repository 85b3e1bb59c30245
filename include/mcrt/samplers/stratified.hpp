#pragma once
// The stratified (jittered) sampler, after pbrt-v4's StratifiedSampler
// (Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed., sec. 8.5),
// with the interface of samplers/independent.hpp and the dimensions of
// samplers/layout.hpp.
//
// Each draw -- a 1-D dimension d, or a 2-D pair (d, d+1) -- stratifies the
// spp samples of a pixel on its own:
//   1-D   [0, 1) is cut into spp strata of length 1/spp;
//   2-D   [0, 1)^2 is cut into nx x ny = spp cells, nx columns along x and
//         ny rows along y, of area 1/spp each.
// Sample i of the pixel takes stratum permute(i, strata, p_d) (Kensler's
// random-access permutation, samplers/hash.hpp) with p_d the low 32 bits of
// h_d = hash(sampler seed, pixel x, pixel y, d), so every stratum holds
// exactly one of the spp samples, and the strata of different dimensions
// are matched at random (pbrt's "padding" of 1-D and 2-D stratified
// patterns by a per-dimension permutation); the point is then uniform in its
// stratum, jittered by hash(h_d, i). Every value depends on (seed, pixel,
// sample index, dimension) only, never on the draws made before.
//
// An spp that is not a square. nx is the largest divisor of spp that is not
// above sqrt(spp), ny = spp / nx >= nx: 16 -> 4 x 4, 12 -> 3 x 4, 8 -> 2 x 4,
// 100 -> 10 x 10, 7 (prime) -> 1 x 7, i.e. 7 horizontal strips, uniform in x.
// Every sample still owns a cell of area 1/spp, but cells are taller than
// wide when spp is not a square, and a prime spp stratifies y alone (pbrt
// instead asks for nx and ny and renders nx * ny samples; here the renderer's
// spp is kept exactly). Unlike the independent sampler, no sample is left
// over: spp = nx * ny always.
//
// Exactness. The strata boundaries are multiples of 1/n (n = spp, nx or ny)
// while the floats returned are multiples of 2^-24; stratum s of n gets the
// grid values v 2^-24 with ceil(s 2^24 / n) <= v < ceil((s+1) 2^24 / n),
// computed in integers, and the jitter picks one of them uniformly (24
// bits). So a value always lies in its own stratum (never rounded into the
// next one, never 1.0f); n <= 2^24 leaves at least one grid value per
// stratum.
#include <cmath>
#include <cstdint>

#include "mcrt/core/math.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/samplers/hash.hpp"
#include "mcrt/samplers/layout.hpp"

namespace mcrt {

namespace stratified_detail {

// Largest strata count along x: the largest divisor of n not above sqrt(n).
constexpr int columns_for(int n) {
  if (n <= 1) return 1;
  int r = 1;
  while ((r + 1) * (r + 1) <= n) ++r;  // r = floor(sqrt(n)); n <= 2^20, so at most 1024 steps, once per render
  while (n % r != 0) --r;
  return r;
}

// The 24-bit value of stratum s of n (0 <= s < n <= 2^24) jittered by the
// top 24 bits of the 32-bit `jitter`, as a float (see "Exactness" above).
inline float stratum_point(std::uint32_t s, std::uint32_t n, std::uint32_t jitter) {
  constexpr std::uint64_t one = 1ull << 24;
  const std::uint64_t lo = (static_cast<std::uint64_t>(s) * one + n - 1) / n;
  const std::uint64_t hi = (static_cast<std::uint64_t>(s + 1) * one + n - 1) / n;
  const std::uint64_t v = lo + (((hi - lo) * (jitter >> 8)) >> 24);
  return static_cast<float>(v) * 0x1p-24f;
}

}  // namespace stratified_detail

class stratified_sampler {
 public:
  stratified_sampler(std::uint64_t seed, int spp)
      : seed_hash_(mix64(seed)),
        spp_(static_cast<std::uint32_t>(spp < 1 ? 1 : spp)),
        nx_(static_cast<std::uint32_t>(stratified_detail::columns_for(static_cast<int>(spp_)))),
        ny_(spp_ / nx_) {}

  // The 2-D strata grid: columns along x, rows along y (columns * rows == spp).
  int columns() const { return static_cast<int>(nx_); }
  int rows() const { return static_cast<int>(ny_); }

  class pixel_sampler {
   public:
    static constexpr bool sequential = false;

    void start_sample(int index) { index_ = static_cast<std::uint32_t>(index); }

    vec2 pixel() { return get2d(layout::pixel); }

    float get1d(int dim) const {
      const std::uint64_t h = hash_combine(pixel_hash_, static_cast<std::uint64_t>(dim));
      const std::uint32_t s = permute(index_, spp_, static_cast<std::uint32_t>(h));
      const std::uint64_t jitter = hash_combine(h, index_);
      return stratified_detail::stratum_point(s, spp_, static_cast<std::uint32_t>(jitter >> 32));
    }

    vec2 get2d(int dim) const {
      const std::uint64_t h = hash_combine(pixel_hash_, static_cast<std::uint64_t>(dim));
      const std::uint32_t s = permute(index_, spp_, static_cast<std::uint32_t>(h));
      const std::uint64_t jitter = hash_combine(h, index_);
      return {stratified_detail::stratum_point(s % nx_, nx_, static_cast<std::uint32_t>(jitter >> 32)),
              stratified_detail::stratum_point(s / nx_, ny_, static_cast<std::uint32_t>(jitter))};
    }

   private:
    friend class stratified_sampler;
    pixel_sampler(std::uint64_t pixel_hash, std::uint32_t spp, std::uint32_t nx, std::uint32_t ny)
        : pixel_hash_(pixel_hash), spp_(spp), nx_(nx), ny_(ny) {}
    std::uint64_t pixel_hash_;
    std::uint32_t spp_, nx_, ny_;
    std::uint32_t index_ = 0;
  };

  pixel_sampler start_pixel(int x, int y, int /*width*/) const {
    return {hash_combine(hash_combine(seed_hash_, static_cast<std::uint64_t>(x)), static_cast<std::uint64_t>(y)), spp_,
            nx_, ny_};
  }

 private:
  std::uint64_t seed_hash_;
  std::uint32_t spp_, nx_, ny_;
};

}  // namespace mcrt
