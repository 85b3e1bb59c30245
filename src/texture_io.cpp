#include "texture_io.hpp"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <stdexcept>

namespace mcrt::cli {

texture_image decode_texture_image(const std::string& path, const std::string& encoding) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error("cannot read the image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1) throw std::runtime_error("the image is empty");
  const int nc = spec.nchannels;
  std::vector<float> px(static_cast<std::size_t>(spec.width) * std::size_t(spec.height) * std::size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, px.data()))
    throw std::runtime_error("cannot decode the image: " + in->geterror());
  // 8-bit images carry encoded values; wider ones are linear (pbrt-v4's Image::Read).
  const bool eight_bit = spec.format.basetype == OIIO::TypeDesc::UINT8;
  float gamma = 0.0f;  // 0: sRGB's transfer function
  bool linear = !eight_bit || encoding == "linear";
  if (eight_bit && encoding.rfind("gamma ", 0) == 0) {
    gamma = std::stof(encoding.substr(6));
    if (!(gamma > 0.0f)) throw std::runtime_error("encoding \"" + encoding + "\": the gamma must be > 0");
  }
  const auto decode = [&](float v) {
    if (linear) return v;
    if (gamma > 0.0f) return std::pow(v, gamma);
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);  // IEC 61966-2-1
  };
  texture_image img;
  img.width = spec.width;
  img.height = spec.height;
  img.texels.resize(static_cast<std::size_t>(spec.width) * std::size_t(spec.height));
  for (std::size_t i = 0; i < img.texels.size(); ++i) {
    const float* p = &px[i * std::size_t(nc)];
    const color c = nc >= 3 ? color(p[0], p[1], p[2]) : color(p[0]);
    img.texels[i] = color(decode(c.r), decode(c.g), decode(c.b));
  }
  return img;
}

}  // namespace mcrt::cli
