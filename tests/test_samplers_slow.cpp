// Exhaustive check that the hash-based Owen scramble
// (samplers/owen_scrambling.hpp) is a bijection of the 32-bit words: for two
// seeds, all 2^32 inputs are scrambled and their images marked in a bitset of
// 2^32 bits (512 MiB); the images are all distinct exactly when all 2^32 bits
// end up set (pigeonhole). The inputs go in blocks of 64 consecutive values;
// by the Owen property the 64 images of a block share their top 26 bits, i.e.
// one 64-bit word of the bitset, which is then written once (a block whose
// images do not share a word -- none is expected -- is written value by
// value, so the check does not rely on that property, but it counts them).
// 10-18 s per seed on the development machine (2 shared cores), depending on
// its load and on whether reverse_bits is the GFNI form (-march=native: one
// call at a time) or the portable one (vectorised over the block); the times
// are printed.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <iostream>
#include <vector>

#include "mcrt/samplers/owen_scrambling.hpp"

namespace {

using namespace mcrt;

// The images of the 64 inputs base .. base + 63 (a separate function, which
// GCC vectorises when reverse_bits is the portable shift form).
[[gnu::noinline]] void scramble_block(std::uint32_t* __restrict y, std::uint32_t base, std::uint32_t seed) {
  for (std::uint32_t t = 0; t < 64; ++t) y[t] = nested_uniform_scramble(base + t, seed);
}

TEST(OwenScrambleExhaustive, IsABijectionOfAll32BitWords) {
  std::vector<std::uint64_t> seen(std::size_t{1} << 26);  // 2^32 bits
  for (std::uint32_t seed : {0x9e3779b9u, 0x00000001u}) {
    const auto start = std::chrono::steady_clock::now();
    std::fill(seen.begin(), seen.end(), 0);
    std::uint64_t split_blocks = 0;
    for (std::uint32_t block = 0; block < (1u << 26); ++block) {
      std::uint32_t y[64];
      scramble_block(y, block << 6, seed);
      const std::uint32_t word = y[0] >> 6;
      std::uint64_t mask = 0;
      bool same_word = true;
      for (std::uint32_t t = 0; t < 64; ++t) {
        mask |= std::uint64_t{1} << (y[t] & 63u);
        same_word &= (y[t] >> 6) == word;
      }
      if (same_word) {
        seen[word] |= mask;
      } else {
        ++split_blocks;
        for (std::uint32_t t = 0; t < 64; ++t) seen[y[t] >> 6] |= std::uint64_t{1} << (y[t] & 63u);
      }
    }
    std::uint64_t set = 0;
    for (std::uint64_t w : seen) set += static_cast<std::uint64_t>(std::popcount(w));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "seed " << seed << ": " << set << " distinct images of 2^32 inputs, " << split_blocks
              << " blocks of 64 split across words, " << seconds << " s\n";
    EXPECT_EQ(set, std::uint64_t{1} << 32) << "seed " << seed;
    EXPECT_EQ(split_blocks, 0u) << "seed " << seed << ": the Owen property fails somewhere";
  }
}

}  // namespace
