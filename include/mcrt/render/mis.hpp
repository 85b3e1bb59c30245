#pragma once
// Multiple importance sampling weights (Veach & Guibas 1995; Veach 1997,
// sec. 9.2.2-9.2.4) for two techniques that each take one sample: the weight
// of a sample drawn by technique a, whose density is p_a, when technique b
// could have drawn the same direction with density p_b (both per unit solid
// angle). For every direction w_a(p_a, p_b) + w_b(p_b, p_a) = 1.
#include "mcrt/core/math.hpp"

namespace mcrt {

enum class mis_heuristic { power, balance };

// Balance heuristic (Veach 1997, eq. 9.10 with one sample each):
// p_a / (p_a + p_b).
inline float balance_heuristic(float p_a, float p_b) {
  if (!(p_a > 0.0f)) return 0.0f;
  return 1.0f / (1.0f + p_b / p_a);
}

// Power heuristic with exponent beta = 2 (Veach 1997, eq. 9.13):
// p_a^2 / (p_a^2 + p_b^2), written as 1 / (1 + (p_b / p_a)^2) so that the
// densities of tiny lights (1e20 per steradian and more) do not overflow
// when squared. An infinite ratio gives 0, as it should.
inline float power_heuristic(float p_a, float p_b) {
  if (!(p_a > 0.0f)) return 0.0f;
  const float r = p_b / p_a;
  return 1.0f / (1.0f + r * r);
}

inline float mis_weight(mis_heuristic h, float p_a, float p_b) {
  return h == mis_heuristic::power ? power_heuristic(p_a, p_b) : balance_heuristic(p_a, p_b);
}

}  // namespace mcrt
