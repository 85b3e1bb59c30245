#pragma once
// Sampling a sphere uniformly by AREA over the part of its surface the
// observer sees, converted to a density per unit solid angle by d^2 / |cos|
// as for the rectangle and the ellipse (Shirley, "The Rest of Your Life",
// sec. 9; Veach 1997, eq. 8.10). Sample, pdf and inverse in the Mitsuba
// warp.h / pbrt-v4 sampling.h layout (square_to_visible_sphere_cap,
// square_to_visible_sphere_cap_pdf, visible_sphere_cap_to_square), and the
// light strategy sphere_area_sampler with the interface of light_sample.hpp.
//
// The visible part. From o at distance d > r from the centre c, the points p
// of the sphere with (p - c) . (o - c) >= r^2 face o: the spherical cap about
// a = (o - c) / d of angular radius theta_v, cos theta_v = r / d (the rest is
// hidden behind it; the tangent cone from o touches the sphere along the
// cap's rim). Its area is 2 pi r^2 (1 - r / d), and uniform points on it are
// the uniform cone of directions about a with 1 - cos theta_v = (d - r) / d,
// scaled by r (Archimedes: area on a sphere is uniform in the height).
// Every point of it is seen from o, and every direction of the sphere's cone
// of directions meets it once (at the near intersection), so its density in
// solid angle, p_A t^2 / cos_light, covers the whole cone.
//
// Numerics, in double (inputs are float, so c - o is exact):
//  * d - r = (d^2 - r^2) / (d + r) and 1 - r / d = (d - r) / d, without
//    cancellation for observers close to the surface;
//  * the sample's offset from o is r n - d a = r (n_t t + n_b b) - (r (1 -
//    cos theta) + (d - r)) a, with 1 - cos theta = u.x (1 - cos theta_v) of
//    the cone map, so neither far spheres (d >> r) nor observers next to the
//    surface (the sampled points cluster at the foot of o) lose the offset's
//    relative precision;
//  * cos_light at the point, n . (o - p) / t, is (d - r - d (1 - cos theta)) /
//    t = d (1 - cos theta_v)(1 - u.x) / t, not a difference of nearly equal
//    numbers near the rim; for a direction (pdf) it is sqrt(r^2 - p^2) / r,
//    p^2 the squared distance of the centre from the ray, and the distance to
//    the near intersection is (d^2 - r^2) / (b + sqrt(r^2 - p^2)).
//
// The density in solid angle diverges at the rim like 1 / cos_light (the
// sphere is seen edge-on there; integrable, E[1 / pdf] is the cone's solid
// angle), which is why a float direction near the rim has a density that
// depends on its rounding: see sphere_area_sampler.
#include <cfloat>
#include <cmath>
#include <numbers>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

// The cap of the sphere's surface visible from o, set up once per observer.
struct visible_sphere_cap {
  dvec3 c{0.0};  // centre
  dvec3 v{0.0};  // c - o
  double r = 0.0, d2 = 0.0, d = 0.0;
  double d_minus_r = 0.0;      // d - r
  double one_minus_cos = 0.0;  // 1 - cos theta_v = (d - r) / d
  dvec3 t{1.0, 0.0, 0.0}, b{0.0, 1.0, 0.0}, a{0.0, 0.0, 1.0};  // a = (o - c) / d
  bool valid = false;          // o outside the sphere

  static visible_sphere_cap make(const sphere& s, const vec3& o) {
    visible_sphere_cap cap;
    cap.c = dvec3(s.center);
    cap.v = cap.c - dvec3(o);  // exact: a difference of floats in double
    cap.r = s.radius;
    cap.d2 = glm::dot(cap.v, cap.v);
    const double r2 = cap.r * cap.r;
    if (!(cap.d2 > r2) || !(cap.r > 0.0) || !std::isfinite(cap.d2)) return cap;
    cap.d = std::sqrt(cap.d2);
    cap.d_minus_r = (cap.d2 - r2) / (cap.d + cap.r);
    cap.one_minus_cos = cap.d_minus_r / cap.d;
    cap.a = -cap.v / cap.d;
    // Orthonormal frame about a (Duff et al. 2017, as onb.hpp), in double.
    const double sign = std::copysign(1.0, cap.a.z);
    const double p = -1.0 / (sign + cap.a.z), q = cap.a.x * cap.a.y * p;
    cap.t = dvec3(1.0 + sign * cap.a.x * cap.a.x * p, sign * q, -sign * cap.a.x);
    cap.b = dvec3(q, sign + cap.a.y * cap.a.y * p, -cap.a.y);
    cap.valid = true;
    return cap;
  }

  // Area of the visible cap, 2 pi r^2 (1 - r / d).
  double area() const { return 2.0 * std::numbers::pi * r * r * one_minus_cos; }
};

namespace sphere_area_detail {

// sin and cos of 2 pi f, f in [0, 1): the quadrant from 4 f (exact), then
// fast_math::sincos_quadrant on the remainder.
inline void sincos_turn(double f, double& s, double& c) {
  const double q = 4.0 * f;
  const int k = std::min(int(q), 3);
  double sq, cq;
  fast_math::sincos_quadrant((q - k) * (0.5 * std::numbers::pi), sq, cq);
  switch (k) {
    case 0: s = sq, c = cq; break;
    case 1: s = cq, c = -sq; break;
    case 2: s = -sq, c = -cq; break;
    default: s = -cq, c = sq; break;
  }
}

// The sample's local coordinates: n = (sin theta cos phi, sin theta sin phi,
// 1 - omc) about a, omc = 1 - cos theta = u.x (1 - cos theta_v).
struct local_point {
  double nt, nb, omc;
};
inline local_point local_at(dvec2 u, const visible_sphere_cap& cap) {
  const double omc = u.x * cap.one_minus_cos;
  const double st = std::sqrt(std::max(omc * (2.0 - omc), 0.0));
  double sp, cp;
  sincos_turn(u.y, sp, cp);
  return {st * cp, st * sp, omc};
}

}  // namespace sphere_area_detail

// u in [0,1)^2 -> the sampled point of the visible cap, as its offset p - c
// from the centre (double, world frame: r times the unit normal there).
// cap must be valid.
inline dvec3 square_to_visible_sphere_cap(dvec2 u, const visible_sphere_cap& cap) {
  const sphere_area_detail::local_point l = sphere_area_detail::local_at(u, cap);
  return cap.r * (l.nt * cap.t + l.nb * cap.b + (1.0 - l.omc) * cap.a);
}
inline dvec3 square_to_visible_sphere_cap(vec2 u, const visible_sphere_cap& cap) {
  return square_to_visible_sphere_cap(dvec2(u), cap);
}

// Density per unit AREA on the visible cap: 1 / (2 pi r^2 (1 - r / d)).
inline double square_to_visible_sphere_cap_pdf(const visible_sphere_cap& cap) {
  return cap.valid ? 1.0 / cap.area() : 0.0;
}

// Offset p - c of a point of the visible cap -> unit square; the inverse of
// square_to_visible_sphere_cap. 1 - cos theta as |n - a|^2 / 2, no
// cancellation near the cap's centre.
inline dvec2 visible_sphere_cap_to_square(const dvec3& offset, const visible_sphere_cap& cap) {
  const dvec3 n = offset / cap.r;
  const dvec3 e = n - cap.a;
  const double omc = 0.5 * glm::dot(e, e);
  double phi = std::atan2(glm::dot(n, cap.b), glm::dot(n, cap.t));
  if (phi < 0.0) phi += 2.0 * std::numbers::pi;
  return {std::clamp(omc / cap.one_minus_cos, 0.0, 1.0), std::min(phi / (2.0 * std::numbers::pi), 1.0)};
}

// Light-sampling strategy: uniform by area over the visible cap; pdf per unit
// SOLID ANGLE t^2 / (cos_light A). An observer inside (or on) the sphere
// gets no sample, as with sphere_cone_sampler (and like it, sphere::flip is
// ignored).
//
// Agreement of sample and pdf: the pdf returned with a sample is computed as
// pdf() computes it, from the direction as returned (rounded to float): the
// density diverges at the rim, and a rounding of ~6e-8 rad changes it there
// by far more than 1e-4 (for 1 % of the samples of a sphere 2 radii away,
// since the samples crowd towards the rim in solid angle). Where the rounded
// direction misses the sphere altogether (within ~6e-8 rad of the rim: ~3e-4
// sqrt(d / r) of the samples), pdf() gives 0, as for any ray that misses, and
// the sample carries the density of its exact direction.
struct sphere_area_sampler {
  sphere shape;

  bool faces(const vec3& o) const {
    const dvec3 v = dvec3(shape.center) - dvec3(o);
    return glm::dot(v, v) > double(shape.radius) * double(shape.radius);
  }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const visible_sphere_cap cap = visible_sphere_cap::make(shape, o);
    if (!cap.valid) return false;
    const sphere_area_detail::local_point l = sphere_area_detail::local_at(dvec2(u), cap);
    // p - o = r n - d a, the a component -(r omc + (d - r)) without cancellation.
    const dvec3 q = cap.r * (l.nt * cap.t + l.nb * cap.b) - (cap.r * l.omc + cap.d_minus_r) * cap.a;
    const double dist = glm::length(q);
    if (!(dist > 0.0)) return false;
    s.dir = vec3(q / dist);
    s.dist = float(dist);
    double p = density(cap, dvec3(s.dir));
    if (p == 0.0) {
      // Rounded off the sphere: the exact direction's density, dist^3 / (d
      // (1 - cos theta_v)(1 - u.x) A).
      p = dist * dist * dist / (cap.d * cap.one_minus_cos * (1.0 - double(u.x)) * cap.area());
    }
    if (!(p > 0.0) || !(p <= double(FLT_MAX))) return false;
    s.pdf = float(p);
    return true;
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir: t^2 /
  // (cos_light A) at the near intersection, 0 if the ray misses.
  float pdf(const vec3& o, const vec3& dir) const {
    const visible_sphere_cap cap = visible_sphere_cap::make(shape, o);
    if (!cap.valid) return 0.0f;
    const double p = density(cap, dvec3(dir));
    return p <= double(FLT_MAX) ? float(p) : 0.0f;
  }

 private:
  // t^2 / (cos_light A) with cos_light = sqrt(r^2 - p^2) / r and t = (d^2 -
  // r^2) / (b + sqrt(r^2 - p^2)): t^2 r / (sqrt(r^2 - p^2) A).
  static double density(const visible_sphere_cap& cap, const dvec3& dir) {
    const double b = glm::dot(dir, cap.v);
    if (!(b > 0.0)) return 0.0;
    const dvec3 perp = cap.v - b * dir;
    const double r2 = cap.r * cap.r;
    const double disc = r2 - glm::dot(perp, perp);
    if (!(disc > 0.0)) return 0.0;
    const double sq = std::sqrt(disc);
    const double t = (cap.d2 - r2) / (b + sq);
    return t * t * cap.r / (sq * cap.area());
  }
};

}  // namespace mcrt
