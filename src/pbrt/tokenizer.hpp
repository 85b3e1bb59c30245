#pragma once
// The lexical layer of pbrt-v4's scene format (pbrt-v4 File Format
// reference; its src/pbrt/parser.cpp): a file is a sequence of tokens
// separated by white space — quoted strings, the brackets [ and ], and bare
// words (directive names, numbers, true/false) — with comments from '#' to
// the end of the line. Every token carries its file, line and column, so
// every error names its place.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace mcrt::pbrt {

// A place in a scene file: "FILE:LINE:COLUMN".
struct file_loc {
  std::shared_ptr<const std::string> file;
  int line = 1, column = 1;

  std::string str() const { return (file ? *file : std::string("<input>")) + ":" + std::to_string(line); }
};

// Bad input in a scene file (or a file it refers to): what() is one line
// beginning with the place, "scene.pbrt:12: ...".
class parse_error : public std::runtime_error {
 public:
  parse_error(const file_loc& loc, const std::string& what)
      : std::runtime_error(one_line(loc.str() + ": " + what)), loc_(loc) {}
  const file_loc& loc() const { return loc_; }

  // The message with control characters written as escapes (\n, \t,
  // \xHH), so that text quoted from the file keeps it on one line.
  // The message is cut at max_message bytes: every quote from a file is
  // bounded already (quote_prefix), this only guards the line's length.
  static constexpr std::size_t max_message = 1000;
  static std::string one_line(const std::string& s) {
    static const char hex[] = "0123456789abcdef";
    std::string out;
    for (const char c : s) {
      if (out.size() >= max_message) {
        out += "...";
        break;
      }
      const auto u = static_cast<unsigned char>(c);
      if (c == '\n') out += "\\n";
      else if (c == '\t') out += "\\t";
      else if (c == '\r') out += "\\r";
      else if (u < 0x20 || u == 0x7f) out += std::string("\\x") + hex[u >> 4] + hex[u & 15];
      else out += c;
    }
    return out;
  }

 private:
  file_loc loc_;
};

// Text quoted from a file in a message, at most `limit` bytes of it: a
// 100,000-digit number or a megabyte-long word is shown by its beginning
// and its length, so that an error stays one readable line.
inline std::string quote_prefix(const std::string& s, std::size_t limit = 80) {
  if (s.size() <= limit) return s;
  std::size_t n = limit;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xc0) == 0x80) --n;  // not inside a UTF-8 character
  return s.substr(0, n) + "... (" + std::to_string(s.size()) + " bytes)";
}

struct token {
  enum class kind { word, string, open_bracket, close_bracket, end };
  kind k = kind::end;
  std::string text;  // a word as written; a string without its quotes, escapes resolved
  file_loc loc;

  bool is_word(std::string_view w) const { return k == kind::word && text == w; }
};

// Splits the text of one file into tokens. The text is kept by the
// tokenizer; `file` names it in errors.
class tokenizer {
 public:
  tokenizer(std::string text, std::string file);

  // The next token (kind::end at the end of the text); throws parse_error
  // on an unterminated string, a string that runs over a line, or an
  // unknown escape.
  token next();

 private:
  std::string text_;
  std::shared_ptr<const std::string> file_;
  std::size_t pos_ = 0;
  int line_ = 1, column_ = 1;

  char get();
  file_loc here() const { return {file_, line_, column_}; }
};

// The whole content of a scene file, decompressed where its name ends in
// ".gz" (gzip, as pbrt-v4 reads .pbrt.gz files); throws parse_error at
// `from` (the directive that names the file, or the command line's place)
// when the file cannot be read, is not a regular file, or holds (or
// unpacks to) more than max_bytes bytes (input_file.hpp).
std::string read_scene_text(const std::string& path, const file_loc& from, std::uint64_t max_bytes);

}  // namespace mcrt::pbrt
