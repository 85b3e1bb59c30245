#pragma once
// Owen scrambling in base 2 by hashing, after B. Burley, "Practical
// Hash-based Owen Scrambling", Journal of Computer Graphics Techniques 9(4),
// 2020 (below [B20]), and its inverse.
//
// Owen's scramble (A. B. Owen, "Randomly permuted (t,m,s)-nets and
// (t,s)-sequences", 1995; "nested uniform scrambling"). Write a coordinate
// in base 2, x = sum_(j>=1) x_j 2^-j (x_1 the most significant digit). The
// scrambled coordinate is
//     y_j = x_j XOR pi_j(x_1, ..., x_(j-1)),                              (1)
// one random bit pi_j for each node (x_1 .. x_(j-1)) of the binary tree of
// digit prefixes: at every node, the two halves of the interval the prefix
// names are swapped or not. So y_j depends only on x_1..x_j, the same and
// MORE significant digits, and two points that share their first k digits
// still share their first k digits after scrambling. Elementary intervals of
// length 2^-k are mapped onto elementary intervals of length 2^-k, one to
// one, hence a (t,m,s)-net stays a (t,m,s)-net in every coordinate that is
// scrambled this way (Owen 1995, who proves it), and each scrambled point is
// uniform on [0,1) when the pi_j are uniform.
//
// The hash ([B20], after S. Laine and T. Karras, "Stratified sampling for
// stochastic transparency", EGSR 2011). On a 32-bit word x, bit b (b = 0 the
// least significant), the steps
//     x += seed              bit b of the sum = x_b ^ seed_b ^ carry_b, and
//                            carry_b depends on bits < b only;
//     x ^= x * c, c even     bit b of x * c depends on bits < b only,
// each flip bit b by a function of the LESS significant bits; so does their
// composition, laine_karras_permutation. That is (1) with the bit order
// reversed: the Owen scramble of a 32-bit fixed-point value is
//     nested_uniform_scramble(x, seed)
//         = reverse_bits(laine_karras_permutation(reverse_bits(x), seed)),   (2)
// [B20]'s nested_uniform_scramble, with the constants of its
// laine_karras_permutation listing (Laine and Karras's). It is a bijection of
// the 32-bit words: every step is (x += seed: subtract; x ^= x * c: solve bit
// by bit from the bottom, below), so its inverse can be tested by round trip
// and its bijectivity exhaustively (tests/test_samplers_slow.cpp).
//
// The pi_j of (2) are not independent coin flips but a hash of the prefix and
// the seed; [B20] measures the resulting error as that of true Owen
// scrambling in practice. The seed should itself be a hash (nearby seeds give
// related permutations: the seed enters through one addition).
#include <bit>
#include <cstdint>

#include "mcrt/samplers/hash.hpp"

namespace mcrt {

namespace owen_detail {

// The multipliers of the Laine-Karras permutation ([B20], Laine and Karras
// 2011); all even, so x ^= x * c only flips bits from lower ones.
inline constexpr std::uint32_t lk_mul[4] = {0x6c50b47cu, 0xb82f1e52u, 0xc7afe638u, 0x8d22f6e6u};

// Inverse of x -> x ^ (x * c) for even c = 2^t c' (t >= 1): y = x ^ (x * c)
// gives the low t bits of x directly (x * c has t trailing zeros), and if the
// low n bits of an estimate are right, so are the low n + t bits of
// y ^ (estimate * c). ceil(32 / t) rounds recover all 32 bits.
constexpr std::uint32_t inverse_xor_mul(std::uint32_t y, std::uint32_t c) {
  const int t = std::countr_zero(c);
  std::uint32_t x = y;
  for (int n = t; n < 32; n += t) x = y ^ (x * c);
  return x;
}

}  // namespace owen_detail

// [B20]'s laine_karras_permutation: flips each bit by a hash of the lower
// bits and the seed (the Owen scramble (1) in reversed bit order).
constexpr std::uint32_t laine_karras_permutation(std::uint32_t x, std::uint32_t seed) {
  x += seed;
  x ^= x * owen_detail::lk_mul[0];
  x ^= x * owen_detail::lk_mul[1];
  x ^= x * owen_detail::lk_mul[2];
  x ^= x * owen_detail::lk_mul[3];
  return x;
}

// Inverse of laine_karras_permutation for the same seed.
constexpr std::uint32_t inverse_laine_karras_permutation(std::uint32_t y, std::uint32_t seed) {
  y = owen_detail::inverse_xor_mul(y, owen_detail::lk_mul[3]);
  y = owen_detail::inverse_xor_mul(y, owen_detail::lk_mul[2]);
  y = owen_detail::inverse_xor_mul(y, owen_detail::lk_mul[1]);
  y = owen_detail::inverse_xor_mul(y, owen_detail::lk_mul[0]);
  return y - seed;
}

// Owen scramble of the 32-bit fixed-point value x (x / 2^32 in [0, 1)), eq. (2).
constexpr std::uint32_t nested_uniform_scramble(std::uint32_t x, std::uint32_t seed) {
  return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

// Inverse: inverse_nested_uniform_scramble(nested_uniform_scramble(x, s), s) == x.
constexpr std::uint32_t inverse_nested_uniform_scramble(std::uint32_t y, std::uint32_t seed) {
  return reverse_bits(inverse_laine_karras_permutation(reverse_bits(y), seed));
}

}  // namespace mcrt
