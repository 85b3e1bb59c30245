#include "input_file.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace mcrt::io {
namespace fs = std::filesystem;

std::string byte_count(std::uint64_t n) {
  std::string s = std::to_string(n) + " bytes";
  const char* units[] = {"KiB", "MiB", "GiB", "TiB"};
  double v = static_cast<double>(n);
  int u = -1;
  while (v >= 1024.0 && u < 3) v /= 1024.0, ++u;
  if (u >= 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " (%.3g %s)", v, units[u]);
    s += buf;
  }
  return s;
}

bool is_gzip_path(const std::string& path) { return path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0; }

namespace {

std::string too_large(std::uint64_t max_bytes) {
  return "more than the input size bound of " + byte_count(max_bytes) + " (--max-input-size raises it)";
}

}  // namespace

std::uint64_t check_input_file(const std::string& path, std::uint64_t max_bytes) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  // (A loop of symbolic links or a directory that may not be searched is
  // an error of its own, not a missing file.)
  if (ec && ec != std::errc::no_such_file_or_directory) throw input_file_error(ec.message());
  if (!fs::exists(st)) throw input_file_error("no such file");
  if (fs::is_directory(st)) throw input_file_error("is a directory, not a file");
  if (!fs::is_regular_file(st)) {
    const char* kind = fs::is_character_file(st) || fs::is_block_file(st) ? "a device"
                       : fs::is_fifo(st)                                 ? "a FIFO"
                       : fs::is_socket(st)                               ? "a socket"
                                                                         : "not a regular file";
    throw input_file_error(std::string("is ") + kind + ", not a regular file (only regular files are read)");
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw input_file_error("cannot read its size: " + ec.message());
  if (size > max_bytes) throw input_file_error("is " + byte_count(size) + ", " + too_large(max_bytes));
  return size;
}

input_file::input_file(const std::string& path, std::uint64_t max_bytes) : path_(path), max_bytes_(max_bytes) {
  size_ = check_input_file(path, max_bytes);
  if (is_gzip_path(path)) {
    gzFile f = gzopen(path.c_str(), "rb");
    if (!f) throw input_file_error(std::string("cannot open: ") + std::strerror(errno));
    gz_ = f;
    return;
  }
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw input_file_error(std::string("cannot open: ") + std::strerror(errno));
}

input_file::~input_file() {
  if (file_) std::fclose(file_);
  if (gz_) gzclose(static_cast<gzFile>(gz_));
}

std::uint64_t input_file::remaining_bound() const {
  if (gz_) return max_bytes_ - consumed_;
  return size_ > consumed_ ? size_ - consumed_ : 0;
}

std::size_t input_file::read(char* buf, std::size_t n) {
  if (ended_ || n == 0) return 0;
  // One byte past the bound is asked for, so that a stream of exactly
  // max_bytes bytes is told from a longer one.
  if (max_bytes_ - consumed_ < n) n = static_cast<std::size_t>(max_bytes_ - consumed_ + 1);
  std::size_t got = 0;
  if (gz_) {
    const auto f = static_cast<gzFile>(gz_);
    const unsigned ask = static_cast<unsigned>(std::min<std::size_t>(n, 1u << 30));
    const int r = gzread(f, buf, ask);
    if (r < 0) {
      int code = 0;
      const char* msg = gzerror(f, &code);
      throw input_file_error(std::string("not a valid gzip file (") + (msg ? msg : "corrupt") + ")");
    }
    got = static_cast<std::size_t>(r);
    if (got == 0) {
      // The end of the stream: a truncated one ends without its trailer.
      ended_ = true;
      const int rc = gzclose(f);
      gz_ = nullptr;
      if (rc != Z_OK) throw input_file_error("a truncated or corrupt gzip file");
      return 0;
    }
  } else {
    got = std::fread(buf, 1, n, file_);
    if (got == 0) {
      if (std::ferror(file_)) throw input_file_error(std::string("read error: ") + std::strerror(errno));
      ended_ = true;
      return 0;
    }
  }
  consumed_ += got;
  if (consumed_ > max_bytes_)
    throw input_file_error(std::string(gz_ ? "unpacks to " : "holds ") + too_large(max_bytes_));
  return got;
}

std::string input_file::read_rest() {
  std::string out;
  // A plain file's size is known: one allocation. (A file that grows
  // while it is read is still bounded by read().)
  if (!gz_) out.reserve(static_cast<std::size_t>(remaining_bound()));
  char buffer[1 << 16];
  for (std::size_t n; (n = read(buffer, sizeof buffer)) > 0;) out.append(buffer, n);
  return out;
}

std::string read_input_file(const std::string& path, std::uint64_t max_bytes) {
  input_file f(path, max_bytes);
  return f.read_rest();
}

}  // namespace mcrt::io
