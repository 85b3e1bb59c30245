#pragma once
// Cosine-aware sampling of ellipse and disk lights by a bilinear pre-warp
// of the spherical ellipse's parallel map: the product-sampling idea of
// Hart, Pharr, Mueller, Lopes, McGuire and Shirley 2020, "Practical Product
// Sampling by Fitting and Composing Warps" (EGSR 2020, sec. 4.1: a bilinear
// fit of cos theta over the unit square of an area-preserving map, composed
// with it), which pbrt-v4 applies to spherical triangles and rectangles,
// transposed here to the spherical ellipse of Guillen et al. 2017
// (sampling/spherical_ellipse.hpp).
//
// The warp. u in [0,1]^2 is first warped by the bilinear density
//   f(x, y) = 4 [(1-x)(1-y) w00 + x(1-y) w10 + (1-x) y w01 + x y w11] / (w00 + w10 + w01 + w11)
// (corner weights w_ij > 0, i for the first coordinate), then carried onto
// the spherical ellipse by the exact parallel map, whose density is 1 / Omega
// per unit solid angle. The composition has the density
//   p(omega) = f(M^-1(omega)) / Omega   per unit SOLID ANGLE
// above the receiver's horizon (0 below it, see "The horizon"), exact
// whatever the weights (only the variance depends on them), and is
// inverted by the parallel map's inverse followed by the bilinear inverse.
//
// The bilinear warp itself (square_to_bilinear / _pdf / bilinear_to_square)
// is the marginal-conditional factorization of f: the first coordinate from
// the marginal density, linear between (w00 + w01) and (w10 + w11); the
// second from the conditional density, linear between lerp(x, w00, w10) and
// lerp(x, w01, w11). A linear density on [0, 1] with end values a, b has
// CDF P(x) = x (a (2 - x) + b x) / (a + b); its inverse is the root of a
// quadratic, written in the rationalized form
//   x = u (a + b) / (a + sqrt((1 - u) a^2 + u b^2)),
// which does not cancel for a ~ b (where the quadratic's leading
// coefficient b - a vanishes).
//
// Which four weights. In the parallel map the first coordinate picks the
// slice across the minor axis (u1 = 0 and 1 are the two ends of the minor
// axis, where the slice shrinks to a point) and the second the position
// along it. So the unit square's four corners land on only two directions
// (the minor axis's ends, whatever u2): the cosines "at the corners" would
// give a warp that ignores the major axis altogether. Instead the weights are
// the least-squares bilinear fit of cos theta over the unit square,
// approximated by its interpolant at the 2 x 2 Gauss-Legendre points
// u = 1/2 +- 1/(2 sqrt 3) (the L2 projection onto bilinears computed with that
// rule), extrapolated to the corners. The directions of the Gauss points are
// taken from the parallel map of the planar ellipse (the small-cone limit,
// the Newton solver's own initial guess): the slice at psi_g with
// 2 psi_g + sin 2 psi_g = pi / sqrt 3, tangent-plane point (x_g, y_g) =
// (a c_g / sqrt 3 sqrt(k / (k + (2/3) a^2 c_g^2)), b sin psi_g), k = 1 + b^2 sin^2 psi_g,
// mirrored into the four quadrants. They cost no solve; for wide cones they
// are approximate, which costs variance, not exactness. With cos theta =
// (nu_x x + nu_y y + nu_z) / sqrt(1 + x^2 + y^2) at those four points (nu the
// receiver's normal in the cone frame: all four share one denominator) the
// interpolant is linear, and its value at the corners is
//   w_ij = nu_z + sqrt(3) (2j - 1) nu_x x_g + sqrt(3) (2i - 1) nu_y y_g
// (times the common 1 / sqrt(1 + x_g^2 + y_g^2), dropped: the warp is
// scale-free).
//
// Clamp. Each weight is raised to at least bilinear_weight_floor (5 %) of the
// largest. A fitted corner weight can be <= 0 where that corner of the light
// is below the receiver's horizon, or just where the linear fit undershoots;
// a weight of 0 would give that corner zero density while the light there may
// still be above the horizon (the fit is approximate), which would bias the
// estimate. The floor keeps the density positive everywhere, which bounds
// cos theta / pdf by about Omega / (5 %) of the mean weight; it is relative
// (pbrt-v4 clamps the cosines at an absolute 0.01) so that a light low over
// the horizon, all of whose cosines are small, keeps its fitted shape. If no
// weight is positive the warp is the identity (all weights 1).
//
// The horizon. The spherical ellipse covers the whole light, also the part
// below the receiver's horizon. A sampled direction with n . omega <= 0 (the
// float direction, tested in double) returns no sample, and pdf() is 0
// there: the sampler is then a sub-probability density on the visible part
// (its mass is the bilinear-weighted fraction of the solid angle above the
// horizon), which keeps every estimate unbiased (a missing sample
// contributes 0, as the integrand would), as bilinear_spherical_rectangle.hpp
// does. A light wholly below the horizon of n gets no sample and pdf 0
// without any set-up: the largest n . (x - o) over the ellipse,
// n . (c - o) + sqrt((n . a1)^2 + (n . a2)^2) (in double), is <= 0.
//
// Fallbacks are the solid-angle sampler's (make_ellipse_cone): where the
// spherical map is unreliable the light is sampled by area with the exact
// area pdf (no warp), for sample, pdf and invert alike; the decision depends
// on (light, observer) only, the horizon test on (light, observer, normal).
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "mcrt/core/math.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

// --- the bilinear warp on [0,1]^2 (Hart et al. 2020, sec. 4.1).

// Corner weights w[i][j] of the bilinear density at (x, y) = (i, j), all > 0.
using bilinear_weights = std::array<std::array<double, 2>, 2>;

// u -> (x, y): x from the marginal, y from the conditional.
inline dvec2 square_to_bilinear(dvec2 u, const bilinear_weights& w) {
  const double x = square_to_linear(u.x, w[0][0] + w[0][1], w[1][0] + w[1][1]);
  const double y = square_to_linear(u.y, (1.0 - x) * w[0][0] + x * w[1][0], (1.0 - x) * w[0][1] + x * w[1][1]);
  return {x, y};
}
// Density per unit AREA of the square at p.
inline double square_to_bilinear_pdf(dvec2 p, const bilinear_weights& w) {
  const double sum = w[0][0] + w[0][1] + w[1][0] + w[1][1];
  const double f = (1.0 - p.x) * ((1.0 - p.y) * w[0][0] + p.y * w[0][1]) + p.x * ((1.0 - p.y) * w[1][0] + p.y * w[1][1]);
  return 4.0 * f / sum;
}
// (x, y) -> u.
inline dvec2 bilinear_to_square(dvec2 p, const bilinear_weights& w) {
  return {linear_to_square(p.x, w[0][0] + w[0][1], w[1][0] + w[1][1]),
          linear_to_square(p.y, (1.0 - p.x) * w[0][0] + p.x * w[1][0], (1.0 - p.x) * w[0][1] + p.x * w[1][1])};
}

// Each weight is at least this fraction of the largest (see the header).
inline constexpr double bilinear_weight_floor = 0.05;

// The corner weights for a cone and the receiver's unit normal nu in the
// cone frame (see the header comment): the least-squares bilinear fit of
// cos theta through the planar parallel map's Gauss points, clamped.
inline bilinear_weights spherical_ellipse_cosine_weights(const spherical_ellipse& se, const dvec3& nu) {
  // psi_g: 2 psi + sin 2 psi = pi / sqrt(3) (the planar parallel map at
  // u1 = 1/2 + 1/(2 sqrt 3)); its sine and cosine to 17 digits.
  constexpr double sg = 0.47156173930914613, cg = 0.88183304883619150;
  constexpr double sqrt3 = 1.7320508075688772;
  const double k = 1.0 + sqr(se.b * sg), ac = se.a * cg;
  // x = w a c sqrt(k / (k + (1 - w^2) a^2 c^2)) at w = 1/sqrt(3) (spherical_ellipse.hpp).
  const double xg = ac / sqrt3 * std::sqrt(k / (k + (2.0 / 3.0) * ac * ac)), yg = se.b * sg;
  const double gx = sqrt3 * nu.x * xg, gy = sqrt3 * nu.y * yg;
  bilinear_weights w;
  double wmax = 0.0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      w[i][j] = nu.z + (2 * j - 1) * gx + (2 * i - 1) * gy;
      wmax = std::max(wmax, w[i][j]);
    }
  if (!(wmax > 0.0) || !std::isfinite(wmax)) return {{{1.0, 1.0}, {1.0, 1.0}}};
  for (auto& row : w)
    for (double& x : row) x = std::max(x, bilinear_weight_floor * wmax);
  return w;
}

// The receiver's unit normal in the cone frame (normalized in double).
inline dvec3 ellipse_cone_normal(const ellipse_cone& cone, const vec3& n) {
  const dvec3 v = cone.to_cone(dvec3(n));
  return v / glm::length(v);
}

// Whether the ellipse lies wholly on or below the plane through o with
// normal n (its largest n . (x - o) is <= 0), in double.
inline bool ellipse_below_horizon(const ellipse_frame& f, const vec3& o, const vec3& n) {
  const dvec3 nd(n);
  const double top = glm::dot(nd, f.center - dvec3(o)) + std::hypot(glm::dot(nd, f.a1), glm::dot(nd, f.a2));
  return !(top > 0.0);
}

// Light-sampling strategy: the bilinear cosine pre-warp over the parallel
// map of the spherical ellipse (one-sided; area sampling with its exact pdf
// where make_ellipse_cone() says so; nothing where the light is behind o or
// wholly below the horizon of n).
struct ellipse_bilinear_solid_angle_sampler {
  using solver = newton_carlson_solver;
  ellipse shape;  // fixed after construction (frame_ is derived from it)

  explicit ellipse_bilinear_solid_angle_sampler(const ellipse& e) : shape(e), frame_(e) {}

  bool faces(const vec3& o) const { return shape.faces(o); }

  // The point on the light (ellipse coordinates: centre + x a1 + y a2)
  // that sample() maps u to, with its density per unit solid angle, in
  // double; false where sample() returns false (the horizon tested in
  // double here, on the float direction there: they differ only within a
  // float rounding of the horizon). For tests.
  bool sample_point(const vec3& o, const vec3& n, vec2 u, dvec2& xe, double& pdf) const {
    if (!shape.faces(o) || ellipse_below_horizon(frame_, o, n)) return false;
    const ellipse_cone cone = make_ellipse_cone<solver>(shape, frame_, o);
    if (cone.mode == ellipse_cone_mode::none) return false;
    if (cone.mode == ellipse_cone_mode::area) {
      // The fallback's own map and density (ellipse_area.hpp), in double.
      const vec3 p = square_to_ellipse(u, shape);
      const dvec3 q = dvec3(p) - frame_.center;
      xe = {glm::dot(q, dvec3(shape.a1_dual)), glm::dot(q, dvec3(shape.a2_dual))};
      const dvec3 v = dvec3(p) - dvec3(o);
      const double d2 = glm::dot(v, v), h = glm::dot(dvec3(o) - frame_.center, frame_.n);
      pdf = d2 * std::sqrt(d2) / (h * static_cast<double>(shape.area));
      return glm::dot(v, dvec3(n)) > 0.0;  // below the horizon: no sample
    }
    const bilinear_weights w = spherical_ellipse_cosine_weights(cone.se, ellipse_cone_normal(cone, n));
    const dvec2 uw = square_to_bilinear(dvec2(u), w);
    xe = cone.ellipse_coords(square_to_spherical_ellipse<solver>(uw, cone.se, cone.omega));
    pdf = square_to_bilinear_pdf(uw, w) * square_to_spherical_ellipse_pdf(cone.omega);
    const dvec3 v = frame_.center - dvec3(o) + xe.x * frame_.a1 + xe.y * frame_.a2;
    return glm::dot(v, dvec3(n)) > 0.0;  // below the horizon: no sample
  }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    if (!shape.faces(o) || ellipse_below_horizon(frame_, o, n)) return false;
    const ellipse_cone cone = make_ellipse_cone<solver>(shape, frame_, o);
    if (cone.mode == ellipse_cone_mode::none) return false;
    if (cone.mode == ellipse_cone_mode::area) {
      light_sample t;
      if (!ellipse_area_sampler{shape}.sample(o, u, t)) return false;
      if (!(glm::dot(dvec3(t.dir), dvec3(n)) > 0.0)) return false;  // below the horizon
      s = t;
      return true;
    }
    const bilinear_weights w = spherical_ellipse_cosine_weights(cone.se, ellipse_cone_normal(cone, n));
    const dvec2 uw = square_to_bilinear(dvec2(u), w);
    dvec2 xe = cone.ellipse_coords(square_to_spherical_ellipse<solver>(uw, cone.se, cone.omega));
    const double pdf = square_to_bilinear_pdf(uw, w) * square_to_spherical_ellipse_pdf(cone.omega);
    // The map lands inside the ellipse; rounding may leave it ~1e-12 out.
    const double r2 = glm::dot(xe, xe);
    if (r2 > 1.0) xe /= std::sqrt(r2);
    const dvec3 v = frame_.center - dvec3(o) + xe.x * frame_.a1 + xe.y * frame_.a2;
    const double len = glm::length(v);
    s.dir = vec3(v / len);
    s.dist = static_cast<float>(len);
    s.pdf = static_cast<float>(pdf);
    if (!(glm::dot(dvec3(s.dir), dvec3(n)) > 0.0)) return false;  // below the horizon
    return std::isfinite(s.pdf) && s.pdf > 0.0f && all_finite(s.dir);
  }

  // Density per unit SOLID ANGLE at o (normal n) of the unit direction dir:
  // the bilinear density at the parallel map's inverse of dir over Omega;
  // 0 below the horizon, behind the light, or where the ray misses.
  // The ray test comes first, as in the solid-angle samplers.
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const {
    float t;
    if (!shape.faces(o) || !shape.intersect({o, dir}, 0.0f, infinity, t)) return 0.0f;
    if (!(glm::dot(dvec3(dir), dvec3(n)) > 0.0)) return 0.0f;  // below the horizon: no sample there
    if (ellipse_below_horizon(frame_, o, n)) return 0.0f;
    const ellipse_cone cone = make_ellipse_cone<solver>(shape, frame_, o);
    if (cone.mode == ellipse_cone_mode::none) return 0.0f;
    if (cone.mode == ellipse_cone_mode::area) return ellipse_area_sampler{shape}.pdf(o, dir);
    const dvec3 p = cone.to_cone(dvec3(dir));
    if (!(p.z > 0.0)) return 0.0f;
    const bilinear_weights w = spherical_ellipse_cosine_weights(cone.se, ellipse_cone_normal(cone, n));
    const dvec2 uw = spherical_ellipse_to_square<solver>({p.x / p.z, p.y / p.z}, cone.se, cone.omega);
    return static_cast<float>(square_to_bilinear_pdf(uw, w) * square_to_spherical_ellipse_pdf(cone.omega));
  }

  // The u that sample() maps to dir (dir must hit the ellipse); false where
  // sample() has no sample for (o, n).
  bool invert(const vec3& o, const vec3& n, const vec3& dir, vec2& u) const {
    if (!shape.faces(o) || ellipse_below_horizon(frame_, o, n)) return false;
    const ellipse_cone cone = make_ellipse_cone<solver>(shape, frame_, o);
    if (cone.mode == ellipse_cone_mode::none) return false;
    if (cone.mode == ellipse_cone_mode::area) {
      float t;
      if (!shape.intersect({o, dir}, 0.0f, infinity, t)) return false;
      u = ellipse_to_square(o + t * dir, shape);
      return true;
    }
    const dvec3 p = cone.to_cone(dvec3(dir));
    if (!(p.z > 0.0)) return false;
    const bilinear_weights w = spherical_ellipse_cosine_weights(cone.se, ellipse_cone_normal(cone, n));
    u = vec2(bilinear_to_square(spherical_ellipse_to_square<solver>({p.x / p.z, p.y / p.z}, cone.se, cone.omega), w));
    return true;
  }

  const ellipse_frame& frame() const { return frame_; }

 private:
  ellipse_frame frame_;
};

}  // namespace mcrt
