#include "samples_command.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "image_io.hpp"
#include "scene_loader.hpp"

namespace mcrt::cli {
namespace {

// "X,Y,Z" -> a finite vector; throws input_error naming the flag.
vec3 parse_vector(const std::string& text, const char* flag) {
  vec3 v;
  std::istringstream in(text);
  char comma = 0;
  std::string rest;
  if (!(in >> v.x >> comma) || comma != ',' || !(in >> v.y >> comma) || comma != ',' || !(in >> v.z) || (in >> rest))
    throw input_error(std::string(flag) + ": expected X,Y,Z (three numbers separated by commas), got '" + text + "'");
  if (!all_finite(v)) throw input_error(std::string(flag) + ": numbers must be finite, got '" + text + "'");
  return v;
}

// Shortest text that reads back as the same float.
void put(std::string& out, float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  out += buf;
}

}  // namespace

int run_samples(const samples_options& opt) {
  const vec3 o = parse_vector(opt.from, "--from");
  vec3 n = parse_vector(opt.normal, "--normal");
  const float len = glm::length(n);
  if (!(len > 0.0f) || !std::isfinite(len)) throw input_error("--normal: must be a non-zero vector, got '" + opt.normal + "'");
  n /= len;  // the receiving surface's unit normal
  if (opt.n < 1 || opt.n > 100000000) throw input_error("--n: must be in [1, 100000000], got " + std::to_string(opt.n));
  const std::optional<light_sampling> strategy = parse_light_sampling_flag(opt.light_sampling);
  const ellipse_map map = opt.ellipse_map == "polar" ? ellipse_map::polar : ellipse_map::parallel;
  if (!opt.output.empty()) check_writable(opt.output, false);
  const loaded_scene ls = load_scene(opt.scene, strategy, map, {}, false, {}, opt.max_input_bytes);
  // A pbrt-v4 file numbers its lights in file order, a two-sided one with
  // an entry per side: the side that faces the point is sampled.
  const bool by_file = !ls.file_lights.empty();
  const std::size_t count = by_file ? ls.file_lights.size() : ls.world.emitters.size();
  if (opt.light < 0 || static_cast<std::size_t>(opt.light) >= count)
    throw input_error("--light: the scene " + opt.scene + " has " + std::to_string(count) + " light" +
                      (count == 1 ? "" : "s") + " (indices 0.." + std::to_string(count == 0 ? 0 : count - 1) +
                      "), got " + std::to_string(opt.light));
  std::size_t entry = static_cast<std::size_t>(opt.light);
  if (by_file) {
    const std::vector<std::uint32_t>& sides = ls.file_lights[entry];
    entry = sides.front();
    for (const std::uint32_t e : sides)
      if (faces(ls.world.lights[ls.world.emitters[e].light], o)) entry = e;
  }
  const light_ref l = ls.world.lights[ls.world.emitters[entry].light];

  // Written a block at a time (10^8 rows take about 9 GB): to standard
  // output, or to a temporary file renamed into place at the end.
  std::optional<output_file> file;
  if (!opt.output.empty()) file.emplace(opt.output);
  std::ostream& os = file ? file->stream() : std::cout;
  std::string csv = "u1,u2,dx,dy,dz,px,py,pz,pdf\n";
  constexpr std::size_t block = std::size_t(1) << 20;
  csv.reserve(block + 256);
  pcg32 rng(mix64(opt.seed), 0x5a3c1f7d2b9e4861ULL);
  for (long long i = 0; i < opt.n; ++i) {
    const vec2 u = rng.uniform2();
    light_sample s;
    const bool ok = sample(l, o, n, u, s);
    put(csv, u.x);
    csv += ',';
    put(csv, u.y);
    if (ok) {
      const vec3 p = o + s.dist * s.dir;
      for (const float v : {s.dir.x, s.dir.y, s.dir.z, p.x, p.y, p.z, s.pdf}) {
        csv += ',';
        put(csv, v);
      }
    } else {
      csv += ",0,0,0,0,0,0,0";  // no sample: pdf 0
    }
    csv += '\n';
    if (csv.size() >= block) {
      os << csv;
      csv.clear();
    }
  }
  os << csv << std::flush;
  if (file) file->commit();
  return 0;
}

}  // namespace mcrt::cli
