#pragma once
// Shirley's pinhole camera ("In One Weekend", sec. 11): vfov is the vertical
// field of view in degrees; the image's horizontal axis is
// cross(vup, lookfrom - lookat), its vertical axis vup projected.
#include "mcrt/core/ray.hpp"

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

  // (s, t) in [0,1]^2 over the image, s to the right, t downwards (row order).
  ray generate(float s, float t) const {
    return {origin_, upper_left_ + s * horizontal_ - t * vertical_ - origin_};
  }

  // The inverse of generate: the image coordinates (s, t) of the point p,
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
};

}  // namespace mcrt
