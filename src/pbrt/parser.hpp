#pragma once
// The syntactic layer of pbrt-v4's scene format: directives and their
// parameter lists, read from a file and the files it Includes or Imports,
// with the place of each in every error. It knows the syntax and nothing of
// what a directive means: a scene builder walks the directives in order.
//
// Grammar (pbrt-v4 File Format reference; pbrt-v4 src/pbrt/parser.cpp):
//   directive  := NAME arguments params
//   arguments  := what NAME takes: nothing (AttributeBegin, WorldBegin ...),
//                 numbers (Translate 3, Scale 3, Rotate 4, LookAt 9,
//                 TransformTimes 2; Transform and ConcatTransform [16]),
//                 strings (CoordinateSystem "n", Include "file", Texture
//                 "name" "type" "class", ...), or a quoted type ("Shape
//                 "sphere"")
//   params     := { "TYPE NAME" value | "TYPE NAME" [ value ... ] }
//   value      := a number, a quoted string, or true / false
// Parameter types: integer, float, point2, vector2, point3, vector3,
// normal (normal3), rgb, blackbody, spectrum, bool, string, texture (and the
// older point, vector, color for point3, vector3, rgb).
#include <optional>
#include <string>
#include <vector>

#include "input_file.hpp"
#include "pbrt/tokenizer.hpp"

namespace mcrt::pbrt {

// One parameter, "float fov" [ 45 ]: its type and name as declared and its
// values, numbers, strings or booleans as the type takes them.
struct param {
  std::string type, name;
  std::vector<double> numbers;
  std::vector<std::string> strings;
  std::vector<bool> bools;
  file_loc loc;

  // Values of a numeric type, of a string type, or of bool.
  std::size_t size() const { return numbers.size() + strings.size() + bools.size(); }
};

struct directive {
  std::string name;                  // "Shape", "Translate", "AttributeBegin", ...
  std::string type;                  // the quoted type of Shape, Material, Camera, ... ("sphere")
  std::vector<std::string> strings;  // string arguments (Texture's name, type and class; Include's file ...)
  std::vector<double> numbers;       // numeric arguments (Translate's x, y, z; Transform's 16 ...)
  std::vector<param> params;
  file_loc loc;

  // The parameter of that name, or nullptr.
  const param* find(const std::string& param_name) const;
};

struct parse_options {
  // Relative file names of Include and Import are resolved against this
  // directory (pbrt-v4: that of the top-level scene file); empty: the
  // top-level file's.
  std::string search_directory;
  // Includes nested deeper than this are refused (a file that includes
  // itself).
  int max_include_depth = 64;
  // Includes read in all, each time counted: a few files that include each
  // other twice over would make 2^depth of them.
  std::uint64_t max_includes = 100000;
  // No file is read past this many bytes (nor a .gz file's unpacked
  // stream): src/input_file.hpp, the executable's --max-input-size.
  std::uint64_t max_input_bytes = io::default_max_input_bytes;
};

// A number as pbrt writes it ("-2", "+3.5", ".5", "5.", "1e-3"): its value
// (infinity where it overflows a double), or nullopt where it is not one.
std::optional<double> parse_number(const std::string& word);

// The directives of a scene file and of the files it includes, in order,
// Include and Import replaced by the included files' directives. Throws
// parse_error (one line: file, line, reason) on bad syntax, unknown
// directives or parameter types, values that do not fit their type,
// non-finite numbers, unbalanced AttributeBegin/AttributeEnd (and
// TransformBegin/End, ObjectBegin/End), and files that cannot be read.
std::vector<directive> parse_file(const std::string& path, const parse_options& options = {});

// The same for scene text held in memory; `name` names it in errors and
// relative Includes are resolved against options.search_directory (the
// current directory when empty).
std::vector<directive> parse_text(std::string text, const std::string& name, const parse_options& options = {});

}  // namespace mcrt::pbrt
