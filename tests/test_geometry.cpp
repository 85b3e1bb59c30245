// Ray-shape intersection: hits, misses, normals, front faces, flip, and the
// box's rotate_y/translate instancing.
#include <gtest/gtest.h>

#include "mcrt/mcrt.hpp"

using namespace mcrt;

namespace {

void expect_vec_near(const vec3& a, const vec3& b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

}  // namespace

TEST(Geometry, SphereHitFromOutsideAndInside) {
  const sphere s{{0, 0, 0}, 2.0f};
  hit_record rec;
  ASSERT_TRUE(s.hit({{0, 0, -10}, {0, 0, 1}}, 1e-3f, infinity, rec));
  EXPECT_NEAR(rec.t, 8.0f, 1e-5f);
  expect_vec_near(rec.n, {0, 0, -1}, 1e-6f);
  EXPECT_TRUE(rec.front_face);
  ASSERT_TRUE(s.hit({{0, 0, 0}, {0, 1, 0}}, 1e-3f, infinity, rec));  // from the centre
  EXPECT_NEAR(rec.t, 2.0f, 1e-5f);
  EXPECT_FALSE(rec.front_face);
  EXPECT_FALSE(s.hit({{0, 3, -10}, {0, 0, 1}}, 1e-3f, infinity, rec));  // passes above
  EXPECT_FALSE(s.hit({{0, 0, -10}, {0, 0, 1}}, 1e-3f, 5.0f, rec));     // beyond tmax
  const sphere f{{0, 0, 0}, 2.0f, true};
  ASSERT_TRUE(f.hit({{0, 0, -10}, {0, 0, 1}}, 1e-3f, infinity, rec));
  expect_vec_near(rec.n, {0, 0, 1}, 1e-6f);  // flipped: the front side is inside
  EXPECT_FALSE(rec.front_face);
}

TEST(Geometry, SmallFarSphereStillHit) {
  // The discriminant from the ray's distance to the centre stays accurate.
  const sphere s{{0, 0, 1e4f}, 1e-2f};
  hit_record rec;
  ASSERT_TRUE(s.hit({{0, 0, 0}, {0, 0, 1}}, 1e-3f, infinity, rec));
  EXPECT_NEAR(rec.t, 1e4f - 1e-2f, 1e-2f);
  EXPECT_TRUE(s.hit({{0, 0, 0}, glm::normalize(vec3{0.9e-6f, 0, 1})}, 1e-3f, infinity, rec));
}

TEST(Geometry, AxisRectsHaveTheContractsFrontNormals) {
  hit_record rec;
  const xz_rect_shape xz{0, 1, 0, 1, 2};  // z in [0,1], x in [0,1], y = 2
  ASSERT_TRUE(xz.hit({{0.5f, 5, 0.5f}, {0, -1, 0}}, 1e-3f, infinity, rec));
  expect_vec_near(rec.n, {0, 1, 0}, 0);
  EXPECT_TRUE(rec.front_face);
  EXPECT_NEAR(rec.t, 3.0f, 1e-6f);
  const xy_rect_shape xy{0, 1, 0, 1, 0};
  ASSERT_TRUE(xy.hit({{0.5f, 0.5f, -1}, {0, 0, 1}}, 1e-3f, infinity, rec));
  expect_vec_near(rec.n, {0, 0, 1}, 0);
  EXPECT_FALSE(rec.front_face);
  const yz_rect_shape yz{0, 1, 0, 1, 0, true};
  ASSERT_TRUE(yz.hit({{1, 0.5f, 0.5f}, {-1, 0, 0}}, 1e-3f, infinity, rec));
  expect_vec_near(rec.n, {-1, 0, 0}, 0);
  EXPECT_FALSE(rec.front_face);  // flipped: +x side is now the back
  EXPECT_FALSE(yz.hit({{1, 1.5f, 0.5f}, {-1, 0, 0}}, 1e-3f, infinity, rec));
}

TEST(Geometry, AxisRectAgreesWithGeneralRect) {
  // The same rectangle as the fast axis-aligned shape and as a general one:
  // same hits, same t, same front normal.
  const xz_rect_shape a{227, 332, 213, 343, 554, true};
  const rect r = a.to_rect();
  const rect f = xz_rect(213, 343, 227, 332, 554, true);
  expect_vec_near(r.n, f.n, 0);
  expect_vec_near(r.n, {0, -1, 0}, 0);
  EXPECT_NEAR(r.area, 130.0f * 105.0f, 1e-2f);
  pcg32 rng(3, 4);
  for (int i = 0; i < 10000; ++i) {
    const vec3 o{rng.uniform() * 555, rng.uniform() * 554, rng.uniform() * 555};
    const vec3 d = glm::normalize(square_to_uniform_sphere(rng.uniform2()));
    hit_record ha, hr;
    const bool ba = a.hit({o, d}, 1e-3f, infinity, ha), br = r.hit({o, d}, 1e-3f, infinity, hr);
    ASSERT_EQ(ba, br) << i;
    if (ba) {
      EXPECT_NEAR(ha.t, hr.t, 1e-3f);
      expect_vec_near(ha.n, hr.n, 0);
      EXPECT_EQ(ha.front_face, hr.front_face);
    }
  }
}

TEST(Geometry, GeneralRectAndEllipse) {
  const rect r = rect::make({0, 0, 0}, {2, 0, 0}, {0, 0, -1});  // n = x cross -z = +y
  expect_vec_near(r.n, {0, 1, 0}, 1e-6f);
  hit_record rec;
  ASSERT_TRUE(r.hit({{1, 1, -0.5f}, {0, -1, 0}}, 1e-3f, infinity, rec));
  EXPECT_TRUE(rec.front_face);
  EXPECT_FALSE(r.hit({{1, 1, 0.5f}, {0, -1, 0}}, 1e-3f, infinity, rec));
  const rect rf = rect::make({0, 0, 0}, {2, 0, 0}, {0, 0, -1}, true);
  expect_vec_near(rf.n, {0, -1, 0}, 1e-6f);

  const ellipse e = ellipse::make({0, 0, 0}, {3, 0, 0}, {0, 1, 0});  // n = +z
  expect_vec_near(e.n, {0, 0, 1}, 1e-6f);
  EXPECT_NEAR(e.area, pi * 3.0f, 1e-5f);
  EXPECT_TRUE(e.hit({{2.9f, 0, 1}, {0, 0, -1}}, 1e-3f, infinity, rec));
  EXPECT_TRUE(rec.front_face);
  EXPECT_FALSE(e.hit({{2.9f, 0.5f, 1}, {0, 0, -1}}, 1e-3f, infinity, rec));  // inside the box, outside the ellipse
  EXPECT_TRUE(e.hit({{0, 0.99f, 1}, {0, 0, -1}}, 1e-3f, infinity, rec));
  EXPECT_TRUE(e.faces({0, 0, 1}));
  EXPECT_FALSE(e.faces({0, 0, -1}));
}

TEST(Geometry, BoxFacesAndNormals) {
  const box b{{0, 0, 0}, {1, 2, 3}};
  hit_record rec;
  ASSERT_TRUE(b.hit({{0.5f, 1, -5}, {0, 0, 1}}, 1e-3f, infinity, rec));
  EXPECT_NEAR(rec.t, 5.0f, 1e-5f);
  expect_vec_near(rec.n, {0, 0, -1}, 0);
  EXPECT_TRUE(rec.front_face);
  ASSERT_TRUE(b.hit({{0.5f, 1, 1}, {1, 0, 0}}, 1e-3f, infinity, rec));  // from inside
  EXPECT_NEAR(rec.t, 0.5f, 1e-5f);
  expect_vec_near(rec.n, {1, 0, 0}, 0);
  EXPECT_FALSE(rec.front_face);
  EXPECT_FALSE(b.hit({{0.5f, 3, -5}, {0, 0, 1}}, 1e-3f, infinity, rec));
}

TEST(Geometry, BoxRotateYTranslate) {
  // Shirley's tall box: rotated 15 degrees about y, then moved to (265,0,295).
  const rigid_y xf = rigid_y::make(15.0f, {265, 0, 295});
  const box b{{0, 0, 0}, {165, 330, 165}, xf};
  // Local corner (165, 0, 0) lands at R_y(15)(165,0,0) + t.
  const float c = std::cos(glm::radians(15.0f)), s = std::sin(glm::radians(15.0f));
  expect_vec_near(xf.to_world({165, 0, 0}), {265 + 165 * c, 0, 295 - 165 * s}, 1e-3f);
  expect_vec_near(xf.to_local(xf.to_world({1, 2, 3})), {1, 2, 3}, 1e-4f);
  // A ray straight down through the rotated box's centre hits its top at y=330
  // with normal +y.
  const vec3 centre = xf.to_world({82.5f, 0, 82.5f});
  hit_record rec;
  ASSERT_TRUE(b.hit({centre + vec3(0, 1000, 0), {0, -1, 0}}, 1e-3f, infinity, rec));
  EXPECT_NEAR(rec.p.y, 330.0f, 1e-2f);
  expect_vec_near(rec.n, {0, 1, 0}, 1e-6f);
  // A ray along -z at the local face x=0 plane's outside misses; the rotated
  // face normal of local -x is R_y(-x).
  const vec3 face_point = xf.to_world({0, 100, 82.5f});
  const vec3 nx = xf.rotate({-1, 0, 0});
  ASSERT_TRUE(b.hit({face_point + 10.0f * nx, -nx}, 1e-3f, infinity, rec));
  EXPECT_NEAR(rec.t, 10.0f, 1e-2f);
  expect_vec_near(rec.n, nx, 1e-5f);
  // Generic instancing agrees with the box's own transform.
  const transformed<box> tb{box{{0, 0, 0}, {165, 330, 165}}, xf};
  hit_record r2;
  ASSERT_TRUE(tb.hit({face_point + 10.0f * nx, -nx}, 1e-3f, infinity, r2));
  EXPECT_NEAR(r2.t, rec.t, 1e-3f);
  expect_vec_near(r2.n, rec.n, 1e-5f);
}

TEST(Geometry, SceneReturnsClosestHitAndItsMaterial) {
  scene sc;
  sc.materials = {lambertian{}, lambertian{}};
  sc.add(xy_rect_shape{-1, 1, -1, 1, 5}, 0);
  sc.add(sphere{{0, 0, 2}, 1.0f}, 1);
  hit_record rec;
  ASSERT_TRUE(sc.hit({{0, 0, -5}, {0, 0, 1}}, 1e-3f, infinity, rec));
  EXPECT_NEAR(rec.t, 6.0f, 1e-5f);
  EXPECT_EQ(rec.material, 1u);
  ASSERT_TRUE(sc.hit({{0.9f, 0.9f, -5}, {0, 0, 1}}, 1e-3f, infinity, rec));
  EXPECT_NEAR(rec.t, 10.0f, 1e-5f);
  EXPECT_EQ(rec.material, 0u);
  EXPECT_EQ(sc.object_count(), 2u);
}

TEST(Geometry, AxisRectSetAgreesWithItsMembers) {
  // Eleven rectangles (two blocks of lanes, the second partly empty) tested
  // as a set and one by one: same nearest hit, same record.
  axis_rect_set set;
  std::vector<any_axis_rect> all;
  pcg32 rng(5, 6);
  for (int i = 0; i < 11; ++i) {
    const int axis = i % 3;
    const float a0 = rng.uniform() * 4 - 2, b0 = rng.uniform() * 4 - 2;
    const any_axis_rect m{axis, a0, a0 + 0.2f + rng.uniform(), b0, b0 + 0.2f + rng.uniform(), rng.uniform() * 4 - 2,
                          (i % 2) == 1, static_cast<std::uint32_t>(i)};
    set.add(m);
    all.push_back(m);
  }
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const ray r{{rng.uniform() * 6 - 3, rng.uniform() * 6 - 3, rng.uniform() * 6 - 3},
                square_to_uniform_sphere(rng.uniform2())};
    float best = infinity;
    int best_i = -1;
    for (int j = 0; j < 11; ++j) {
      const any_axis_rect& m = all[static_cast<std::size_t>(j)];
      const float t = (m.k - r.o[m.axis]) / r.d[m.axis];
      const float pu = r.o[(m.axis + 1) % 3] + t * r.d[(m.axis + 1) % 3];
      const float pv = r.o[(m.axis + 2) % 3] + t * r.d[(m.axis + 2) % 3];
      if (t > 1e-3f && t < best && pu >= m.a0 && pu <= m.a1 && pv >= m.b0 && pv <= m.b1) best = t, best_i = j;
    }
    float t;
    const any_axis_rect* m = nullptr;
    const bool hit = set.intersect(r, 1e-3f, infinity, t, m);
    ASSERT_EQ(hit, best_i >= 0) << i;
    if (hit) {
      ++hits;
      EXPECT_EQ(t, best);
      EXPECT_EQ(m->material, static_cast<std::uint32_t>(best_i));
      hit_record rec;
      m->surface(r, t, rec);
      EXPECT_EQ(rec.p[m->axis], m->k);
      EXPECT_EQ(std::abs(rec.n[m->axis]), 1.0f);
    }
  }
  EXPECT_GT(hits, 400);  // enough hits for the comparison to mean something
}
