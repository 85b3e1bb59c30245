#pragma once
// Shirley's pinhole camera ("In One Weekend", sec. 11): vfov is the vertical
// field of view in degrees; the image's horizontal axis is
// cross(vup, lookfrom - lookat), its vertical axis vup projected.
//
// A camera may also have a thin lens (pbrt-v4's PerspectiveCamera,
// "Physically Based Rendering", 4th ed., sec. 5.2.3; Shirley's "In One
// Weekend", sec. 13): a disk around the eye, in the plane through it
// parallel to the image, and a plane of focus. The ray of image point (s, t)
// and lens point u then starts at the lens point and passes through the
// point the pinhole ray of (s, t) meets on the plane of focus, so that the
// plane of focus is sharp and everything else is blurred by the lens.
#include "mcrt/core/ray.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

class camera {
 public:
  camera() = default;
  camera(const vec3& lookfrom, const vec3& lookat, const vec3& vup, float vfov_degrees, float aspect) {
    const float h = std::tan(glm::radians(vfov_degrees) * 0.5f);
    const float viewport_h = 2.0f * h, viewport_w = aspect * viewport_h;
    const vec3 w = glm::normalize(lookfrom - lookat);
    const vec3 u = glm::normalize(glm::cross(vup, w));
    const vec3 v = glm::cross(w, u);
    origin_ = lookfrom;
    horizontal_ = viewport_w * u;
    vertical_ = viewport_h * v;
    upper_left_ = origin_ - 0.5f * horizontal_ + 0.5f * vertical_ - w;
  }

  // A pinhole camera given by its image plane: the eye, the plane's
  // upper-left corner and its horizontal (to the image's right) and vertical
  // (upwards) extents. Any frame, a mirrored one included (pbrt-v4's cameras,
  // whose camera-from-world matrix may contain a reflection).
  static camera from_image_plane(const vec3& eye, const vec3& upper_left, const vec3& horizontal, const vec3& vertical) {
    camera c;
    c.origin_ = eye;
    c.upper_left_ = upper_left;
    c.horizontal_ = horizontal;
    c.vertical_ = vertical;
    return c;
  }

  // A thin lens: lens_x and lens_y are the lens disk's two radii in the
  // world (the images of the camera's x and y axes scaled by the lens
  // radius; a camera matrix with a reflection or a scale maps them as it
  // maps everything else), and the plane of focus is where the pinhole ray
  // generate(s, t) = o + k d reaches k = focal (pbrt-v4: focaldistance in
  // camera space, along z, with d's camera-space z equal to 1).
  void set_thin_lens(const vec3& lens_x, const vec3& lens_y, float focal) {
    lens_x_ = lens_x;
    lens_y_ = lens_y;
    focal_ = focal;
    has_lens_ = true;
  }
  // Whether camera rays need a lens sample (two more sample dimensions).
  bool has_lens() const { return has_lens_; }

  // (s, t) in [0,1]^2 over the image, s to the right, t downwards (row order):
  // the pinhole ray through the lens's centre.
  ray generate(float s, float t) const {
    return {origin_, upper_left_ + s * horizontal_ - t * vertical_ - origin_};
  }

  // The same image point through the lens point of u in [0,1]^2 (uniform
  // over the lens disk: the concentric map, sampling/warp.hpp); the pinhole
  // ray where there is no lens. The direction is formed as
  // focal d - lens offset, never as the difference of two world points, so
  // a far plane of focus (pbrt-v4's default 1e6) costs no precision.
  ray generate(float s, float t, vec2 u) const {
    const ray pinhole = generate(s, t);
    if (!has_lens_) return pinhole;
    const vec2 l = square_to_uniform_disk_concentric(u);
    const vec3 offset = l.x * lens_x_ + l.y * lens_y_;
    return {origin_ + offset, focal_ * pinhole.d - offset};
  }

  // The inverse of generate(s, t), the pinhole ray: the image coordinates (s, t) of the point p,
  // false where p is not in front of the camera (on or behind the plane
  // through the eye parallel to the image).
  bool project(const vec3& p, float& s, float& t) const {
    vec3 w = glm::normalize(glm::cross(horizontal_, vertical_));  // towards the viewer ...
    const vec3 centre = upper_left_ + 0.5f * horizontal_ - 0.5f * vertical_;
    if (glm::dot(centre - origin_, w) > 0.0f) w = -w;                // ... also for a mirrored frame
    const vec3 d = p - origin_;
    const float depth = -glm::dot(d, w);
    if (!(depth > 0.0f)) return false;
    const vec3 q = d / depth - (upper_left_ - origin_);  // on the image plane, from its upper-left corner
    s = glm::dot(q, horizontal_) / glm::dot(horizontal_, horizontal_);
    t = -glm::dot(q, vertical_) / glm::dot(vertical_, vertical_);
    return true;
  }

 private:
  vec3 origin_{0.0f}, upper_left_{0.0f}, horizontal_{0.0f}, vertical_{0.0f};
  vec3 lens_x_{0.0f}, lens_y_{0.0f};
  float focal_ = 1.0f;
  bool has_lens_ = false;
};

}  // namespace mcrt
