#pragma once
// Image textures of pbrt-v4 scenes decoded through OpenImageIO into the
// library's linear RGB texels (mcrt/materials/texture.hpp), so that the
// header-only library needs no image library.
#include <cstdint>
#include <string>

#include "mcrt/materials/texture.hpp"

namespace mcrt::cli {

// The image at path as linear RGB, row 0 at the top. 8-bit images are
// decoded by `encoding` (pbrt-v4's ColorEncoding: "sRGB", "linear" or
// "gamma G"); 16-bit, half and float images are linear, as pbrt-v4 reads
// them. A grey image gives three equal channels; alpha is dropped. Only a
// regular file is read, and an image that would decode to more than
// max_bytes bytes is refused from its header (image_input.hpp). Throws
// std::runtime_error with the reason.
texture_image decode_texture_image(const std::string& path, const std::string& encoding, std::uint64_t max_bytes);

}  // namespace mcrt::cli
