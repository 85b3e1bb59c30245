#include "pbrt/transform.hpp"

#include <cmath>
#include <numbers>

namespace mcrt::pbrt {

transform transform::translate(const glm::dvec3& d) {
  transform t;
  t.m[3] = glm::dvec4(d, 1.0);
  t.inv[3] = glm::dvec4(-d, 1.0);
  return t;
}

transform transform::scale(const glm::dvec3& s) {
  transform t;
  for (int i = 0; i < 3; ++i) {
    t.m[i][i] = s[i];
    t.inv[i][i] = 1.0 / s[i];
  }
  return t;
}

std::optional<transform> transform::rotate(double degrees, const glm::dvec3& axis) {
  const double len = glm::length(axis);
  if (!(len > 0.0)) return std::nullopt;
  const glm::dvec3 a = axis / len;
  const double th = degrees * std::numbers::pi / 180.0, s = std::sin(th), c = std::cos(th);
  // pbrt-v4's Rotate, element (row i, column j) as r[i][j].
  const double r[3][3] = {
      {a.x * a.x + (1 - a.x * a.x) * c, a.x * a.y * (1 - c) - a.z * s, a.x * a.z * (1 - c) + a.y * s},
      {a.x * a.y * (1 - c) + a.z * s, a.y * a.y + (1 - a.y * a.y) * c, a.y * a.z * (1 - c) - a.x * s},
      {a.x * a.z * (1 - c) - a.y * s, a.y * a.z * (1 - c) + a.x * s, a.z * a.z + (1 - a.z * a.z) * c}};
  transform t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      t.m[j][i] = r[i][j];    // GLM: [column][row]
      t.inv[i][j] = r[i][j];  // a rotation's inverse is its transpose
    }
  return t;
}

namespace {

// The inverse of m. Of an affine m (last row 0 0 0 1) it is affine with
// that row exact: GLM's general 4x4 inverse leaves rounding noise of ~1e-17
// there, and the camera's check (camera.hpp) refuses a last row that is
// not exactly 0 0 0 1 (pbrt-v4's cameras are affine).
glm::dmat4 inverse_of(const glm::dmat4& m) {
  if (m[0][3] == 0.0 && m[1][3] == 0.0 && m[2][3] == 0.0 && m[3][3] == 1.0) {
    const glm::dmat3 a_inv = glm::inverse(glm::dmat3(m));
    glm::dmat4 r(a_inv);  // last row and column 0 0 0 1
    r[3] = glm::dvec4(-(a_inv * glm::dvec3(m[3])), 1.0);
    return r;
  }
  return glm::inverse(m);
}

}  // namespace

std::optional<transform> transform::look_at(const glm::dvec3& eye, const glm::dvec3& look, const glm::dvec3& up) {
  const glm::dvec3 view = look - eye;
  if (!(glm::length(view) > 0.0) || !(glm::length(up) > 0.0)) return std::nullopt;
  const glm::dvec3 dir = glm::normalize(view);
  const glm::dvec3 side = glm::cross(glm::normalize(up), dir);
  if (!(glm::length(side) > 0.0)) return std::nullopt;
  const glm::dvec3 right = glm::normalize(side), new_up = glm::cross(dir, right);
  transform world_from_camera;
  world_from_camera.m[0] = glm::dvec4(right, 0.0);
  world_from_camera.m[1] = glm::dvec4(new_up, 0.0);
  world_from_camera.m[2] = glm::dvec4(dir, 0.0);
  world_from_camera.m[3] = glm::dvec4(eye, 1.0);
  world_from_camera.inv = inverse_of(world_from_camera.m);
  return world_from_camera.inverse();
}

std::optional<transform> transform::from_pbrt_matrix(const std::array<double, 16>& v) {
  transform t;
  // Column-major as written: column j is v[4j .. 4j + 3], which is GLM's
  // own layout.
  for (int j = 0; j < 4; ++j) t.m[j] = glm::dvec4(v[4 * j], v[4 * j + 1], v[4 * j + 2], v[4 * j + 3]);
  const double det = glm::determinant(t.m);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return std::nullopt;
  t.inv = inverse_of(t.m);
  return t;
}

}  // namespace mcrt::pbrt
