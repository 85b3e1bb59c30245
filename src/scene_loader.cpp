#include "scene_loader.hpp"

#include "input_file.hpp"
#include "pbrt/builder.hpp"
#include "texture_io.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <span>
#include <sstream>

namespace mcrt::cli {
namespace {

using json = nlohmann::json;

// Error reporting bound to one file: fail("objects[3].radius", "must be > 0").
struct context {
  std::string file;
  [[noreturn]] void fail(const std::string& place, const std::string& what) const {
    throw input_error(file + ": " + (place.empty() ? "" : place + ": ") + what);
  }
};

std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

const char* type_name(const json& j) {
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::string: return "a string";
    case json::value_t::array: return "an array";
    case json::value_t::object: return "an object";
    default: return "a number";
  }
}

// Stands in for a number literal too large for a double (JSON has no
// infinity, but 1e999 is valid JSON text), so that the place is reported.
constexpr const char* overflow_marker = "<mcrt: number overflows a double>";

// Parses JSON text; number literals that overflow a double are replaced by
// overflow_marker first (one pass over the text, outside strings), so the
// reader can name where they are.
json parse_json(std::string text, const context& ctx) {
  std::string marked;
  marked.reserve(text.size());
  bool in_string = false;
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (in_string) {
      marked += c;
      if (c == '\\' && i + 1 < text.size()) {
        marked += text[i + 1];
        i += 2;
        continue;
      }
      if (c == '"') in_string = false;
      ++i;
      continue;
    }
    if (c == '"') {
      in_string = true;
      marked += c;
      ++i;
      continue;
    }
    if (c == '-' || (c >= '0' && c <= '9')) {
      std::size_t end = i + 1;
      const auto is_num = [](char d) { return (d >= '0' && d <= '9') || d == '.' || d == 'e' || d == 'E' || d == '+' || d == '-'; };
      while (end < text.size() && is_num(text[end])) ++end;
      const std::string token = text.substr(i, end - i);
      // strtod: an overflowing literal gives +-HUGE_VAL (an underflowing
      // one 0, which JSON readers also take).
      const double v = std::strtod(token.c_str(), nullptr);
      if (std::isinf(v)) {
        marked += '"';
        marked += overflow_marker;
        marked += '"';
      } else {
        marked += token;
      }
      i = end;
      continue;
    }
    marked += c;
    ++i;
  }
  try {
    return json::parse(marked);
  } catch (const json::exception& e) {
    std::string what = e.what();
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." -> keep the readable part.
    if (const auto p = what.find("parse error"); p != std::string::npos) what = what.substr(p);
    ctx.fail("", "invalid JSON: " + pbrt::quote_prefix(what, 300));
  }
}

// Accessors that check presence, type and finiteness.
struct reader {
  const context& ctx;

  const json& field(const json& obj, const std::string& path, const std::string& key) const {
    const auto it = obj.find(key);
    if (it == obj.end()) ctx.fail(join(path, key), "missing required field");
    return *it;
  }
  double number(const json& j, const std::string& place) const {
    if (j.is_string() && j.get<std::string>() == overflow_marker) ctx.fail(place, "number is not finite (overflows a double)");
    if (!j.is_number()) ctx.fail(place, std::string("expected a number, got ") + type_name(j));
    const double v = j.get<double>();
    if (!std::isfinite(v)) ctx.fail(place, "number is not finite");
    // Every value of a scene becomes a float: beyond 3.4e38 it is infinite.
    if (!std::isfinite(static_cast<float>(v))) ctx.fail(place, "number is not finite in single precision (beyond 3.4e38)");
    return v;
  }
  double number(const json& obj, const std::string& path, const std::string& key) const {
    return number(field(obj, path, key), join(path, key));
  }
  double number_or(const json& obj, const std::string& path, const std::string& key, double dflt) const {
    return obj.contains(key) ? number(obj, path, key) : dflt;
  }
  int integer(const json& obj, const std::string& path, const std::string& key, int lo, int hi) const {
    const json& j = field(obj, path, key);
    const std::string place = join(path, key);
    const double v = number(j, place);
    if (v != std::floor(v)) ctx.fail(place, "expected an integer, got " + j.dump());
    if (v < lo || v > hi)
      ctx.fail(place, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + j.dump());
    return static_cast<int>(v);
  }
  vec3 vector3(const json& obj, const std::string& path, const std::string& key) const {
    const json& j = field(obj, path, key);
    const std::string place = join(path, key);
    if (!j.is_array() || j.size() != 3)
      ctx.fail(place, std::string("expected an array of 3 numbers, got ") + (j.is_array() ? "an array of " + std::to_string(j.size()) : type_name(j)));
    vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = static_cast<float>(number(j[static_cast<std::size_t>(i)], place + "[" + std::to_string(i) + "]"));
    if (!all_finite(v)) ctx.fail(place, "number is not finite in single precision");
    return v;
  }
  vec3 vector3_or(const json& obj, const std::string& path, const std::string& key, vec3 dflt) const {
    return obj.contains(key) ? vector3(obj, path, key) : dflt;
  }
  bool boolean_or(const json& obj, const std::string& path, const std::string& key, bool dflt) const {
    if (!obj.contains(key)) return dflt;
    const json& j = obj[key];
    if (!j.is_boolean()) ctx.fail(join(path, key), std::string("expected true or false, got ") + type_name(j));
    return j.get<bool>();
  }
  std::string string(const json& obj, const std::string& path, const std::string& key) const {
    const json& j = field(obj, path, key);
    if (!j.is_string()) ctx.fail(join(path, key), std::string("expected a string, got ") + type_name(j));
    return j.get<std::string>();
  }
  const json& object(const json& obj, const std::string& path, const std::string& key) const {
    const json& j = field(obj, path, key);
    if (!j.is_object()) ctx.fail(join(path, key), std::string("expected an object, got ") + type_name(j));
    return j;
  }
  // Fields a part of the scene may have; anything else is refused, so a
  // misspelt optional field ("flipp") is not silently ignored.
  void only(const json& obj, const std::string& path, std::initializer_list<const char*> allowed) const {
    for (const auto& [k, v] : obj.items()) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || k == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        ctx.fail(join(path, k), "unknown field (expected one of: " + list + ")");
      }
    }
  }
};

float positive(const reader& rd, const json& obj, const std::string& path, const std::string& key) {
  const double v = rd.number(obj, path, key);
  if (!(v > 0.0)) rd.ctx.fail(join(path, key), "must be > 0, got " + obj[key].dump());
  return static_cast<float>(v);
}

color non_negative_color(const reader& rd, const json& obj, const std::string& path, const std::string& key) {
  const vec3 c = rd.vector3(obj, path, key);
  if (c.x < 0 || c.y < 0 || c.z < 0) rd.ctx.fail(join(path, key), "components must be >= 0");
  return c;
}

// An albedo: the share of the light a surface reflects, in [0, 1] (more
// would create energy, and a path's throughput would grow without bound).
color albedo_color(const reader& rd, const json& obj, const std::string& path, const std::string& key) {
  const color c = non_negative_color(rd, obj, path, key);
  if (c.x > 1 || c.y > 1 || c.z > 1)
    rd.ctx.fail(join(path, key), "components must be in [0, 1] (a surface reflects at most the light it receives)");
  return c;
}

material read_material(const reader& rd, const json& m, const std::string& path) {
  if (!m.is_object()) rd.ctx.fail(path, std::string("expected an object, got ") + type_name(m));
  const std::string type = rd.string(m, path, "type");
  if (type == "lambertian") {
    rd.only(m, path, {"type", "albedo"});
    return lambertian{albedo_color(rd, m, path, "albedo")};
  }
  if (type == "metal") {
    rd.only(m, path, {"type", "albedo", "fuzz"});
    const double fuzz = rd.number_or(m, path, "fuzz", 0.0);
    if (fuzz < 0.0 || fuzz > 1.0) rd.ctx.fail(join(path, "fuzz"), "must be in [0, 1]");
    return metal{albedo_color(rd, m, path, "albedo"), static_cast<float>(fuzz)};
  }
  if (type == "dielectric") {
    rd.only(m, path, {"type", "ior"});
    return dielectric{positive(rd, m, path, "ior")};
  }
  if (type == "diffuse_light") {
    rd.only(m, path, {"type", "emit"});
    return diffuse_light{non_negative_color(rd, m, path, "emit")};
  }
  rd.ctx.fail(join(path, "type"),
              "unknown material type '" + type + "' (expected lambertian, metal, dielectric or diffuse_light)");
}

// Two edges/semi-axes that must be non-zero and orthogonal.
void check_frame(const reader& rd, const std::string& path, const char* k1, const char* k2, vec3 a, vec3 b) {
  const float la = glm::length(a), lb = glm::length(b);
  if (!(la > 0.0f)) rd.ctx.fail(join(path, k1), "must be a non-zero vector (degenerate shape)");
  if (!(lb > 0.0f)) rd.ctx.fail(join(path, k2), "must be a non-zero vector (degenerate shape)");
  if (std::abs(glm::dot(a, b)) > 1e-4f * la * lb)
    rd.ctx.fail(path, std::string(k1) + " and " + k2 + " must be orthogonal");
  if (!(glm::length(glm::cross(a, b)) > 0.0f) || !std::isfinite(la * lb))
    rd.ctx.fail(path, "degenerate shape (zero or non-representable area)");
}

// Reads `lo`..`hi` of an axis-aligned rectangle, which must span a non-empty interval.
std::pair<float, float> interval(const reader& rd, const json& o, const std::string& path, const char* lo, const char* hi) {
  const float a = static_cast<float>(rd.number(o, path, lo)), b = static_cast<float>(rd.number(o, path, hi));
  if (!(b > a))
    rd.ctx.fail(path, std::string(hi) + " must be greater than " + lo + " (zero-area or inverted rectangle)");
  return {a, b};
}

// Adds a directly sampled shape (a light, or an importance target such as
// book 3's glass sphere) with its strategy: the geometry and the light.
// `strategy` is nullopt where neither the scene nor the command line names
// one: rectangles and ellipses are then sampled by area, spheres by their
// cone of directions (solid angle), as the thesis's scenes were. A shape
// without the named strategy keeps the closest one it has: a sphere asked
// for bilinear-solid-angle (a pre-warp of a planar light's map) gets its
// exact projected-solid-angle map, which that pre-warp approximates.
// `pbrt` is pbrt-v4's choice for the shape (sampling/pbrt_strategy.hpp):
// rect_pbrt_sampler for rectangles, the cone for spheres, area sampling for
// ellipses (pbrt-v4's disks).
void add_light(scene& world, const rect& s, std::uint32_t mat, std::optional<light_sampling> strategy, ellipse_map,
               const auto_params& ap) {
  switch (strategy.value_or(light_sampling::area)) {
    case light_sampling::area: world.add_light(rect_area_sampler{s}, mat); return;
    case light_sampling::solid_angle: world.add_light(rect_solid_angle_sampler{s}, mat); return;
    case light_sampling::projected_solid_angle: world.add_light(rect_projected_solid_angle_sampler{s}, mat); return;
    case light_sampling::bilinear_solid_angle: world.add_light(rect_bilinear_solid_angle_sampler{s}, mat); return;
    case light_sampling::automatic: world.add_light(rect_auto_sampler{s, ap}, mat); return;
    case light_sampling::pbrt: world.add_light(rect_pbrt_sampler{s}, mat); return;
  }
}
void add_light(scene& world, const ellipse& s, std::uint32_t mat, std::optional<light_sampling> strategy,
               ellipse_map map, const auto_params& ap) {
  switch (strategy.value_or(light_sampling::area)) {
    case light_sampling::area: world.add_light(ellipse_area_sampler{s}, mat); return;
    case light_sampling::solid_angle:
      if (map == ellipse_map::polar)
        world.add_light(ellipse_polar_solid_angle_sampler{s}, mat);
      else
        world.add_light(ellipse_solid_angle_sampler{s}, mat);
      return;
    case light_sampling::projected_solid_angle: world.add_light(ellipse_projected_solid_angle_sampler{s}, mat); return;
    case light_sampling::bilinear_solid_angle: world.add_light(ellipse_bilinear_solid_angle_sampler{s}, mat); return;
    case light_sampling::automatic: world.add_light(ellipse_auto_sampler{s, ap}, mat); return;
    case light_sampling::pbrt: world.add_light(ellipse_area_sampler{s}, mat); return;
  }
}
void add_light(scene& world, const sphere& s, std::uint32_t mat, std::optional<light_sampling> strategy, ellipse_map,
               const auto_params& ap) {
  switch (strategy.value_or(light_sampling::solid_angle)) {
    case light_sampling::area: world.add_light(sphere_area_sampler{s}, mat); return;
    case light_sampling::solid_angle: world.add_light(sphere_cone_sampler{s}, mat); return;
    case light_sampling::projected_solid_angle:
    case light_sampling::bilinear_solid_angle: world.add_light(sphere_projected_solid_angle_sampler{s}, mat); return;
    case light_sampling::automatic: world.add_light(sphere_auto_sampler{s, ap}, mat); return;
    case light_sampling::pbrt: world.add_light(sphere_cone_sampler{s}, mat); return;
  }
}

// A strategy's name in a scene file or on the command line; nullopt for a
// name that is not a strategy.
std::optional<light_sampling> strategy_named(const std::string& value) {
  for (const light_sampling s : {light_sampling::area, light_sampling::solid_angle, light_sampling::projected_solid_angle,
                                 light_sampling::bilinear_solid_angle, light_sampling::automatic, light_sampling::pbrt})
    if (value == to_string(s)) return s;
  return std::nullopt;
}
constexpr const char* strategy_names = "area, solid-angle, projected-solid-angle, bilinear-solid-angle, pbrt or auto";

void read_object(const reader& rd, const json& o, const std::string& path, scene& world,
                 const std::map<std::string, std::uint32_t>& material_ids,
                 std::optional<light_sampling> override_strategy, ellipse_map map, const auto_params& ap,
                 bool auto_pilot, std::span<const auto_receiver> auto_receivers, loaded_scene& out) {
  if (!o.is_object()) rd.ctx.fail(path, std::string("expected an object, got ") + type_name(o));
  std::string type = rd.string(o, path, "type");
  const std::string mat_name = rd.string(o, path, "material");
  const auto mit = material_ids.find(mat_name);
  if (mit == material_ids.end()) rd.ctx.fail(join(path, "material"), "unknown material '" + mat_name + "'");
  const std::uint32_t mat = mit->second;
  const bool flip = rd.boolean_or(o, path, "flip", false);
  const bool is_light = std::holds_alternative<diffuse_light>(world.materials[mat]);
  const bool sampled = rd.boolean_or(o, path, "sample", false) || is_light;

  std::optional<light_sampling> strategy;  // nullopt: the shape's default (see add_light)
  const bool typed_sa = type.size() > 3 && type.ends_with("_sa");
  if (typed_sa) {
    strategy = light_sampling::solid_angle;
    type.resize(type.size() - 3);
    if (type != "xz_rect" && type != "xy_rect" && type != "yz_rect" && type != "rect" && type != "ellipse")
      rd.ctx.fail(join(path, "type"), "unknown object type '" + type + "_sa'");
  }
  if (o.contains("sampling")) {
    // The light's own strategy (the contract's per-light "sampling" field);
    // --light-sampling, when given, still overrides it.
    const std::string place = join(path, "sampling");
    if (!sampled) rd.ctx.fail(place, "only a light or a sampled object (\"sample\": true) has a sampling strategy");
    const std::string value = rd.string(o, path, "sampling");
    const std::optional<light_sampling> chosen = strategy_named(value);
    if (!chosen) rd.ctx.fail(place, "unknown strategy '" + value + "' (expected " + strategy_names + ")");
    if (typed_sa && *chosen != light_sampling::solid_angle)
      rd.ctx.fail(place, "'" + value + "' contradicts the type '" + type + "_sa' (sampled by solid angle)");
    strategy = chosen;
  }
  // --light-sampling switches the lights (the contract: "every light of the
  // scene"); an importance target that emits nothing (book 3's glass sphere)
  // keeps its own strategy.
  if (override_strategy && is_light) strategy = *override_strategy;

  auto add = [&](const auto& shape) {
    if (!sampled) {
      world.add(shape, mat);
      return;
    }
    if (strategy == light_sampling::automatic && is_light) {
      ++out.auto_lights;
      // The noise pilot's scene: the shape's default strategy (its cheapest).
      if (auto_pilot) {
        add_light(world, shape, mat, std::nullopt, map, ap);
        return;
      }
      // The light's radiance (the mean of its channels) for the rule's v_rest.
      auto_params lp = ap;
      const color e = std::get<diffuse_light>(world.materials[mat]).emit;
      lp.radiance = (e.r + e.g + e.b) / 3.0f;
      // Its set-up (the rule's constants and its table's cells, not yet
      // evaluated) is part of the image's time (loaded_scene).
      const auto start = std::chrono::steady_clock::now();
      add_light(world, shape, mat, strategy, map, lp);
      // Where its choice does not pay for its own cost at the pilot's
      // receivers, the light takes its cheapest strategy's sampler, with no
      // choice per light sample (auto_sampler::table_gain).
      if (!auto_receivers.empty() && use_cheapest_where_choice_does_not_pay(world.lights, world.lights.size() - 1, auto_receivers))
        out.auto_cheapest_lights.push_back(static_cast<std::uint32_t>(world.lights.size() - 1));
      out.auto_setup_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return;
    }
    add_light(world, shape, mat, strategy, map, ap);
  };

  if (type == "xz_rect" || type == "xy_rect" || type == "yz_rect") {
    const char a = type[0], b = type[1];
    const std::string a0 = std::string(1, a) + "0", a1 = std::string(1, a) + "1";
    const std::string b0 = std::string(1, b) + "0", b1 = std::string(1, b) + "1";
    rd.only(o, path, {"type", "material", "flip", "sample", "sampling", a0.c_str(), a1.c_str(), b0.c_str(), b1.c_str(), "k"});
    const auto [u0, u1] = interval(rd, o, path, a0.c_str(), a1.c_str());
    const auto [v0, v1] = interval(rd, o, path, b0.c_str(), b1.c_str());
    const float k = static_cast<float>(rd.number(o, path, "k"));
    add(type == "xz_rect"   ? xz_rect(u0, u1, v0, v1, k, flip)
        : type == "xy_rect" ? xy_rect(u0, u1, v0, v1, k, flip)
                            : yz_rect(u0, u1, v0, v1, k, flip));
  } else if (type == "rect") {
    rd.only(o, path, {"type", "material", "flip", "sample", "sampling", "corner", "edge1", "edge2"});
    const vec3 c = rd.vector3(o, path, "corner"), e1 = rd.vector3(o, path, "edge1"), e2 = rd.vector3(o, path, "edge2");
    check_frame(rd, path, "edge1", "edge2", e1, e2);
    add(rect::make(c, e1, e2, flip));
  } else if (type == "ellipse") {
    rd.only(o, path, {"type", "material", "flip", "sample", "sampling", "center", "axis1", "axis2"});
    const vec3 c = rd.vector3(o, path, "center"), a1 = rd.vector3(o, path, "axis1"), a2 = rd.vector3(o, path, "axis2");
    check_frame(rd, path, "axis1", "axis2", a1, a2);
    add(ellipse::make(c, a1, a2, flip));
  } else if (type == "sphere") {
    rd.only(o, path, {"type", "material", "flip", "sample", "sampling", "center", "radius"});
    add(sphere{rd.vector3(o, path, "center"), positive(rd, o, path, "radius"), flip});
  } else if (type == "box") {
    rd.only(o, path, {"type", "material", "flip", "sample", "min", "max", "rotate_y", "translate"});
    const vec3 lo = rd.vector3(o, path, "min"), hi = rd.vector3(o, path, "max");
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
      rd.ctx.fail(join(path, "max"), "must be greater than min in every coordinate (degenerate box)");
    if (sampled)
      rd.ctx.fail(path, is_light ? "a box cannot be a light (boxes have no direct sampling strategy)"
                                 : "a box cannot be sampled (boxes have no direct sampling strategy)");
    const float angle = static_cast<float>(rd.number_or(o, path, "rotate_y", 0.0));
    const vec3 t = rd.vector3_or(o, path, "translate", vec3(0.0f));
    world.add(box{lo, hi, rigid_y::make(angle, t), flip}, mat);
  } else {
    rd.ctx.fail(join(path, "type"), "unknown object type '" + type + "'");
  }
}

}  // namespace

std::optional<light_sampling> parse_light_sampling_flag(const std::string& value) {
  if (value.empty()) return std::nullopt;
  if (const auto s = strategy_named(value)) return s;
  throw input_error("--light-sampling: unknown strategy '" + value + "' (expected " + strategy_names + ")");
}

bool is_pbrt_file(const std::string& path) { return path.ends_with(".pbrt") || path.ends_with(".pbrt.gz"); }

namespace {

loaded_scene load_pbrt_scene(const std::string& path, std::optional<light_sampling> override_strategy,
                             const auto_params& ap, bool auto_pilot, std::uint64_t max_input_bytes) {
  pbrt::build_options opt;
  opt.max_input_bytes = max_input_bytes;
  opt.strategy = override_strategy;
  opt.auto_rule = ap;
  opt.auto_pilot = auto_pilot;
  opt.decode_image = decode_texture_image;
  pbrt::built_scene b;
  try {
    b = pbrt::load_pbrt_file(path, opt);
  } catch (const pbrt::parse_error& e) {
    throw input_error(e.what());
  }
  loaded_scene out;
  std::string name = std::filesystem::path(path).filename().string();
  name = name.substr(0, name.find('.'));
  out.name = name;
  out.world = std::move(b.world);
  out.cam.width = b.film.width;
  out.cam.height = b.film.height;
  out.make_camera = [cfw = b.camera_from_world, pp = b.perspective, path](int w, int h) {
    try {
      return pbrt::perspective_camera(cfw, pp, w, h);
    } catch (const std::domain_error& e) {
      throw input_error(path + ": at " + std::to_string(w) + " x " + std::to_string(h) + " pixels: " + e.what());
    }
  };
  out.spp = b.spp;
  out.max_depth = b.max_depth;
  out.sampler = b.sampler;
  out.light_select = b.light_select;
  out.integrator_requested = b.integrator_requested;
  out.output = b.film.filename;
  out.file_lights = std::move(b.file_lights);
  out.auto_lights = b.auto_lights;
  out.auto_setup_seconds = b.auto_setup_seconds;
  out.filter = b.filter.kind;
  out.filter_radius = b.filter.radius;
  out.filter_sigma = b.filter.sigma;
  return out;
}

}  // namespace

loaded_scene load_scene(const std::string& path, std::optional<light_sampling> override_strategy, ellipse_map map,
                        const auto_params& ap, bool auto_pilot, std::span<const auto_receiver> auto_receivers,
                        std::uint64_t max_input_bytes) {
  if (is_pbrt_file(path)) return load_pbrt_scene(path, override_strategy, ap, auto_pilot, max_input_bytes);
  const context ctx{path};
  const reader rd{ctx};
  std::string text;
  try {
    text = io::read_input_file(path, max_input_bytes);
  } catch (const io::input_file_error& e) {
    ctx.fail("", std::string("cannot read the scene file: ") + e.what());
  }
  const json root = parse_json(std::move(text), ctx);
  if (!root.is_object()) ctx.fail("", std::string("expected a JSON object at the top level, got ") + type_name(root));
  rd.only(root, "", {"camera", "render", "materials", "objects"});

  loaded_scene out;
  out.name = std::filesystem::path(path).stem().string();

  // camera
  const json& cam = rd.object(root, "", "camera");
  rd.only(cam, "camera", {"lookfrom", "lookat", "vup", "vfov", "width", "height"});
  out.cam.lookfrom = rd.vector3(cam, "camera", "lookfrom");
  out.cam.lookat = rd.vector3(cam, "camera", "lookat");
  out.cam.vup = rd.vector3_or(cam, "camera", "vup", vec3(0.0f, 1.0f, 0.0f));
  out.cam.vfov = static_cast<float>(rd.number(cam, "camera", "vfov"));
  if (!(out.cam.vfov > 0.0f && out.cam.vfov < 180.0f)) ctx.fail("camera.vfov", "must be in (0, 180) degrees");
  out.cam.width = rd.integer(cam, "camera", "width", 1, max_resolution);
  out.cam.height = rd.integer(cam, "camera", "height", 1, max_resolution);
  const vec3 view = out.cam.lookfrom - out.cam.lookat;
  if (!(glm::length(view) > 0.0f)) ctx.fail("camera.lookat", "must differ from lookfrom");
  if (!(glm::length(glm::cross(out.cam.vup, view)) > 1e-6f * glm::length(view) * glm::length(out.cam.vup)))
    ctx.fail("camera.vup", "must not be zero or parallel to the viewing direction");

  // render
  if (root.contains("render")) {
    const json& r = rd.object(root, "", "render");
    rd.only(r, "render", {"spp", "max_depth", "background"});
    if (r.contains("spp")) out.spp = rd.integer(r, "render", "spp", 1, max_spp);
    if (r.contains("max_depth")) out.max_depth = rd.integer(r, "render", "max_depth", 0, max_depth_limit);
    out.world.background = rd.vector3_or(r, "render", "background", color(0.0f));
  }

  // materials
  const json& mats = rd.object(root, "", "materials");
  std::map<std::string, std::uint32_t> ids;
  for (const auto& [name, m] : mats.items()) {
    ids[name] = static_cast<std::uint32_t>(out.world.materials.size());
    out.world.materials.push_back(read_material(rd, m, "materials." + name));
  }

  // objects
  const json& objs = rd.field(root, "", "objects");
  if (!objs.is_array()) ctx.fail("objects", std::string("expected an array, got ") + type_name(objs));
  if (objs.empty()) ctx.fail("objects", "the scene has no objects");
  for (std::size_t i = 0; i < objs.size(); ++i)
    read_object(rd, objs[i], "objects[" + std::to_string(i) + "]", out.world, ids, override_strategy, map, ap, auto_pilot,
                auto_receivers, out);

  // Shirley's scenes keep their lists: their few shapes are large (the
  // Cornell boxes' boxes), which the hierarchy's boxes do not cull, and
  // they render 11-22 % slower through it (bench/ab_render.sh).
  out.world.build_light_tree();
  out.make_camera = [c = out.cam](int, int) {
    return camera(c.lookfrom, c.lookat, c.vup, c.vfov, static_cast<float>(c.width) / static_cast<float>(c.height));
  };
  return out;
}

}  // namespace mcrt::cli
