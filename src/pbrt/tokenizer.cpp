#include "pbrt/tokenizer.hpp"

#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace mcrt::pbrt {

tokenizer::tokenizer(std::string text, std::string file)
    : text_(std::move(text)), file_(std::make_shared<const std::string>(std::move(file))) {}

char tokenizer::get() {
  const char c = text_[pos_++];
  if (c == '\n') {
    ++line_;
    column_ = 1;
  } else {
    ++column_;
  }
  return c;
}

token tokenizer::next() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
      get();
      continue;
    }
    if (c == '#') {  // a comment runs to the end of the line
      while (pos_ < text_.size() && text_[pos_] != '\n') get();
      continue;
    }
    const file_loc start = here();
    if (c == '[' || c == ']') {
      get();
      return {c == '[' ? token::kind::open_bracket : token::kind::close_bracket, std::string(1, c), start};
    }
    if (c == '"') {
      get();
      std::string s;
      while (true) {
        if (pos_ >= text_.size()) throw parse_error(start, "unterminated string");
        const char d = get();
        if (d == '"') break;
        if (d == '\n') throw parse_error(start, "unterminated string (a string may not run over a line)");
        if (d != '\\') {
          s += d;
          continue;
        }
        if (pos_ >= text_.size()) throw parse_error(start, "unterminated string");
        const char e = get();
        switch (e) {  // pbrt-v4's escapes
          case 'b': s += '\b'; break;
          case 'f': s += '\f'; break;
          case 'n': s += '\n'; break;
          case 'r': s += '\r'; break;
          case 't': s += '\t'; break;
          case '\\': s += '\\'; break;
          case '\'': s += '\''; break;
          case '"': s += '"'; break;
          default: throw parse_error(start, std::string("unknown escape '\\") + e + "' in a string");
        }
      }
      return {token::kind::string, std::move(s), start};
    }
    std::string w;
    while (pos_ < text_.size()) {
      const char d = text_[pos_];
      if (d == ' ' || d == '\t' || d == '\n' || d == '\r' || d == '\f' || d == '\v' || d == '"' || d == '[' ||
          d == ']' || d == '#')
        break;
      w += get();
    }
    return {token::kind::word, std::move(w), start};
  }
  return {token::kind::end, "", here()};
}

std::string read_scene_text(const std::string& path, const file_loc& from) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw parse_error(from, "'" + path + "' is a directory, not a scene file");
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0) {
    gzFile f = gzopen(path.c_str(), "rb");
    if (!f) throw parse_error(from, "cannot open '" + path + "'");
    std::string text;
    char buffer[1 << 16];
    while (true) {
      const int n = gzread(f, buffer, sizeof buffer);
      if (n < 0) {
        gzclose(f);
        throw parse_error(from, "'" + path + "': not a valid gzip file");
      }
      if (n == 0) break;
      text.append(buffer, static_cast<std::size_t>(n));
    }
    const bool eof_ok = gzclose(f) == Z_OK;
    if (!eof_ok) throw parse_error(from, "'" + path + "': truncated or corrupt gzip file");
    return text;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw parse_error(from, "cannot open '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace mcrt::pbrt
