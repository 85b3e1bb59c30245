#include "pbrt/ply.hpp"

#include "input_file.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>

namespace mcrt::pbrt {
namespace {

enum class scalar { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

std::optional<scalar> scalar_named(const std::string& s) {
  if (s == "char" || s == "int8") return scalar::int8;
  if (s == "uchar" || s == "uint8") return scalar::uint8;
  if (s == "short" || s == "int16") return scalar::int16;
  if (s == "ushort" || s == "uint16") return scalar::uint16;
  if (s == "int" || s == "int32") return scalar::int32;
  if (s == "uint" || s == "uint32") return scalar::uint32;
  if (s == "float" || s == "float32") return scalar::float32;
  if (s == "double" || s == "float64") return scalar::float64;
  return std::nullopt;
}

std::size_t size_of(scalar s) {
  switch (s) {
    case scalar::int8: case scalar::uint8: return 1;
    case scalar::int16: case scalar::uint16: return 2;
    case scalar::int32: case scalar::uint32: case scalar::float32: return 4;
    case scalar::float64: return 8;
  }
  return 1;
}

bool is_integer(scalar s) { return s != scalar::float32 && s != scalar::float64; }

struct property {
  std::string name;
  scalar type = scalar::float32;
  bool list = false;
  scalar count_type = scalar::uint8;
};

struct element {
  std::string name;
  std::size_t count = 0;
  std::vector<property> properties;
  int line = 0;
};

enum class format { ascii, little, big };

// Reads the values of the data section, in either format.
class cursor {
 public:
  cursor(const std::string& bytes, std::size_t pos, format f, const file_loc& loc)
      : b_(bytes), pos_(pos), f_(f), loc_(loc) {}

  std::size_t remaining() const { return b_.size() - pos_; }

  double read(scalar s, const std::string& what) {
    if (f_ == format::ascii) return read_ascii(s, what);
    const std::size_t n = size_of(s);
    if (remaining() < n) throw parse_error(loc_, what + ": the file ends early (truncated)");
    unsigned char raw[8];
    std::memcpy(raw, b_.data() + pos_, n);
    pos_ += n;
    const bool swap = (f_ == format::big) == (std::endian::native == std::endian::little);
    // Byte order reversed pair by pair: std::reverse here, vectorised and
    // inlined across units (-flto), drew GCC 12's false -Wstringop-overflow
    // of a 32-byte write (n is at most 8, from size_of).
    if (swap)
      for (std::size_t i = 0, j = n - 1; i < j; ++i, --j) std::swap(raw[i], raw[j]);
    switch (s) {
      case scalar::int8: { std::int8_t v; std::memcpy(&v, raw, 1); return v; }
      case scalar::uint8: return raw[0];
      case scalar::int16: { std::int16_t v; std::memcpy(&v, raw, 2); return v; }
      case scalar::uint16: { std::uint16_t v; std::memcpy(&v, raw, 2); return v; }
      case scalar::int32: { std::int32_t v; std::memcpy(&v, raw, 4); return v; }
      case scalar::uint32: { std::uint32_t v; std::memcpy(&v, raw, 4); return v; }
      case scalar::float32: { float v; std::memcpy(&v, raw, 4); return v; }
      case scalar::float64: { double v; std::memcpy(&v, raw, 8); return v; }
    }
    return 0.0;
  }

 private:
  const std::string& b_;
  std::size_t pos_;
  format f_;
  file_loc loc_;

  double read_ascii(scalar s, const std::string& what) {
    while (pos_ < b_.size() && std::isspace(static_cast<unsigned char>(b_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < b_.size() && !std::isspace(static_cast<unsigned char>(b_[pos_]))) ++pos_;
    if (start == pos_) throw parse_error(loc_, what + ": the file ends early (truncated)");
    const char* first = b_.data() + start;
    if (*first == '+') ++first;
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(first, b_.data() + pos_, v);
    if (ec != std::errc() || ptr != b_.data() + pos_)
      throw parse_error(loc_, what + ": '" + b_.substr(start, std::min<std::size_t>(pos_ - start, 40)) + "' is not a number");
    if (is_integer(s) && v != std::floor(v))
      throw parse_error(loc_, what + ": '" + quote_prefix(b_.substr(start, pos_ - start)) + "' is not an integer");
    return v;
  }
};


// What a PLY header says: the data's format and its elements, and where
// the data begins (the byte after end_header's line, header_lines lines in).
struct ply_header {
  format fmt = format::ascii;
  std::vector<element> elements;
  std::size_t body = 0;
  int lines = 0;
};

using fail_fn = std::function<parse_error(int line, const std::string& what)>;

// Reads the header at the start of `bytes`, which must hold it whole.
ply_header parse_header(const std::string& bytes, const fail_fn& fail) {
  ply_header h;
  std::size_t pos = 0;
  int line_no = 0;
  const auto next_line = [&](std::string& out) {
    if (pos >= bytes.size()) return false;
    const std::size_t end = bytes.find('\n', pos);
    out = bytes.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (!out.empty() && out.back() == '\r') out.pop_back();
    pos = end == std::string::npos ? bytes.size() : end + 1;
    ++line_no;
    return true;
  };
  std::string line;
  if (!next_line(line) || line != "ply") throw fail(1, "not a PLY file (no 'ply' on its first line)");
  format fmt = format::ascii;
  bool have_format = false, ended = false;
  std::vector<element> elements;
  while (next_line(line)) {
    std::istringstream in(line);
    std::string word;
    in >> word;
    if (word.empty() || word == "comment" || word == "obj_info") continue;
    if (word == "end_header") {
      ended = true;
      break;
    }
    if (word == "format") {
      std::string f, version;
      in >> f >> version;
      if (f == "ascii") fmt = format::ascii;
      else if (f == "binary_little_endian") fmt = format::little;
      else if (f == "binary_big_endian") fmt = format::big;
      else throw fail(line_no, "unknown format '" + quote_prefix(f) + "'");
      if (version != "1.0") throw fail(line_no, "unknown format version '" + quote_prefix(version) + "'");
      have_format = true;
    } else if (word == "element") {
      element e;
      long long count = -1;
      in >> e.name >> count;
      if (e.name.empty() || count < 0 || in.fail()) throw fail(line_no, "bad element line '" + quote_prefix(line) + "'");
      e.count = static_cast<std::size_t>(count);
      e.line = line_no;
      elements.push_back(std::move(e));
    } else if (word == "property") {
      if (elements.empty()) throw fail(line_no, "a property before any element");
      property p;
      std::string t;
      in >> t;
      if (t == "list") {
        std::string ct, it;
        in >> ct >> it >> p.name;
        const auto c = scalar_named(ct), i = scalar_named(it);
        if (!c || !i || !is_integer(*c)) throw fail(line_no, "bad list property '" + quote_prefix(line) + "'");
        p.list = true;
        p.count_type = *c;
        p.type = *i;
      } else {
        in >> p.name;
        const auto s = scalar_named(t);
        if (!s) throw fail(line_no, "unknown property type '" + quote_prefix(t) + "'");
        p.type = *s;
      }
      if (p.name.empty()) throw fail(line_no, "a property without a name");
      elements.back().properties.push_back(p);
    } else {
      throw fail(line_no, "unknown header line '" + quote_prefix(line) + "'");
    }
  }
  if (!ended) throw fail(line_no, "the header has no end_header (truncated)");
  if (!have_format) throw fail(2, "no format line");
  h.fmt = fmt;
  h.elements = std::move(elements);
  h.body = pos;
  h.lines = line_no;
  return h;
}

// The fewest bytes an element's entry takes: a byte or more per value
// (binary; a list at least its count), two characters per value (ASCII:
// a digit and a separator).
std::size_t min_entry_bytes(const element& e, format fmt) {
  if (fmt == format::ascii) return 2 * e.properties.size();
  std::size_t n = 0;
  for (const property& p : e.properties) n += p.list ? size_of(p.count_type) : size_of(p.type);
  return n;
}

// Refuses a header whose counts the data cannot hold (`available` bytes at
// most), before the data is read or anything is allocated for it.
void check_counts(const ply_header& h, std::uint64_t available, const fail_fn& fail) {
  std::uint64_t need = 0;
  for (const element& e : h.elements) {
    const std::uint64_t m = min_entry_bytes(e, h.fmt);
    if (m > 0 && e.count > (available - std::min(need, available)) / m)
      throw fail(e.line, "element '" + quote_prefix(e.name) + "' has " + std::to_string(e.count) +
                             " entries, more than the file holds (truncated, or a header that lies)");
    need += m * e.count;
  }
}

triangle_mesh parse_body(const std::string& bytes, const ply_header& h, const std::shared_ptr<const std::string>& file,
                         const fail_fn& fail, ply_stats* stats) {
  const format fmt = h.fmt;
  const std::vector<element>& elements = h.elements;
  const std::size_t pos = h.body;
  const int line_no = h.lines;
  triangle_mesh mesh;
  // Quads, in face order with the triangles: planar and convex ones as two
  // triangles; a quad with a repeated corner is the triangle of the other
  // three (one with fewer distinct corners has no area and is left out).
  std::size_t quad_count = 0;
  const auto add_quad = [&](const std::uint32_t* v, std::size_t face, int line) {
    std::vector<std::uint32_t> distinct;
    for (int j = 0; j < 4; ++j)
      if (std::find(distinct.begin(), distinct.end(), v[j]) == distinct.end()) distinct.push_back(v[j]);
    if (distinct.size() < 3) return;
    if (distinct.size() == 3) {
      mesh.indices.insert(mesh.indices.end(), distinct.begin(), distinct.end());
      return;
    }
    const dvec3 p0(mesh.p[v[0]]), p1(mesh.p[v[1]]), p2(mesh.p[v[2]]), p3(mesh.p[v[3]]);
    const dvec3 na = glm::cross(p1 - p0, p2 - p0), nb = glm::cross(p2 - p0, p3 - p0);
    const dvec3 nc = glm::cross(p2 - p1, p3 - p1), nd = glm::cross(p3 - p1, p0 - p1);
    const double size = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p3 - p2), glm::length(p0 - p3)});
    const double len = glm::length(na + nb);
    const double off = len > 0.0 ? std::abs(glm::dot(p3 - p0, (na + nb) / len)) : 0.0;
    const bool convex = glm::dot(na, nb) > 0.0 && glm::dot(nc, nd) > 0.0;
    if (!(off <= 1e-5 * size) || !convex)
      throw fail(line, "face " + std::to_string(face) + ": a quad that is not planar and convex (mcrt has no bilinear patches)");
    mesh.indices.insert(mesh.indices.end(), {v[0], v[1], v[2], v[0], v[2], v[3]});
    ++quad_count;
  };
  const element* vertex = nullptr;
  bool have_faces = false;
  cursor cur(bytes, pos, fmt, file_loc{file, line_no + 1, 1});
  for (const element& e : elements) {
    // A count the rest of the file cannot hold is a truncated or corrupt
    // file, refused before anything is allocated for it (check_counts
    // checked the whole header so; this holds the ASCII data's own pace).
    const std::size_t min_bytes = min_entry_bytes(e, fmt);
    if (min_bytes > 0 && e.count > cur.remaining() / min_bytes)
      throw fail(e.line, "element '" + quote_prefix(e.name) + "' has " + std::to_string(e.count) + " entries, more than the file holds (truncated)");
    // An element of no properties has nothing to read, however many entries it claims.
    if (e.properties.empty() && e.name != "vertex" && e.name != "face") continue;
    if (e.name == "vertex") {
      vertex = &e;
      int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, iu = -1, iv = -1;
      for (int k = 0; k < int(e.properties.size()); ++k) {
        const std::string& n = e.properties[std::size_t(k)].name;
        if (e.properties[std::size_t(k)].list) continue;
        if (n == "x") ix = k; else if (n == "y") iy = k; else if (n == "z") iz = k;
        else if (n == "nx") inx = k; else if (n == "ny") iny = k; else if (n == "nz") inz = k;
        else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s") iu = k;
        else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t") iv = k;
      }
      if (ix < 0 || iy < 0 || iz < 0) throw fail(e.line, "the vertex element has no x, y and z");
      const bool normals = inx >= 0 && iny >= 0 && inz >= 0, uvs = iu >= 0 && iv >= 0;
      mesh.p.resize(e.count);
      if (normals) mesh.n.resize(e.count);
      if (uvs) mesh.uv.resize(e.count);
      std::vector<double> values(e.properties.size());
      for (std::size_t i = 0; i < e.count; ++i) {
        const std::string what = "vertex " + std::to_string(i);
        for (std::size_t k = 0; k < e.properties.size(); ++k) {
          const property& p = e.properties[k];
          if (p.list) {
            const double n = cur.read(p.count_type, what);
            for (double j = 0; j < n; ++j) cur.read(p.type, what);
            continue;
          }
          values[k] = cur.read(p.type, what);
        }
        const vec3 pt(float(values[std::size_t(ix)]), float(values[std::size_t(iy)]), float(values[std::size_t(iz)]));
        if (!all_finite(pt)) throw fail(e.line, what + ": a coordinate is not finite");
        mesh.p[i] = pt;
        // Shading normals and uv must be finite as the positions must (a
        // NaN normal would make every shading frame there NaN).
        if (normals) {
          mesh.n[i] = vec3(float(values[std::size_t(inx)]), float(values[std::size_t(iny)]), float(values[std::size_t(inz)]));
          if (!all_finite(mesh.n[i])) throw fail(e.line, what + ": a normal (nx, ny, nz) is not finite");
        }
        if (uvs) {
          mesh.uv[i] = vec2(float(values[std::size_t(iu)]), float(values[std::size_t(iv)]));
          if (!std::isfinite(mesh.uv[i].x) || !std::isfinite(mesh.uv[i].y))
            throw fail(e.line, what + ": a texture coordinate (u, v) is not finite");
        }
      }
      continue;
    }
    const bool is_face = e.name == "face";
    int idx = -1;
    if (is_face)
      for (int k = 0; k < int(e.properties.size()); ++k)
        if (e.properties[std::size_t(k)].list &&
            (e.properties[std::size_t(k)].name == "vertex_indices" || e.properties[std::size_t(k)].name == "vertex_index"))
          idx = k;
    if (is_face && idx < 0) throw fail(e.line, "the face element has no vertex_indices list");
    if (is_face) have_faces = true;
    for (std::size_t i = 0; i < e.count; ++i) {
      const std::string what = e.name + " " + std::to_string(i);
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const property& p = e.properties[k];
        if (!p.list) {
          cur.read(p.type, what);
          continue;
        }
        const double n = cur.read(p.count_type, what);
        if (!(n >= 0.0)) throw fail(e.line, what + ": a negative list length");
        if (int(k) != idx) {
          for (double j = 0; j < n; ++j) cur.read(p.type, what);
          continue;
        }
        if (n != 3.0 && n != 4.0)
          throw fail(e.line, what + ": a face of " + std::to_string(static_cast<long long>(n)) +
                                 " vertices (triangles and quads are supported)");
        std::uint32_t v[4];
        for (int j = 0; j < int(n); ++j) {
          const double x = cur.read(p.type, what);
          if (!vertex || !(x >= 0.0) || x >= double(mesh.p.size()))
            throw fail(e.line, what + ": vertex index " + std::to_string(static_cast<long long>(x)) + " out of range (" +
                                   std::to_string(mesh.p.size()) + " vertices)");
          v[j] = static_cast<std::uint32_t>(x);
        }
        if (n == 3.0)
          mesh.indices.insert(mesh.indices.end(), {v[0], v[1], v[2]});
        else
          add_quad(v, i, e.line);
      }
    }
  }
  if (!vertex) throw fail(1, "no vertex element");
  if (!have_faces) throw fail(1, "no face element");

  if (stats) *stats = {mesh.p.size(), mesh.indices.size() / 3, quad_count};
  return mesh;
}

fail_fn failer(const std::shared_ptr<const std::string>& file) {
  return [file](int line, const std::string& what) { return parse_error(file_loc{file, line, 1}, "PLY: " + what); };
}

}  // namespace

triangle_mesh read_ply_bytes(const std::string& bytes, const std::string& name, ply_stats* stats) {
  const auto file = std::make_shared<const std::string>(name);
  const fail_fn fail = failer(file);
  const ply_header h = parse_header(bytes, fail);
  check_counts(h, bytes.size() - h.body, fail);
  return parse_body(bytes, h, file, fail, stats);
}

triangle_mesh read_ply(const std::string& path, std::uint64_t max_bytes, ply_stats* stats) {
  const auto file = std::make_shared<const std::string>(path);
  const fail_fn fail = failer(file);
  try {
    io::input_file in(path, max_bytes);
    // The header first, read until its end_header line (a header is small:
    // one that runs past max_header_bytes is not a PLY header) ...
    constexpr std::size_t max_header_bytes = std::size_t(1) << 20;
    std::string bytes;
    char buffer[1 << 14];
    std::size_t end = std::string::npos;
    while (true) {
      const std::size_t n = in.read(buffer, sizeof buffer);
      const std::size_t from = bytes.size() > 16 ? bytes.size() - 16 : 0;
      bytes.append(buffer, n);
      if (bytes.size() >= 4 && !(bytes.starts_with("ply\n") || bytes.starts_with("ply\r")))
        throw fail(1, "not a PLY file (no 'ply' on its first line)");
      for (std::size_t k = bytes.find("end_header", from); k != std::string::npos; k = bytes.find("end_header", k + 1))
        if ((k == 0 || bytes[k - 1] == '\n') && (k + 10 < bytes.size() || n == 0)) {
          end = k;
          break;
        }
      if (end != std::string::npos || n == 0) break;
      if (bytes.size() > max_header_bytes)
        throw fail(1, "no end_header in the first " + io::byte_count(max_header_bytes) + " (not a PLY header)");
    }
    const ply_header h = parse_header(bytes, fail);
    // ... checked against what the file can hold before the data is read.
    const std::uint64_t have = bytes.size() - std::min(h.body, bytes.size());
    check_counts(h, have + in.remaining_bound(), fail);
    bytes += in.read_rest();
    check_counts(h, bytes.size() - h.body, fail);
    return parse_body(bytes, h, file, fail, stats);
  } catch (const io::input_file_error& e) {
    throw fail(1, e.what());
  }
}

}  // namespace mcrt::pbrt
