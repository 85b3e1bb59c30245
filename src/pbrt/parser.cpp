#include "pbrt/parser.hpp"

#include <cctype>
#include <charconv>
#include <limits>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>

namespace mcrt::pbrt {
namespace {

namespace fs = std::filesystem;

// What a directive takes after its name.
enum class shape_of {
  nothing,       // AttributeBegin, WorldBegin, ...
  numbers,       // a fixed count of numbers: Translate 3, LookAt 9, ...
  matrix,        // [ 16 numbers ]: Transform, ConcatTransform
  one_string,    // CoordinateSystem "name", Include "file", ...
  word,          // ActiveTransform All|StartTime|EndTime (a bare word)
  typed,         // "type" params: Shape, Material, Camera, ...
  named,         // "name" params: MakeNamedMaterial, MakeNamedMedium, Attribute
  params_only,   // params: Option
  texture,       // "name" "type" "class" params
  one_or_two,    // "inside" ["outside"]: MediumInterface
};

struct directive_syntax {
  shape_of shape;
  int count = 0;  // for numbers
};

const std::map<std::string, directive_syntax, std::less<>>& directives() {
  static const std::map<std::string, directive_syntax, std::less<>> table = {
      {"AttributeBegin", {shape_of::nothing}},     {"AttributeEnd", {shape_of::nothing}},
      {"TransformBegin", {shape_of::nothing}},     {"TransformEnd", {shape_of::nothing}},
      {"ObjectEnd", {shape_of::nothing}},          {"ReverseOrientation", {shape_of::nothing}},
      {"WorldBegin", {shape_of::nothing}},         {"WorldEnd", {shape_of::nothing}},
      {"Identity", {shape_of::nothing}},           {"Translate", {shape_of::numbers, 3}},
      {"Scale", {shape_of::numbers, 3}},           {"Rotate", {shape_of::numbers, 4}},
      {"LookAt", {shape_of::numbers, 9}},          {"TransformTimes", {shape_of::numbers, 2}},
      {"Transform", {shape_of::matrix}},           {"ConcatTransform", {shape_of::matrix}},
      {"CoordinateSystem", {shape_of::one_string}}, {"CoordSysTransform", {shape_of::one_string}},
      {"ObjectBegin", {shape_of::one_string}},     {"ObjectInstance", {shape_of::one_string}},
      {"NamedMaterial", {shape_of::one_string}},   {"ColorSpace", {shape_of::one_string}},
      {"Include", {shape_of::one_string}},         {"Import", {shape_of::one_string}},
      {"ActiveTransform", {shape_of::word}},       {"Shape", {shape_of::typed}},
      {"Material", {shape_of::typed}},             {"Camera", {shape_of::typed}},
      {"Film", {shape_of::typed}},                 {"PixelFilter", {shape_of::typed}},
      {"Sampler", {shape_of::typed}},              {"Integrator", {shape_of::typed}},
      {"Accelerator", {shape_of::typed}},          {"LightSource", {shape_of::typed}},
      {"AreaLightSource", {shape_of::typed}},      {"MakeNamedMaterial", {shape_of::named}},
      {"MakeNamedMedium", {shape_of::named}},      {"Attribute", {shape_of::named}},
      {"Option", {shape_of::params_only}},         {"Texture", {shape_of::texture}},
      {"MediumInterface", {shape_of::one_or_two}},
  };
  return table;
}

std::string directive_names() {
  std::string s;
  for (const auto& [name, _] : directives()) s += (s.empty() ? "" : ", ") + name;
  return s;
}

// How many values a parameter of each type takes per element, and whether
// they are numbers, strings or booleans.
enum class value_kind { number, integer, string, boolean, spectrum };
struct param_syntax {
  value_kind kind;
  int group = 1;  // values per element (3 for point3), 0: exactly `exact`
  int exact = 0;
};

std::optional<param_syntax> param_type(std::string_view t) {
  if (t == "integer") return param_syntax{value_kind::integer};
  if (t == "float") return param_syntax{value_kind::number};
  if (t == "point2" || t == "vector2") return param_syntax{value_kind::number, 2};
  if (t == "point3" || t == "vector3" || t == "normal" || t == "normal3" || t == "point" || t == "vector")
    return param_syntax{value_kind::number, 3};
  if (t == "rgb" || t == "color") return param_syntax{value_kind::number, 0, 3};
  if (t == "blackbody") return param_syntax{value_kind::number, 0, 1};
  if (t == "spectrum") return param_syntax{value_kind::spectrum};
  if (t == "bool") return param_syntax{value_kind::boolean};
  if (t == "string" || t == "texture") return param_syntax{value_kind::string};
  return std::nullopt;
}

class parser {
 public:
  parser(const parse_options& options, std::vector<directive>& out) : options_(options), out_(out) {}

  void parse(std::string text, const std::string& name, int depth) {
    // Every file's text counts, each time it is included: a few small files
    // that include each other twice over would otherwise make 2^depth
    // copies (the depth bound alone lets that run for ever).
    total_bytes_ += text.size();
    if (total_bytes_ > options_.max_input_bytes)
      throw parse_error(file_loc{std::make_shared<const std::string>(name), 1, 1},
                        "the scene's text with its Includes (each counted as often as it is included) is more than " +
                            io::byte_count(options_.max_input_bytes) + " (--max-input-size raises the bound)");
    open_files_.push_back(canonical(name));
    tokenizer tok(std::move(text), name);
    token t = tok.next();
    while (t.k != token::kind::end) {
      if (t.k != token::kind::word) throw parse_error(t.loc, "expected a directive, got " + describe(t));
      const auto it = directives().find(t.text);
      if (it == directives().end())
        throw parse_error(t.loc, "unknown directive '" + quote_prefix(t.text) + "' (directives: " + directive_names() + ")");
      directive d;
      d.name = t.text;
      d.loc = t.loc;
      t = arguments(tok, it->second, d);
      t = params(tok, t, d);
      if (d.name == "Include" || d.name == "Import") {
        include(d, depth);
        continue;
      }
      balance(d);
      out_.push_back(std::move(d));
    }
    if (depth == 0 && !open_.empty())
      throw parse_error(open_.back().second, open_.back().first + " without its matching end");
    open_files_.pop_back();
  }

 private:
  const parse_options& options_;
  std::vector<directive>& out_;
  std::vector<std::pair<std::string, file_loc>> open_;  // AttributeBegin, TransformBegin, ObjectBegin
  std::vector<std::string> open_files_;  // the files being read, the including before the included
  std::uint64_t total_bytes_ = 0;        // the text read so far, Includes counted each time
  std::uint64_t includes_ = 0;           // the Includes read so far

  static std::string canonical(const std::string& file) {
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::path(file), ec);
    return ec ? fs::path(file).lexically_normal().string() : p.string();
  }

  static std::string describe(const token& t) {
    switch (t.k) {
      case token::kind::string: return "the string \"" + quote_prefix(t.text) + "\"";
      case token::kind::open_bracket: return "'['";
      case token::kind::close_bracket: return "']'";
      case token::kind::end: return "the end of the file";
      default: return "'" + quote_prefix(t.text) + "'";
    }
  }

  static double number(const token& t, const std::string& what) {
    if (t.k != token::kind::word) throw parse_error(t.loc, what + ": expected a number, got " + describe(t));
    const std::optional<double> v = parse_number(t.text);
    if (!v) throw parse_error(t.loc, what + ": '" + quote_prefix(t.text) + "' is not a number");
    if (!std::isfinite(*v)) throw parse_error(t.loc, what + ": '" + quote_prefix(t.text) + "' is not a finite number");
    // pbrt-v4 reads every value in single precision (its Float): beyond
    // FLT_MAX a value is infinite there, and mcrt's geometry, colours and
    // parameters are floats too.
    if (!std::isfinite(static_cast<float>(*v)))
      throw parse_error(t.loc, what + ": '" + quote_prefix(t.text) + "' is not finite in single precision (beyond 3.4e38)");
    return *v;
  }

  static std::string string_arg(const token& t, const std::string& what) {
    if (t.k != token::kind::string) throw parse_error(t.loc, what + ": expected a quoted string, got " + describe(t));
    return t.text;
  }

  // The directive's arguments; returns the token after them.
  token arguments(tokenizer& tok, const directive_syntax& s, directive& d) {
    token t = tok.next();
    switch (s.shape) {
      case shape_of::nothing:
      case shape_of::params_only: return t;
      case shape_of::numbers:
        for (int i = 0; i < s.count; ++i, t = tok.next())
          d.numbers.push_back(number(t, d.name + " (" + std::to_string(s.count) + " numbers)"));
        return t;
      case shape_of::matrix: {
        const std::string what = d.name + " (16 numbers in brackets)";
        if (t.k != token::kind::open_bracket) throw parse_error(t.loc, what + ": expected '[', got " + describe(t));
        for (t = tok.next(); t.k != token::kind::close_bracket; t = tok.next()) {
          if (t.k == token::kind::end) throw parse_error(d.loc, what + ": no closing ']'");
          d.numbers.push_back(number(t, what));
        }
        if (d.numbers.size() != 16)
          throw parse_error(d.loc, what + ": got " + std::to_string(d.numbers.size()) + " numbers");
        return tok.next();
      }
      case shape_of::one_string:
        d.strings.push_back(string_arg(t, d.name));
        return tok.next();
      case shape_of::word:
        if (t.k != token::kind::word || !(t.text == "All" || t.text == "StartTime" || t.text == "EndTime"))
          throw parse_error(t.loc, d.name + ": expected All, StartTime or EndTime, got " + describe(t));
        d.strings.push_back(t.text);
        return tok.next();
      case shape_of::typed:
        d.type = string_arg(t, d.name + " (its type)");
        return tok.next();
      case shape_of::named:
        d.strings.push_back(string_arg(t, d.name + " (its name)"));
        return tok.next();
      case shape_of::texture:
        for (const char* part : {"name", "type", "class"}) {
          d.strings.push_back(string_arg(t, d.name + std::string(" (its ") + part + ")"));
          t = tok.next();
        }
        d.type = d.strings[2];
        return t;
      case shape_of::one_or_two:
        d.strings.push_back(string_arg(t, d.name));
        t = tok.next();
        if (t.k == token::kind::string && t.text.find(' ') == std::string::npos) {
          d.strings.push_back(t.text);
          t = tok.next();
        }
        return t;
    }
    return t;
  }

  // The parameter list starting at t; returns the token after it.
  token params(tokenizer& tok, token t, directive& d) {
    while (t.k == token::kind::string) {
      param p;
      p.loc = t.loc;
      // "type name": two words separated by white space.
      const std::string decl = t.text;  // (a copy: t moves on below)
      const std::string shown = quote_prefix(decl);  // for messages
      const std::size_t a = decl.find_first_not_of(" \t");
      const std::size_t b = decl.find_first_of(" \t", a);
      const std::size_t c = b == std::string::npos ? b : decl.find_first_not_of(" \t", b);
      const std::size_t e = c == std::string::npos ? c : decl.find_first_of(" \t", c);
      if (a == std::string::npos || c == std::string::npos ||
          (e != std::string::npos && decl.find_first_not_of(" \t", e) != std::string::npos))
        throw parse_error(t.loc, d.name + ": expected a parameter \"TYPE NAME\", got the string \"" + shown + "\"");
      p.type = decl.substr(a, b - a);
      p.name = decl.substr(c, e == std::string::npos ? std::string::npos : e - c);
      const std::optional<param_syntax> syntax = param_type(p.type);
      if (!syntax)
        throw parse_error(t.loc, "parameter \"" + shown + "\": unknown type '" + quote_prefix(p.type) +
                                     "' (integer, float, point2, vector2, point3, vector3, normal, rgb, blackbody, "
                                     "spectrum, bool, string, texture)");
      for (const param& q : d.params)
        if (q.name == p.name) throw parse_error(t.loc, "parameter '" + quote_prefix(p.name) + "' given twice");
      t = tok.next();
      std::vector<token> values;
      if (t.k == token::kind::open_bracket) {
        for (t = tok.next(); t.k != token::kind::close_bracket; t = tok.next()) {
          if (t.k == token::kind::end || t.k == token::kind::open_bracket)
            throw parse_error(p.loc, "parameter \"" + shown + "\": no closing ']'");
          values.push_back(t);
        }
        t = tok.next();
      } else {
        if (t.k != token::kind::word && t.k != token::kind::string)
          throw parse_error(t.loc, "parameter \"" + shown + "\": expected a value, got " + describe(t));
        values.push_back(t);
        t = tok.next();
      }
      fill(p, *syntax, values);
      d.params.push_back(std::move(p));
    }
    return t;
  }

  static void fill(param& p, const param_syntax& s, const std::vector<token>& values) {
    const std::string what = "parameter \"" + p.type + " " + quote_prefix(p.name) + "\"";
    if (values.empty()) throw parse_error(p.loc, what + ": no values");
    const bool strings = values.front().k == token::kind::string;
    if (s.kind == value_kind::string || (s.kind == value_kind::spectrum && strings)) {
      for (const token& v : values) {
        if (v.k != token::kind::string) throw parse_error(v.loc, what + ": expected quoted strings, got " + describe(v));
        p.strings.push_back(v.text);
      }
      if (s.kind == value_kind::spectrum && p.strings.size() != 1)
        throw parse_error(p.loc, what + ": expected one named spectrum or file name");
      return;
    }
    if (s.kind == value_kind::boolean) {
      for (const token& v : values) {
        if (v.text != "true" && v.text != "false")
          throw parse_error(v.loc, what + ": expected true or false, got " + describe(v));
        p.bools.push_back(v.text == "true");
      }
      return;
    }
    for (const token& v : values) {
      const double x = number(v, what);
      if (s.kind == value_kind::integer && (x != std::floor(x) || std::abs(x) > 2147483647.0))
        throw parse_error(v.loc, what + ": '" + quote_prefix(v.text) + "' is not an integer");
      p.numbers.push_back(x);
    }
    const std::size_t n = p.numbers.size();
    if (s.group == 0 && n != static_cast<std::size_t>(s.exact))
      throw parse_error(p.loc, what + ": expected " + std::to_string(s.exact) + " values, got " + std::to_string(n));
    if (s.group > 1 && n % static_cast<std::size_t>(s.group) != 0)
      throw parse_error(p.loc, what + ": expected a multiple of " + std::to_string(s.group) + " values, got " +
                                   std::to_string(n));
    if (s.kind == value_kind::spectrum && n % 2 != 0)
      throw parse_error(p.loc, what + ": expected (wavelength, value) pairs, got " + std::to_string(n) + " values");
  }

  void balance(const directive& d) {
    static const std::map<std::string, std::string, std::less<>> ends = {
        {"AttributeEnd", "AttributeBegin"}, {"TransformEnd", "TransformBegin"}, {"ObjectEnd", "ObjectBegin"}};
    if (d.name == "AttributeBegin" || d.name == "TransformBegin" || d.name == "ObjectBegin") {
      open_.emplace_back(d.name, d.loc);
      return;
    }
    const auto it = ends.find(d.name);
    if (it == ends.end()) return;
    if (open_.empty()) throw parse_error(d.loc, d.name + " without a matching " + it->second);
    if (open_.back().first != it->second)
      throw parse_error(d.loc, d.name + " closes the " + open_.back().first + " of line " +
                                   std::to_string(open_.back().second.line));
    open_.pop_back();
  }

  void include(const directive& d, int depth) {
    if (++includes_ > options_.max_includes)
      throw parse_error(d.loc, d.name + ": more than " + std::to_string(options_.max_includes) +
                                   " files included in all (each Include counted every time it is read)");
    if (depth + 1 > options_.max_include_depth)
      throw parse_error(d.loc, d.name + ": includes nested deeper than " + std::to_string(options_.max_include_depth));
    fs::path p(d.strings.at(0));
    if (p.is_relative() && !options_.search_directory.empty()) p = fs::path(options_.search_directory) / p;
    const std::string file = p.lexically_normal().string();
    // A file that includes itself, directly or through others, never ends.
    const std::string key = canonical(file);
    for (std::size_t i = 0; i < open_files_.size(); ++i)
      if (open_files_[i] == key) {
        std::string chain;
        for (std::size_t j = i; j < open_files_.size(); ++j) chain += fs::path(open_files_[j]).filename().string() + " -> ";
        throw parse_error(d.loc, d.name + ": '" + quote_prefix(d.strings.at(0), 200) + "' includes itself (" +
                                     quote_prefix(chain + fs::path(key).filename().string(), 300) + ")");
      }
    parse(read_scene_text(file, d.loc, options_.max_input_bytes), file, depth + 1);
  }
};

}  // namespace

// A number as pbrt writes it: an optional sign, digits with an optional
// point, an optional exponent ("-2", "+3.5", ".5", "5.", "1e-3").
std::optional<double> parse_number(const std::string& w) {
  if (w.empty()) return std::nullopt;
  std::size_t i = 0;
  if (w[0] == '+') i = 1;
  if (i == 1 && w.size() > 1 && w[1] == '-') return std::nullopt;
  const char* first = w.data() + i;
  const char* last = w.data() + w.size();
  if (first == last || !(std::isdigit(static_cast<unsigned char>(*first)) || *first == '.' || *first == '-'))
    return std::nullopt;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(first, last, v, std::chars_format::general);
  if (ptr != last) return std::nullopt;
  if (ec == std::errc::result_out_of_range) return std::numeric_limits<double>::infinity();
  if (ec != std::errc()) return std::nullopt;
  return v;
}

const param* directive::find(const std::string& param_name) const {
  for (const param& p : params)
    if (p.name == param_name) return &p;
  return nullptr;
}

std::vector<directive> parse_text(std::string text, const std::string& name, const parse_options& options) {
  std::vector<directive> out;
  parser(options, out).parse(std::move(text), name, 0);
  return out;
}

std::vector<directive> parse_file(const std::string& path, const parse_options& options) {
  parse_options o = options;
  if (o.search_directory.empty()) {
    o.search_directory = fs::path(path).parent_path().string();
    if (o.search_directory.empty()) o.search_directory = ".";
  }
  const auto name = std::make_shared<const std::string>(path);
  std::vector<directive> ds = parse_text(read_scene_text(path, file_loc{name, 1, 1}, o.max_input_bytes), path, o);
  // (An empty file, or one of comments and white space only: named here,
  // where its name is known.)
  if (ds.empty()) throw parse_error(file_loc{name, 1, 1}, "the file has no directives (no WorldBegin)");
  return ds;
}

}  // namespace mcrt::pbrt
