// The mcrt executable: `mcrt render`, `mcrt diff` and `mcrt samples` (docs/cli.md).
#include <cmath>
#include <CLI/CLI.hpp>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <string>

#include "auto_pilot.hpp"
#include "image_io.hpp"
#include "render_instances.hpp"
#include "samples_command.hpp"
#include "mcrt/mcrt.hpp"
#include "scene_loader.hpp"

namespace {

using namespace mcrt;
using namespace mcrt::cli;

struct render_options {
  std::string scene, output, stats, light_sampling, ellipse_map = "parallel";
  // sampler and light_select: "" where the command line is silent (the
  // scene file's, else sobol and power).
  std::string integrator = "mis", sampler, mis_heuristic = "power", light_select;
  std::optional<int> spp, width, height, max_depth, rr_depth;
  std::optional<unsigned> threads;
  std::optional<float> auto_rest_cost, auto_rest_variance;
  std::uint64_t seed = 0;
  std::string max_input_size;
  bool quiet = false;
};

struct diff_options {
  std::string image, reference, max_input_size;
  bool json = false;
};

// --max-input-size: bytes, or a number with the suffix K, M, G or T
// (powers of 1024; "1G" is 1073741824 bytes).
std::uint64_t parse_max_input_size(const std::string& text) {
  const auto bad = [&] {
    return input_error("--max-input-size: expected a size in bytes such as 1073741824, 512M or 4G, got '" +
                       text.substr(0, 80) + "'");
  };
  if (text.empty()) throw bad();
  std::size_t digits = 0;
  while (digits < text.size() && std::isdigit(static_cast<unsigned char>(text[digits]))) ++digits;
  if (digits == 0 || digits > 19 || text.size() - digits > 1) throw bad();
  std::uint64_t shift = 0;
  if (digits < text.size()) {
    switch (std::toupper(static_cast<unsigned char>(text.back()))) {
      case 'K': shift = 10; break;
      case 'M': shift = 20; break;
      case 'G': shift = 30; break;
      case 'T': shift = 40; break;
      default: throw bad();
    }
  }
  const std::uint64_t v = std::stoull(text.substr(0, digits));
  if (v == 0) throw input_error("--max-input-size: must be > 0");
  if (v > (std::numeric_limits<std::uint64_t>::max() >> shift)) throw bad();
  return v << shift;
}

void check_range(const std::optional<int>& v, const char* flag, int lo, int hi) {
  if (v && (*v < lo || *v > hi))
    throw input_error(std::string(flag) + ": must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                      "], got " + std::to_string(*v));
}

// What the lights of a scene use, for --stats: one strategy's name (see
// light_sampling), "mixed" or "none". Only emitters count: book 3's glass
// sphere ("sample": true, emits nothing) is an importance target of the
// mixture, not a light.
std::string strategy_summary(const loaded_scene& ls) {
  const scene& world = ls.world;
  std::optional<light_sampling> first;
  for (const emitter& e : world.emitters) {
    // A light `auto` found best sampled by its cheapest strategy is still
    // auto's (the list is in increasing order: a binary search, as a scene
    // may hold 10^5 of them).
    const bool cheapest = std::ranges::binary_search(ls.auto_cheapest_lights, e.light);
    const light_sampling s = cheapest ? light_sampling::automatic : strategy_of(world.lights[e.light]);
    if (first && *first != s) return "mixed";
    first = s;
  }
  return first ? std::string(to_string(*first)) : "none";
}

// The progress display: on a terminal one line redrawn in place (every
// report of the renderer, 4 a second); to a file or a pipe, where a redrawn
// line would pile up as one long line, a line of its own at every tenth of
// the image and at least every 30 s, and the last at the end.
class progress_display {
 public:
  progress_display() : terminal_(::isatty(::fileno(stderr)) != 0) {}

  void operator()(double fraction, double elapsed) {
    const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    if (terminal_) {
      std::fprintf(stderr, "\rrendering %5.1f%%  elapsed %7.1f s  ETA %7.1f s", 100.0 * fraction, elapsed, eta);
      if (fraction >= 1.0) std::fputc('\n', stderr);
      std::fflush(stderr);
      return;
    }
    const int tenth = static_cast<int>(std::floor(10.0 * fraction + 1e-9));
    const bool last = fraction >= 1.0;
    if (done_ || (!last && tenth <= last_tenth_ && elapsed - last_seconds_ < 30.0)) return;
    std::fprintf(stderr, "rendering %5.1f%%  elapsed %7.1f s  ETA %7.1f s\n", 100.0 * fraction, elapsed, eta);
    std::fflush(stderr);
    last_tenth_ = std::max(last_tenth_, tenth);
    last_seconds_ = elapsed;
    done_ = last;
  }

 private:
  bool terminal_;
  int last_tenth_ = 0;         // the last tenth of the image reported (0: none past the start)
  double last_seconds_ = 0.0;  // when the last line was written
  bool done_ = false;
};

int run_render(const render_options& opt) {
  check_range(opt.spp, "--spp", 1, max_spp);
  check_range(opt.width, "--width", 1, max_resolution);
  check_range(opt.height, "--height", 1, max_resolution);
  check_range(opt.max_depth, "--max-depth", 0, max_depth_limit);
  check_range(opt.rr_depth, "--rr-depth", 0, max_depth_limit);
  if (opt.threads && *opt.threads == 0) throw input_error("--threads: must be >= 1");
  const std::optional<light_sampling> strategy = parse_light_sampling_flag(opt.light_sampling);

  const cli::ellipse_map map = opt.ellipse_map == "polar" ? cli::ellipse_map::polar : cli::ellipse_map::parallel;
  auto_params ap;
  // nee takes each light sample's pdf with it: `auto` weighs the strategies'
  // costs inside such renders (auto_costs).
  ap.pdf_with_sample = opt.integrator == "nee";
  if (opt.auto_rest_cost) {
    if (!(*opt.auto_rest_cost >= 0.0f) || !std::isfinite(*opt.auto_rest_cost))
      throw input_error("--auto-rest-cost: must be a finite number >= 0");
    ap.rest_cost = *opt.auto_rest_cost;
  }
  if (opt.auto_rest_variance) {
    if (!(*opt.auto_rest_variance > 0.0f) || !std::isfinite(*opt.auto_rest_variance))
      throw input_error("--auto-rest-variance: must be a finite number > 0");
    ap.rest_variance = *opt.auto_rest_variance;
  }
  // Unless v_rest is given, `auto` takes it from the image's noise, which a
  // pilot measures on the scene with those lights sampled by their cheapest
  // strategy (auto_strategy.hpp, auto_params; render/noise_pilot.hpp).
  const bool pilot = !opt.auto_rest_variance;
  const std::uint64_t max_input =
      opt.max_input_size.empty() ? io::default_max_input_bytes : parse_max_input_size(opt.max_input_size);
  loaded_scene ls = load_scene(opt.scene, strategy, map, ap, pilot, {}, max_input);
  // Without -o: a pbrt-v4 file's Film filename (in the current directory), else SCENE-NAME.exr.
  const std::string output = !opt.output.empty() ? opt.output
                             : !ls.output.empty() ? std::filesystem::path(ls.output).filename().string()
                                                  : ls.name + ".exr";
  check_writable(output, true);
  if (!opt.stats.empty()) check_writable(opt.stats, false, "--stats");

  render_settings rs;
  // The camera keeps the scene's aspect ratio: --width/--height change the
  // sampling resolution, not the view.
  rs.width = opt.width.value_or(ls.cam.width);
  rs.height = opt.height.value_or(ls.cam.height);
  const camera cam = ls.make_camera(rs.width, rs.height);
  rs.spp = opt.spp.value_or(ls.spp);
  rs.max_depth = opt.max_depth.value_or(ls.max_depth);
  if (opt.rr_depth) rs.rr_depth = *opt.rr_depth;
  rs.seed = opt.seed;
  rs.threads = opt.threads.value_or(0u);
  rs.integrator = opt.integrator == "nee" ? integrator_kind::nee : opt.integrator == "mis" ? integrator_kind::mis : integrator_kind::mixture;
  const std::string sampler_name = !opt.sampler.empty() ? opt.sampler : !ls.sampler.empty() ? ls.sampler : "sobol";
  const std::string light_select = !opt.light_select.empty() ? opt.light_select
                                   : !ls.light_select.empty() ? ls.light_select
                                                              : "power";
  rs.sampler = sampler_name == "stratified" ? sampler_kind::stratified
               : sampler_name == "sobol"    ? sampler_kind::sobol
                                            : sampler_kind::independent;
  rs.heuristic = opt.mis_heuristic == "balance" ? mis_heuristic::balance : mis_heuristic::power;
  rs.filter = ls.filter == "gaussian" ? pixel_filter::gaussian(ls.filter_radius, ls.filter_sigma)
              : ls.filter == "triangle" ? pixel_filter::triangle(ls.filter_radius)
                                        : pixel_filter::box(ls.filter_radius);
  rs.choose = light_select == "uniform"    ? light_choice::uniform
              : light_select == "bvh"      ? light_choice::bvh
              : light_select == "pbrt-bvh" ? light_choice::pbrt_bvh
                                           : light_choice::power;

  std::optional<noise_pilot_result> noise;
  double edge_factor = 1.0;  // kappa_E (render/noise_pilot.hpp)
  std::vector<auto_light_settlement> settlements;
  // The pilot's parts (auto_pilot_seconds is their sum): the noise pilot,
  // kappa_E, and the lights' settling.
  double noise_seconds = 0.0, emission_seconds = 0.0, settle_seconds = 0.0;
  if (pilot && ls.auto_lights > 0) {
    image_noise pilot_noise = measure_image_noise(ls.world, cam, rs);
    noise = std::move(pilot_noise.noise);
    edge_factor = pilot_noise.edge_factor;
    noise_seconds = pilot_noise.noise_seconds;
    emission_seconds = pilot_noise.emission_seconds;
    // A noise-free pilot leaves nothing for a cheaper strategy to hide in.
    ap.image_variance = std::max(static_cast<float>(noise->image_variance), std::numeric_limits<float>::min());
    ap.albedo = static_cast<float>(std::sqrt(noise->mean_albedo2));
    ls = load_scene(opt.scene, strategy, map, ap, false, {}, max_input);
    // Each light's rule at the fixed point of the image's noise and time
    // its choice makes, and the gate of its choice (render/choice_gain_pilot.hpp).
    const auto settle_start = std::chrono::steady_clock::now();
    settlements = settle_lights(ls.world, cam, rs, *noise, !opt.auto_rest_cost);
    for (const auto_light_settlement& a : settlements)
      if (a.cheapest) ls.auto_cheapest_lights.push_back(static_cast<std::uint32_t>(a.light));
    settle_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - settle_start).count();
    noise->seconds += settle_seconds;
  }

  render_result res = render_scene(ls.world, cam, rs, opt.quiet ? progress_callback{} : progress_callback(progress_display{}));
  // The pilot and the set-up of the lights `auto` samples are part of the image's time.
  if (noise) res.seconds += noise->seconds;
  res.seconds += ls.auto_setup_seconds;
  const double samples = static_cast<double>(rs.width) * rs.height * rs.spp;
  const std::string strategy_used = strategy_summary(ls);
  if (res.nonfinite_samples && !opt.quiet)
    std::fprintf(stderr, "mcrt: %llu non-finite radiance samples were dropped\n",
                 static_cast<unsigned long long>(res.nonfinite_samples));

  write_image(output, res.img,
              {{"mcrt:render_seconds", "", res.seconds, true, false},
               {"mcrt:spp", "", static_cast<double>(rs.spp), true, true},
               {"mcrt:seed", std::to_string(rs.seed)},
               {"mcrt:light_sampling", strategy_used},
               {"mcrt:ellipse_map", opt.ellipse_map},
               {"mcrt:integrator", opt.integrator},
               {"mcrt:sampler", sampler_name},
               {"mcrt:scene", ls.name}});
  if (!opt.stats.empty()) {
    nlohmann::ordered_json j;
    j["render_seconds"] = res.seconds;
    j["spp"] = rs.spp;
    j["width"] = rs.width;
    j["height"] = rs.height;
    j["threads"] = res.threads;
    j["samples_per_second"] = samples / res.seconds;
    j["light_sampling"] = strategy_used;
    j["integrator"] = opt.integrator;
    if (!ls.integrator_requested.empty()) j["integrator_requested"] = ls.integrator_requested;
    j["sampler"] = sampler_name;
    j["mis_heuristic"] = opt.mis_heuristic;
    j["light_select"] = light_select;
    j["ellipse_map"] = opt.ellipse_map;
    j["seed"] = rs.seed;
    j["max_depth"] = rs.max_depth;
    j["rr_depth"] = rs.rr_depth;
    j["scene"] = ls.name;
    j["nonfinite_samples"] = res.nonfinite_samples;
    if (ls.auto_lights > 0) j["auto_setup_seconds"] = ls.auto_setup_seconds;
    if (noise) {
      j["auto_cheapest_lights"] = ls.auto_cheapest_lights.size();
      j["auto_pilot_seconds"] = noise->seconds;
      j["auto_pilot_parts_seconds"] = {{"noise", noise_seconds}, {"emission", emission_seconds}, {"settle", settle_seconds}};
      j["auto_image_variance"] = noise->image_variance;
      j["auto_image_variance_edges"] = noise->edge_variance;
      j["auto_edge_noise_factor"] = edge_factor;
      j["auto_albedo"] = std::sqrt(noise->mean_albedo2);
      j["auto_pilot_ns_per_light_sample"] = noise->seconds_per_light_sample * 1e9;
      j["auto_pilot_rays_per_light_sample"] = noise->rays_per_light_sample;
      j["auto_pilot_paths_per_light_sample"] = noise->paths_per_light_sample;
      nlohmann::ordered_json lights = nlohmann::ordered_json::array();
      for (const auto_light_settlement& a : settlements)
        lights.push_back({{"light", a.light},
                          {"gain_factor", a.kappa},
                          {"gain_factor_first_bounce", a.kappa_first_bounce},
                          {"noise_share", a.noise_share},
                          {"noise_share_measured", a.noise_share_measured},
                          {"noise_share_model", a.noise_share_model},
                          {"image_variance", a.image_variance},
                          {"rest_cost", a.rest_cost},
                          {"rest_noise", a.rest_noise},
                          {"rest_weight", a.rest_weight},
                          {"fixed_point_steps", a.fixed_point_steps},
                          {"cheapest", a.cheapest},
                          {"gain_factor_seconds", a.kappa_seconds},
                          {"rest_pilot_seconds", a.rest_pilot_seconds}});
      j["auto_lights"] = lights;
    }
    write_text(opt.stats, j.dump(2) + "\n");
  }
  return 0;
}

int run_diff(const diff_options& opt) {
  const std::uint64_t max_input =
      opt.max_input_size.empty() ? io::default_max_input_bytes : parse_max_input_size(opt.max_input_size);
  const image a = read_image(opt.image, max_input), r = read_image(opt.reference, max_input);
  if (a.width != r.width || a.height != r.height)
    throw input_error("images differ in size: " + opt.image + " is " + std::to_string(a.width) + "x" +
                      std::to_string(a.height) + ", " + opt.reference + " is " + std::to_string(r.width) + "x" +
                      std::to_string(r.height));
  // Accumulated in double over all pixels and channels.
  double se = 0.0, rel = 0.0, sum_a = 0.0, sum_r = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double v = a.pixels[i][c], ref = r.pixels[i][c];
      se += (v - ref) * (v - ref);
      rel += (v - ref) * (v - ref) / ((ref + 0.01) * (ref + 0.01));  // pbrt's relative MSE
      sum_a += v;
      sum_r += ref;
    }
  const double n = 3.0 * static_cast<double>(a.pixels.size());
  const double mse = se / n, relmse = rel / n;
  // Signed difference of the mean values, in percent of the reference's.
  const double mean_diff = sum_r != 0.0 ? 100.0 * (sum_a - sum_r) / sum_r : (sum_a == 0.0 ? 0.0 : 100.0);
  if (opt.json) {
    nlohmann::ordered_json j;
    j["rmse"] = std::sqrt(mse);
    j["mse"] = mse;
    j["relmse"] = relmse;
    j["mean_diff_percent"] = mean_diff;
    std::cout << j.dump() << "\n";
  } else {
    std::printf("rmse %.9g\nmse %.9g\nrelmse %.9g\nmean_diff_percent %.9g\n", std::sqrt(mse), mse, relmse, mean_diff);
  }
  return 0;
}

// A message as one line on stderr: control characters (a newline or an
// escape sequence in a file name or a value the user gave) written as
// escapes, and at most 1000 bytes.
std::string printable_line(const std::string& s) {
  static const char hex[] = "0123456789abcdef";
  std::string out;
  for (const char c : s) {
    if (out.size() >= 1000) {
      out += "...";
      break;
    }
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (u < 0x20 || u == 0x7f) out += std::string("\\x") + hex[u >> 4] + hex[u & 15];
    else out += c;
  }
  return out;
}

// Every option that takes a value was given a non-empty one (CLI11 takes
// `--width ''` as no value at all, which would leave the default).
void refuse_empty_values(const CLI::App& cmd) {
  for (const CLI::Option* o : cmd.get_options())
    if (o->get_expected_min() > 0)
      for (const std::string& r : o->results())
        if (r.empty()) throw input_error(o->get_name() + ": an empty value");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcrt: a Monte-Carlo path tracer for comparing direct sampling of area lights"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("mcrt ") + MCRT_VERSION);

  render_options ro;
  CLI::App* render_cmd = app.add_subcommand("render", "Render a scene file to an image");
  render_cmd->add_option("scene", ro.scene, "Scene file (JSON, or pbrt-v4: .pbrt, .pbrt.gz)")->required();
  render_cmd->add_option("-o,--output", ro.output, "Output image: .exr, .png or .ppm (default SCENE-NAME.exr)");
  render_cmd->add_option("--spp", ro.spp, "Samples per pixel (overrides the scene)");
  render_cmd->add_option("--width", ro.width, "Image width in pixels (overrides the scene; keeps the view)");
  render_cmd->add_option("--height", ro.height, "Image height in pixels (overrides the scene; keeps the view)");
  render_cmd->add_option("--max-depth", ro.max_depth, "Maximum number of scattering events (overrides the scene)");
  render_cmd->add_option("--rr-depth", ro.rr_depth,
                         "Scattering events before Russian roulette starts (default 1; >= max depth: off)");
  // A seed is a whole number in [0, 2^64 - 1] (CLI11 would wrap -1 round).
  const CLI::Validator whole_number(
      [](std::string& v) -> std::string {
        std::uint64_t x = 0;
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
        return !v.empty() && v.find_first_not_of("0123456789") == std::string::npos && ec == std::errc() &&
                       end == v.data() + v.size()
                   ? std::string()
                   : "must be a whole number in [0, 18446744073709551615]";
      },
      "UINT64");
  render_cmd->add_option("--seed", ro.seed, "Random seed (default 0)")->check(whole_number);
  render_cmd->add_option("--threads", ro.threads, "Threads (default: all hardware threads)");
  render_cmd->add_option("--light-sampling", ro.light_sampling,
                         "Sample every light by area, solid-angle, projected-solid-angle (cosine-aware), "
                         "bilinear-solid-angle (comparison: bilinear cosine pre-warp), pbrt (pbrt-v4's choice per shape, "
                         "thresholds included) or auto (per light and shading point, the strategy expected to pay best) "
                         "(default: each light's own; area for rectangles, ellipses and triangles, solid-angle for "
                         "spheres)")
      ->check(CLI::IsMember({"area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle", "pbrt", "auto"}));
  render_cmd->add_option("--auto-rest-cost", ro.auto_rest_cost,
                         "--light-sampling auto: the rest of the path's time per light sample, ns (default: modelled from the "
                         "pilot's rays per light sample; 265 with --auto-rest-variance)");
  render_cmd->add_option("--auto-rest-variance", ro.auto_rest_variance,
                         "--light-sampling auto: the relative variance the rest of the path adds, one value everywhere "
                         "(default: from the image's noise, measured by a pilot of up to 1024 pixels x 2 samples)");
  render_cmd->add_option("--ellipse-map", ro.ellipse_map,
                         "Map of the spherical ellipse for ellipses sampled by solid angle (default parallel)")
      ->check(CLI::IsMember({"parallel", "polar"}));
  render_cmd->add_option("--integrator", ro.integrator,
                         "Estimator: mis (next-event estimation with multiple importance sampling, default), nee "
                         "(next-event estimation) or mixture (Shirley's mixture pdf)")
      ->check(CLI::IsMember({"mixture", "nee", "mis"}));
  render_cmd->add_option("--sampler", ro.sampler,
                         "Sample generator: independent, stratified or sobol (default: the pbrt-v4 file's, else sobol)")
      ->check(CLI::IsMember({"independent", "stratified", "sobol"}));
  render_cmd->add_option("--mis-heuristic", ro.mis_heuristic, "Weights of --integrator mis: power (beta = 2, default) or balance")
      ->check(CLI::IsMember({"power", "balance"}));
  render_cmd->add_option("--light-select", ro.light_select,
                         "How nee and mis choose among several lights: power (by emitted flux; the default of JSON "
                         "scenes), uniform, bvh (a light hierarchy with mcrt's importance; pbrt-v4's default) or "
                         "pbrt-bvh (pbrt-v4's BVHLightSampler as it ships); a pbrt-v4 file's lightsampler otherwise")
      ->check(CLI::IsMember({"power", "uniform", "bvh", "pbrt-bvh"}));
  render_cmd->add_option("--stats", ro.stats, "Write render statistics as JSON to this file");
  render_cmd->add_flag("--quiet", ro.quiet, "No progress line");
  const char* max_input_help =
      "Read no input file (scene, included file, PLY mesh, image), nor a .gz file's unpacked stream, past this "
      "size: bytes, or with K, M, G or T (default 1G)";
  render_cmd->add_option("--max-input-size", ro.max_input_size, max_input_help);

  diff_options dop;
  CLI::App* diff_cmd = app.add_subcommand("diff", "Compare an image with a reference");
  diff_cmd->add_option("image", dop.image, "Image")->required();
  diff_cmd->add_option("reference", dop.reference, "Reference image")->required();
  diff_cmd->add_flag("--json", dop.json, "Print one JSON object");
  diff_cmd->add_option("--max-input-size", dop.max_input_size, max_input_help);

  samples_options sop;
  CLI::App* samples_cmd = app.add_subcommand("samples", "Write samples of one light's strategy as CSV");
  samples_cmd->add_option("scene", sop.scene, "Scene file (JSON, or pbrt-v4: .pbrt, .pbrt.gz)")->required();
  samples_cmd->add_option("--light", sop.light, "Index of the light among the scene's lights, in file order")->required();
  samples_cmd->add_option("--from", sop.from, "The receiving point X,Y,Z")->required();
  samples_cmd->add_option("--normal", sop.normal, "The receiving surface's normal X,Y,Z")->required();
  samples_cmd->add_option("--light-sampling", sop.light_sampling, "Strategy (default: the light's own)")
      ->check(CLI::IsMember({"area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle", "pbrt", "auto"}));
  samples_cmd->add_option("--ellipse-map", sop.ellipse_map, "Map of the spherical ellipse (default parallel)")
      ->check(CLI::IsMember({"parallel", "polar"}));
  samples_cmd->add_option("--n", sop.n, "Number of samples (default 100000)");
  samples_cmd->add_option("--seed", sop.seed, "Random seed (default 0)")->check(whole_number);
  samples_cmd->add_option("-o,--output", sop.output, "CSV file (default: standard output)");
  samples_cmd->add_option("--max-input-size", sop.max_input_size, max_input_help);

  if (argc > 1 && argv[1][0] != '-' && std::string(argv[1]) != "render" && std::string(argv[1]) != "diff" &&
      std::string(argv[1]) != "samples") {
    std::fprintf(stderr, "mcrt: unknown command '%s' (expected render, diff or samples; see mcrt --help)\n",
                 printable_line(std::string(argv[1]).substr(0, 80)).c_str());
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string msg = e.what();
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    std::fprintf(stderr, "mcrt: %s (see mcrt --help)\n", printable_line(msg).c_str());
    return 2;
  }
  try {
    for (const CLI::App* cmd : {render_cmd, samples_cmd, diff_cmd})
      if (cmd->parsed()) refuse_empty_values(*cmd);
    if (render_cmd->parsed()) return run_render(ro);
    if (samples_cmd->parsed()) {
      sop.max_input_bytes =
          sop.max_input_size.empty() ? io::default_max_input_bytes : parse_max_input_size(sop.max_input_size);
      return run_samples(sop);
    }
    return run_diff(dop);
  } catch (const input_error& e) {
    std::fprintf(stderr, "mcrt: %s\n", printable_line(e.what()).c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mcrt: error: %s\n", printable_line(e.what()).c_str());
    return 1;
  }
}
