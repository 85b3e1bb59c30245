// Ray-shape intersection: hits, misses, normals, front faces, flip, and the
// box's rotate_y/translate instancing.
#include <gtest/gtest.h>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

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

// ---------------------------------------------------------------------------
// Rectangles in a scene against a direct reference intersection.
//
// A scene keeps a rectangle in its axis-aligned set only when both edges lie
// along coordinate axes; every other rectangle, including one whose normal
// is a coordinate axis but whose edges are turned in its plane, is a general
// `rect`. Whatever the scene keeps, scene::hit must find the rectangle the
// corner and edges describe. The reference intersects in double precision:
// the ray meets the plane at t = n.(c - o) / n.d, and the point
// q = o + t d - c is inside where q.e1 / |e1|^2 and q.e2 / |e2|^2 lie in
// [0, 1]; the nearest such rectangle is the hit.
//
// Band of rounding. The scene computes in single precision. Its hit point
// in the plane is uncertain by about delta = 64 * 2^-24 * s / |cos|, with
// s the size of the numbers involved (|o| + |c| + |e1| + |e2| + t) and cos
// the cosine between the ray and the rectangle's normal; the ray parameter
// by the same amount (|d| = 1). A ray whose reference hit point lies within
// delta of an edge of any rectangle, whose hit lies within delta of the
// ray's t_min, or whose two nearest hits are within delta of each other is
// left out (counted, and required to be rare); every other ray must agree:
// hit or miss, t within delta, the rectangle (its material), its front
// normal and the side the ray arrives at.
namespace {

enum class rect_kind { general, axis_normal_turned_edges, axis_edges };

// A rectangle of the given kind with edges of 0.1-1.6, its corner in [-2, 2]^3.
rect random_rect(pcg32& rng, rect_kind kind) {
  const vec3 corner{rng.uniform() * 4 - 2, rng.uniform() * 4 - 2, rng.uniform() * 4 - 2};
  const float l1 = 0.1f + 1.5f * rng.uniform(), l2 = 0.1f + 1.5f * rng.uniform();
  const bool flip = rng.uniform() < 0.5f;
  vec3 e1, e2;
  if (kind == rect_kind::general) {
    const vec3 u = square_to_uniform_sphere(rng.uniform2());
    const vec3 w = square_to_uniform_sphere(rng.uniform2());
    const vec3 v = glm::normalize(glm::cross(u, w));
    e1 = l1 * u;
    e2 = l2 * v;
  } else {
    const int axis = static_cast<int>(rng.uniform() * 3);
    int a = (axis + 1) % 3, b = (axis + 2) % 3;
    if (rng.uniform() < 0.5f) std::swap(a, b);
    vec3 ua(0.0f), ub(0.0f);
    ua[a] = rng.uniform() < 0.5f ? -1.0f : 1.0f;
    ub[b] = rng.uniform() < 0.5f ? -1.0f : 1.0f;
    if (kind == rect_kind::axis_edges) {
      e1 = l1 * ua;
      e2 = l2 * ub;
    } else {
      // Turned in the plane by an angle in (1, 89) degrees, or the 30.
      const float phi = rng.uniform() < 0.25f ? glm::radians(30.0f) : glm::radians(1.0f + 88.0f * rng.uniform());
      e1 = l1 * (std::cos(phi) * ua + std::sin(phi) * ub);
      e2 = l2 * (-std::sin(phi) * ua + std::cos(phi) * ub);
      e1[axis] = e2[axis] = 0.0f;  // exactly in the coordinate plane
    }
  }
  return rect::make(corner, e1, e2, flip);
}

struct reference_hit {
  bool hit = false;
  bool in_band = false;  // too close to an edge or to t_min to decide in single precision
  double t = 0.0, delta = 0.0;
};

reference_hit reference_intersection(const rect& r, const ray& ry, double tmin) {
  using glm::dvec3;
  const dvec3 o(ry.o), d(ry.d), c(r.corner), e1(r.e1), e2(r.e2);
  const dvec3 n = glm::normalize(glm::cross(e1, e2));
  reference_hit h;
  const double cosine = glm::dot(n, d);
  if (std::abs(cosine) < 1e-6) {  // (nearly) parallel: no decision in single precision
    h.in_band = true;
    return h;
  }
  h.t = glm::dot(n, c - o) / cosine;
  const double size = glm::length(o) + glm::length(c) + glm::length(e1) + glm::length(e2) + std::abs(h.t);
  h.delta = 64.0 * 0x1p-24 * size / std::abs(cosine);
  if (std::abs(h.t - tmin) < h.delta) h.in_band = true;
  if (h.t <= tmin) return h;
  const dvec3 q = o + h.t * d - c;
  const double l1 = glm::length(e1), l2 = glm::length(e2);
  const double u = glm::dot(q, e1) / l1, v = glm::dot(q, e2) / l2;  // lengths along the edges
  const bool inside = u >= 0 && u <= l1 && v >= 0 && v <= l2;
  const double edge = std::min({std::abs(u), std::abs(u - l1), std::abs(v), std::abs(v - l2)});
  // Near an edge line only matters where the point is near the rectangle.
  if (edge < h.delta && u > -h.delta && u < l1 + h.delta && v > -h.delta && v < l2 + h.delta) h.in_band = true;
  h.hit = inside;
  return h;
}

}  // namespace

TEST(Geometry, SceneRectanglesAgreeWithADirectReferenceIntersection) {
  pcg32 rng(2028, 28);
  const float tmin = 1e-4f;
  int rays = 0, hits = 0, band = 0;
  int kind_hits[3] = {0, 0, 0};
  for (int trial = 0; trial < 3000; ++trial) {
    // 1 to 6 rectangles of mixed kinds, some added as lights (the same
    // geometry path a light's shape takes).
    const int count = 1 + static_cast<int>(rng.uniform() * 6);
    scene sc;
    std::vector<rect> rects;
    std::vector<rect_kind> kinds;
    for (int j = 0; j < count; ++j) {
      const auto kind = static_cast<rect_kind>(static_cast<int>(rng.uniform() * 3));
      rects.push_back(random_rect(rng, kind));
      kinds.push_back(kind);
      sc.materials.push_back(lambertian{});
      if (rng.uniform() < 0.5f)
        sc.add(rects.back(), static_cast<std::uint32_t>(j));
      else
        sc.add_light(rect_area_sampler{rects.back()}, static_cast<std::uint32_t>(j));
    }
    for (int i = 0; i < 100; ++i) {
      // From a point in [-4, 4]^3 towards a point about a random rectangle
      // (its parameters in [-0.25, 1.25]^2, so about half of these hit it),
      // or in a uniform direction.
      const vec3 o{rng.uniform() * 8 - 4, rng.uniform() * 8 - 4, rng.uniform() * 8 - 4};
      const rect& aim = rects[static_cast<std::size_t>(rng.uniform() * static_cast<float>(count))];
      const vec3 target = aim.corner + (rng.uniform() * 1.5f - 0.25f) * aim.e1 + (rng.uniform() * 1.5f - 0.25f) * aim.e2;
      vec3 d = rng.uniform() < 0.8f ? target - o : square_to_uniform_sphere(rng.uniform2());
      if (!(glm::length(d) > 1e-3f)) continue;
      d = glm::normalize(d);
      const ray ry{o, d};

      int best = -1;
      double best_t = 0.0, second_t = std::numeric_limits<double>::infinity(), best_delta = 0.0;
      bool ambiguous = false;
      for (int j = 0; j < count; ++j) {
        const reference_hit h = reference_intersection(rects[static_cast<std::size_t>(j)], ry, tmin);
        ambiguous = ambiguous || h.in_band;
        if (!h.hit) continue;
        if (best < 0 || h.t < best_t) {
          second_t = best < 0 ? second_t : best_t;
          best = j, best_t = h.t, best_delta = h.delta;
        } else {
          second_t = std::min(second_t, h.t);
        }
      }
      if (best >= 0 && second_t - best_t < 2.0 * best_delta) ambiguous = true;
      ++rays;
      if (ambiguous) {
        ++band;
        continue;
      }
      hit_record rec;
      const bool hit = sc.hit(ry, tmin, infinity, rec);
      ASSERT_EQ(hit, best >= 0) << "trial " << trial << " ray " << i << ": reference "
                                << (best >= 0 ? "hits rectangle " + std::to_string(best) : std::string("misses"));
      if (!hit) continue;
      ++hits;
      ++kind_hits[static_cast<int>(kinds[static_cast<std::size_t>(best)])];
      const rect& r = rects[static_cast<std::size_t>(best)];
      ASSERT_EQ(rec.material, static_cast<std::uint32_t>(best)) << "trial " << trial << " ray " << i;
      EXPECT_NEAR(rec.t, best_t, best_delta) << "trial " << trial << " ray " << i;
      expect_vec_near(rec.n, r.n, 1e-6f);
      EXPECT_EQ(rec.front_face, glm::dot(d, r.n) < 0.0f);
    }
  }
  // Every kind is hit often; the band leaves out few rays.
  EXPECT_GT(hits, 50000);
  for (int k = 0; k < 3; ++k) EXPECT_GT(kind_hits[k], 10000) << "kind " << k;
  EXPECT_LT(band, rays / 100) << band << " of " << rays << " rays in the band of rounding";
  std::cout << rays << " rays, " << hits << " hits (general " << kind_hits[0] << ", axis normal with turned edges "
            << kind_hits[1] << ", axis edges " << kind_hits[2] << "), " << band << " in the band\n";
}

// Only a rectangle whose two edges lie along coordinate axes is an
// axis-aligned one, with the extent its edges span; a rectangle whose normal
// is an axis but whose edges are turned in its plane is not.
TEST(Geometry, OnlyRectanglesWithEdgesAlongTheAxesAreAxisAligned) {
  const float c = std::cos(glm::radians(30.0f)), s = std::sin(glm::radians(30.0f));
  // The rectangle of the bug: horizontal, facing down, edges turned 30 degrees.
  const rect turned = rect::make({0, 1, 0}, 0.8f * vec3(c, 0, s), 0.5f * vec3(-s, 0, c));
  ASSERT_EQ(turned.n, vec3(0, -1, 0));  // its normal is exactly an axis
  EXPECT_FALSE(as_axis_rect(turned, 0).has_value());
  // Edges along the axes, in either order and with either sign.
  const rect along = rect::make({1, 2, 3}, {0, 0, -0.5f}, {0.8f, 0, 0});  // -z x +x = -y
  const auto a = as_axis_rect(along, 7);
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->axis, 1);
  EXPECT_EQ(a->k, 2.0f);
  EXPECT_EQ(a->a0, 2.5f);  // z in [2.5, 3]
  EXPECT_EQ(a->a1, 3.0f);
  EXPECT_EQ(a->b0, 1.0f);  // x in [1, 1.8]
  EXPECT_EQ(a->b1, 1.8f);
  EXPECT_TRUE(a->flip);
  EXPECT_EQ(a->material, 7u);
  // Shirley's factories give axis-aligned rectangles.
  EXPECT_TRUE(as_axis_rect(xz_rect(0, 1, 0, 1, 2), 0).has_value());
  EXPECT_TRUE(as_axis_rect(xy_rect(0, 1, 0, 1, 2, true), 0).has_value());
  EXPECT_TRUE(as_axis_rect(yz_rect(0, 1, 0, 1, 2), 0).has_value());
  // A tilted normal is no axis-aligned rectangle either.
  EXPECT_FALSE(as_axis_rect(rect::make({0, 0, 0}, {1, 0, 0}, {0, 1, 1e-3f}), 0).has_value());
  // In a scene: the turned rectangle is kept whole, and its corner region
  // that the old extent from corner to corner + e1 + e2 left out is hit.
  scene sc;
  sc.materials = {lambertian{}};
  sc.add(turned, 0);
  EXPECT_EQ(sc.axis_rects.size(), 0u);
  const vec3 p = turned.corner + 0.95f * turned.e1 + 0.05f * turned.e2;  // x = 0.65, beyond the far corner's x (0.44)
  hit_record rec;
  EXPECT_TRUE(sc.hit({p + vec3(0, 1, 0), {0, -1, 0}}, 1e-4f, infinity, rec));
  EXPECT_NEAR(rec.t, 1.0f, 1e-6f);
}

// spawn_origin's rounding away from the surface (detail::step_away) is
// next_float_up for a positive move and next_float_down for a negative one,
// bit for bit: on zeros of both signs, denormals, normals of every
// magnitude, the largest floats and infinities.
TEST(Geometry, SpawnOriginsRoundingStepIsNextFloatUpOrDown) {
  std::vector<float> values = {0.0f, -0.0f, std::numeric_limits<float>::denorm_min(),
                               -std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::min(),
                               -std::numeric_limits<float>::min(), std::numeric_limits<float>::max(),
                               -std::numeric_limits<float>::max(), std::numeric_limits<float>::infinity(),
                               -std::numeric_limits<float>::infinity(), 1.0f, -1.0f, 555.0f, -1e4f};
  mcrt::pcg32 rng(7, 1);
  for (int i = 0; i < 100000; ++i) {
    // Random bit patterns: every exponent alike, NaNs skipped.
    const float v = std::bit_cast<float>(rng.next_u32());
    if (!std::isnan(v)) values.push_back(v);
  }
  const auto bits = [](float x) { return std::bit_cast<std::uint32_t>(x); };
  for (const float v : values) {
    ASSERT_EQ(bits(mcrt::detail::step_away(v, 1e-3f)), bits(mcrt::next_float_up(v))) << v;
    ASSERT_EQ(bits(mcrt::detail::step_away(v, -1e-3f)), bits(mcrt::next_float_down(v))) << v;
    ASSERT_EQ(bits(mcrt::detail::step_away(v, 0.0f)), bits(v)) << v;
  }
}
