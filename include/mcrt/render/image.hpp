#pragma once
// A linear-radiance RGB float image, rows top to bottom.
#include <cstddef>
#include <vector>

#include "mcrt/core/math.hpp"

namespace mcrt {

struct image {
  int width = 0, height = 0;
  std::vector<color> pixels;

  image() = default;
  image(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h)) {}
  color& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)]; }
  const color& at(int x, int y) const {
    return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
  }
};

}  // namespace mcrt
