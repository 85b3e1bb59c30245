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
// Sample i of the pixel takes stratum P_d(i), P_d the Kensler random-access
// permutation of [0, spp) (samplers/hash.hpp, kensler_domain) keyed by
// h_d = hash(sampler seed, pixel x, pixel y, d) and rotated by a second hash
// of h_d, so every stratum holds exactly one of the spp samples, and the
// strata of different dimensions are matched at random (pbrt's "padding" of
// 1-D and 2-D stratified patterns by a per-dimension permutation); the point
// is then uniform in its stratum, jittered by hash(h_d, i) (24 bits per
// coordinate). The strata of a 2-D cell index c are column c mod nx, row
// c div nx. Every value depends on (seed, pixel, sample index, dimension)
// only, never on the draws made before.
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
// stratum. The divisions by n are multiplications by a reciprocal computed
// once per render, with a one-step correction that makes them exact
// (exact_divider below), so a draw uses no hardware division.
//
// Cost. The 64-bit seeds h_d of the first `cached_bounces` bounces, and the
// permutations' rotations, are computed once in start_pixel and kept in the
// pixel_sampler (fixed arrays, 360 bytes); a draw then costs one Kensler
// permutation (five hash rounds, applied fewer than two times on average),
// one mix64 for the jitter and the exact divisions -- about 4-5 times a
// sobol_sampler draw (bench/bench_samplers_sequences.cpp), the permutation's
// chain of dependent rounds being most of it.
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

// floor(a / n) for any 64-bit a and 32-bit n >= 1, by one multiplication:
// with m = floor((2^64 - 1) / n), 0 < 2^64 - m n <= n, so a m / 2^64 lies in
// (a / n - 1, a / n] and q = floor(a m / 2^64) is floor(a / n) or one less;
// one comparison corrects it.
class exact_divider {
 public:
  constexpr explicit exact_divider(std::uint32_t n) : n_(n < 1 ? 1 : n), m_(~std::uint64_t{0} / n_) {}
  constexpr std::uint64_t divisor() const { return n_; }
  constexpr std::uint64_t floor_div(std::uint64_t a) const {
#ifdef __SIZEOF_INT128__
    __extension__ using u128 = unsigned __int128;
    const auto q = static_cast<std::uint64_t>((static_cast<u128>(a) * m_) >> 64);
    return q + ((q + 1) * n_ <= a ? 1u : 0u);
#else
    return a / n_;
#endif
  }
  constexpr std::uint64_t ceil_div(std::uint64_t a) const { return floor_div(a + n_ - 1); }

 private:
  std::uint64_t n_, m_;
};

// The 24-bit value of stratum s of n = div.divisor() (0 <= s < n <= 2^24)
// jittered by the top 24 bits of the 32-bit `jitter`, as a float (see
// "Exactness" above).
constexpr float stratum_point(std::uint32_t s, const exact_divider& div, std::uint32_t jitter) {
  constexpr std::uint64_t one = 1ull << 24;
  const std::uint64_t lo = div.ceil_div(static_cast<std::uint64_t>(s) * one);
  const std::uint64_t hi = div.ceil_div(static_cast<std::uint64_t>(s + 1) * one);
  const std::uint64_t v = lo + (((hi - lo) * (jitter >> 8)) >> 24);
  return static_cast<float>(v) * 0x1p-24f;
}

}  // namespace stratified_detail

class stratified_sampler {
 public:
  // Bounces whose per-dimension seeds are cached by start_pixel.
  static constexpr int cached_bounces = 4;
  static constexpr int cached_dims = layout::bounce(cached_bounces);  // 30 dimensions

  stratified_sampler(std::uint64_t seed, int spp)
      : seed_hash_(mix64(seed)),
        perm_(static_cast<std::uint32_t>(spp < 1 ? 1 : spp)),
        spp_(perm_.size()),
        nx_(static_cast<std::uint32_t>(stratified_detail::columns_for(static_cast<int>(perm_.size())))),
        ny_(perm_.size() / static_cast<std::uint32_t>(nx_.divisor())) {}

  // The 2-D strata grid: columns along x, rows along y (columns * rows == spp).
  int columns() const { return static_cast<int>(nx_.divisor()); }
  int rows() const { return static_cast<int>(ny_.divisor()); }

  class pixel_sampler {
   public:
    static constexpr bool sequential = false;

    void start_sample(int index) { index_ = static_cast<std::uint32_t>(index); }

    vec2 pixel() { return get2d(layout::pixel); }

    float get1d(int dim) const {
      std::uint64_t h;
      std::uint32_t r;
      seed(dim, h, r);
      const std::uint32_t s = perm_(index_, h, r);
      const std::uint64_t jitter = hash_combine(h, index_);
      return stratified_detail::stratum_point(s, spp_, static_cast<std::uint32_t>(jitter >> 32));
    }

    vec2 get2d(int dim) const {
      std::uint64_t h;
      std::uint32_t r;
      seed(dim, h, r);
      const std::uint32_t s = perm_(index_, h, r);
      const auto row = static_cast<std::uint32_t>(nx_.floor_div(s));
      const auto column = s - row * static_cast<std::uint32_t>(nx_.divisor());
      const std::uint64_t jitter = hash_combine(h, index_);
      return {stratified_detail::stratum_point(column, nx_, static_cast<std::uint32_t>(jitter >> 32)),
              stratified_detail::stratum_point(row, ny_, static_cast<std::uint32_t>(jitter))};
    }

   private:
    friend class stratified_sampler;
    pixel_sampler(const stratified_sampler& s, std::uint64_t pixel_hash)
        : perm_(s.perm_), spp_(s.spp_), nx_(s.nx_), ny_(s.ny_), pixel_hash_(pixel_hash) {
      for (int d = 0; d < cached_dims; ++d) make_seed(d, seeds_[d], rotations_[d]);
    }

    // The permutation of dimension d: its key h_d = hash(seed, x, y, d) and
    // its rotation, uniform in [0, spp) (Lemire's multiply-shift range
    // reduction of a second hash of h_d).
    void make_seed(int d, std::uint64_t& h, std::uint32_t& r) const {
      h = hash_combine(pixel_hash_, static_cast<std::uint64_t>(d));
      r = static_cast<std::uint32_t>(((mix64(h) >> 32) * perm_.size()) >> 32);
    }
    void seed(int d, std::uint64_t& h, std::uint32_t& r) const {
      if (d < cached_dims) {
        h = seeds_[d];
        r = rotations_[d];
      } else {
        make_seed(d, h, r);
      }
    }

    kensler_domain perm_;  // copies of the sampler's set-up (no reference to it)
    stratified_detail::exact_divider spp_, nx_, ny_;
    std::uint64_t pixel_hash_;
    std::uint32_t index_ = 0;
    std::uint64_t seeds_[cached_dims];
    std::uint32_t rotations_[cached_dims];
  };

  pixel_sampler start_pixel(int x, int y, int /*width*/) const {
    return {*this, hash_combine(hash_combine(seed_hash_, static_cast<std::uint64_t>(x)), static_cast<std::uint64_t>(y))};
  }

 private:
  std::uint64_t seed_hash_;
  kensler_domain perm_;  // the permutations of [0, spp)
  stratified_detail::exact_divider spp_, nx_, ny_;
};

}  // namespace mcrt
