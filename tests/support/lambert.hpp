#pragma once
// Closed-form irradiance from uniform Lambertian emitters, in double, as
// references for render tests.
#include <glm/glm.hpp>

#include <cmath>
#include <numbers>
#include <vector>

namespace mcrt::test {

// Irradiance at x (surface normal n) from a polygon of constant radiance L
// that x sees in full (Lambert 1760; e.g. Arvo 1995, "Applications of
// Irradiance Tensors", eq. 2): E = L/2 sum_i gamma_i n . (r_i x r_{i+1}) / |r_i x r_{i+1}|
// with r_i the unit vectors to the vertices and gamma_i the angle between
// consecutive ones. The vertex order must wind clockwise as seen from x
// (otherwise the sign flips); the absolute value is returned.
inline double polygon_irradiance(const glm::dvec3& x, const glm::dvec3& n, const std::vector<glm::dvec3>& poly,
                                 double L) {
  double sum = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 a = glm::normalize(poly[i] - x), b = glm::normalize(poly[(i + 1) % poly.size()] - x);
    const glm::dvec3 c = glm::cross(a, b);
    const double s = glm::length(c);
    const double gamma = std::atan2(s, glm::dot(a, b));
    sum += gamma * glm::dot(n, c / s);
  }
  return std::abs(0.5 * L * sum);
}

// The part of a convex polygon on the side of the plane through x with
// normal n that n points into (Sutherland & Hodgman 1974, one plane): what a
// receiver at x with normal n sees of a light that its horizon cuts. The
// vertex order is kept, so the winding rule above still holds.
inline std::vector<glm::dvec3> clip_to_horizon(const glm::dvec3& x, const glm::dvec3& n,
                                               const std::vector<glm::dvec3>& poly) {
  std::vector<glm::dvec3> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double da = glm::dot(a - x, n), db = glm::dot(b - x, n);
    if (da >= 0.0) out.push_back(a);
    if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

// Irradiance at x (normal n) from a convex polygon of radiance L partly
// behind x's horizon: Lambert's formula over the part in front.
inline double clipped_polygon_irradiance(const glm::dvec3& x, const glm::dvec3& n, const std::vector<glm::dvec3>& poly,
                                         double L) {
  const std::vector<glm::dvec3> front = clip_to_horizon(x, n, poly);
  return front.size() < 3 ? 0.0 : polygon_irradiance(x, n, front, L);
}

// Irradiance on a plane parallel to a disk of radius R and radiance L, at
// height h below it and horizontal distance d from its axis (e.g. Howell's
// catalogue of configuration factors, C-13):
// E = pi L (1 - (h^2 + d^2 - R^2) / sqrt((h^2 + d^2 + R^2)^2 - 4 d^2 R^2)) / 2.
inline double disk_irradiance(double h, double d, double R, double L) {
  const double a = h * h + d * d;
  return std::numbers::pi * L * 0.5 * (1.0 - (a - R * R) / std::sqrt((a + R * R) * (a + R * R) - 4.0 * d * d * R * R));
}

}  // namespace mcrt::test
