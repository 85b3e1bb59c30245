#pragma once
// Image files for the mcrt executable: EXR (32-bit float linear RGB), PNG
// (8-bit sRGB-encoded) and PPM (8-bit, gamma 2 as in Shirley's books).
// Writes go to a temporary file beside the target, renamed into place, so
// an output file is never left half-written.
#include <cstdint>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include "mcrt/render/image.hpp"

namespace mcrt::cli {

enum class image_format { exr, png, ppm };

struct image_attribute {
  std::string name;
  std::string value;  // written as a string attribute unless numeric is set
  double number = 0.0;
  bool numeric = false;
  bool integer = false;
};

// Format from the extension (.exr, .png, .ppm; case-insensitive); throws
// input_error for anything else.
image_format format_from_path(const std::string& path);

// Checks, before any work, that `path` can be written: a known extension,
// an existing directory, and permission to create a file there (checked by
// creating and removing a temporary file beside it; the target is untouched).
// `flag` names the option in a message about a name too long to show.
void check_writable(const std::string& path, bool needs_image_format, const std::string& flag = "--output");

void write_image(const std::string& path, const image& img, const std::vector<image_attribute>& attributes);

// Writes text (e.g. a JSON stats file) atomically.
void write_text(const std::string& path, const std::string& text);

// A file written piece by piece to a temporary name beside `path` and
// renamed into place by commit(); destroyed uncommitted (an exception on
// the way), the temporary is removed and the target never touched.
class output_file {
 public:
  explicit output_file(const std::string& path);
  ~output_file();
  output_file(const output_file&) = delete;
  output_file& operator=(const output_file&) = delete;
  std::ostream& stream() { return os_; }
  void commit();

 private:
  std::string path_, tmp_;
  std::ofstream os_;
  bool committed_ = false;
};

// Reads any image render writes, as float RGB (8-bit formats as their
// stored 0..1 values). Throws input_error if unreadable, not a regular
// file, or larger than max_bytes (file or decoded pixels: image_input.hpp).
image read_image(const std::string& path, std::uint64_t max_bytes);

}  // namespace mcrt::cli
