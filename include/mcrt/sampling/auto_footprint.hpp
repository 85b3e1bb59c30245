#pragma once
// The footprint of a pixel on the surfaces its camera rays first meet, over
// which `auto` takes one choice for all of the pixel's samples
// (docs/auto.md, "One choice per pixel").
//
// `auto` chooses a light's strategy per shading point from a table of cells
// (auto_table.hpp). Where a boundary between two choices crosses a pixel,
// the pixel's samples are split between two strategies, and each strategy
// sees only a part of the pixel's points of the sample sequence: that part
// is not stratified as the whole is, and the light's noise in the pixel
// comes back to near its size with independent samples. With Sobol points
// under a small light 3 edges above a floor (tri_distance_h3, 32 spp), a
// choice of solid angle over a ring of the floor and area sampling inside
// and outside it left 15-250x area sampling's error in the ~460 pixels on
// the ring's two edges, 57 % of the image's squared error.
//
// So at a camera ray's first surface, a point on the plane the pixel's
// footprint meets takes, for each light, the dearest (lowest-variance:
// projected solid angle, then solid angle, then area) of the choices at
// the footprint's points on that plane: where the corners of the pixel's
// filter support, seen through the lens's centre, meet it (the renderer's
// pixel_footprint, tile_footprints). Every sample of
// the pixel on that plane then takes the same strategy. The choice stays a
// pure function of the light, the point and normal and the pixel, fixed
// along a path, so sample(), its pdf and pdf() agree as before; deeper
// vertices, points on other surfaces (another plane, a curved surface) and
// pixels whose footprint meets no surface keep the per-point choice.
#include <array>
#include <cmath>
#include <cstdint>

#include "mcrt/core/math.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

class auto_footprint {
 public:
  static constexpr int max_points = 4;

  // Adds a point of the footprint (the spawn point of a camera ray's first
  // hit, with its facing shading normal); at most max_points are kept.
  void add(const vec3& o, const vec3& n) {
    if (count_ == max_points) return;
    o_[static_cast<std::size_t>(count_)] = o, n_[static_cast<std::size_t>(count_)] = n;
    ++count_;
  }
  int size() const { return count_; }
  bool empty() const { return count_ == 0; }
  const vec3& point(int i) const { return o_[static_cast<std::size_t>(i)]; }
  const vec3& normal(int i) const { return n_[static_cast<std::size_t>(i)]; }

  // The first footprint point on the plane of (o, n), or -1: the same
  // normal (within 0.8 degrees) and o within 1 % of its distance to the
  // point off that point's tangent plane (points of one plane differ there
  // by rounding and their spawn offsets alone; a parallel surface a little
  // above it, a table over a floor, is another plane).
  int plane_of(const vec3& o, const vec3& n) const {
    for (int i = 0; i < count_; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (!(glm::dot(n, n_[k]) > 0.9999f)) continue;
      const vec3 d = o - o_[k];
      const float off = std::abs(glm::dot(d, n_[k]));
      const float scale = std::max({std::abs(o.x), std::abs(o.y), std::abs(o.z), 1.0f});
      if (off <= 0.01f * glm::length(d) + 1e-4f * scale) return i;
    }
    return -1;
  }

  // The dearest of choose(point, normal) over the footprint's points on
  // plane (plane_of's index), each taken with that plane's normal;
  // remembered for the last (light, plane) asked (a pixel's samples ask
  // about the same light again and again).
  template <class Choose>
  light_sampling dearest(const void* light, int plane, Choose&& choose) const {
    if (light == memo_light_ && plane == memo_plane_) return memo_;
    const vec3& np = n_[static_cast<std::size_t>(plane)];
    light_sampling c = choose(o_[static_cast<std::size_t>(plane)], np);
    for (int i = plane + 1; i < count_; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (plane_of(o_[k], n_[k]) == plane) c = dearer(c, choose(o_[k], np));
    }
    memo_light_ = light, memo_plane_ = plane, memo_ = c;
    return c;
  }

  // The lower-variance of two of auto's choices.
  static light_sampling dearer(light_sampling a, light_sampling b) { return rank(a) >= rank(b) ? a : b; }

 private:
  static int rank(light_sampling s) {
    switch (s) {
      case light_sampling::projected_solid_angle: return 2;
      case light_sampling::solid_angle: return 1;
      default: return 0;
    }
  }

  std::array<vec3, max_points> o_{}, n_{};
  int count_ = 0;
  // The last answer (a pixel's footprint lives on its thread's stack).
  mutable const void* memo_light_ = nullptr;
  mutable int memo_plane_ = -1;
  mutable light_sampling memo_ = light_sampling::area;
};

}  // namespace mcrt
