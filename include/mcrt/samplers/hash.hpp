#pragma once
// Integer helpers of the stratified and Sobol samplers: a 64-bit hash of
// several integers (the per-pixel, per-dimension seeds), the 32-bit bit
// reversal, the fixed-point to float conversion, and Kensler's random-access
// permutation.
//
// Random-access permutation (A. Kensler, "Correlated Multi-Jittered
// Sampling", Pixar Technical Memo 13-01, 2013, sec. 3 "Shuffling"):
// permute(i, l, p) is the i-th element of a pseudo-random permutation of
// [0, l) chosen by the seed p, computed for one i alone, without a table.
// The construction is the memo's:
//  * a hash that is a bijection of the k-bit words [0, 2^k), 2^k the
//    smallest power of two >= l, built only from steps that are invertible
//    on k-bit words (mask w = 2^k - 1):
//        i ^= c          (xor with a constant or seed word, masked)
//        i *= c, c odd   (modulo 2^k: odd numbers are units)
//        i ^= i >> r     (xorshift to the right: the top r bits are kept,
//                         each lower bit is recovered from the bits above)
//  * "cycle walking": apply the hash again while the value is >= l. Since
//    the hash is a permutation of [0, 2^k), the orbit of any i < l comes back
//    below l (at worst to i itself), and the first return is again a
//    permutation, now of [0, l); on average fewer than 2^k / l < 2 rounds;
//  * a final rotation by the seed, (i + p) mod l, as in the memo, which
//    evens out what bias the cycle walking leaves in the positions.
// The sequence of steps below is this library's own (constants from
// splitmix / murmur finalisers, shifts relative to the word width so that a
// small l is mixed as well as a large one), not the memo's listing; its
// quality is checked in tests/test_samplers.cpp (bijection for many l, and
// chi-square uniformity of single positions and of pairs over seeds).
#include <bit>
#include <cstdint>

#include "mcrt/core/rng.hpp"

namespace mcrt {

// ------------------------------------------------------------ hashing

// Combines a hash value h with one more integer v (64 bits): v is spread by
// an odd multiplication (a bijection), xored in, and the whole mixed by the
// splitmix64 finaliser mix64 (core/rng.hpp). Two (h, v) pairs collide only
// if h1 ^ f(v1) == h2 ^ f(v2), i.e. with probability 2^-64 for hashed h.
constexpr std::uint64_t hash_combine(std::uint64_t h, std::uint64_t v) {
  return mix64(h ^ (v * 0xd6e8feb86659fd93ULL));
}

// A 64-bit hash of several integers, in order: hash_values(a, b, c) !=
// hash_values(b, a, c) in general. Negative ints are hashed through their
// 64-bit two's complement.
template <class... T>
constexpr std::uint64_t hash_values(std::uint64_t first, T... rest) {
  std::uint64_t h = mix64(first);
  ((h = hash_combine(h, static_cast<std::uint64_t>(rest))), ...);
  return h;
}

// ------------------------------------------------------------ bits

// The bits of x in reverse order (bit 0 <-> bit 31): swap halves, then bytes,
// nibbles, pairs and single bits.
constexpr std::uint32_t reverse_bits(std::uint32_t x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x >> 8) & 0x00ff00ffu);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu);
  x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u);
  x = ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u);
  return x;
}

// The float in [0, 1) of a 32-bit fixed-point value v / 2^32: its top 24 bits,
// exactly representable, so 1.0f is never returned (v / 2^32 rounded to
// nearest would give 1.0f for v >= 2^32 - 2^7).
constexpr float unit_float(std::uint32_t v) { return static_cast<float>(v >> 8) * 0x1p-24f; }

// ------------------------------------------------------------ Kensler's permutation

namespace kensler_detail {

// One application of the bijection of k-bit words (w = 2^k - 1, k >= 1;
// h = ceil(k / 2) and q = ceil(k / 4) the xorshift amounts, >= 1) chosen by the
// seed p. Every step maps [0, 2^k) onto itself one-to-one (see the header
// comment), so the whole does.
constexpr std::uint32_t hash_word(std::uint32_t i, std::uint32_t w, int h, int q, std::uint32_t p) {
  i ^= p & w;
  i = (i * 0x9e3779b1u) & w;
  i ^= i >> h;
  i ^= (p >> 11) & w;
  i = (i * ((p >> 3) | 1u)) & w;  // seed-dependent odd multiplier
  i ^= i >> q;
  i = (i * 0x85ebca6bu) & w;
  i ^= i >> h;
  i ^= (p >> 21) & w;
  i = (i * 0xc2b2ae35u) & w;
  i ^= i >> q;
  i = (i * 0x27d4eb2fu) & w;
  i ^= i >> h;
  return i;
}

}  // namespace kensler_detail

// The element at position i of the permutation of [0, l) chosen by seed p
// (Kensler 2013, sec. 3). Preconditions: l >= 1, i < l. For fixed (l, p),
// i -> permute(i, l, p) is a bijection of [0, l).
constexpr std::uint32_t permute(std::uint32_t i, std::uint32_t l, std::uint32_t p) {
  if (l <= 1) return 0;
  const int k = std::bit_width(l - 1);  // 2^k >= l, k >= 1
  const std::uint32_t w = (k == 32) ? 0xffffffffu : ((1u << k) - 1u);
  const int h = (k + 1) / 2, q = (k + 3) / 4;
  // The seed enters mixed, so that nearby seeds give unrelated permutations.
  const auto s = static_cast<std::uint32_t>(mix64(p) >> 32);
  do {
    i = kensler_detail::hash_word(i, w, h, q, s);
  } while (i >= l);  // cycle walking
  return static_cast<std::uint32_t>((static_cast<std::uint64_t>(i) + p) % l);
}

}  // namespace mcrt
