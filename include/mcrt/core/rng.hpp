#pragma once
// PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient
// Statistically Good Algorithms for Random Number Generation"), the
// XSH-RR 64/32 variant. Small (16 bytes), fast and seedable per pixel, so an
// image does not depend on how pixels are shared among threads.
//
// pcg32 follows O'Neill's reference implementation pcg_basic.c
// (pcg32_srandom_r, pcg32_random_r, the default state of PCG32_INITIALIZER):
// "PCG Random Number Generation for C. Copyright 2014 Melissa O'Neill
// <oneill@pcg-random.org>. Licensed under the Apache License, Version 2.0";
// the notice and the licence's text are in THIRD_PARTY.md.
#include <cstdint>

#include "mcrt/core/math.hpp"

namespace mcrt {

class pcg32 {
 public:
  constexpr pcg32() = default;
  constexpr pcg32(std::uint64_t seed, std::uint64_t stream) { reseed(seed, stream); }

  constexpr void reseed(std::uint64_t seed, std::uint64_t stream) {
    state_ = 0u;
    inc_ = (stream << 1u) | 1u;
    next_u32();
    state_ += seed;
    next_u32();
  }

  constexpr std::uint32_t next_u32() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }

  // Uniform float in [0, 1): the top 24 bits, so 1 is never returned.
  constexpr float uniform() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }
  // Uniform double in [0, 1) from 53 random bits.
  constexpr double uniform_double() {
    const std::uint64_t hi = next_u32() >> 5, lo = next_u32() >> 6;
    return static_cast<double>((hi << 26) | lo) * 0x1p-53;
  }
  vec2 uniform2() {
    const float a = uniform();
    return {a, uniform()};
  }

 private:
  std::uint64_t state_ = 0x853c49e6748fea9bULL;
  std::uint64_t inc_ = 0xda3e39cb94b95bdbULL;
};

// 64-bit finaliser (splitmix64): decorrelates neighbouring pixel indices
// before they become PCG seeds.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace mcrt
