#pragma once
// Reads a scene file (the contract of scenes/FORMAT.md, or a pbrt-v4 file:
// the contract pbrt-scenes.md, src/pbrt/builder.hpp) into an mcrt::scene.
// Every violation of the contract throws input_error with one line naming
// the file, the place in it and what is wrong.
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "input_file.hpp"
#include "mcrt/mcrt.hpp"

namespace mcrt::cli {

// Bad input (command line or scene): reported as one line, exit status 2.
struct input_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Documented limits of what a scene or the command line may ask for.
inline constexpr int max_resolution = 16384;    // pixels per side
inline constexpr int max_spp = 1 << 20;          // samples per pixel
inline constexpr int max_depth_limit = 100000;   // scattering events

struct camera_desc {
  vec3 lookfrom{278.0f, 278.0f, -800.0f}, lookat{278.0f, 278.0f, 0.0f}, vup{0.0f, 1.0f, 0.0f};
  float vfov = 40.0f;
  int width = 600, height = 600;
};

struct loaded_scene {
  std::string name;  // file name without directory and extension
  scene world;
  camera_desc cam;  // the JSON format's camera (its width and height also for pbrt-v4 files)
  // The camera for an image of width x height: the JSON format's keeps the
  // scene's aspect ratio (another resolution resamples the same view);
  // pbrt-v4's screen window follows the image's aspect ratio, as in pbrt.
  std::function<camera(int width, int height)> make_camera;
  int spp = 100, max_depth = 50;
  // What a pbrt-v4 file asks for where the command line is silent: the
  // sample generator, the light selection and the output file (its Film's
  // filename); empty for JSON scenes.
  std::string sampler, light_select, output;
  // pbrt-v4 files: the Integrator the file names (volpath where none);
  // empty for JSON scenes.
  std::string integrator_requested;
  // pbrt-v4 files: each light in file order (a mesh's triangles in face
  // order) as its entries in world.emitters (two for a two-sided light).
  std::vector<std::vector<std::uint32_t>> file_lights;
  // pbrt-v4 files: the pixel filter (kind box, gaussian or triangle; radius;
  // sigma); JSON scenes: box of radius 0.5.
  std::string filter = "box";
  vec2 filter_radius{0.5f, 0.5f};
  float filter_sigma = 0.5f;
  int auto_lights = 0;  // lights sampled by `auto`
  // Time spent making those lights' samplers (seconds): `mcrt render` counts
  // it in the image's time, as it does the noise pilot.
  double auto_setup_seconds = 0.0;
  // Of those, the lights (indices in world.lights) whose per-point choice
  // did not pay for its cost at the noise pilot's receivers: sampled by
  // their cheapest strategy everywhere. In increasing order.
  std::vector<std::uint32_t> auto_cheapest_lights;
};

// Which area-preserving map of the spherical ellipse samples an ellipse by
// solid angle (Guillen et al. 2017): the parallel one, as the seed, or the
// polar one.
enum class ellipse_map { parallel, polar };

// The strategy a --light-sampling value names; nullopt for "" (no flag).
// Throws input_error for the strategies this build does not have.
std::optional<light_sampling> parse_light_sampling_flag(const std::string& value);

// override_strategy: --light-sampling; switches every light (emitter) to one
// strategy; non-emitting sampled objects keep their own.
// map: --ellipse-map; the map of every ellipse sampled by solid angle.
// ap: the parameters of every light sampled by `auto` (--auto-rest-cost,
// --auto-rest-variance, and the image's variance its noise pilot measured),
// each with its own light's radiance.
// auto_pilot: the scene for that pilot: every light that would be sampled by
// `auto` takes its shape's default (cheapest) strategy instead.
// auto_receivers: the surfaces the noise pilot's pixels see; where given, a
// light sampled by `auto` whose choice does not pay for its cost there
// takes its cheapest strategy everywhere (auto_sampler::table_gain).
// Whether a path names a pbrt-v4 file (.pbrt, .pbrt.gz).
bool is_pbrt_file(const std::string& path);

// max_input_bytes: --max-input-size; no file the scene reads (the scene,
// files it includes, PLY meshes, images) is read past this many bytes, nor
// a gzip-compressed one's unpacked stream (input_file.hpp).
loaded_scene load_scene(const std::string& path, std::optional<light_sampling> override_strategy = std::nullopt,
                        ellipse_map map = ellipse_map::parallel, const auto_params& ap = {}, bool auto_pilot = false,
                        std::span<const auto_receiver> auto_receivers = {},
                        std::uint64_t max_input_bytes = io::default_max_input_bytes);

}  // namespace mcrt::cli
