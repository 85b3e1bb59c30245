#include "pbrt/tokenizer.hpp"

#include "input_file.hpp"

namespace mcrt::pbrt {

tokenizer::tokenizer(std::string text, std::string file)
    : text_(std::move(text)), file_(std::make_shared<const std::string>(std::move(file))) {
  // A UTF-8 byte-order mark, which some editors write at the start of a
  // file, is skipped (an extension: pbrt-v4 refuses it as a directive).
  if (text_.starts_with("\xEF\xBB\xBF")) pos_ = 3;
}

// A line ends at LF, CR LF or a lone CR (classic Mac OS line endings), so
// that comments end and lines are counted in all three.
char tokenizer::get() {
  const char c = text_[pos_++];
  if (c == '\n' || (c == '\r' && (pos_ >= text_.size() || text_[pos_] != '\n'))) {
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
      while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') get();
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
        if (d == '\n' || d == '\r') throw parse_error(start, "unterminated string (a string may not run over a line)");
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

std::string read_scene_text(const std::string& path, const file_loc& from, std::uint64_t max_bytes) {
  try {
    return io::read_input_file(path, max_bytes);
  } catch (const io::input_file_error& e) {
    throw parse_error(from, "'" + quote_prefix(path, 200) + "': " + e.what());
  }
}

}  // namespace mcrt::pbrt
