// pbrt-v4's transforms (src/pbrt/transform.cpp) against their definitions:
// translation and scale; Rotate as a right-handed rotation (Rodrigues), its
// inverse its transpose; LookAt as pbrt's camera-from-world (the eye to the
// origin, the look point on +z, up in the +y half-plane, the camera's x axis
// up x dir: left-handed); Transform's sixteen numbers column-major;
// composition in the CTM's order (the last written applies first);
// normals by the inverse transpose; handedness.
#include <gtest/gtest.h>

#include <cmath>

#include "pbrt/transform.hpp"

using namespace mcrt::pbrt;
using glm::dvec3;

namespace {

void expect_near(const dvec3& a, const dvec3& b, double tol = 1e-12) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

}  // namespace

TEST(PbrtTransform, TranslateScaleAndTheirInverses) {
  const transform t = transform::translate({1, 2, 3}), s = transform::scale({2, -1, 4});
  expect_near(t.point({0, 0, 0}), {1, 2, 3});
  expect_near(t.vector({1, 1, 1}), {1, 1, 1});  // vectors do not move
  expect_near(s.point({1, 1, 1}), {2, -1, 4});
  expect_near(t.inverse().point(t.point({5, -6, 7})), {5, -6, 7});
  expect_near(s.inverse().point(s.point({5, -6, 7})), {5, -6, 7});
  EXPECT_TRUE(s.swaps_handedness());
  EXPECT_FALSE(t.swaps_handedness());
  // The CTM's order: Translate then Scale written means p' = T (S p).
  const transform ctm = t * s;
  expect_near(ctm.point({1, 1, 1}), {3, 1, 7});
  expect_near((ctm.inverse()).point(ctm.point({0.5, 2, -3})), {0.5, 2, -3});
}

TEST(PbrtTransform, RotateIsRightHanded) {
  const transform rz = *transform::rotate(90, {0, 0, 1});
  expect_near(rz.point({1, 0, 0}), {0, 1, 0});
  expect_near(rz.point({0, 1, 0}), {-1, 0, 0});
  const transform rx = *transform::rotate(90, {2, 0, 0});  // the axis is normalised
  expect_near(rx.point({0, 1, 0}), {0, 0, 1});
  const transform r = *transform::rotate(37, {1, 2, -0.5});
  const dvec3 p{0.3, -1.2, 2.5};
  expect_near(r.inverse().point(r.point(p)), p);
  EXPECT_NEAR(glm::length(r.point(p)), glm::length(p), 1e-12);
  // The axis stays fixed.
  expect_near(r.point(glm::normalize(dvec3(1, 2, -0.5))), glm::normalize(dvec3(1, 2, -0.5)));
  EXPECT_FALSE(transform::rotate(30, {0, 0, 0}).has_value());
}

TEST(PbrtTransform, LookAtIsPbrtsCameraFromWorld) {
  const dvec3 eye{1, 2, 3}, look{4, 2, 7}, up{0, 1, 0};
  const transform c = *transform::look_at(eye, look, up);
  expect_near(c.point(eye), {0, 0, 0});
  expect_near(c.point(look), {0, 0, 5});  // |look - eye| = 5 along +z
  EXPECT_GT(c.point(eye + up).y, 0.0);
  // Camera x = normalize(up x dir): with dir = (0.6, 0, 0.8), (0.8, 0, -0.6).
  expect_near(c.inverse().vector({1, 0, 0}), {0.8, 0, -0.6});
  EXPECT_FALSE(c.swaps_handedness());
  EXPECT_FALSE(transform::look_at(eye, eye, up).has_value());
  EXPECT_FALSE(transform::look_at(eye, eye + up, up).has_value());
}

TEST(PbrtTransform, MatrixNumbersAreColumnMajor) {
  // "Transform [1 0 0 0  0 1 0 0  0 0 1 0  tx ty tz 1]" is a translation.
  const transform t = *transform::from_pbrt_matrix({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 6, 7, 1});
  expect_near(t.point({1, 1, 1}), {6, 7, 8});
  expect_near(t.inverse().point({6, 7, 8}), {1, 1, 1});
  // A mirror in x swaps handedness.
  EXPECT_TRUE(transform::from_pbrt_matrix({-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1})->swaps_handedness());
  EXPECT_FALSE(transform::from_pbrt_matrix({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}).has_value());  // singular
}

TEST(PbrtTransform, NormalsStayPerpendicular) {
  const transform t = transform::scale({1, 4, 0.5}) * *transform::rotate(30, {1, 1, 0});
  const dvec3 tangent = glm::normalize(dvec3(1, -1, 2)), n = glm::normalize(glm::cross(tangent, dvec3(0, 0, 1)));
  EXPECT_NEAR(glm::dot(t.vector(tangent), t.normal(n)), 0.0, 1e-12);
}
