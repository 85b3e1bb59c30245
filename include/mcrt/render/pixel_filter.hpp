#pragma once
// pbrt-v4's pixel reconstruction filters (src/pbrt/filters.h) used by filter
// importance sampling: each camera sample is placed at an offset from the
// pixel's centre drawn with density proportional to the filter f, so its
// filter weight f / pdf is the same constant (f's integral) for every sample
// and cancels in the weighted mean of pbrt-v4's film: every sample weighs
// exactly 1 and the pixel's value stays the plain mean of its samples, as
// the renderer computes it.
//
// Kinds (pbrt-v4's defaults; radii may differ in x and y, all in pixels):
//   box      radius 0.5:          f = 1 on [-rx, rx] x [-ry, ry]
//   gaussian radius 1.5, sigma 0.5: f = max(0, g(x) - g(rx)) * max(0, g(y) - g(ry)),
//            g the normal density of mean 0 and standard deviation sigma
//   triangle radius 2:            f = max(0, rx - |x|) * max(0, ry - |y|)
// All three are separable, f(x, y) = f_x(x) f_y(y), and sample() inverts
// each axis's cumulative distribution exactly:
//   box       uniform, x = r (2u - 1);
//   triangle  pbrt-v4's SampleTent, x = -r + r sqrt(2u) for u < 1/2 and its
//             mirror image above, in a form without cancellation near x = 0;
//   gaussian  the CDF of g(x) - g(r) on [-r, r], by erfc in double, solved
//             by safeguarded Newton iteration (below). pbrt-v4 instead
//             tabulates f (FilterSampler: 32 entries per pixel of radius
//             along each axis) and samples the piecewise-constant table,
//             so its samples carry weights f / pdf that vary with the
//             table's error; here the inversion is exact and the weight
//             exactly 1.
//
// Accuracy. Every map is computed in double and rounded once to float:
// box and triangle offsets and all inverse() values are within ~1 ulp of the
// exact ones. The gaussian's quantile is the root of T(x) = v on [-r, 0]
// (v = min(u, 1 - u), mirrored for u > 1/2), T the CDF: by erfc (absolute
// error ~1e-16, no cancellation in the tails), and within
// min(sigma, sigma^2 / r) of the edge, where that closed form cancels, by
// an 8-point Gauss-Legendre rule (relative error ~1e-16; all of [-r, 0] for
// a gaussian wider than its radius). On [-r, 0] T is
// increasing, convex and log-concave; Newton's method runs on log T
// (gauss_quantile_lower), and a bracket [lo, hi] that every iterate narrows
// replaces any step that leaves it by bisection, so neither rounding nor a
// vanishing T or T' (at -r, or where g(r) underflows) can make it diverge.
// It stops once a step is below 2^-36 r, after which (quadratic convergence)
// the double root is within ~1e-15 r of the exact one, plus the ~1e-16 / T'
// of the CDF's own rounding (below 1e-9 r except within ~1e-7 r of the
// edge, where float offsets are ulp(r) apart anyway): the float returned is
// the exact quantile to within 1 ulp, or 1e-9 r absolute, whichever is
// larger (tests/test_pixel_filter.cpp checks it against a long double
// reference). 3-6 evaluations of T per axis (~8 down to v = 1e-45), at
// most 100.
//
// Edges. u in [0, 1] maps to [-r, r] (u = 0 to -r exactly, u = 1 to r), so
// samples never leave the support, even for u within 2^-24 of 0 or 1. Float
// u's next to 1 are only 2^-24 apart (next to 0 they are far finer), so
// inverse() then sample() returns an offset to within about 2^-23 / p(offset),
// p the axis's density, which grows towards the far edge of a triangle or
// gaussian; offsets whose mass beyond them is below 2^-25 have u = 1 and
// come back as r (a narrow gaussian's beyond ~5.5 sigma). In u the round
// trip holds to 2^-22 everywhere.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "mcrt/core/math.hpp"

namespace mcrt {

enum class pixel_filter_kind { box, gaussian, triangle };

struct pixel_filter {
  // The box of radius 0.5: today's unfiltered renderer (see film_point).
  pixel_filter() = default;

  static pixel_filter box(vec2 radius = vec2(0.5f)) { return {pixel_filter_kind::box, radius, 0.0f}; }
  // sigma > 0; radius > 0 as for every kind.
  static pixel_filter gaussian(vec2 radius = vec2(1.5f), float sigma = 0.5f) {
    return {pixel_filter_kind::gaussian, radius, sigma};
  }
  static pixel_filter triangle(vec2 radius = vec2(2.0f)) { return {pixel_filter_kind::triangle, radius, 0.0f}; }

  pixel_filter_kind kind() const { return kind_; }
  // Half-widths of the support [-rx, rx] x [-ry, ry], in pixels.
  vec2 radius() const { return radius_; }
  // The gaussian's standard deviation in pixels (0 for the other kinds).
  float sigma() const { return sigma_; }

  // pbrt-v4's Filter::Evaluate: f at an offset from the pixel's centre (in
  // pixels); 0 outside the support. Not normalized: pbrt's values.
  float eval(vec2 offset) const {
    if (!inside(offset)) return 0.0f;
    switch (kind_) {
      case pixel_filter_kind::box:
        return 1.0f;
      case pixel_filter_kind::triangle:
        return std::max(0.0f, radius_.x - std::abs(offset.x)) * std::max(0.0f, radius_.y - std::abs(offset.y));
      case pixel_filter_kind::gaussian:
        return static_cast<float>(gauss_f(0, offset.x) * gauss_f(1, offset.y));
    }
    return 0.0f;
  }

  // pbrt-v4's Filter::Integral: the integral of eval over the support, in
  // pixels^2 (4 rx ry, rx^2 ry^2, and (erf(r / (sigma sqrt 2)) - 2 r g(r))
  // per axis for the gaussian). f(o) / pdf(o) equals it for every offset.
  float integral() const {
    switch (kind_) {
      case pixel_filter_kind::box:
        return 4.0f * radius_.x * radius_.y;
      case pixel_filter_kind::triangle:
        return sqr(radius_.x) * sqr(radius_.y);
      case pixel_filter_kind::gaussian:
        return static_cast<float>(4.0 * half_mass_[0] * half_mass_[1]);
    }
    return 0.0f;
  }

  // Maps u in [0, 1]^2 to an offset from the pixel's centre in pixels,
  // distributed with density pdf() (per unit area of the offset plane), i.e.
  // proportional to eval(); axis by axis, u.x gives offset.x. Monotone in
  // each coordinate; u = 0 and 1 map to the support's edges.
  vec2 sample(vec2 u) const { return {sample_axis(0, u.x), sample_axis(1, u.y)}; }

  // Density of sample() per unit area of the pixel-offset plane (pixels^-2):
  // eval(offset) / integral(), 0 outside the support; integrates to 1 over
  // [-rx, rx] x [-ry, ry].
  float pdf(vec2 offset) const {
    if (!inside(offset)) return 0.0f;
    return static_cast<float>(axis_pdf(0, offset.x) * axis_pdf(1, offset.y));
  }

  // The u in [0, 1]^2 that sample() maps to offset (each axis's CDF);
  // offsets outside the support are first clamped onto it.
  vec2 inverse(vec2 offset) const { return {inverse_axis(0, offset.x), inverse_axis(1, offset.y)}; }

  // The point of pixel (x, y), in the renderer's pixel coordinates, of a
  // sample u: pbrt-v4's pFilm = pPixel + (0.5, 0.5) + offset, i.e.
  // (x + 0.5 + sample(u).x, y + 0.5 + sample(u).y), rounded once to float;
  // pixel_ray(cam, 0, 0, film_point(x, y, u), inv_w, inv_h) is the ray
  // through it. The box is evaluated as (x + (0.5 - r)) + 2 r u in float, so
  // that the box of radius 0.5 gives float(x) + u.x bit for bit, the point
  // the renderer's pixel_ray(cam, x, y, u, ...) uses today (forming the
  // offset u - 0.5 first would round for u < 1/4); other radii round as
  // the float expression does.
  vec2 film_point(int x, int y, vec2 u) const {
    if (kind_ == pixel_filter_kind::box)
      return {static_cast<float>(x) + (0.5f - radius_.x) + (2.0f * radius_.x) * u.x,
              static_cast<float>(y) + (0.5f - radius_.y) + (2.0f * radius_.y) * u.y};
    const vec2 o = sample(u);
    return {static_cast<float>(static_cast<double>(x) + 0.5 + static_cast<double>(o.x)),
            static_cast<float>(static_cast<double>(y) + 0.5 + static_cast<double>(o.y))};
  }

 private:
  pixel_filter(pixel_filter_kind k, vec2 radius, float sigma) : kind_(k), radius_(radius), sigma_(sigma) {
    if (k == pixel_filter_kind::gaussian)
      for (int a = 0; a < 2; ++a) {
        const double r = radius_[a], s = sigma_;
        edge_[a] = std::exp(-0.5 * sqr(r / s)) / (s * std::sqrt(2.0 * std::numbers::pi));
        erfc_edge_[a] = std::erfc(r / (s * std::numbers::sqrt2));
        half_mass_[a] = gauss_lower_mass(a, 0.0);
      }
  }

  bool inside(vec2 o) const { return std::abs(o.x) <= radius_.x && std::abs(o.y) <= radius_.y; }

  // --- the gaussian along axis a, in double
  // g(x) - g(r) at distance e = r - |x| from the edge, as
  // g(x) (1 - exp(-e (2r - e) / (2 sigma^2))): accurate near the edge, where
  // pbrt's float difference cancels, and free of overflow when g(r)
  // underflows.
  double gauss_from_edge(int a, double e) const {
    const double r = radius_[a], s = sigma_;
    const double g = std::exp(-0.5 * sqr((r - e) / s)) / (s * std::sqrt(2.0 * std::numbers::pi));
    return std::max(0.0, g * -std::expm1(-0.5 * e * (2.0 * r - e) / (s * s)));
  }
  double gauss_f(int a, double x) const {
    const double r = radius_[a];
    return std::abs(x) <= r ? gauss_from_edge(a, r - std::abs(x)) : 0.0;  // r - |x| exact for |x| >= r/2
  }
  // Integral of gauss_f over [-r, x] for x in [-r, 0]. Within
  // min(sigma, sigma^2 / r) of the edge by 8-point Gauss-Legendre in the
  // distance from the edge (the integrand is entire and, on that interval,
  // within a degree-15 polynomial to ~1e-18 of itself), where the closed
  // form cancels; elsewhere the closed form by erfc, which has no
  // cancellation in the tail: 0.5 (erfc(-x / (sigma sqrt 2)) -
  // erfc(r / (sigma sqrt 2))) - (x + r) g(r).
  double gauss_lower_mass(int a, double x) const {
    const double r = radius_[a], s = sigma_, d = x + r;  // d exact near the edge
    if (d <= std::min(s, s * s / r)) {
      static constexpr double node[4] = {0.18343464249564980494, 0.52553240991632898582, 0.79666647741362673959,
                                         0.96028985649753623168};
      static constexpr double weight[4] = {0.36268378337836198297, 0.31370664587788728734, 0.22238103445337447054,
                                           0.10122853629037625915};
      double sum = 0.0;
      for (int i = 0; i < 4; ++i)
        sum += weight[i] * (gauss_from_edge(a, 0.5 * d * (1.0 - node[i])) + gauss_from_edge(a, 0.5 * d * (1.0 + node[i])));
      return 0.5 * d * sum;
    }
    return 0.5 * (std::erfc(-x / (s * std::numbers::sqrt2)) - erfc_edge_[a]) - d * edge_[a];
  }
  // The CDF T on [-r, 0]: T(-r) = 0, T(0) = 1/2 exactly.
  double gauss_cdf_lower(int a, double x) const { return gauss_lower_mass(a, x) / (2.0 * half_mass_[a]); }
  // The root of T(x) = v, v in (0, 1/2), on [-r, 0].
  double gauss_quantile_lower(int a, double v) const {
    const double r = radius_[a], inv_mass = 1.0 / (2.0 * half_mass_[a]);
    double lo = -r, hi = 0.0;
    const double tol = 0x1p-36 * r;
    // Newton's method on log T(x) = log v: T is log-concave (so is its
    // density), and in a narrow gaussian's far tail, where T falls like
    // exp(-x^2 / (2 sigma^2)), Newton on T itself would crawl by ~sigma^2 / |x|
    // per step; on log T it takes at most ~8 steps down to v = 1e-45 and 3-6
    // elsewhere. It starts from the nearer of two estimates: the tangent of T
    // at 0, right of the root as T is convex on [-r, 0], and the edge's
    // quadratic T ~ g(r) r d^2 / (2 sigma^2 I), d = x + r, exact as d -> 0.
    const double c = edge_[a] * r / (2.0 * sqr(static_cast<double>(sigma_))) * inv_mass;
    const double d_edge = c > 0.0 ? std::sqrt(v / c) : std::numeric_limits<double>::infinity();
    if (d_edge <= tol) return -r + d_edge;  // the quadratic is exact to O(d^3) there
    double x = std::min(-(0.5 - v) / (gauss_f(a, 0.0) * inv_mass), -r + d_edge);
    if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
    const double log_v = std::log(v);
    for (int i = 0; i < 100; ++i) {
      const double cdf = gauss_cdf_lower(a, x);
      if (cdf < v)
        lo = x;
      else if (cdf > v)
        hi = x;
      else
        return x;
      // Newton's step on log T (NaN where T or T' is 0: bisection instead).
      const double step = (std::log(cdf) - log_v) * cdf / (gauss_f(a, x) * inv_mass);
      if (std::abs(step) <= tol) return std::clamp(x - step, lo, hi);
      x = x - step;
      if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
      if (hi - lo <= tol) return x;
    }
    return x;
  }

  // --- one axis of the triplet
  float sample_axis(int a, float uf) const {
    const double r = radius_[a], u = std::clamp(static_cast<double>(uf), 0.0, 1.0);
    switch (kind_) {
      case pixel_filter_kind::box:
        return static_cast<float>(r * (2.0 * u - 1.0));
      case pixel_filter_kind::triangle: {
        // Distance from the centre r (1 - sqrt(2v)) = r (1 - 2v) / (1 + sqrt(2v)).
        const double v = std::min(u, 1.0 - u);
        const double d = r * (1.0 - 2.0 * v) / (1.0 + std::sqrt(2.0 * v));
        return static_cast<float>(u < 0.5 ? -d : d);
      }
      case pixel_filter_kind::gaussian: {
        const double v = std::min(u, 1.0 - u);  // 1 - u is exact for a float u >= 1/2
        const double x = v <= 0.0 ? -r : v >= 0.5 ? 0.0 : gauss_quantile_lower(a, v);
        return static_cast<float>(u < 0.5 ? x : -x);
      }
    }
    return 0.0f;
  }

  double axis_pdf(int a, double x) const {
    const double r = radius_[a];
    switch (kind_) {
      case pixel_filter_kind::box:
        return 0.5 / r;
      case pixel_filter_kind::triangle:
        return std::max(0.0, r - std::abs(x)) / (r * r);
      case pixel_filter_kind::gaussian:
        return gauss_f(a, x) / (2.0 * half_mass_[a]);
    }
    return 0.0;
  }

  float inverse_axis(int a, float of) const {
    const double r = radius_[a], x = std::clamp(static_cast<double>(of), -r, r);
    switch (kind_) {
      case pixel_filter_kind::box:
        return static_cast<float>((x + r) / (2.0 * r));
      case pixel_filter_kind::triangle: {
        const double v = 0.5 * sqr(1.0 - std::abs(x) / r);  // the mass beyond |x| on its side
        return static_cast<float>(x <= 0.0 ? v : 1.0 - v);
      }
      case pixel_filter_kind::gaussian: {
        const double v = gauss_cdf_lower(a, -std::abs(x));
        return static_cast<float>(x <= 0.0 ? v : 1.0 - v);
      }
    }
    return 0.0f;
  }

  pixel_filter_kind kind_ = pixel_filter_kind::box;
  vec2 radius_{0.5f};
  float sigma_ = 0.0f;
  // The gaussian's per-axis constants: g(r), erfc(r / (sigma sqrt 2)) and
  // half its axis's integral, 0.5 erf(r / (sigma sqrt 2)) - r g(r).
  double edge_[2] = {0.0, 0.0};
  double erfc_edge_[2] = {0.0, 0.0};
  double half_mass_[2] = {0.0, 0.0};
};

}  // namespace mcrt
