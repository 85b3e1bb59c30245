#pragma once
// Reference solid angles and bounding cones of the light shapes, in double
// and independent of the samplers under test.
//
//   solid_angle_rect     exact: two triangles, each by Van Oosterom &
//                        Strackee (1983), "The Solid Angle of a Plane
//                        Triangle", IEEE Trans. Biomed. Eng. 30(2):
//                        tan(Omega/2) = |a.(b x c)| / (abc + (a.b)c + (a.c)b + (b.c)a),
//                        with the triple product formed from the triangle's
//                        edges, so it stays accurate for tiny solid angles.
//   solid_angle_ellipse  the boundary form of Omega = integral of h / r^3 dA
//                        (see the function), by the trapezoidal rule.
//   solid_angle_sphere   2 pi (1 - cos theta_max), cancellation-free.
//   bounding_cap         a spherical cap that contains every direction from
//                        an observer to a shape, for the chi-square grid.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "mcrt/core/math.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"

namespace mcrt::test {

// The cap {d : 1 - dot(d, axis) <= one_minus_cos}; one_minus_cos = 2 is the
// whole sphere.
struct spherical_cap {
  dvec3 axis{0.0, 0.0, 1.0};
  double one_minus_cos = 2.0;
};

// Solid angle at o of the triangle p0 p1 p2 (Van Oosterom & Strackee 1983).
inline double solid_angle_triangle(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2) {
  const dvec3 a = p0 - o, b = p1 - o, c = p2 - o;
  // a.(b x c) = a.((p1 - p0) x (p2 - p0)): no cancellation when a, b, c are
  // long and nearly parallel.
  const double triple = glm::dot(a, glm::cross(p1 - p0, p2 - p0));
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double denom = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2.0 * std::atan2(std::abs(triple), denom);
}

// Exact solid angle at o of the parallelogram corner + s e1 + t e2,
// (s, t) in [0,1]^2, as two triangles that share the diagonal.
inline double solid_angle_rect(const dvec3& o, const dvec3& corner, const dvec3& e1, const dvec3& e2) {
  const dvec3 far = corner + e1 + e2;
  return solid_angle_triangle(o, corner, corner + e1, far) + solid_angle_triangle(o, corner, far, corner + e2);
}

// Solid angle at o of the ellipse center + cos(t) a1 + sin(t) a2.
//
// With n the unit normal, h >= 0 the distance of o from the plane, F its foot
// and polar coordinates (rho, theta) about F in the plane,
//   Omega = int h / (rho^2 + h^2)^(3/2) rho drho dtheta
//         = oint (1 - h / s) dtheta,          s = |P - o|
// over the boundary P(t) (each ray from F contributes between where it
// enters and leaves). With q = P - F, dtheta = n.(q x q') dt / |q|^2 and
// 1 - h/s = |q|^2 / (s (s + h)), so
//   Omega = int_0^{2 pi} (|a1 x a2| + n.((C - F) x P'(t))) / (s (s + h)) dt,
// a smooth periodic integrand without cancellation near the axis. The
// trapezoidal rule converges geometrically for it; the number of nodes is
// doubled (from 256) until two estimates agree to 1e-13.
//
// Accuracy (checked against fans of Van Oosterom-Strackee triangles):
// ~1e-13 relative, also for observers close to the rim (1e-5 of the size
// away), where the integrand is peaked and the node count grows like
// size / distance, up to the cap of 2^22 nodes. For grazing observers far
// outside, the numerator cancels between opposite sides of the ellipse: the
// relative error grows like 1e-16 rho_F s / (b h), with rho_F the distance
// of F from the centre and b the minor semi-axis, ~1e-10 at rho_F / b = 2e3,
// s / h = 1e2. Undefined for observers on the rim itself.
inline double solid_angle_ellipse(const dvec3& o, const dvec3& center, const dvec3& a1, const dvec3& a2) {
  const dvec3 c = glm::cross(a1, a2);
  const double area_factor = glm::length(c);  // |a1 x a2|
  if (!(area_factor > 0.0)) return 0.0;
  const dvec3 n = c / area_factor;
  const dvec3 co = center - o;
  const double h_signed = -glm::dot(co, n);  // dot(o - center, n)
  const double h = std::abs(h_signed);
  const dvec3 w = co + h_signed * n;  // C - F, in the plane
  const double k1 = glm::dot(n, glm::cross(w, a1)), k2 = glm::dot(n, glm::cross(w, a2));
  const auto f = [&](double t) {
    const double ct = std::cos(t), st = std::sin(t);
    const double s = glm::length(co + ct * a1 + st * a2);
    return (area_factor + ct * k2 - st * k1) / (s * (s + h));
  };
  constexpr double two_pi = 2.0 * std::numbers::pi;
  constexpr int max_nodes = 1 << 22;
  int nodes = 256;
  double sum = 0.0;
  for (int j = 0; j < nodes; ++j) sum += f(two_pi * j / nodes);
  double estimate = sum * two_pi / nodes;
  while (nodes < max_nodes) {
    for (int j = 0; j < nodes; ++j) sum += f(two_pi * (j + 0.5) / nodes);
    nodes *= 2;
    const double next = sum * two_pi / nodes;
    const bool converged = std::abs(next - estimate) <= 1e-13 * std::abs(next);
    estimate = next;
    if (converged) break;
  }
  return std::abs(estimate);
}

// Solid angle at o of a sphere, 2 pi (1 - cos theta_max) with
// 1 - cos theta_max = x / (1 + sqrt(1 - x)), x = r^2 / d^2; 4 pi from inside.
inline double solid_angle_sphere(const dvec3& o, const dvec3& center, double radius) {
  const dvec3 v = center - o;
  const double d2 = glm::dot(v, v), r2 = radius * radius;
  if (!(d2 > r2)) return 4.0 * std::numbers::pi;
  const double x = r2 / d2;
  return 2.0 * std::numbers::pi * x / (1.0 + std::sqrt(1.0 - x));
}

// The same for the library's shapes (given in float, evaluated in double).
inline double solid_angle(const dvec3& o, const rect& r) {
  return solid_angle_rect(o, dvec3(r.corner), dvec3(r.e1), dvec3(r.e2));
}
inline double solid_angle(const dvec3& o, const ellipse& e) {
  return solid_angle_ellipse(o, dvec3(e.center), dvec3(e.a1), dvec3(e.a2));
}
inline double solid_angle(const dvec3& o, const sphere& s) {
  return solid_angle_sphere(o, dvec3(s.center), static_cast<double>(s.radius));
}

namespace detail {

// Angle between unit vectors, accurate for small angles.
inline double angle_between(const dvec3& a, const dvec3& b) {
  return 2.0 * std::asin(std::min(1.0, 0.5 * glm::length(a - b)));
}

// The cap of half-angle theta about axis, widened by a relative margin of
// 1e-3 and an absolute one of 1e-6 rad, which covers directions computed in
// float (~6e-8 rad per component). Whole sphere from pi on.
inline spherical_cap widened_cap(const dvec3& axis, double theta) {
  const double t = theta * (1.0 + 1e-3) + 1e-6;
  if (!(t < std::numbers::pi)) return {axis, 2.0};
  const double s = std::sin(0.5 * t);
  return {axis, std::min(2.0, 2.0 * s * s)};
}

// Cap containing every direction from o to a convex planar shape (normal n,
// a point p on it) whose boundary directions are `dirs` (unit), each
// boundary direction lying within `extra` rad of one of them. For a
// candidate axis, the cone of half-angle < pi/2 about it is convex, so it
// holds the whole shape once it holds the boundary. Candidates: towards the
// centroid of dirs, towards `center`, and the normal towards the plane; the
// smallest valid one wins, and the hemisphere towards the plane is the
// fallback.
inline spherical_cap cap_of_planar_convex(const dvec3& o, const dvec3& center, const dvec3& n, const dvec3& p,
                                          const std::vector<dvec3>& dirs, double extra) {
  const double h = glm::dot(o - p, n);
  if (h == 0.0) return {n, 2.0};  // observer in the plane of the shape
  const dvec3 toward_plane = h > 0.0 ? -n : n;
  dvec3 mean(0.0);
  for (const dvec3& d : dirs) mean += d;
  std::vector<dvec3> candidates = {toward_plane};
  if (glm::length(mean) > 0.0) candidates.push_back(glm::normalize(mean));
  if (glm::length(center - o) > 0.0) candidates.push_back(glm::normalize(center - o));
  spherical_cap best = widened_cap(toward_plane, 0.5 * std::numbers::pi);
  for (const dvec3& a : candidates) {
    double theta = 0.0;
    for (const dvec3& d : dirs) theta = std::max(theta, angle_between(a, d));
    theta += extra;
    if (!(theta < 0.5 * std::numbers::pi)) continue;
    const spherical_cap c = widened_cap(a, theta);
    if (c.one_minus_cos < best.one_minus_cos) best = c;
  }
  return best;
}

}  // namespace detail

// Caps that contain every direction from o to the shape, with a small margin
// (relative 1e-3 of the half-angle plus 1e-6 rad); one_minus_cos <= 2.
inline spherical_cap bounding_cap(const dvec3& o, const rect& r) {
  const dvec3 c(r.corner), e1(r.e1), e2(r.e2);
  const std::vector<dvec3> corners = {c, c + e1, c + e1 + e2, c + e2};
  std::vector<dvec3> dirs;
  for (const dvec3& p : corners) {
    if (!(glm::length(p - o) > 0.0)) return {dvec3(r.n), 2.0};
    dirs.push_back(glm::normalize(p - o));
  }
  return detail::cap_of_planar_convex(o, c + 0.5 * (e1 + e2), glm::normalize(glm::cross(e1, e2)), c, dirs, 0.0);
}

inline spherical_cap bounding_cap(const dvec3& o, const ellipse& e) {
  // The boundary at 2048 points; `extra` is the largest angle between
  // consecutive ones, at least twice the angle from any boundary direction
  // to the nearest sampled one while the boundary is smooth at that scale,
  // and large enough to defeat the candidate axes otherwise.
  constexpr int count = 2048;
  const dvec3 c(e.center), a1(e.a1), a2(e.a2);
  std::vector<dvec3> dirs;
  dirs.reserve(count);
  for (int i = 0; i < count; ++i) {
    const double t = 2.0 * std::numbers::pi * i / count;
    const dvec3 v = c + std::cos(t) * a1 + std::sin(t) * a2 - o;
    if (!(glm::length(v) > 0.0)) return {dvec3(e.n), 2.0};
    dirs.push_back(glm::normalize(v));
  }
  double extra = 0.0;
  for (int i = 0; i < count; ++i) extra = std::max(extra, detail::angle_between(dirs[i], dirs[(i + 1) % count]));
  return detail::cap_of_planar_convex(o, c, glm::normalize(glm::cross(a1, a2)), c, dirs, extra);
}

inline spherical_cap bounding_cap(const dvec3& o, const sphere& s) {
  const dvec3 v = dvec3(s.center) - o;
  const double d = glm::length(v), r = static_cast<double>(s.radius);
  if (!(d > r)) return {dvec3(0.0, 0.0, 1.0), 2.0};
  return detail::widened_cap(v / d, std::asin(r / d));
}

inline spherical_cap bounding_cap(const dvec3& o, const triangle& t) {
  const dvec3 p[3] = {dvec3(t.vertex(0)), dvec3(t.vertex(1)), dvec3(t.vertex(2))};
  std::vector<dvec3> dirs;
  for (const dvec3& q : p) {
    if (!(glm::length(q - o) > 0.0)) return {dvec3(t.normal()), 2.0};
    dirs.push_back(glm::normalize(q - o));
  }
  return detail::cap_of_planar_convex(o, (p[0] + p[1] + p[2]) / 3.0, glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0])),
                                      p[0], dirs, 0.0);
}

// The same with the arguments the other way round.
inline spherical_cap bounding_cap(const rect& r, const dvec3& o) { return bounding_cap(o, r); }
inline spherical_cap bounding_cap(const ellipse& e, const dvec3& o) { return bounding_cap(o, e); }
inline spherical_cap bounding_cap(const sphere& s, const dvec3& o) { return bounding_cap(o, s); }

}  // namespace mcrt::test
