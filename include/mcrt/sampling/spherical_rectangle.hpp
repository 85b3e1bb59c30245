#pragma once
// Sampling a rectangle uniformly in the solid angle it subtends: the
// area-preserving map from the unit square to the spherical rectangle of
// Urena, Fajardo and King 2013, "An Area-Preserving Parametrization for
// Spherical Rectangles" (EGSR 2013), below [UFK13]. Sample, pdf and inverse
// in the Mitsuba warp.h / pbrt-v4 sampling.h layout, and the light-sampling
// strategy rect_solid_angle_sampler with the interface of light_sample.hpp.
//
// Local frame (UFK13 sec. 3, "R"): the observer o is the origin, x along e1,
// y along the part of e2 orthogonal to e1, z the rectangle's FRONT normal, so
// the rectangle is [x0, x1] x [y0, y1] in the plane z = -h, h > 0 being the
// observer's height above it. The frame is left-handed when the light is
// flipped; every formula below is invariant under that mirror (angles and
// triple products enter through their magnitudes only). The rectangle
// sampled is the one spanned by e1 and the part of e2 orthogonal to e1:
// float edges are orthogonal only up to rounding, and the two shapes differ
// by less than the float resolution of the corners.
//
// Numerics. The set-up and the map run in double: inputs are float, so every
// coordinate difference is exact in double, and the map needs the extra bits
// (see the threshold below). Where the paper, and code following it, lose
// precision, this header uses equivalent closed forms:
//  * the solid angle S is NOT sum(gamma_i) - 2 pi (UFK13 sec. 3), which
//    cancels catastrophically for small S, but the Van Oosterom-Strackee
//    formula (IEEE Trans. Biomed. Eng. 30(2), 1983) tan(Omega/2) =
//    |a.(b x c)| / (abc + (a.b)c + (a.c)b + (b.c)a) for the two triangles of
//    the rectangle, whose two half-angles are added as one complex argument:
//    a single atan2, no cancellation (the triple product is h * w * l exactly);
//  * the constant k = 2 pi - gamma_2 - gamma_3 (UFK13 sec. 3) is never formed:
//    cos(au) and sin(au) of au = u S + k (sec. 4, first stage) come from the
//    addition theorem with cos k, sin k in closed form, so u S is not rounded
//    against k ~ pi;
//  * x_u (sec. 4: f_u, c_u, x_u) is h sign(N) D / sqrt(N^2 - c0^2 D^2), with
//    N = cos(au) b0 - b1, D = sin(au), c0^2 = 1 - b0^2 = h^2 / (y0^2 + h^2):
//    the same quantity as -c_u z0 / sqrt(1 - c_u^2) without 1 - c_u^2, and
//    without the division by sin(au), which vanishes where x_u = 0;
//  * h_1 - h_0 and 1 -+ h_v (sec. 4, second stage) are formed without
//    subtracting nearly equal numbers (sine_difference, one_minus_sine).
//
// Two implementations. spherical_rectangle is exact for every observer in
// front (down to grazing views at 1e-7 of the light's size, 1e-10 sr, aspect
// 1e4) at the price of a per-observer set-up with the rectangle cut at the
// observer's foot, libm's atan2 / sin / cos and Newton polishing.
// rect_solid_angle_sampler, the strategy the renderer uses, serves the
// common configurations by a lean version of the same map (its "fast path":
// no cut, no libm call, square roots packed four at a time, equally exact
// there) and hands the rest to spherical_rectangle; its comment lists the
// thresholds.
#include <array>
#include <cfloat>
#include <numbers>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

namespace spherical_rectangle_detail {

// y1 / r1 - y0 / r0 with r_j = sqrt(d2 + y_j^2), y0 <= y1: the difference of
// two sines of elevation. When y0, y1 have the same sign it is rewritten as
// d2 (y1 - y0)(y1 + y0) / (r0 r1 (y1 r0 + y0 r1)), which has no cancellation
// (the direct form loses all digits for a thin strip far from the observer).
inline double sine_difference(double y0, double r0, double y1, double r1, double d2) {
  if (y0 >= 0.0 || y1 <= 0.0)
    return d2 * (y1 - y0) * (y1 + y0) / (r0 * r1 * (y1 * r0 + y0 * r1));
  return y1 / r1 - y0 / r0;  // opposite signs: a sum of magnitudes
}
// 1 - y / r and 1 + y / r with r = sqrt(d2 + y^2): whichever side is close to
// 0 is computed as d2 / (r (r + |y|)).
inline double one_minus_sine(double y, double r, double d2) {
  return y > 0.0 ? d2 / (r * (r + y)) : (r - y) / r;
}
inline double one_plus_sine(double y, double r, double d2) {
  return y < 0.0 ? d2 / (r * (r - y)) : (r + y) / r;
}

}  // namespace spherical_rectangle_detail

namespace spherical_rectangle_detail {

// Multiplies (re, im) by the two Van Oosterom-Strackee factors
// (den_i + i num) / (r_a r_b r_c) of the triangles (v00, v10, v11) and
// (v00, v11, v01) of the rectangle [x0, x1] x [y0, y1] in the plane z = -h.
// For both triangles the triple product is num = h (x1 - x0)(y1 - y0)
// exactly, and den / (r_a r_b r_c) = 1 + cos ab + cos ac + cos bc. The
// caller only passes rectangles whose vertices lie in one closed quadrant
// around the foot of the observer, so every cosine is >= 0 and nothing
// cancels (for a long rectangle seen from near its middle two vertices are
// almost antipodal and 1 + cos ab + ... loses all its digits otherwise).
inline void multiply_vos_factors(double x0, double x1, double y0, double y1, double h, double& re,
                                 double& im) {
  const double h2 = h * h;
  const double r00 = std::sqrt(x0 * x0 + y0 * y0 + h2), r10 = std::sqrt(x1 * x1 + y0 * y0 + h2);
  const double r11 = std::sqrt(x1 * x1 + y1 * y1 + h2), r01 = std::sqrt(x0 * x0 + y1 * y1 + h2);
  // Dot products of the vertex vectors (x_i, y_j, -h).
  const double d00_10 = x0 * x1 + y0 * y0 + h2, d00_11 = x0 * x1 + y0 * y1 + h2;
  const double d10_11 = x1 * x1 + y0 * y1 + h2, d00_01 = x0 * x0 + y0 * y1 + h2;
  const double d11_01 = x0 * x1 + y1 * y1 + h2;
  const double num = h * (x1 - x0) * (y1 - y0);
  const double f1 = 1.0 / (r00 * r10 * r11), f2 = 1.0 / (r00 * r11 * r01);
  const double re1 = (r00 * r10 * r11 + d00_10 * r11 + d00_11 * r10 + d10_11 * r00) * f1;
  const double re2 = (r00 * r11 * r01 + d00_11 * r01 + d00_01 * r11 + d11_01 * r00) * f2;
  const double im1 = num * f1, im2 = num * f2;
  const double re12 = re1 * re2 - im1 * im2, im12 = re1 * im2 + im1 * re2;
  const double r = re * re12 - im * im12;
  im = re * im12 + im * re12;
  re = r;
}

// The rectangle's orthonormal frame in double: x along e1, y along the part
// of e2 orthogonal to e1, z the front normal (e1 x e2 oriented by r.n); w and
// l the side lengths. One function for both sampling paths, so that the
// height and the facing decision are the same on both.
struct rect_frame {
  dvec3 ex, ey, ez;
  double w, l;
};

inline rect_frame make_rect_frame(const rect& r) {
  rect_frame f;
  const dvec3 e1 = r.e1, e2 = r.e2;
  f.w = glm::length(e1);
  f.ex = e1 / f.w;
  const dvec3 e2o = e2 - glm::dot(e2, f.ex) * f.ex;
  f.l = glm::length(e2o);
  f.ey = e2o / f.l;
  f.ez = glm::cross(f.ex, f.ey);
  if (glm::dot(f.ez, dvec3(r.n)) < 0.0) f.ez = -f.ez;
  return f;
}

}  // namespace spherical_rectangle_detail

// Solid angle of the rectangle [x0, x1] x [y0, y1] in the plane z = -h, h > 0,
// seen from the origin (x0 <= x1, y0 <= y1): Van Oosterom-Strackee (see the
// header comment) on the up to four pieces cut by the lines x = 0 and y = 0
// through the foot of the observer. Each triangle contributes its half solid
// angle as the argument of one complex factor; the product's argument is
// S / 2, in [0, pi), so its imaginary part is >= 0 and one atan2 returns the
// right branch. Relative error a few ulp for every S in (0, 2 pi): the
// imaginary parts are sums of non-negative terms except when S / 2 > pi / 2,
// where the absolute error of the angle is what matters.
inline double solid_angle_local_rect(double x0, double x1, double y0, double y1, double h) {
  using spherical_rectangle_detail::multiply_vos_factors;
  double re = 1.0, im = 0.0;
  const bool split_x = x0 < 0.0 && x1 > 0.0, split_y = y0 < 0.0 && y1 > 0.0;
  const double xs[3] = {x0, split_x ? 0.0 : x1, x1}, ys[3] = {y0, split_y ? 0.0 : y1, y1};
  for (int i = 0; i < (split_x ? 2 : 1); ++i)
    for (int j = 0; j < (split_y ? 2 : 1); ++j) multiply_vos_factors(xs[i], xs[i + 1], ys[j], ys[j + 1], h, re, im);
  return 2.0 * std::atan2(im, re);
}

// Per-observer set-up of the spherical rectangle of `r` seen from `o`, and
// the map between it and the unit square.
class spherical_rectangle {
 public:
  // Accuracy of the closed-form map. It recovers angles of the spherical
  // rectangle from cosines and sines (b0, b1, cos(au), sin(au)) that carry
  // absolute rounding errors of a few eps = 2^-52; an angle near 0 or pi
  // recovered that way is off by ~eps / sin, and the smallest such sine is,
  // up to a constant, the sine of the lowest elevation of a vertex above the
  // light's plane, sin_e = h / r_max. The sub-area u S of the first stage is
  // then realised with an absolute error ~eps / sin_e, a relative error
  // ~eps / (S sin_e) of the first sample coordinate (measured over the test
  // battery: within a factor 10 of this). Where that prediction exceeds
  // refine_tolerance = 1e-9 (distant lights, S < ~2e-7 sr, and grazing
  // views of small ones), x_u is refined by safeguarded Newton steps on the
  // cancellation-free sub-rectangle solid angle (solid_angle_local_rect),
  // which is exact to a few ulp whatever S and sin_e: the map then stays
  // exact down to min_map_solid_angle. Elsewhere the closed form alone is
  // already accurate to 1e-9, far below anything a chi-square test or an
  // image can resolve, and the refinement (one atan2 per step) is skipped.
  static constexpr double refine_tolerance = 1e-9;
  // Below this solid angle the map is replaced by uniform area sampling with
  // its exact pdf d^2 / (|cos| A) for sampling and evaluation alike. Why:
  // the map would need the Newton refinement for every sample there, while
  // a rectangle subtending < 1e-10 sr spans < 2 sqrt(S / pi) ~ 1.1e-5 rad,
  // over which the area density is constant to ~1e-5 relative unless the
  // view is grazing, so area sampling costs nothing in variance. Both
  // decisions depend on (rectangle, observer) only, so sample() and pdf()
  // always take the same branch.
  static constexpr double min_map_solid_angle = 1e-10;

  spherical_rectangle(const rect& r, const vec3& o) : o_(o), e1_(r.e1), e2_(r.e2) {
    // Orthonormal frame in double (see the header comment); z is the front
    // normal, taken from e1 x e2 in double and oriented by r.n.
    const spherical_rectangle_detail::rect_frame f = spherical_rectangle_detail::make_rect_frame(r);
    ex_ = f.ex, ey_ = f.ey, ez_ = f.ez, w_ = f.w, l_ = f.l;
    area_ = w_ * l_;

    const dvec3 d = dvec3(r.corner) - dvec3(o);  // exact: a difference of floats in double
    h_ = -glm::dot(d, ez_);
    x0_ = glm::dot(d, ex_);
    y0_ = glm::dot(d, ey_);
    x1_ = x0_ + w_;
    y1_ = y0_ + l_;
    // One-sided light: o strictly in front. !(h > 0) also rejects NaN and a
    // degenerate (zero-area) rectangle, whose frame is NaN.
    if (!(h_ > 0.0) || !(area_ > 0.0)) return;
    S_ = solid_angle_local_rect(x0_, x1_, y0_, y1_, h_);
    if (!(S_ > 0.0)) return;
    valid_ = true;
    const double r_max = std::sqrt(std::max(x0_ * x0_, x1_ * x1_) + std::max(y0_ * y0_, y1_ * y1_) + h_ * h_);
    use_map_ = S_ >= min_map_solid_angle;
    refine_ = S_ * h_ < (DBL_EPSILON / refine_tolerance) * r_max;  // eps / (S sin_e) > tolerance
  }

  // Whether o sees the front of the rectangle (no sample and pdf 0 if not).
  bool valid() const { return valid_; }
  // true: spherical map, density 1/S; false: area fallback (see above).
  bool uses_map() const { return use_map_; }
  // Whether the map's first stage is polished by Newton steps (see above).
  bool refines() const { return use_map_ && refine_; }
  // Solid angle subtended at o, in sr (0 when !valid()).
  double solid_angle() const { return S_; }
  double height() const { return h_; }

  // u in [0,1)^2 -> point on the rectangle minus o, in double (so that
  // direction and distance keep all their bits for grazing views).
  dvec3 sample_offset(vec2 u) const {
    if (!use_map_) return to_offset({x0_ + double(u.x) * w_, y0_ + double(u.y) * l_});
    return to_offset(sample_local(u));
  }
  // u in [0,1)^2 -> point on the rectangle.
  vec3 sample(vec2 u) const { return vec3(dvec3(o_) + sample_offset(u)); }

  // Density per unit SOLID ANGLE at o of the direction towards the point
  // o + v of the rectangle: 1 / S on the map, |v|^3 / (h A) on the area
  // fallback (p_A = 1/A times d^2 / |cos|, |cos| = h / d).
  double pdf_offset(const dvec3& v) const {
    if (!valid_) return 0.0;
    if (use_map_) return 1.0 / S_;
    const double d = glm::length(v);
    return d * d * d / (h_ * area_);
  }
  // The same for a point p of the rectangle, as a float (+inf never: FLT_MAX
  // at most, see rect_solid_angle_sampler).
  float pdf(const vec3& p) const {
    return float(std::min(pdf_offset(dvec3(p) - dvec3(o_)), double(FLT_MAX)));
  }

  // Point o + v of the rectangle -> unit square; the inverse of sample().
  dvec2 invert_offset(const dvec3& v) const {
    const double xu = std::clamp(glm::dot(v, ex_), x0_, x1_);
    const double yv = std::clamp(glm::dot(v, ey_), y0_, y1_);
    if (!use_map_) return {(xu - x0_) / w_, (yv - y0_) / l_};
    using namespace spherical_rectangle_detail;
    // First coordinate: the solid angle of [x0, xu] x [y0, y1] over S
    // (UFK13 sec. 4, the definition of the first stage), cancellation-free.
    const double u0 = solid_angle_local_rect(x0_, xu, y0_, y1_, h_) / S_;
    // Second coordinate: (h_v - h_0) / (h_1 - h_0) (UFK13 sec. 4, second stage).
    const double d2 = xu * xu + h_ * h_;
    const double r0 = std::sqrt(d2 + y0_ * y0_), r1 = std::sqrt(d2 + y1_ * y1_);
    const double rv = std::sqrt(d2 + yv * yv);
    const double u1 = sine_difference(y0_, r0, yv, rv, d2) / sine_difference(y0_, r0, y1_, r1, d2);
    return {std::clamp(u0, 0.0, 1.0), std::clamp(u1, 0.0, 1.0)};
  }
  vec2 invert(const vec3& p) const { return vec2(invert_offset(dvec3(p) - dvec3(o_))); }

  // Ray o + t dir (dir unit) against the rectangle, in double in the local
  // frame; t is the distance to the hit. Edges count as inside.
  bool intersect(const dvec3& dd, double& t) const {
    if (!valid_) return false;
    const double dz = glm::dot(dd, ez_);
    if (!(dz < 0.0)) return false;  // parallel to the plane or going away from it
    t = h_ / -dz;
    const double x = t * glm::dot(dd, ex_), y = t * glm::dot(dd, ey_);
    return x >= x0_ && x <= x1_ && y >= y0_ && y <= y1_;
  }

 private:
  // The point (x, y, -h) of the local frame as an offset from o. Built from
  // the local coordinates, not as corner + s e1 + t e2: near the foot of a
  // grazing observer x and y are small and keep their relative precision,
  // where corner + s e1 would round them to the ulp of the corner's offset.
  dvec3 to_offset(const dvec2& xy) const { return xy.x * ex_ + xy.y * ey_ - h_ * ez_; }

  // UFK13 sec. 4 in the local frame: (xu, yv) of the sample.
  dvec2 sample_local(vec2 u) const {
    using namespace spherical_rectangle_detail;
    const double h = h_, h2 = h * h, x0 = x0_, y0 = y0_, y1 = y1_;
    // Set-up constants of UFK13 sec. 3. b0, b1: z components of the normals of the
    // planes through o and the edges y = y0, y = y1.
    const double q0 = std::sqrt(y0 * y0 + h2), q1 = std::sqrt(y1 * y1 + h2);
    const double b0 = -y0 / q0, b1 = y1 / q1;
    const double c0sq = h2 / (y0 * y0 + h2);  // 1 - b0^2 without cancellation
    // cos and sin of gamma_2 + gamma_3, the internal angles at v01 and v00,
    // in closed form: cos gamma = -sx sy x y / sqrt((y^2+h^2)(x^2+h^2)),
    // sin gamma = h |v| / sqrt(...), sx, sy the directions of the two edges
    // leaving the vertex. sin(gamma_2 + gamma_3) contains y1/r01 - y0/r00.
    const double p0 = x0 * x0 + h2;
    const double r00 = std::sqrt(p0 + y0 * y0), r01 = std::sqrt(p0 + y1 * y1);
    const double inv = 1.0 / (p0 * q0 * q1);
    const double cos_g23 = -(x0 * x0 * y0 * y1 + h2 * r00 * r01) * inv;
    const double sin_g23 = h * x0 * r00 * r01 * sine_difference(y0, r00, y1, r01, p0) * inv;
    // k = 2 pi - gamma_2 - gamma_3; au = u0 S + k (UFK13 sec. 4) by the
    // addition theorem.
    const double cos_k = cos_g23, sin_k = -sin_g23;
    const double phi = double(u.x) * S_;
    const double cp = std::cos(phi), sp = std::sin(phi);
    const double cos_au = cp * cos_k - sp * sin_k;
    const double sin_au = sp * cos_k + cp * sin_k;
    // UFK13 sec. 4: f_u = N / D, c_u = sign(f_u) / sqrt(f_u^2 + b0^2),
    // x_u = -c_u z0 / sqrt(1 - c_u^2) = h sign(N) D / sqrt(N^2 - c0^2 D^2).
    const double N = cos_au * b0 - b1;
    const double den2 = N * N - c0sq * sin_au * sin_au;
    // den2 is mathematically (h D / x_u)^2 > 0; where rounding takes it to 0
    // x_u is beyond the rectangle, which the clamp expresses.
    const double xu_raw = den2 > 0.0 ? h * std::copysign(1.0, N) * sin_au / std::sqrt(den2)
                                     : std::copysign(double(infinity), N * sin_au);
    const double xu = refine_ ? refine_x(phi, std::clamp(xu_raw, x0, x1_)) : std::clamp(xu_raw, x0, x1_);
    // UFK13 sec. 4, second stage: along the segment x = x_u, h_v = sin(elevation) is
    // uniform between h_0 and h_1; y_v = h_v d / sqrt(1 - h_v^2), with
    // 1 - h_v^2 = (1 - h_v)(1 + h_v) from cancellation-free parts.
    const double d2 = xu * xu + h2;
    const double r0 = std::sqrt(d2 + y0 * y0), r1 = std::sqrt(d2 + y1 * y1);
    const double v = u.y;
    const double hv = y0 / r0 + v * sine_difference(y0, r0, y1, r1, d2);
    const double om = (1.0 - v) * one_minus_sine(y0, r0, d2) + v * one_minus_sine(y1, r1, d2);
    const double op = (1.0 - v) * one_plus_sine(y0, r0, d2) + v * one_plus_sine(y1, r1, d2);
    const double yv = std::clamp(hv * std::sqrt(d2 / (om * op)), y0, y1);
    return {xu, yv};
  }

  // Solves S_sub(x) = target for x in [x0, x1], S_sub(x) the solid angle of
  // [x0, x] x [y0, y1] (the first-stage CDF of UFK13 sec. 4 times S), from
  // the closed-form guess x: Newton with S_sub'(x) = h (h_1(x) - h_0(x)) /
  // (x^2 + h^2) (the marginal density of x), kept inside a bracket that
  // shrinks with the sign of the residual, bisection when a step leaves it.
  double refine_x(double target, double x) const {
    using spherical_rectangle_detail::sine_difference;
    double lo = x0_, hi = x1_;
    for (int i = 0; i < 24; ++i) {
      const double f = solid_angle_local_rect(x0_, x, y0_, y1_, h_) - target;
      if (std::abs(f) <= 1e-13 * S_) break;
      (f > 0.0 ? hi : lo) = x;
      const double d2 = x * x + h_ * h_;
      const double r0 = std::sqrt(d2 + y0_ * y0_), r1 = std::sqrt(d2 + y1_ * y1_);
      const double df = h_ * sine_difference(y0_, r0, y1_, r1, d2) / d2;
      double xn = x - f / df;
      if (std::abs(xn - x) <= 4.0 * DBL_EPSILON * std::abs(x)) return x;  // step below the resolution of x
      if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);  // also catches df = 0 and NaN
      x = xn;
    }
    return x;
  }

  vec3 o_, e1_, e2_;
  dvec3 ex_{}, ey_{}, ez_{};
  double w_ = 0.0, l_ = 0.0, area_ = 0.0;
  double h_ = 0.0, x0_ = 0.0, x1_ = 0.0, y0_ = 0.0, y1_ = 0.0, S_ = 0.0;
  bool valid_ = false, use_map_ = false, refine_ = false;
};

// Light-sampling strategy: uniform in solid angle (spherical rectangle),
// with the area fallback of spherical_rectangle. One-sided: an observer on
// the back of the light or in its plane gets no sample and pdf 0.
//
// Two paths, chosen from (rectangle, observer) alone, so sample() and pdf()
// always take the same one:
//  * the fast path: UFK13's algorithm (sec. 3 and 4) with the formulas of
//    spherical_rectangle::sample_local, in double in the local frame cached
//    at construction, with S from Van Oosterom-Strackee on the two triangles
//    of the rectangle (no cut at the foot of the observer: the predicate
//    below excludes the configurations where that cancels), no libm call
//    (atan2_upper for S, sincos_quadrant for the map), square roots packed
//    four at a time (sqrt4, inverse_sqrt4), and no division where a product
//    does. The sub-area u S enters the addition theorem through sin(u S) and
//    cos(u S) - 1, formed from sin and cos of u S / 4 so that both keep the
//    relative precision of u S (it is never rounded against k ~ pi).
//    Accuracy: S, and the pdf 1/S, to a few ulp of double (the polynomials
//    are accurate to 5e-15); the map's first coordinate to ~eps / (S sin_e)
//    relative (sin_e = h / r_max, see spherical_rectangle), the second to
//    ~eps / sin_e^2, so that directions agree with spherical_rectangle's to
//    the rounding of a float direction (tests);
//  * the exact path, spherical_rectangle (foot split, Newton polish, area
//    fallback), where those bounds could pass 1e-8 (fast_view):
//    grazing views, sin_e < fast_min_sine; small solid angles, S sin_e <
//    fast_min_solid_angle_sine (spherical_rectangle would polish the map by
//    Newton steps below 2.2e-7); a Van Oosterom-Strackee factor of modulus
//    < fast_min_vos_factor times the product of its three distances (seen
//    from near a long rectangle, its ends almost opposite, the factor
//    cancels); and corner distances^2 outside [1e-60, 1e60] (the factors
//    are of the order r^3, their product r^6). Every observer of the
//    samplers' benchmark (bench/observers.hpp: 0.2 to 5 sizes away, at least
//    3 degrees above the plane) takes the fast path.
struct rect_solid_angle_sampler {
  rect shape;  // fixed after construction (the frame below is derived from it)

  static constexpr double fast_min_sine = 1e-3;
  static constexpr double fast_min_solid_angle_sine = 1e-6;
  static constexpr double fast_min_vos_factor = 1e-3;

  explicit rect_solid_angle_sampler(const rect& r) : shape(r) {
    // The frame of spherical_rectangle, from the same function, so h and the
    // facing decision are the same on both paths.
    const spherical_rectangle_detail::rect_frame f = spherical_rectangle_detail::make_rect_frame(r);
    ex_ = f.ex, ey_ = f.ey, ez_ = f.ez, w_ = f.w, l_ = f.l;
  }

  bool faces(const vec3& o) const {
    const dvec3 n = glm::cross(dvec3(shape.e1), dvec3(shape.e2));
    return glm::dot(dvec3(o) - dvec3(shape.corner), n) * double(glm::dot(dvec3(n), dvec3(shape.n))) > 0.0;
  }

  // Whether o is served by the fast path (for tests and benchmarks).
  bool fast_path(const vec3& o) const { return fast_view(o).path == path_kind::fast; }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const view v = fast_view(o);
    if (v.path == path_kind::fast) return sample_fast(v, u, s);
    return v.path == path_kind::exact && sample_exact(o, u, s);
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir: 1/S on the
  // spherical map, t^3 / (h A) on the area fallback, 0 if the ray misses or
  // o does not face the light. The ray test comes first, so a direction
  // that misses (most directions a BSDF samples) costs no set-up.
  float pdf(const vec3& o, const vec3& dir) const {
    view v = local_view(o);
    if (!hits(v, dir)) return 0.0f;
    classify(v);
    if (v.path == path_kind::none) return 0.0f;
    if (v.path == path_kind::exact) return pdf_exact(o, dir);
    return float(1.0 / v.solid_angle);
  }

 private:
  enum class path_kind { none, fast, exact };
  // What sample() and pdf() share for one observer: the local coordinates of
  // spherical_rectangle (the rectangle is [x0, x1] x [y0, y1] in the plane
  // z = -h), the distances r00, r01 to the corners (x0, y0), (x0, y1) and S.
  struct view {
    path_kind path = path_kind::none;
    double x0 = 0.0, x1 = 0.0, y0 = 0.0, y1 = 0.0, h = 0.0, solid_angle = 0.0, r00 = 0.0, r01 = 0.0;
  };

  // The local coordinates of o (h, x0, x1, y0, y1 of view); path none.
  view local_view(const vec3& o) const {
    view v;
    const dvec3 d = dvec3(shape.corner) - dvec3(o);  // exact: a difference of floats in double
    v.h = -glm::dot(d, ez_);
    v.x0 = glm::dot(d, ex_);
    v.y0 = glm::dot(d, ey_);
    v.x1 = v.x0 + w_;
    v.y1 = v.y0 + l_;
    return v;
  }

  // The ray o + t dir against the rectangle, in double in the local frame
  // of v = local_view(o), with the arithmetic of spherical_rectangle::intersect
  // (same frame, same local coordinates), so both paths agree with it.
  // Edges count as inside.
  bool hits(const view& v, const vec3& dir) const {
    if (!(v.h > 0.0)) return false;  // behind or in the plane (also NaN)
    const dvec3 dd(dir);
    const double dz = glm::dot(dd, ez_);
    if (!(dz < 0.0)) return false;  // parallel to the plane or going away from it
    const double t = v.h / -dz;
    const double x = t * glm::dot(dd, ex_), y = t * glm::dot(dd, ey_);
    return x >= v.x0 && x <= v.x1 && y >= v.y0 && y <= v.y1;
  }

  view fast_view(const vec3& o) const {
    view v = local_view(o);
    classify(v);
    return v;
  }

  // The path for the local coordinates in v, and on the fast path S and the
  // corner distances.
  void classify(view& v) const {
    using namespace spherical_rectangle_detail;
    using namespace fast_math;
    // Behind or in the plane (also NaN): no sample, as spherical_rectangle.
    if (!(v.h > 0.0)) return;
    v.path = path_kind::exact;
    const double x0 = v.x0, x1 = v.x1, y0 = v.y0, y1 = v.y1, h2 = v.h * v.h;
    const double xx0 = x0 * x0, xx1 = x1 * x1, yy0 = y0 * y0, yy1 = y1 * y1;
    const double r00 = xx0 + yy0 + h2, r10 = xx1 + yy0 + h2, r11 = xx1 + yy1 + h2, r01 = xx0 + yy1 + h2;
    const double r_max2 = std::max(std::max(r00, r11), std::max(r10, r01));
    if (!(h2 >= fast_min_sine * fast_min_sine * r_max2) || !(r_max2 <= 1e60 && h2 >= 1e-60)) return;
    // Van Oosterom-Strackee on the triangles (v00, v10, v11) and (v00, v11,
    // v01): the factor of each is r_a r_b r_c + (a.b) r_c + (a.c) r_b +
    // (b.c) r_a + i h w l, and S / 2 is the argument of their product (see
    // solid_angle_local_rect).
    const std::array<double, 4> r = sqrt4(r00, r10, r11, r01);
    const double ac = x0 * x1 + y0 * y1 + h2;  // v00 . v11, the shared diagonal
    const double r0011 = r[0] * r[2];
    const double d1 = r0011 * r[1] + (x0 * x1 + yy0 + h2) * r[2] + ac * r[1] + (xx1 + y0 * y1 + h2) * r[0];
    const double d2 = r0011 * r[3] + ac * r[3] + (xx0 + y0 * y1 + h2) * r[2] + (x0 * x1 + yy1 + h2) * r[0];
    const double n = v.h * w_ * l_;
    v.solid_angle = 2.0 * atan2_upper(n * (d1 + d2), d1 * d2 - n * n);
    v.r00 = r[0];
    v.r01 = r[3];
    // The factors carry absolute errors of a few ulp of r_a r_b r_c (the
    // dot products); the half angles, of a few ulp times r_a r_b r_c /
    // |factor|, which fast_min_vos_factor bounds. Small S: see the class
    // comment.
    const double rrr1 = r0011 * r[1], rrr2 = r0011 * r[3];
    const double z2 = std::min((d1 * d1 + n * n) / (rrr1 * rrr1), (d2 * d2 + n * n) / (rrr2 * rrr2));
    const double s2 = v.solid_angle * v.solid_angle;
    if (z2 >= fast_min_vos_factor * fast_min_vos_factor &&
        s2 * h2 >= fast_min_solid_angle_sine * fast_min_solid_angle_sine * r_max2)
      v.path = path_kind::fast;
  }

  // UFK13 sec. 4 on the fast path, with the formulas (and notation) of
  // spherical_rectangle::sample_local.
  bool sample_fast(const view& v, vec2 u, light_sample& s) const {
    using namespace spherical_rectangle_detail;
    using namespace fast_math;
    const double h = v.h, h2 = h * h, x0 = v.x0, y0 = v.y0, y1 = v.y1;
    const double q0sq = y0 * y0 + h2, q1sq = y1 * y1 + h2, p0 = x0 * x0 + h2;
    const double xmax2 = std::max(x0 * x0, v.x1 * v.x1);
    const std::array<double, 4> iq = inverse_sqrt4(q0sq, q1sq, p0, xmax2);
    const double iq0 = iq[0], iq1 = iq[1], ip = iq[2], r00 = v.r00, r01 = v.r01;
    const double b0 = -y0 * iq0, b1 = y1 * iq1, c0sq = h2 * iq0 * iq0;
    // cos and sin of k = 2 pi - gamma_2 - gamma_3; inv = 1 / (p0 q0 q1).
    // Every term is bounded by 1 after the scaling by inv, so their absolute
    // errors are a few eps.
    const double inv = iq0 * iq1 * ip * ip;
    const double cos_k = -(x0 * x0 * y0 * y1 + h2 * r00 * r01) * inv;
    const double sin_k = -h * x0 * (y1 * r00 - y0 * r01) * inv;
    // au = u S + k by the addition theorem, from sin and cos of u S / 4:
    // sin(u S) = 4 s c (1 - 2 s^2), cos(u S) - 1 = -8 (s c)^2.
    double sq, cq;
    sincos_quadrant(double(u.x) * (0.25 * v.solid_angle), sq, cq);
    const double sc = sq * cq;
    const double sp = 4.0 * sc * (1.0 - 2.0 * sq * sq), cm = -8.0 * sc * sc;
    const double cos_au = cos_k + (cm * cos_k - sp * sin_k);
    const double sin_au = sin_k + (sp * cos_k + cm * sin_k);
    // x_u = h sign(N) D / sqrt(den2), den2 = N^2 - c0^2 D^2, D = sin(au).
    // den2 is kept >= h^2 D^2 / max(x0^2, x1^2), i.e. |x_u| within the
    // rectangle (it rounds below only where x_u is beyond it), and > 0.
    const double N = cos_au * b0 - b1, D2 = sin_au * sin_au;
    const double den2 = std::max({N * N - c0sq * D2, D2 * (h2 * iq[3] * iq[3]), DBL_MIN});
    // Second stage (UFK13 sec. 4): h_v = sin(elevation) uniform between h_0
    // and h_1 along x = x_u. With m = den2 + D^2, x_u^2 + h^2 = h^2 m / den2,
    // so h_j = y_j / sqrt(x_u^2 + h^2 + y_j^2) = y_j sqrt(den2) /
    // sqrt(h^2 m + y_j^2 den2), and the plane x = x_u is at the angle alpha
    // from the vertical, cos alpha = h / sqrt(x_u^2 + h^2) = sqrt(den2 / m),
    // sin alpha = x_u / sqrt(x_u^2 + h^2) = sign(N D) |D| / sqrt(m): one
    // packed square root and division for all of them, no other.
    const double m = den2 + D2;
    const std::array<double, 4> ir = inverse_sqrt4(h2 * m + y0 * y0 * den2, h2 * m + y1 * y1 * den2, m, den2);
    const double sqrt_den2 = den2 * ir[3];
    const double h0 = y0 * sqrt_den2 * ir[0], h1 = y1 * sqrt_den2 * ir[1];
    const double hv = h0 + double(u.y) * (h1 - h0);
    const double cos_alpha = sqrt_den2 * ir[2], sin_alpha = std::copysign(std::abs(sin_au) * ir[2], N * sin_au);
    // The unit direction is cos(elevation) (sin alpha, 0, -cos alpha) + h_v
    // ey. 1 - h_v^2 >= (h / r_max)^2 >= fast_min_sine^2: the product form
    // loses at most eps / fast_min_sine^2 ~ 2e-10.
    const double ce = std::sqrt((1.0 - hv) * (1.0 + hv));
    s.dir = vec3((ce * sin_alpha) * ex_ + hv * ey_ - (ce * cos_alpha) * ez_);
    s.dist = float(h / (ce * cos_alpha));
    s.pdf = float(1.0 / v.solid_angle);
    return true;
  }

  bool sample_exact(const vec3& o, vec2 u, light_sample& s) const {
    const spherical_rectangle sr(shape, o);
    if (!sr.valid()) return false;
    const dvec3 v = sr.sample_offset(u);
    const double d = glm::length(v);
    const double p = sr.pdf_offset(v);
    // A float pdf must be finite: the area fallback's |v|^3 / (h A) can
    // overflow for an observer almost in the plane; pdf() gives 0 there too.
    if (!(d > 0.0) || !(p <= double(FLT_MAX))) return false;
    s.dir = vec3(v / d);
    s.dist = float(d);
    s.pdf = float(p);
    return s.pdf > 0.0f;
  }

  float pdf_exact(const vec3& o, const vec3& dir) const {
    const spherical_rectangle sr(shape, o);
    double t;
    if (!sr.intersect(dvec3(dir), t)) return 0.0f;
    const double p = sr.pdf_offset(t * dvec3(dir));
    return p <= double(FLT_MAX) ? float(p) : 0.0f;
  }

  dvec3 ex_{1.0, 0.0, 0.0}, ey_{0.0, 1.0, 0.0}, ez_{0.0, 0.0, 1.0};
  double w_ = 1.0, l_ = 1.0;
};

}  // namespace mcrt
