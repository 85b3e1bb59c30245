#pragma once
// A directive's parameters as the builder's families read them (builder.cpp,
// materials.cpp, ...): typed lookups that mark each parameter used, and
// finish(), which refuses any the directive gave that nothing used. Messages
// are parse_error (FILE:LINE: what), with values from the file quoted within
// bounds.
#include <cmath>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pbrt/parser.hpp"
#include "pbrt/tokenizer.hpp"

namespace mcrt::pbrt {

// A name or value from the file in a message (bounded: tokenizer.hpp).
// (Appended piece by piece: GCC 12 at -O3 flags "\"" + s + "\"" with a
// false -Wrestrict, GCC bug 105329.)
inline std::string quoted(const std::string& s) {
  std::string out;
  out.reserve(s.size() + 2);
  out += '"';
  out += quote_prefix(s, 200);
  out += '"';
  return out;
}

[[noreturn]] inline void refuse(const file_loc& loc, const std::string& what) { throw parse_error(loc, what); }

// A directive's parameters as one shape, material, texture ... reads them:
// each lookup marks the parameter used, and finish() refuses any the
// directive gave that nothing used (nothing is silently ignored). Attribute
// defaults of the directive's kind are looked up after its own parameters.
class params {
 public:
  params(const directive& d, const std::vector<param>* defaults = nullptr)
      : d_(d), defaults_(defaults), what_(d.name + (d.type.empty() ? "" : " " + quoted(d.type))) {}

  const std::string& what() const { return what_; }
  const file_loc& loc() const { return d_.loc; }

  const param* find(const std::string& name) {
    for (const param& p : d_.params)
      if (p.name == name) {
        used_.insert(&p);
        return &p;
      }
    if (defaults_)
      for (const param& p : *defaults_)
        if (p.name == name) return &p;
    return nullptr;
  }

  [[noreturn]] void fail(const param& p, const std::string& reason) const {
    refuse(p.loc, what_ + ": " + quoted(p.type + " " + p.name) + " " + reason);
  }
  [[noreturn]] void fail(const std::string& reason) const { refuse(d_.loc, what_ + ": " + reason); }

  void expect_type(const param& p, std::initializer_list<const char*> types) const {
    for (const char* t : types)
      if (p.type == t) return;
    std::string list;
    for (const char* t : types) list += (list.empty() ? "" : " or ") + std::string(t);
    fail(p, "must be of type " + list);
  }

  std::optional<double> number(const std::string& name, std::initializer_list<const char*> types = {"float"}) {
    const param* p = find(name);
    if (!p) return std::nullopt;
    expect_type(*p, types);
    if (p->numbers.size() != 1) fail(*p, "must have one value, has " + std::to_string(p->size()));
    return p->numbers[0];
  }
  double real(const std::string& name, double def) { return number(name).value_or(def); }
  int integer(const std::string& name, int def) {
    const std::optional<double> v = number(name, {"integer"});
    if (!v) return def;
    if (*v != std::floor(*v) || std::abs(*v) > 2e9) fail(*find(name), "must be an integer");
    return static_cast<int>(*v);
  }
  bool boolean(const std::string& name, bool def) {
    const param* p = find(name);
    if (!p) return def;
    expect_type(*p, {"bool"});
    if (p->bools.size() != 1) fail(*p, "must have one value");
    return p->bools[0];
  }
  std::optional<std::string> string(const std::string& name) {
    const param* p = find(name);
    if (!p) return std::nullopt;
    expect_type(*p, {"string"});
    if (p->strings.size() != 1) fail(*p, "must have one value");
    return p->strings[0];
  }
  std::vector<double> numbers(const std::string& name, std::initializer_list<const char*> types, std::size_t group) {
    const param* p = find(name);
    if (!p) return {};
    expect_type(*p, types);
    if (p->numbers.size() % group != 0)
      fail(*p, "must have a multiple of " + std::to_string(group) + " values, has " + std::to_string(p->numbers.size()));
    return p->numbers;
  }

  // A parameter mcrt does not implement is accepted at pbrt-v4's default
  // value only (where it does not change the image).
  void accept_default(const std::string& name, double def) {
    const param* p = find(name);
    if (p && !(p->numbers.size() == 1 && p->numbers[0] == def))
      fail(*p, "is not supported except at its default " + std::to_string(def));
  }
  void accept_default_string(const std::string& name, const std::string& def) {
    const param* p = find(name);
    if (p && !(p->strings.size() == 1 && p->strings[0] == def)) fail(*p, "is not supported except at its default " + quoted(def));
  }
  // Parameters that do not change the expected image (render options).
  void accept_any(const std::string& name) { find(name); }

  // Refuses what the directive gave and nothing used.
  void finish() const {
    for (const param& p : d_.params)
      if (!used_.count(&p)) fail(p, "is not supported");
  }

 private:
  const directive& d_;
  const std::vector<param>* defaults_;
  std::string what_;
  std::set<const param*> used_;
};

}  // namespace mcrt::pbrt
