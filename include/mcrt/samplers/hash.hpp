#pragma once
// Integer helpers of the stratified and Sobol samplers: a 64-bit hash of
// several integers (the per-pixel, per-dimension seeds), the 32-bit bit
// reversal, the fixed-point to float conversion, and Kensler's random-access
// permutation.
//
// Random-access permutation (A. Kensler, "Correlated Multi-Jittered
// Sampling", Pixar Technical Memo 13-01, 2013, its section on shuffling):
// permute(i, l, p) is the i-th element of a pseudo-random permutation of
// [0, l) chosen by the seed p, computed for one i alone, without a table.
// The construction is the memo's:
//  * a hash that is a bijection of the k-bit words [0, 2^k), 2^k the
//    smallest power of two >= l, built only from steps that are invertible
//    on k-bit words (mask w = 2^k - 1):
//        i ^= c          (xor with a constant or seed word, masked)
//        i += c          (modulo 2^k)
//        i *= c, c odd   (modulo 2^k: odd numbers are units)
//        i ^= i >> r     (xorshift to the right: the top r bits are kept,
//                         each lower bit is recovered from the bits above)
//  * "cycle walking": apply the hash again while the value is >= l. Since
//    the hash is a permutation of [0, 2^k), the orbit of any i < l comes back
//    below l (at worst to i itself), and the first return is again a
//    permutation, now of [0, l); about 2^k / l < 2 applications on average;
//  * a final rotation by the seed, (i + p) mod l, as in the memo.
// The sequence of steps below is this library's own (five seeded rounds,
// shifts relative to the word width so that a small l is mixed as well as a
// large one), not the memo's listing; its quality is checked in
// tests/test_samplers.cpp (bijection for many l; chi-square uniformity over
// seeds of single positions, of pairs of positions, and for l = 3, 4, 5 of
// the whole permutation). An application costs 5 rounds of about a dozen
// integer operations (a chain of ~55 cycles of latency); the stratified
// sampler pays it once per draw.
#include <bit>
#include <cstdint>
#include <type_traits>

#if defined(__GFNI__) && defined(__SSE2__)
#include <immintrin.h>
#endif

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

// The bits of x in reverse order (bit 0 <-> bit 31). x86 has no bit-reversal
// instruction; where the compiler targets GFNI (-march=native on recent x86),
// one GF(2) affine transform with the anti-diagonal 8x8 bit matrix reverses
// the bits of every byte and a byte swap finishes the job (3 times the
// throughput of the shifts below in a micro-benchmark on the development
// machine, and the Sobol sampler's draws 1.5-2 times faster); clang's
// __builtin_bitreverse32 elsewhere; otherwise, and at compile time, swap
// halves, then bytes, nibbles, pairs and single bits.
constexpr std::uint32_t reverse_bits(std::uint32_t x) {
#if defined(__GFNI__) && defined(__SSE2__)
  if (!std::is_constant_evaluated()) {
    const __m128i v = _mm_cvtsi32_si128(static_cast<int>(x));
    const __m128i r = _mm_gf2p8affine_epi64_epi8(v, _mm_set1_epi64x(0x8040201008040201LL), 0);
    return __builtin_bswap32(static_cast<std::uint32_t>(_mm_cvtsi128_si32(r)));
  }
#elif defined(__has_builtin)
#if __has_builtin(__builtin_bitreverse32)
  if (!std::is_constant_evaluated()) return __builtin_bitreverse32(x);
#endif
#endif
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

// Odd multipliers of the rounds (golden ratio, murmur3 and xxhash constants).
inline constexpr std::uint32_t round_mul[5] = {0x9e3779b1u, 0x85ebca6bu, 0xc2b2ae35u, 0x27d4eb2fu, 0x165667b1u};
inline constexpr int rounds = 5;

// One application of the bijection of k-bit words (w = 2^k - 1, k >= 1;
// h = ceil(k / 2), q = ceil(h / 2), the xorshift amounts, >= 1) chosen by the
// 64-bit seed s. Each round xors in a seed word, multiplies by a
// seed-dependent odd number, xorshifts by h or q, adds a seed word (modulo
// 2^k) and xorshifts by 1; every step maps [0, 2^k) onto itself one-to-one
// (see the header comment), so the whole does. The additions and the
// multiplications only carry information upwards, the xorshifts downwards;
// with fewer rounds, or without the shift by 1, pairs of positions were
// measurably non-uniform over seeds for l a power of two (l = 4 ... 256).
constexpr std::uint32_t hash_word(std::uint32_t i, std::uint32_t w, int h, int q, std::uint64_t s) {
  const auto s1 = static_cast<std::uint32_t>(s), s2 = static_cast<std::uint32_t>(s >> 32);
  for (int r = 0; r < rounds; ++r) {
    i ^= std::rotr(s1, 5 * r) & w;
    i = (i * (round_mul[r] ^ (std::rotr(s2, 5 * r) & 0xfffffffeu))) & w;
    i ^= i >> ((r & 1) ? q : h);
    i = (i + std::rotr(s1 ^ s2, 5 * r + 3)) & w;
    i ^= i >> 1;
  }
  return i;
}

}  // namespace kensler_detail

// The permutations of [0, l) for one length l: the set-up that depends on l
// alone, done once (the stratified sampler keeps one per render). A
// permutation is then chosen by a 64-bit key s (used as it is: it must
// already be a hash) and a rotation r in [0, l).
class kensler_domain {
 public:
  constexpr explicit kensler_domain(std::uint32_t l)
      : l_(l < 1 ? 1 : l),
        k_(std::bit_width(l_ - 1)),
        w_(k_ == 32 ? 0xffffffffu : ((1u << k_) - 1u)),
        h_((k_ + 1) / 2),
        q_((h_ + 1) / 2) {}

  constexpr std::uint32_t size() const { return l_; }

  // Element i (< l) of the permutation chosen by (s, r): cycle walking of the
  // hash, then the rotation.
  constexpr std::uint32_t operator()(std::uint32_t i, std::uint64_t s, std::uint32_t r) const {
    if (l_ == 1) return 0;
    do {
      i = kensler_detail::hash_word(i, w_, h_, q_, s);
    } while (i >= l_);  // cycle walking
    i += r;             // i, r < l: one conditional subtraction is the modulo
    return i >= l_ ? i - l_ : i;
  }

 private:
  std::uint32_t l_;
  int k_;  // 2^k >= l
  std::uint32_t w_;
  int h_, q_;
};

// The element at position i of the permutation of [0, l) chosen by seed p
// (Kensler 2013). Preconditions: l >= 1, i < l. For fixed (l, p),
// i -> permute(i, l, p) is a bijection of [0, l). The seed enters mixed
// (mix64), so that nearby seeds give unrelated permutations; the rotation is
// the memo's, p mod l.
constexpr std::uint32_t permute(std::uint32_t i, std::uint32_t l, std::uint32_t p) {
  if (l <= 1) return 0;
  return kensler_domain(l)(i, mix64(p), p % l);
}

}  // namespace mcrt
