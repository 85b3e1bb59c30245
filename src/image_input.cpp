#include "image_input.hpp"

#include <OpenImageIO/imageio.h>

#include <cmath>

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <unistd.h>
#endif

namespace mcrt::io {
namespace {

// The first line of a decoder's message (OpenImageIO joins a decoder's
// errors with newlines: "Read error: hit end of file\nPNG read error: ...").
std::string first_line(const std::string& s) {
  std::size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "the decoder says no more (a truncated or corrupt file)";
  const std::size_t b = s.find_first_of("\r\n", a);
  return s.substr(a, b == std::string::npos ? std::string::npos : b - a);
}

// Standard error sent to /dev/null for as long as it lives: libpng, as
// OpenImageIO 2.4 sets it up, prints "libpng error: ..." to stderr before
// the error reaches OpenImageIO, which would break the one-line rule for
// bad input. Images are decoded while the scene is read, before any
// thread of the program starts, so no other output is lost.
class quiet_stderr {
 public:
  quiet_stderr() {
#if defined(__unix__) || defined(__APPLE__)
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, 2);
    if (null >= 0) ::close(null);
#endif
  }
  ~quiet_stderr() {
#if defined(__unix__) || defined(__APPLE__)
    std::fflush(stderr);
    if (saved_ >= 0) {
      ::dup2(saved_, 2);
      ::close(saved_);
    }
#endif
  }
  quiet_stderr(const quiet_stderr&) = delete;
  quiet_stderr& operator=(const quiet_stderr&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace

decoded_image decode_image_file(const std::string& path, std::uint64_t max_bytes) {
  check_input_file(path, max_bytes);
  const quiet_stderr quiet;
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw input_file_error("cannot read the image: " + first_line(OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1) throw input_file_error("the image is empty");
  if (spec.depth > 1) throw input_file_error("a volume image (depth " + std::to_string(spec.depth) + ") is not a 2-D image");
  // The decoded size from the header, in 64 bits (w x h x channels x 4
  // bytes cannot overflow it: each factor is below 2^31).
  const std::uint64_t bytes = std::uint64_t(spec.width) * std::uint64_t(spec.height) * std::uint64_t(spec.nchannels) * 4u;
  if (bytes > max_bytes)
    throw input_file_error("an image of " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " x " +
                           std::to_string(spec.nchannels) + " channels decodes to " + byte_count(bytes) +
                           ", more than the input size bound of " + byte_count(max_bytes) +
                           " (--max-input-size raises it)");
  decoded_image img;
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.eight_bit = spec.format.basetype == OIIO::TypeDesc::UINT8;
  img.px.resize(static_cast<std::size_t>(bytes / 4u));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, img.px.data()))
    throw input_file_error("cannot decode the image: " + first_line(in->geterror()));
  in->close();
  for (std::size_t i = 0; i < img.px.size(); ++i)
    if (!std::isfinite(img.px[i])) {
      const std::size_t pixel = i / std::size_t(img.channels);
      throw input_file_error("pixel (" + std::to_string(pixel % std::size_t(img.width)) + ", " +
                             std::to_string(pixel / std::size_t(img.width)) + ") is not finite (NaN or infinity)");
    }
  return img;
}

}  // namespace mcrt::io
