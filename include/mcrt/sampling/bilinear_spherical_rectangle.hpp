#pragma once
// Cosine-aware sampling of a rectangle light by a bilinear pre-warp of the
// spherical rectangle: Hart, Pharr, Müller, Lopes, McGuire & Shirley 2020,
// "Practical Product Sampling by Fitting and Composing Warps" (EGSR 2020,
// sec. 4.1), below [H20], as pbrt-v4 samples its rectangular bilinear
// patches and quad lights (Pharr, Jakob & Humphreys, pbrt-v4, shapes.h,
// BilinearPatch::Sample). The strategy rect_bilinear_solid_angle_sampler
// has the normal-aware interface of light_sample.hpp.
//
// The warp. A point u of the unit square is first warped by the bilinear
// density on [0,1]^2 whose values at the corners (0,0), (1,0), (0,1), (1,1)
// are weights w00, w10, w01, w11, and the warped point u' is then carried
// onto the light by the spherical-rectangle map of Urena et al. 2013
// (spherical_rectangle.hpp; u'.x runs along e1, u'.y along e2). The weight
// of a corner is the cosine at the receiver of the direction to that corner
// of the rectangle, so that the product density approximates cos(theta)
// times the uniform solid-angle density. The density of a direction omega
// per unit SOLID ANGLE is
//   p(omega) = p_rect(omega) * p_bilinear(u'),  u' = map^-1(omega),
// p_rect the spherical rectangle's density (1/S on its map, the exact area
// density on its area fallback) and p_bilinear the bilinear density at the
// unit-square point the spherical rectangle's inverse returns.
//
// The bilinear warp (after pbrt-v4 util/sampling.h, SampleBilinear,
// BilinearPDF, InvertBilinearSample): u'.y from the marginal density, linear
// on [0, 1] between w00 + w10 and w01 + w11, then u'.x from the conditional
// density, linear between lerp(u'.y, w00, w01) and lerp(u'.y, w10, w11). A
// linear density on [0, 1] with end values a, b > 0 has the inverse CDF
//   x = u (a + b) / (a + sqrt((1 - u) a^2 + u b^2)),
// the root of (a + (b - a) x / 2) x = u (a + b) / 2 without the cancellation
// of the textbook quadratic formula when a ~ b; its inverse is u = x (a (2 -
// x) + b x) / (a + b).
//
// Weights (weight_floor). pbrt-v4 takes max(0.01, |n . omega_i|); the
// absolute value serves its two-sided (transmissive) receivers. Here the
// receiver is one-sided, so a corner below its horizon gets the floor
// itself: w_i = max(weight_floor, n . omega_i), weight_floor = 0.01 as in
// pbrt-v4. The floor keeps every weight positive: the bilinear density is
// at least 4 min(w) / sum(w) >= weight_floor on the whole square (weights
// are at most 1), so every point of the light keeps a positive density and
// nothing divides by zero.
//
// The horizon. The spherical rectangle covers the whole light, also the part
// below the receiver's horizon. A sampled direction with n . omega <= 0
// returns no sample, and pdf() is 0 there: the sampler is then a
// sub-probability density on the visible part (its mass is the fraction of
// the bilinear-weighted solid angle above the horizon), which keeps every
// estimate unbiased (a missing sample contributes 0, as the integrand would).
// Where every corner is at or below the horizon (n . (p_i - o) <= 0 for the
// four corners, hence for the whole rectangle, n . (p - o) being affine in
// p) there is no sample and pdf 0 without any set-up.
//
// Exactness. No threshold of this header changes the density: the bilinear
// warp is exact in double for every weight >= weight_floor, and the
// spherical rectangle is exact with its own documented fallback (tiny solid
// angles, grazing views: spherical_rectangle.hpp), which sample() and pdf()
// take alike. pdf() inverts the map with spherical_rectangle::invert_offset,
// whose map agrees with rect_solid_angle_sampler's fast path to the rounding
// of a float direction; the bilinear density varies by at most its gradient
// (< 4) times that, ~1e-6 relative.
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <utility>

#include "mcrt/geometry/rect.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

namespace bilinear_rect_detail {

// Weights at the corners (0,0), (1,0), (0,1), (1,1) of the unit square, in
// pbrt-v4's order; all > 0.
using corner_weights = std::array<double, 4>;

// Bilinear density on [0,1]^2 (pbrt-v4 order: y from the marginal, x from
// the conditional): sample, pdf (per unit area of the square), inverse.
inline dvec2 square_to_bilinear(dvec2 u, const corner_weights& w) {
  const double y = square_to_linear(u.y, w[0] + w[1], w[2] + w[3]);
  const double x = square_to_linear(u.x, (1.0 - y) * w[0] + y * w[2], (1.0 - y) * w[1] + y * w[3]);
  return {x, y};
}
inline double square_to_bilinear_pdf(dvec2 p, const corner_weights& w) {
  if (!(p.x >= 0.0 && p.x <= 1.0 && p.y >= 0.0 && p.y <= 1.0)) return 0.0;
  return 4.0 *
         ((1.0 - p.x) * (1.0 - p.y) * w[0] + p.x * (1.0 - p.y) * w[1] + (1.0 - p.x) * p.y * w[2] + p.x * p.y * w[3]) /
         (w[0] + w[1] + w[2] + w[3]);
}
inline dvec2 bilinear_to_square(dvec2 p, const corner_weights& w) {
  return {linear_to_square(p.x, (1.0 - p.y) * w[0] + p.y * w[2], (1.0 - p.y) * w[1] + p.y * w[3]),
          linear_to_square(p.y, w[0] + w[1], w[2] + w[3])};
}

}  // namespace bilinear_rect_detail

// What the pre-warped strategies share (this rectangle's, the triangle's of
// bilinear_spherical_triangle.hpp): the bilinear warp of u before the
// solid-angle map, its density at the warped point, and the same through the
// map's inverse for pdf() and invert(). Derived supplies weights(o, n, w)
// (false where the whole light is at or below the horizon) and
// map_inverse(o, dir, u') (the unit-square point of the solid-angle map
// whose direction is dir; false where there is none).
template <class Derived, class SolidAngle>
struct bilinear_prewarp {
  // Least corner weight (see the header): pbrt-v4's 0.01.
  static constexpr double weight_floor = 0.01;

  bool faces(const vec3& o) const { return sa_.faces(o); }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    using namespace bilinear_rect_detail;
    corner_weights w;
    if (!self().weights(o, n, w)) return false;
    // The warped point as the float the solid-angle map receives, and the
    // bilinear density at that very point.
    const vec2 up(square_to_bilinear(dvec2(u), w));
    light_sample t;
    if (!sa_.sample(o, up, t)) return false;
    if (!(glm::dot(dvec3(t.dir), dvec3(n)) > 0.0)) return false;  // below the horizon
    const double p = double(t.pdf) * square_to_bilinear_pdf(dvec2(up), w);
    if (!(p > 0.0) || !(p <= double(FLT_MAX))) return false;
    s = t;
    s.pdf = float(p);
    return true;
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir for the
  // receiver's normal n: p_map(dir) * p_bilinear(map^-1(dir)); 0 below the
  // horizon, behind the light, or if the ray misses. The cheap tests come
  // first: a direction that misses costs no set-up.
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const {
    dvec2 up;
    double p_map;
    bilinear_rect_detail::corner_weights w;
    if (!preimage(o, n, dir, up, p_map, w)) return 0.0f;
    const double p = p_map * bilinear_rect_detail::square_to_bilinear_pdf(up, w);
    return p <= double(FLT_MAX) ? float(p) : 0.0f;
  }

  // Unit direction dir -> the unit-square point sample() maps onto it; false
  // (u untouched) where pdf() is 0.
  bool invert(const vec3& o, const vec3& n, const vec3& dir, vec2& u) const {
    dvec2 up;
    double p_map;
    bilinear_rect_detail::corner_weights w;
    if (!preimage(o, n, dir, up, p_map, w)) return false;
    u = vec2(bilinear_rect_detail::bilinear_to_square(up, w));
    return true;
  }

 protected:
  explicit bilinear_prewarp(SolidAngle sa) : sa_(std::move(sa)) {}
  const Derived& self() const { return static_cast<const Derived&>(*this); }

  // dir -> (u', the map's density, weights); false where the density is 0.
  bool preimage(const vec3& o, const vec3& n, const vec3& dir, dvec2& up, double& p_map,
                bilinear_rect_detail::corner_weights& w) const {
    if (!(glm::dot(dvec3(dir), dvec3(n)) > 0.0)) return false;
    const float ps = sa_.pdf(o, dir);  // ray test first, 0 behind the light
    if (!(ps > 0.0f)) return false;
    if (!self().weights(o, n, w)) return false;
    if (!self().map_inverse(o, dir, up)) return false;
    p_map = double(ps);
    return true;
  }

  SolidAngle sa_;
};

// Light-sampling strategy: the spherical rectangle (rect_solid_angle_sampler)
// behind the bilinear cosine pre-warp of [H20]. One-sided like the
// spherical rectangle; no sample and pdf 0 where the direction or the whole
// light lies below the receiver's horizon.
struct rect_bilinear_solid_angle_sampler
    : bilinear_prewarp<rect_bilinear_solid_angle_sampler, rect_solid_angle_sampler> {
  rect shape;  // fixed after construction (sa_ is built from it)

  explicit rect_bilinear_solid_angle_sampler(const rect& r) : bilinear_prewarp(rect_solid_angle_sampler(r)), shape(r) {}

  // The corner weights for the receiver (o, n); false where the whole light
  // is at or below the horizon (or n is not a direction).
  bool weights(const vec3& o, const vec3& n, bilinear_rect_detail::corner_weights& w) const {
    const dvec3 nd(n), d = dvec3(shape.corner) - dvec3(o), e1(shape.e1), e2(shape.e2);
    const dvec3 p[4] = {d, d + e1, d + e2, d + e1 + e2};  // pbrt-v4's p00, p10, p01, p11
    const double nl = glm::length(nd);
    bool above = false;
    for (int i = 0; i < 4; ++i) {
      const double c = glm::dot(nd, p[i]);
      above = above || c > 0.0;
      w[i] = std::max(weight_floor, c / (nl * glm::length(p[i])));
    }
    return above && nl > 0.0 && std::isfinite(nl);
  }

  // The spherical rectangle's unit-square point of dir (its exact map).
  bool map_inverse(const vec3& o, const vec3& dir, dvec2& up) const {
    const spherical_rectangle sr(shape, o);
    double t;
    if (!sr.intersect(dvec3(dir), t)) return false;
    up = sr.invert_offset(t * dvec3(dir));
    return true;
  }
};

}  // namespace mcrt
