#include "texture_io.hpp"

#include <cmath>
#include <stdexcept>

#include "image_input.hpp"

namespace mcrt::cli {

texture_image decode_texture_image(const std::string& path, const std::string& encoding, std::uint64_t max_bytes) {
  const io::decoded_image in = io::decode_image_file(path, max_bytes);
  const int nc = in.channels;
  // 8-bit images carry encoded values; wider ones are linear (pbrt-v4's Image::Read).
  float gamma = 0.0f;  // 0: sRGB's transfer function
  const bool linear = !in.eight_bit || encoding == "linear";
  if (in.eight_bit && encoding.rfind("gamma ", 0) == 0) {
    // (The scene reader has checked that G is a finite number > 0.)
    gamma = std::strtof(encoding.c_str() + 6, nullptr);
    if (!(gamma > 0.0f) || !std::isfinite(gamma))
      throw std::runtime_error("encoding \"" + encoding + "\": the gamma must be a finite number > 0");
  }
  const auto decode = [&](float v) {
    if (linear) return v;
    if (gamma > 0.0f) return std::pow(v, gamma);
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);  // IEC 61966-2-1
  };
  texture_image img;
  img.width = in.width;
  img.height = in.height;
  img.texels.resize(static_cast<std::size_t>(in.width) * std::size_t(in.height));
  for (std::size_t i = 0; i < img.texels.size(); ++i) {
    const float* p = &in.px[i * std::size_t(nc)];
    const color c = nc >= 3 ? color(p[0], p[1], p[2]) : color(p[0]);
    img.texels[i] = color(decode(c.r), decode(c.g), decode(c.b));
  }
  return img;
}

}  // namespace mcrt::cli
