#include "image_io.hpp"

#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "image_input.hpp"
#include "mcrt/io/ppm.hpp"
#include "scene_loader.hpp"

namespace mcrt::cli {
namespace fs = std::filesystem;

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// A name beside the target, unique to this process, keeping the extension;
// the target's stem and extension are cut so that the name stays within
// the 255 bytes a file name may have (a 250-byte target's is too long).
std::string temp_name(const std::string& path) {
  const fs::path p(path);
  // (Appended piece by piece: GCC 12 at -O3 flags "." + stem + ... with a
  // false -Wrestrict, GCC bug 105329.)
  std::string name = ".";
  name += p.stem().string().substr(0, 100);
  name += ".tmp";
  name += std::to_string(::getpid());
  name += p.extension().string().substr(0, 20);
  return (p.parent_path() / name).string();
}

// sRGB transfer function (IEC 61966-2-1).
float srgb_encode(float v) {
  v = std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

void commit_tmp(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp);
    throw std::runtime_error(path + ": cannot move the output into place: " + ec.message());
  }
}

}  // namespace

image_format format_from_path(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".exr") return image_format::exr;
  if (ext == ".png") return image_format::png;
  if (ext == ".ppm") return image_format::ppm;
  throw input_error(path + ": unknown output format '" + ext + "' (expected .exr, .png or .ppm)");
}

void check_writable(const std::string& path, bool needs_image_format, const std::string& flag) {
  if (path.empty()) throw input_error("an empty output path");
  if (needs_image_format) format_from_path(path);
  const fs::path p(path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw input_error(path + ": output directory '" + dir.string() + "' does not exist");
  if (fs::is_directory(p, ec)) throw input_error(path + ": is a directory");
  // A name the file system cannot hold would fail only at the final rename,
  // after the render.
  const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  const std::size_t name_limit = name_max > 0 ? static_cast<std::size_t>(name_max) : 255;
  if (p.filename().string().size() > name_limit)
    throw input_error(flag + ": " + path.substr(0, 80) + "... (" + std::to_string(path.size()) +
                      " bytes): the file name is longer than the " + std::to_string(name_limit) +
                      " bytes the directory allows");
  // The output replaces its target by a rename: a device, a FIFO or a
  // socket there (-o /dev/null) would be replaced by a regular file.
  if (fs::exists(p, ec) && !fs::is_regular_file(p, ec))
    throw input_error(path + ": is not a regular file (a device, a FIFO or a socket); mcrt writes to files only");
  const std::string tmp = temp_name(path);
  {
    std::ofstream probe(tmp, std::ios::binary);
    if (!probe) throw input_error(path + ": cannot write in directory '" + dir.string() + "'");
  }
  fs::remove(tmp, ec);
}

void write_image(const std::string& path, const image& img, const std::vector<image_attribute>& attributes) {
  const image_format fmt = format_from_path(path);
  const std::string tmp = temp_name(path);
  if (fmt == image_format::ppm) {
    {
      std::ofstream os(tmp, std::ios::binary);
      write_ppm(os, img);
      os.flush();
      if (!os) {
        fs::remove(tmp);
        throw std::runtime_error(path + ": write failed");
      }
    }
    commit_tmp(tmp, path);
    return;
  }
  auto out = OIIO::ImageOutput::create(fmt == image_format::exr ? "openexr" : "png");
  if (!out) throw std::runtime_error(path + ": no image writer: " + OIIO::geterror());
  const std::size_t n = img.pixels.size();
  bool ok;
  if (fmt == image_format::exr) {
    OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    for (const auto& a : attributes) {
      if (!a.numeric)
        spec.attribute(a.name, a.value);
      else if (a.integer)
        spec.attribute(a.name, static_cast<int>(a.number));
      else
        spec.attribute(a.name, static_cast<float>(a.number));
    }
    ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::FLOAT, img.pixels.data()) && out->close();
  } else {
    std::vector<unsigned char> bytes(3 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        bytes[3 * i + static_cast<std::size_t>(c)] =
            static_cast<unsigned char>(std::lround(255.0f * srgb_encode(img.pixels[i][c])));
    OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::UINT8);
    for (const auto& a : attributes)
      spec.attribute(a.name, a.numeric ? std::to_string(a.number) : a.value);
    ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::UINT8, bytes.data()) && out->close();
  }
  if (!ok) {
    const std::string err = out->geterror();
    fs::remove(tmp);
    throw std::runtime_error(path + ": write failed: " + err);
  }
  commit_tmp(tmp, path);
}

void write_text(const std::string& path, const std::string& text) {
  const std::string tmp = temp_name(path);
  {
    std::ofstream os(tmp, std::ios::binary);
    os << text;
    os.flush();
    if (!os) {
      fs::remove(tmp);
      throw std::runtime_error(path + ": write failed");
    }
  }
  commit_tmp(tmp, path);
}

output_file::output_file(const std::string& path) : path_(path), tmp_(temp_name(path)), os_(tmp_, std::ios::binary) {
  if (!os_) throw std::runtime_error(path + ": cannot write");
}

output_file::~output_file() {
  if (committed_) return;
  os_.close();
  std::error_code ec;
  fs::remove(tmp_, ec);
}

void output_file::commit() {
  os_.flush();
  const bool ok = static_cast<bool>(os_);
  os_.close();
  if (!ok) throw std::runtime_error(path_ + ": write failed");
  commit_tmp(tmp_, path_);
  committed_ = true;
}

image read_image(const std::string& path, std::uint64_t max_bytes) {
  io::decoded_image in;
  try {
    in = io::decode_image_file(path, max_bytes);
  } catch (const io::input_file_error& e) {
    throw input_error(path + ": " + e.what());
  }
  image img(in.width, in.height);
  const std::size_t nc = static_cast<std::size_t>(in.channels);
  for (std::size_t i = 0; i < img.pixels.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c) img.pixels[i][static_cast<int>(c)] = in.px[i * nc + std::min(c, nc - 1)];
  return img;
}

}  // namespace mcrt::cli
