// pbrt-v4's perspective camera as mcrt's pinhole camera
// (src/pbrt/camera.hpp): fov across the shorter axis, the image's right
// along pbrt's camera x (up x dir, from LookAt), row 0 at the top, and a
// camera-from-world matrix with a reflection ("Scale -1 1 1" before LookAt)
// used as it is: the image mirrored, and project() still the inverse of
// generate().
#include <gtest/gtest.h>

#include <cmath>

#include "pbrt/camera.hpp"

using namespace mcrt;
using namespace mcrt::pbrt;

namespace {

perspective_params with_fov(double fov) {
  perspective_params p;
  p.fov = fov;
  return p;
}

vec3 dir_at(const camera& c, float s, float t) { return glm::normalize(c.generate(s, t).d); }

void expect_near(const vec3& a, const vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

}  // namespace

TEST(PbrtCamera, FovSpansTheShorterAxisAndRowZeroIsTheTop) {
  const transform look = *transform::look_at({0, 0, 0}, {0, 0, 1}, {0, 1, 0});
  const double t30 = std::tan(glm::radians(30.0));
  // Landscape 200 x 100: fov 60 spans the height.
  const camera wide = perspective_camera(look, with_fov(60), 200, 100);
  expect_near(dir_at(wide, 0.5f, 0.5f), {0, 0, 1});
  expect_near(dir_at(wide, 0.5f, 0.0f), glm::normalize(vec3(0, float(t30), 1)));       // top row: up
  expect_near(dir_at(wide, 1.0f, 0.5f), glm::normalize(vec3(float(2 * t30), 0, 1)));   // right: camera x = up x dir = +x
  // Portrait 100 x 200: fov spans the width.
  const camera tall = perspective_camera(look, with_fov(60), 100, 200);
  expect_near(dir_at(tall, 1.0f, 0.5f), glm::normalize(vec3(float(t30), 0, 1)));
  expect_near(dir_at(tall, 0.5f, 0.0f), glm::normalize(vec3(0, float(2 * t30), 1)));
  // An explicit screen window.
  perspective_params window = with_fov(90);
  window.screen_window = std::array<double, 4>{0, 1, 0, 1};
  const camera win = perspective_camera(look, window, 64, 64);
  expect_near(dir_at(win, 0.0f, 1.0f), {0, 0, 1});  // bottom-left corner = screen (0, 0)
}

TEST(PbrtCamera, AReflectionInTheMatrixMirrorsTheImage) {
  const transform look = *transform::look_at({1, 2, 3}, {1, 2, 10}, {0, 1, 0});
  const transform mirrored = transform::scale({-1, 1, 1}) * look;  // "Scale -1 1 1" then "LookAt ..."
  ASSERT_TRUE(mirrored.swaps_handedness());
  const camera plain = perspective_camera(look, with_fov(45), 64, 48);
  const camera mirror = perspective_camera(mirrored, with_fov(45), 64, 48);
  EXPECT_GT(dir_at(plain, 1.0f, 0.5f).x, 0.1f);
  EXPECT_LT(dir_at(mirror, 1.0f, 0.5f).x, -0.1f);  // the image's right is world -x
  expect_near(dir_at(mirror, 0.5f, 0.5f), {0, 0, 1});
  EXPECT_GT(dir_at(mirror, 0.5f, 0.0f).y, 0.1f);   // still up at the top
  // project() inverts generate() for both.
  for (const camera* c : {&plain, &mirror}) {
    const vec3 p = vec3(1, 2, 3) + 5.0f * c->generate(0.2f, 0.7f).d;
    float s = 0, t = 0;
    ASSERT_TRUE(c->project(p, s, t));
    EXPECT_NEAR(s, 0.2f, 1e-5f);
    EXPECT_NEAR(t, 0.7f, 1e-5f);
    float s2, t2;
    EXPECT_FALSE(c->project(vec3(1, 2, 3) - c->generate(0.5f, 0.5f).d, s2, t2));  // behind the camera
  }
}
