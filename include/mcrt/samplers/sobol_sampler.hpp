#pragma once
// The Owen-scrambled, padded Sobol sampler: B. Burley, "Practical Hash-based
// Owen Scrambling", JCGT 9(4), 2020 (below [B20]: shuffled and scrambled
// Sobol points, padded), as in pbrt-v4's PaddedSobolSampler (Pharr, Jakob,
// Humphreys, "Physically Based Rendering", 4th ed., sec. 8.7). Interface of
// samplers/independent.hpp, dimensions of samplers/layout.hpp.
//
// Every draw of the layout -- the 2-D pairs (0,1), (b+1,b+2), (b+4,b+5) and
// the 1-D dimensions b+0, b+3, b+6 of bounce k, b = 2 + 7k -- is its own
// low-dimensional Sobol sequence:
//   seed      h_d = hash(sampler seed, pixel x, pixel y, d), 64 bits, and for a
//             pair also h_(d+1);
//   shuffle   j = nested_uniform_scramble(i, lo32(h_d)) mod 2^m,
//             with i the sample index and 2^m the smallest power of two >= spp;
//   point     2-D: (sobol(j, 0), sobol(j, 1)), 1-D: sobol(j, 0), each
//             coordinate Owen-scrambled by nested_uniform_scramble with its own
//             seed: hi32(h_d) for x, hi32(h_(d+1)) for y
//             (samplers/owen_scrambling.hpp, samplers/sobol.hpp).
// The draws of different dimensions use the same two Sobol dimensions but
// independently shuffled indices and independent scrambles ("padding",
// [B20]): no Sobol dimension beyond 1 is needed, however long the path, and
// no two draws are correlated beyond what the hash leaves.
//
// Why the shuffle keeps the nets. nested_uniform_scramble is an Owen scramble
// of the index read as a fixed-point number: bit b of the output depends only
// on bits >= b of the input (owen_scrambling.hpp, eq. (1) with the bit order
// of an integer). For the first 2^k samples, i < 2^k, the bits >= k of i are
// all zero, so bits k..m-1 of j are the same for all of them, while their
// bits 0..k-1 run through all 2^k values (the scramble is a bijection). So
// the first 2^k samples use exactly the aligned block of 2^k Sobol indices
// {c 2^k, ..., c 2^k + 2^k - 1}, for every k <= m at once -- and more
// generally every aligned block of 2^k sample indices maps onto an aligned
// block of 2^k Sobol indices. Sobol dimensions (0, 1) form a (0,m,2)-net on
// every such block (sobol.hpp), and the Owen scramble of each coordinate maps
// nets onto nets, so for every k the first 2^k samples of a pixel are a
// (0,k,2)-net in every 2-D draw, and stratified in 2^k intervals in every 1-D
// draw; the order of the samples is random ([B20]'s shuffling) instead of
// Sobol's, so the pairs of different draws are decorrelated.
//
// An spp that is not a power of two. The sampler uses the first spp samples
// of the shuffled sequence of 2^m. Writing spp in binary, spp = 2^k1 + 2^k2
// + ... (k1 > k2 > ...), samples [0, 2^k1) are one aligned block, the next
// 2^k2 samples another, and so on: the spp points are a union of (0,k,2)-nets,
// one per set bit of spp, each net of a different Sobol block (the shuffle is
// a bijection, so no Sobol point repeats). They are not one net, but still
// much better distributed than random; a sample index >= 2^m wraps around
// (only its low m bits count).
//
// Cost. A 2-D draw is three Laine-Karras hashes (index shuffle, x, y),
// three bit reversals and four table lookups (dimension 1 in reversed bit
// order, sobol_sample_dim1_reversed); a 1-D draw two hashes and two
// reversals. The 64-bit seeds h_d of the first `cached_bounces` bounces are
// computed once in start_pixel and kept in the pixel_sampler (a fixed array
// of 240 bytes, no allocation); deeper dimensions hash on the fly (one mix64
// per dimension, two for a pair). The bit reversal of the sample index is
// done once per start_sample. Measured (bench/bench_samplers_sequences.cpp):
// a path of 16 draws costs about 3 times the independent sampler's.
#include <algorithm>
#include <bit>
#include <cstdint>

#include "mcrt/core/math.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/samplers/hash.hpp"
#include "mcrt/samplers/layout.hpp"
#include "mcrt/samplers/owen_scrambling.hpp"
#include "mcrt/samplers/sobol.hpp"

namespace mcrt {

class sobol_sampler {
 public:
  // Bounces whose per-dimension seeds are cached by start_pixel; beyond them
  // a draw hashes its seed itself (one mix64 more per dimension).
  static constexpr int cached_bounces = 4;
  static constexpr int cached_dims = layout::bounce(cached_bounces);  // 30 dimensions, 240 bytes

  sobol_sampler(std::uint64_t seed, int spp)
      : seed_hash_(mix64(seed)),
        log2_spp_(spp <= 1 ? 0 : std::bit_width(static_cast<std::uint32_t>(spp - 1))) {}

  // log2 of the padded sample count 2^m (the smallest power of two >= spp).
  int log2_samples() const { return log2_spp_; }

  class pixel_sampler {
   public:
    static constexpr bool sequential = false;

    void start_sample(int index) { reversed_index_ = reverse_bits(static_cast<std::uint32_t>(index)); }

    vec2 pixel() { return get2d(layout::pixel); }

    float get1d(int dim) const { return unit_float(get1d_bits(dim)); }

    vec2 get2d(int dim) const {
      std::uint32_t x, y;
      get2d_bits(dim, x, y);
      return {unit_float(x), unit_float(y)};
    }

    // The same draws in 32-bit fixed point, before the float conversion
    // (the tests check the nets at full resolution on these).
    std::uint32_t get1d_bits(int dim) const {
      const std::uint64_t h = seed(dim);
      const std::uint32_t j = shuffle(static_cast<std::uint32_t>(h));
      // Sobol dimension 0 of j is reverse_bits(j); its Owen scramble
      // reverse_bits(lk(reverse_bits(reverse_bits(j)))) skips two reversals.
      return reverse_bits(laine_karras_permutation(j, static_cast<std::uint32_t>(h >> 32)));
    }
    void get2d_bits(int dim, std::uint32_t& x, std::uint32_t& y) const {
      const std::uint64_t h = seed(dim), h_next = seed(dim + 1);
      const std::uint32_t j = shuffle(static_cast<std::uint32_t>(h));
      x = reverse_bits(laine_karras_permutation(j, static_cast<std::uint32_t>(h >> 32)));
      // Dimension 1 comes bit-reversed from its tables, as the scramble wants it.
      y = reverse_bits(laine_karras_permutation(sobol_sample_dim1_reversed(j), static_cast<std::uint32_t>(h_next >> 32)));
    }

   private:
    friend class sobol_sampler;
    pixel_sampler(std::uint64_t pixel_hash, int log2_spp)
        : pixel_hash_(pixel_hash), top_mask_(log2_spp == 0 ? 0u : ~0u << (32 - log2_spp)) {
      for (int d = 0; d < cached_dims; ++d) seeds_[d] = hash_combine(pixel_hash_, static_cast<std::uint64_t>(d));
    }

    std::uint64_t seed(int dim) const {
      return dim < cached_dims ? seeds_[dim] : hash_combine(pixel_hash_, static_cast<std::uint64_t>(dim));
    }

    // j = nested_uniform_scramble(index, s) mod 2^m, computed as
    // reverse_bits(lk(reverse_bits(index), s) & top m bits).
    std::uint32_t shuffle(std::uint32_t s) const {
      return reverse_bits(laine_karras_permutation(reversed_index_, s) & top_mask_);
    }

    std::uint64_t pixel_hash_;
    std::uint32_t top_mask_;
    std::uint32_t reversed_index_ = 0;
    std::uint64_t seeds_[cached_dims];
  };

  pixel_sampler start_pixel(int x, int y, int /*width*/) const {
    return {hash_combine(hash_combine(seed_hash_, static_cast<std::uint64_t>(x)), static_cast<std::uint64_t>(y)),
            log2_spp_};
  }

 private:
  std::uint64_t seed_hash_;
  int log2_spp_;
};

}  // namespace mcrt
