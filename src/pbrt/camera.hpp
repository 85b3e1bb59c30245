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
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

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

// Why a camera-from-world matrix cannot be a camera's, or nullopt where it
// can: a non-finite entry, a last row other than 0 0 0 1 (a projective
// matrix: pbrt-v4's cameras are affine), or a singular 3x3 part. The
// determinant is taken of the 3x3 part divided by its largest entry, so
// that a uniform scale, however small or large, is not singular (its
// determinant s^3 would underflow for s below 1e-103), while a zero or
// collapsed axis is (Scale 1 1 0).
inline std::optional<std::string> camera_matrix_problem(const transform& camera_from_world) {
  const glm::dmat4& m = camera_from_world.m;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      if (!std::isfinite(m[j][i])) return "the camera's transformation has a non-finite entry";
  if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
    return "the camera's transformation is not affine (its last row is not 0 0 0 1)";
  glm::dmat3 a(m);
  double largest = 0.0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) largest = std::max(largest, std::abs(a[j][i]));
  if (!(largest > 0.0)) return "the camera's transformation is singular (it collapses space to a point)";
  a /= largest;
  const double det = glm::determinant(a);
  if (!(std::abs(det) > 0.0)) return "the camera's transformation is singular (it collapses an axis)";
  const glm::dmat4& inv = camera_from_world.inv;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      if (!std::isfinite(inv[j][i])) return "the camera's transformation has a non-finite inverse";
  return std::nullopt;
}

// The camera for an image of width x height. The directions of the image
// plane are scaled by a power of two (exactly) to about unit length in the
// world: a camera matrix with a tiny or huge scale (Scale 1e-30 1e-30
// 1e-30) sees the same rays, whose directions would otherwise leave single
// precision; the plane of focus's ray parameter is scaled to match. Throws
// std::domain_error where the camera does not fit single precision even so
// (an eye or a lens beyond 3.4e38).
inline camera perspective_camera(const transform& camera_from_world, const perspective_params& p, int width,
                                 int height) {
  const transform world_from_camera = camera_from_world.inverse();
  const std::array<double, 4> w = screen_window(p, width, height);
  const double s = std::tan(0.5 * p.fov * 3.14159265358979323846 / 180.0);
  const glm::dvec3 upper_left{w[0] * s, w[3] * s, 1.0};
  const glm::dvec3 horizontal{(w[1] - w[0]) * s, 0.0, 0.0}, vertical{0.0, (w[3] - w[2]) * s, 0.0};
  const double forward = glm::length(world_from_camera.vector({0.0, 0.0, 1.0}));
  const double k = forward > 0.0 && std::isfinite(forward) ? std::exp2(-std::round(std::log2(forward))) : 1.0;
  const glm::dvec3 eye = world_from_camera.point({0, 0, 0});
  const vec3 e(eye), ul(eye + k * world_from_camera.vector(upper_left));
  const vec3 h(k * world_from_camera.vector(horizontal)), v(k * world_from_camera.vector(vertical));
  if (!all_finite(e) || !all_finite(ul) || !all_finite(h) || !all_finite(v))
    throw std::domain_error("the camera does not fit single precision (its position or image plane is beyond 3.4e38)");
  camera c = camera::from_image_plane(e, ul, h, v);
  // The image plane is camera z = 1 (k in the world ray's parameter), so
  // the plane of focus is the pinhole ray's parameter focal_distance / k.
  if (p.lens_radius > 0.0) {
    const vec3 lx(world_from_camera.vector({p.lens_radius, 0.0, 0.0})), ly(world_from_camera.vector({0.0, p.lens_radius, 0.0}));
    const float focal = static_cast<float>(p.focal_distance / k);
    if (!all_finite(lx) || !all_finite(ly) || !std::isfinite(focal) || !(focal > 0.0f))
      throw std::domain_error("the camera's lens does not fit single precision (lensradius or focaldistance too large "
                              "or small for the camera's transformation)");
    c.set_thin_lens(lx, ly, focal);
  }
  return c;
}

}  // namespace mcrt::pbrt
