#pragma once
// Sobol's sequence in 32-bit fixed point (I. M. Sobol', 1967), with the
// direction numbers of Joe and Kuo 2008 (samplers/sobol_matrices.hpp).
//
// Coordinate dim of the point of index i is the product of the dimension's
// generator matrix C (columns v_1..v_32, the direction numbers) with the
// binary digits of i, over GF(2):
//     x = XOR_(k : bit k of i is set) v_(k+1),        x / 2^32 in [0, 1)
// (Bratley and Fox 1988, "Algorithm 659", ACM TOMS 14(1); this is the
// natural order, not Antonov and Saleev's Gray-code order, so every aligned
// block of 2^m indices {c 2^m, ..., c 2^m + 2^m - 1} gives a net). Dimension 0
// has C = the anti-diagonal identity, so x is i with its bits reversed (van
// der Corput); dimensions 0 and 1 together are a (0,2)-sequence: every such
// block of 2^m points is a (0,m,2)-net in base 2. Every single dimension is
// a (0,1)-sequence (its C is triangular with a unit diagonal, since every
// m_k is odd).
//
// sobol_sample_dim1_reversed is the fast path the Owen-scrambled sampler
// needs (samplers/sobol_sampler.hpp): dimension 1 with its bits reversed,
// from four byte tables (constant time, no loop over the index bits).
#include <array>
#include <cstdint>

#include "mcrt/samplers/hash.hpp"
#include "mcrt/samplers/sobol_matrices.hpp"

namespace mcrt {

// Coordinate dim (0 <= dim < sobol_dimensions) of the Sobol point of index
// `index`, in 32-bit fixed point.
inline std::uint32_t sobol_sample(std::uint32_t index, int dim) {
  if (dim == 0) return reverse_bits(index);
  const std::array<std::uint32_t, sobol_bits>& v = sobol_matrices()[static_cast<std::size_t>(dim)];
  std::uint32_t x = 0;
  for (int k = 0; index != 0; index >>= 1, ++k)  // branch-free: the bits of an index are not predictable
    x ^= v[static_cast<std::size_t>(k)] & (0u - (index & 1u));
  return x;
}

// The same as a float in [0, 1) (its top 24 bits).
inline float sobol_sample_float(std::uint32_t index, int dim) { return unit_float(sobol_sample(index, dim)); }

namespace sobol_detail {

// table[b][byte] = XOR over the set bits t of byte of reverse_bits(v_(8b+t+1))
// of dimension 1, so that the four lookups of the bytes of an index XOR to
// reverse_bits(sobol_sample(index, 1)) (XOR is linear, the bytes cover the bits).
using byte_tables = std::array<std::array<std::uint32_t, 256>, 4>;
constexpr byte_tables make_dim1_reversed_tables() {
  byte_tables t{};
  const std::array<std::uint32_t, sobol_bits> v = sobol_direction_numbers(1);
  for (int b = 0; b < 4; ++b)
    for (int byte = 0; byte < 256; ++byte) {
      std::uint32_t x = 0;
      for (int bit = 0; bit < 8; ++bit)
        if ((byte >> bit) & 1) x ^= reverse_bits(v[static_cast<std::size_t>(8 * b + bit)]);
      t[static_cast<std::size_t>(b)][static_cast<std::size_t>(byte)] = x;
    }
  return t;
}
inline constexpr byte_tables dim1_reversed_tables = make_dim1_reversed_tables();

}  // namespace sobol_detail

// reverse_bits(sobol_sample(index, 1)).
constexpr std::uint32_t sobol_sample_dim1_reversed(std::uint32_t index) {
  const auto& t = sobol_detail::dim1_reversed_tables;
  return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^ t[3][index >> 24];
}

}  // namespace mcrt
