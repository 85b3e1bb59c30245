#pragma once
// Cosine-aware sampling of a triangle light by a bilinear pre-warp of the
// spherical triangle: Hart, Pharr, Müller, Lopes, McGuire & Shirley 2020,
// "Practical Product Sampling by Fitting and Composing Warps" (EGSR 2020,
// sec. 4.1), as pbrt-v4 samples its triangles (Pharr, Jakob & Humphreys,
// pbrt-v4, shapes.h, Triangle::Sample and Triangle::PDF). The strategy
// triangle_bilinear_solid_angle_sampler has the normal-aware interface of
// light_sample.hpp; it is the comparison for the exact projected-solid-angle
// sampler (projected_triangle.hpp), as rect_bilinear_solid_angle_sampler is
// for rectangles.
//
// The warp. A point u of the unit square is first warped by the bilinear
// density whose values at the corners (0,0), (1,0), (0,1), (1,1) are the
// weights w00, w10, w01, w11 (bilinear_rect_detail::square_to_bilinear,
// pbrt-v4's SampleBilinear), and the warped point u' is then carried onto
// the triangle by Arvo's map (spherical_triangle.hpp): u'.x the share of
// the solid angle swept from p0 towards p2, u'.y the arc from p1. The map
// sends both corners (0,0) and (1,0) to p1, (0,1) to p0 and (1,1) to p2, so
// the weights are the cosines at the receiver of the directions to p1, p1,
// p0, p2 (pbrt-v4's order), and the product density approximates cos(theta)
// times the uniform solid-angle density. Per unit SOLID ANGLE,
//   p(omega) = p_bilinear(u') / Omega,   u' = map^-1(omega).
//
// Weights. pbrt-v4 takes max(0.01, |n . omega_i|); the receiver here is
// one-sided (as rect_bilinear_solid_angle_sampler's), so a vertex below
// its horizon gets the floor itself: w_i = max(weight_floor, n . omega_i),
// weight_floor = 0.01. The bilinear density is then at least weight_floor
// over the whole square: every point of the triangle keeps a positive
// density.
//
// The horizon. The spherical triangle covers the whole light, also the part
// below the receiver's horizon. A sampled direction with n . omega <= 0
// returns no sample and pdf() is 0 there (a sub-probability density on the
// visible part, which keeps every estimate unbiased). Where every vertex is
// at or below the horizon there is no sample and pdf 0 without any set-up.
//
// Exactness. No threshold of this header changes the density: the bilinear
// warp is exact in double, and the spherical triangle has no fallback.
// pdf() inverts the map (spherical_triangle::invert_offset); the bilinear
// density at the inverse differs from the one at the sampled point by its
// gradient (< 4) times the inverse's rounding, ~1e-7 relative.
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>

#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/bilinear_spherical_rectangle.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"

namespace mcrt {

// Light-sampling strategy: the spherical triangle (triangle_solid_angle_
// sampler) behind the bilinear cosine pre-warp of Hart et al. 2020
// (bilinear_prewarp, shared with the rectangle's). One-sided like the
// spherical triangle (back: the sampler of the triangle's back side, for
// two-sided lights); no sample and pdf 0 where the direction or the whole
// light lies below the receiver's horizon.
struct triangle_bilinear_solid_angle_sampler
    : bilinear_prewarp<triangle_bilinear_solid_angle_sampler, triangle_solid_angle_sampler> {
  triangle shape;  // fixed after construction (sa_ is built from it)

  explicit triangle_bilinear_solid_angle_sampler(const triangle& t, bool back = false)
      : bilinear_prewarp(triangle_solid_angle_sampler(t, back)), shape(t) {}

  // The corner weights for the receiver (o, n), in pbrt-v4's order (p1, p1,
  // p0, p2); false where the whole light is at or below the horizon (or n
  // is not a direction).
  bool weights(const vec3& o, const vec3& n, bilinear_rect_detail::corner_weights& w) const {
    const dvec3 nd(n), od(o);
    const double nl = glm::length(nd);
    if (!(nl > 0.0) || !std::isfinite(nl)) return false;
    std::array<double, 3> c;
    bool above = false;
    for (int k = 0; k < 3; ++k) {
      const dvec3 v = dvec3(shape.vertex(k)) - od;
      const double d = glm::dot(nd, v);
      above = above || d > 0.0;
      c[static_cast<std::size_t>(k)] = std::max(weight_floor, d / (nl * glm::length(v)));
    }
    w = {c[1], c[1], c[0], c[2]};
    return above;
  }

  // Arvo's unit-square point of dir (spherical_triangle::invert_offset).
  bool map_inverse(const vec3& o, const vec3& dir, dvec2& up) const {
    const spherical_triangle st(dvec3(o), dvec3(sa_.p0), dvec3(sa_.p1), dvec3(sa_.p2));
    up = st.invert_offset(dvec3(dir));
    return true;
  }
};

}  // namespace mcrt
