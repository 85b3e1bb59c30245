#pragma once
// Reading the files a scene names (scene text, PLY meshes, images) as a
// program fed files from the web must: only regular files are opened (a
// device such as /dev/zero, a FIFO or a directory is refused before it is
// read), and no file, nor the stream a gzip-compressed file unpacks to, is
// read past a size bound (the executable's --max-input-size, default 1 GiB),
// so that a 3 MB gzip bomb or an endless device is refused in a moment and
// within bounded memory. Errors are input_file_error with the reason alone;
// the caller adds the place (the scene file and line that names the file).
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace mcrt::io {

// The size bound of a file read whole, or of a decompressed stream: 1 GiB.
inline constexpr std::uint64_t default_max_input_bytes = std::uint64_t(1) << 30;

struct input_file_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "1073741824 bytes (1 GiB)": a byte count as a message shows it.
std::string byte_count(std::uint64_t n);

// Whether a path names a gzip-compressed file (".gz").
bool is_gzip_path(const std::string& path);

// Throws input_file_error unless `path` is a regular file (symbolic links
// followed) of at most max_bytes bytes; returns its size. Images decoded by
// a library (which opens the file itself) are checked with this first.
std::uint64_t check_input_file(const std::string& path, std::uint64_t max_bytes);

// A file read from start to end: plain, or unpacked on the fly where its
// name ends in ".gz" (zlib; a truncated or corrupt stream is an error). At
// most max_bytes bytes come out of it (of the unpacked stream for .gz).
class input_file {
 public:
  input_file(const std::string& path, std::uint64_t max_bytes);
  ~input_file();
  input_file(const input_file&) = delete;
  input_file& operator=(const input_file&) = delete;

  // Up to n bytes into buf; 0 at the end. Throws input_file_error on a
  // read error, a corrupt stream or more than max_bytes bytes in all.
  std::size_t read(char* buf, std::size_t n);
  // Everything from here to the end.
  std::string read_rest();
  // The bytes read so far (of the unpacked stream for .gz).
  std::uint64_t consumed() const { return consumed_; }
  // Bytes left in a plain file (its size less what was read); for a
  // gzip-compressed one, unknown until it is read: the size bound's rest.
  std::uint64_t remaining_bound() const;
  bool compressed() const { return gz_ != nullptr; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::uint64_t max_bytes_ = 0, size_ = 0, consumed_ = 0;
  std::FILE* file_ = nullptr;
  void* gz_ = nullptr;  // gzFile
  bool ended_ = false;
};

// The whole of a file (unpacked where its name ends in ".gz"), bounded.
std::string read_input_file(const std::string& path, std::uint64_t max_bytes);

}  // namespace mcrt::io
