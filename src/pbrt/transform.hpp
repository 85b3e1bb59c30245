#pragma once
// The transforms of pbrt-v4's scene format, in double precision, as pbrt-v4
// defines them (src/pbrt/util/transform.cpp; the File Format reference):
// each transform directive post-multiplies the current transformation
// matrix (CTM), so the transform written last applies to points first.
//   Translate x y z, Scale x y z
//   Rotate angle x y z       right-handed rotation by `angle` degrees about
//                            the axis (Rodrigues' formula)
//   LookAt eye look up       the camera-from-world matrix of pbrt's camera
//                            space: x = normalize(up x dir), y = dir x x,
//                            z = dir = normalize(look - eye) (left-handed:
//                            x to the image's right, y up, z forward)
//   Transform [16], ConcatTransform [16]
//                            sixteen numbers in column-major order: the
//                            matrix is their transpose read row by row
#include <array>
#include <optional>

#include <glm/glm.hpp>

namespace mcrt::pbrt {

struct transform {
  glm::dmat4 m{1.0}, inv{1.0};  // the matrix and its inverse (GLM: column-major, m[col][row])

  static transform translate(const glm::dvec3& d);
  static transform scale(const glm::dvec3& s);
  // Degrees, about an axis that is normalised here; nullopt for a zero axis.
  static std::optional<transform> rotate(double degrees, const glm::dvec3& axis);
  // pbrt-v4's LookAt: camera-from-world; nullopt where up is parallel to
  // the viewing direction or eye = look.
  static std::optional<transform> look_at(const glm::dvec3& eye, const glm::dvec3& look, const glm::dvec3& up);
  // The matrix of Transform / ConcatTransform from its 16 numbers as
  // written (column-major); nullopt where it is singular.
  static std::optional<transform> from_pbrt_matrix(const std::array<double, 16>& v);

  transform operator*(const transform& b) const { return {m * b.m, b.inv * inv}; }
  transform inverse() const { return {inv, m}; }

  glm::dvec3 point(const glm::dvec3& p) const {
    const glm::dvec4 q = m * glm::dvec4(p, 1.0);
    return glm::dvec3(q) / q.w;
  }
  glm::dvec3 vector(const glm::dvec3& v) const { return glm::dmat3(m) * v; }
  // Normals transform by the inverse transpose.
  glm::dvec3 normal(const glm::dvec3& n) const { return glm::transpose(glm::dmat3(inv)) * n; }
  // Whether the transform mirrors (its 3x3 part has a negative determinant):
  // it turns a triangle's winding, and pbrt-v4 flips spheres' and disks'
  // normals with it.
  bool swaps_handedness() const { return glm::determinant(glm::dmat3(m)) < 0.0; }
};

}  // namespace mcrt::pbrt
