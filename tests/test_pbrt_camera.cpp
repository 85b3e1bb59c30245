// pbrt-v4's perspective camera as mcrt's pinhole camera
// (src/pbrt/camera.hpp): fov across the shorter axis, the image's right
// along pbrt's camera x (up x dir, from LookAt), row 0 at the top, and a
// camera-from-world matrix with a reflection ("Scale -1 1 1" before LookAt)
// used as it is: the image mirrored, and project() still the inverse of
// generate().
#include <gtest/gtest.h>

#include <cmath>

#include "mcrt/core/rng.hpp"
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

// A thin lens (lensradius, focaldistance): every ray of one image point
// starts on the lens disk around the eye, in the plane through the eye
// parallel to the image, and passes through the point the pinhole ray of
// that image point meets on the plane of focus; the lens points are uniform
// over the disk (mean offset 0, mean squared radius R^2 / 2); a radius of 0
// is the pinhole camera itself. Also through a mirrored matrix.
TEST(PbrtCamera, AThinLensFocusesOnThePlaneOfFocus) {
  const transform look = *transform::look_at({1, 2, 3}, {1, 2, 10}, {0, 1, 0});  // looking along +z
  for (const transform& m : {look, transform::scale({-1, 1, 1}) * look}) {
    perspective_params p = with_fov(40);
    const camera pinhole = perspective_camera(m, p, 64, 48);
    EXPECT_FALSE(pinhole.has_lens());
    p.lens_radius = 0.25;
    p.focal_distance = 6.5;
    const camera lens = perspective_camera(m, p, 64, 48);
    ASSERT_TRUE(lens.has_lens());
    pcg32 rng(3, 5);
    for (const vec2 st : {vec2(0.5f), vec2(0.1f, 0.9f), vec2(0.97f, 0.02f)}) {
      const ray pin = pinhole.generate(st.x, st.y);
      const vec3 focus = pin.o + 6.5f * pin.d;  // camera z = 6.5: the pinhole ray's d has camera z = 1
      EXPECT_NEAR(focus.z, 3.0f + 6.5f, 1e-4f);
      glm::dvec3 mean(0.0);
      double r2 = 0.0;
      const int n = 20000;
      for (int i = 0; i < n; ++i) {
        const ray r = lens.generate(st.x, st.y, rng.uniform2());
        const vec3 off = r.o - vec3(1, 2, 3);
        ASSERT_NEAR(off.z, 0.0f, 1e-6f);  // on the lens plane
        ASSERT_LE(glm::length(off), 0.25f * (1.0f + 1e-5f));
        // Through the focus point: the ray at camera z = 6.5.
        const float t = (focus.z - r.o.z) / r.d.z;
        ASSERT_LT(glm::length(r.o + t * r.d - focus), 1e-4f) << "image point " << st.x << ", " << st.y;
        mean += glm::dvec3(off);
        r2 += double(glm::dot(off, off));
      }
      // Uniform over the disk: mean 0 (s.e. 0.25 / sqrt(4 n) per axis) and
      // E r^2 = R^2 / 2 (s.e. R^2 / sqrt(12 n)), each within 5 s.e.
      EXPECT_LT(std::abs(mean.x / n), 5.0 * 0.25 / std::sqrt(4.0 * n));
      EXPECT_LT(std::abs(mean.y / n), 5.0 * 0.25 / std::sqrt(4.0 * n));
      EXPECT_NEAR(r2 / n, 0.0625 / 2.0, 5.0 * 0.0625 / std::sqrt(12.0 * n));
    }
    // Radius 0: the pinhole, whatever the lens sample.
    p.lens_radius = 0.0;
    const camera none = perspective_camera(m, p, 64, 48);
    EXPECT_FALSE(none.has_lens());
    const ray a = none.generate(0.3f, 0.6f, vec2(0.9f, 0.1f)), b = pinhole.generate(0.3f, 0.6f);
    EXPECT_EQ(a.o, b.o);
    EXPECT_EQ(a.d, b.d);
  }
}
