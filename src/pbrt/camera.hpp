#pragma once
// pbrt-v4's perspective camera (src/pbrt/cameras.cpp, PerspectiveCamera;
// the File Format reference) as mcrt's pinhole camera. pbrt's camera space
// has x to the image's right, y up and z forward; the CTM at the Camera
// directive is camera-from-world and is used as a whole matrix (it may hold a
// reflection, as the common "Scale -1 1 1" does), not converted to a
// lookfrom/lookat/up triple. The screen window defaults to [-a, a] x [-1, 1]
// for a frame aspect ratio a = width / height >= 1 and [-1, 1] x [-1/a, 1/a]
// otherwise, so `fov` spans the image's shorter axis; the image plane is
// z = 1 in camera space scaled by tan(fov / 2); raster row 0 is the top
// (screen y = the window's maximum). A `lensradius` > 0 makes it a thin-lens
// camera (pbrt-v4's GenerateRay): the lens disk of that radius in camera
// space's z = 0 plane, focused on the plane z = `focaldistance` (default
// 1e6, pbrt-v4's).
#include <array>
#include <optional>

#include "mcrt/render/camera.hpp"
#include "pbrt/transform.hpp"

namespace mcrt::pbrt {

struct perspective_params {
  double fov = 90.0;                               // degrees, pbrt-v4's default
  std::optional<double> frame_aspect_ratio;        // "frameaspectratio"
  std::optional<std::array<double, 4>> screen_window;  // "screenwindow": xmin xmax ymin ymax
  double lens_radius = 0.0;                        // "lensradius", camera-space units; 0: a pinhole
  double focal_distance = 1e6;                     // "focaldistance", along camera z
};

// The screen window pbrt-v4 uses for an image of width x height.
inline std::array<double, 4> screen_window(const perspective_params& p, int width, int height) {
  if (p.screen_window) return *p.screen_window;
  const double a = p.frame_aspect_ratio.value_or(double(width) / double(height));
  if (a > 1.0) return {-a, a, -1.0, 1.0};
  return {-1.0, 1.0, -1.0 / a, 1.0 / a};
}

inline camera perspective_camera(const transform& camera_from_world, const perspective_params& p, int width,
                                 int height) {
  const transform world_from_camera = camera_from_world.inverse();
  const std::array<double, 4> w = screen_window(p, width, height);
  const double s = std::tan(0.5 * p.fov * 3.14159265358979323846 / 180.0);
  const glm::dvec3 upper_left{w[0] * s, w[3] * s, 1.0};
  const glm::dvec3 horizontal{(w[1] - w[0]) * s, 0.0, 0.0}, vertical{0.0, (w[3] - w[2]) * s, 0.0};
  camera c = camera::from_image_plane(vec3(world_from_camera.point({0, 0, 0})), vec3(world_from_camera.point(upper_left)),
                                      vec3(world_from_camera.vector(horizontal)), vec3(world_from_camera.vector(vertical)));
  // The image plane is camera z = 1, so the plane of focus is the pinhole
  // ray's parameter focal_distance.
  if (p.lens_radius > 0.0)
    c.set_thin_lens(vec3(world_from_camera.vector({p.lens_radius, 0.0, 0.0})),
                    vec3(world_from_camera.vector({0.0, p.lens_radius, 0.0})), static_cast<float>(p.focal_distance));
  return c;
}

}  // namespace mcrt::pbrt
