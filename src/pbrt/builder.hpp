#pragma once
// The semantic layer of pbrt-v4's scene format: walks the directives the
// parser read (parser.hpp), keeping pbrt-v4's graphics state (the current
// transformation, ReverseOrientation, the material, the area light, named
// materials, textures and coordinate systems, Attribute defaults, all saved
// and restored by AttributeBegin/End), and makes mcrt's scene: triangle
// meshes, spheres and disks, their materials and lights, the camera, the
// film and the render settings the file asks for. What the file asks for
// and mcrt does not support is refused with parse_error (FILE:LINE: what),
// never ignored. The contract is pbrt-scenes.md; docs/pbrt.md says what
// each directive becomes.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "pbrt/camera.hpp"
#include "pbrt/parser.hpp"
#include "pbrt/transform.hpp"

namespace mcrt::pbrt {

struct film_desc {
  int width = 1280, height = 720;  // pbrt-v4's defaults
  std::string filename;            // "" when the file names none
};

// PixelFilter: its kind and radius (and sigma of the gaussian), pbrt-v4's
// defaults where the file is silent; without a PixelFilter, pbrt-v4's
// gaussian.
struct filter_desc {
  std::string kind = "gaussian";
  vec2 radius{1.5f, 1.5f};
  float sigma = 0.5f;
};

struct built_scene {
  scene world;
  // The camera: camera-from-world at the Camera directive and the
  // perspective's parameters; the image plane follows the resolution it is
  // rendered at (perspective_camera).
  transform camera_from_world;
  perspective_params perspective;
  film_desc film;
  filter_desc filter;
  // Sampler: mcrt's sample generator and pbrt-v4's count of samples per pixel.
  std::string sampler = "sobol";  // pbrt-v4's default zsobol -> sobol
  int spp = 16;
  // Integrator: maxdepth (pbrt-v4's default 5), and its light sampler as
  // mcrt's light selection ("power", "uniform" or "bvh", pbrt-v4's default).
  int max_depth = 5;
  std::string light_select = "bvh";
  // The Integrator the file names (pbrt-v4's default, volpath, where it
  // names none). mcrt renders every one it accepts with its own
  // integrator (the command line's, mis by default): they converge to the
  // same image.
  std::string integrator_requested = "volpath";
  // The lights in the order the file defines them (a mesh's in face order):
  // each one's entries in world.emitters, two for a two-sided light (its
  // front and its back, each sampled from its own side).
  std::vector<std::vector<std::uint32_t>> file_lights;
  // Lights sampled by `auto` (each side of a two-sided light counts), and
  // the time their set-up took (part of the image's, as for JSON scenes).
  int auto_lights = 0;
  double auto_setup_seconds = 0.0;
};

// Decodes an image file into linear RGB texels (8-bit images are decoded
// with the texture's `encoding`: "sRGB", "linear" or "gamma G"); throws
// std::runtime_error with the reason. Supplied by the executable
// (OpenImageIO), so that this layer needs no image library.
// An image whose decoded texels would take more than max_bytes bytes is
// refused from its header, before it is decoded.
using image_decoder =
    std::function<texture_image(const std::string& path, const std::string& encoding, std::uint64_t max_bytes)>;

struct build_options {
  // Every emitter sampled by this strategy instead of its default (area):
  // --light-sampling.
  std::optional<light_sampling> strategy;
  // With strategy `auto`: the rule's params (each light's radiance is set
  // from its own L), and whether this is the noise pilot's scene, whose
  // lights take their shape's default strategy (its cheapest) instead.
  auto_params auto_rule;
  bool auto_pilot = false;
  image_decoder decode_image;
  // No file (scene text, PLY mesh, image) is read past this many bytes, nor
  // a gzip-compressed one's unpacked stream (src/input_file.hpp): the
  // executable's --max-input-size.
  std::uint64_t max_input_bytes = io::default_max_input_bytes;
};

// The scene of a parsed file; `scene_directory` resolves relative file
// names (PLY meshes, images), as pbrt-v4 resolves them against the
// top-level file's directory. Throws parse_error.
built_scene build_scene(const std::vector<directive>& directives, const std::string& scene_directory,
                        const build_options& options = {});

// parse_file (with options.max_input_bytes) then build_scene.
built_scene load_pbrt_file(const std::string& path, const build_options& options = {});

}  // namespace mcrt::pbrt
