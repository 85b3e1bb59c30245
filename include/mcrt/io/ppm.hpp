#pragma once
// Plain PPM output as in Shirley's books: 8-bit, gamma 2 (square root),
// values clamped to [0, 1). Writes to any std::ostream.
#include <algorithm>
#include <cmath>
#include <ostream>
#include <string>

#include "mcrt/render/image.hpp"

namespace mcrt {

inline int to_byte_gamma2(float v) {
  const float g = std::sqrt(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f));
  return std::min(255, static_cast<int>(256.0f * g));
}

inline void write_ppm(std::ostream& os, const image& img) {
  os << "P3\n" << img.width << ' ' << img.height << "\n255\n";
  std::string line;
  for (const color& c : img.pixels) {
    line.clear();
    line += std::to_string(to_byte_gamma2(c.r)) + ' ' + std::to_string(to_byte_gamma2(c.g)) + ' ' +
            std::to_string(to_byte_gamma2(c.b)) + '\n';
    os << line;
  }
}

}  // namespace mcrt
