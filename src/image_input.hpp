#pragma once
// Images read from files the user gives (pbrt-v4 textures, `mcrt diff`'s
// images), decoded through OpenImageIO as input_file.hpp reads any input:
// only a regular file of at most max_bytes bytes, and an image whose
// decoded pixels would take more than max_bytes bytes is refused from its
// header, before it is decoded. Errors are io::input_file_error with the
// reason in one line (the decoders' own messages, which may span lines, are
// cut to their first; what the PNG library would print to stderr is kept
// off it).
#include <cstdint>
#include <string>
#include <vector>

#include "input_file.hpp"

namespace mcrt::io {

struct decoded_image {
  int width = 0, height = 0, channels = 0;
  bool eight_bit = false;   // 8-bit channels (their values are encoded, e.g. sRGB)
  std::vector<float> px;    // width x height x channels, row 0 at the top
};

// The first subimage at its full resolution, every channel as float (8-bit
// ones as their stored 0..1 values). Non-finite values (NaN, infinity)
// are refused with the pixel where they are.
decoded_image decode_image_file(const std::string& path, std::uint64_t max_bytes);

}  // namespace mcrt::io
