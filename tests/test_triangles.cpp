// Triangle meshes (geometry/triangle_mesh.hpp) and triangle lights sampled by
// area (sampling/triangle_area.hpp).
//
// Intersection: random rays against random triangles agree with a
// double-precision reference outside a band of rounding; watertightness:
// rays aimed exactly at the shared edges and vertices of a triangulated grid
// far from the origin (1e3 - 1e4) never fall through it; no
// self-intersection: rays leaving a hit point from spawn_origin, to either
// side and at grazing angles, never meet the triangle again; orientation as
// pbrt-v4 (winding, ReverseOrientation, shading normals).
// Sampling: the triplet (sample, returned pdf, pdf()) agrees, E[1/pdf] is
// the triangle's solid angle (Van Oosterom & Strackee) within 1 %, the
// chi-square test of the harness (tests/support/chi2.hpp: 1 % family-wise),
// and the square map's inverse round-trips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>

#include "mcrt/mcrt.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/triangle_area.hpp"
#include "support/chi2.hpp"
#include "support/solid_angle.hpp"

using namespace mcrt;

namespace {

std::shared_ptr<triangle_mesh> one_triangle(const vec3& a, const vec3& b, const vec3& c) {
  auto m = std::make_shared<triangle_mesh>();
  m->p = {a, b, c};
  m->indices = {0, 1, 2};
  return m;
}

vec3 random_in_box(pcg32& rng, float half) {
  return {(rng.uniform() * 2 - 1) * half, (rng.uniform() * 2 - 1) * half, (rng.uniform() * 2 - 1) * half};
}

}  // namespace

TEST(Triangles, AgreeWithADirectReferenceIntersection) {
  // Reference in double: t from the plane, barycentrics from sub-areas.
  // Band: rays whose reference point lies within delta = 64 * 2^-24 * size /
  // |cos| of an edge (relative to the triangle's size), or whose t is within
  // delta of 0, are left out.
  pcg32 rng(31, 1);
  int rays = 0, hits = 0, band = 0;
  for (int i = 0; i < 200000; ++i) {
    const vec3 offset = rng.uniform() < 0.3f ? random_in_box(rng, 1e3f) : vec3(0.0f);
    const vec3 a = offset + random_in_box(rng, 2), b = offset + random_in_box(rng, 2), c = offset + random_in_box(rng, 2);
    const auto mesh = one_triangle(a, b, c);
    const triangle tri{mesh, 0};
    const vec3 o = offset + random_in_box(rng, 5);
    const vec3 target = (a + b + c) / 3.0f + 0.4f * glm::length(b - a) * random_in_box(rng, 1);
    if (!(glm::length(target - o) > 1e-3f)) continue;
    const vec3 d = glm::normalize(target - o);
    const glm::dvec3 A(a), B(b), C(c), O(o), D(d);
    const glm::dvec3 nn = glm::cross(B - A, C - A);
    const double area2 = glm::length(nn);
    if (!(area2 > 1e-6)) continue;
    const glm::dvec3 n = nn / area2;
    const double cosine = glm::dot(n, D);
    ++rays;
    if (std::abs(cosine) < 1e-4) {
      ++band;
      continue;
    }
    const double t = glm::dot(n, A - O) / cosine;
    const glm::dvec3 p = O + t * D;
    const double w0 = glm::dot(glm::cross(B - p, C - p), n) / area2, w1 = glm::dot(glm::cross(C - p, A - p), n) / area2;
    const double w2 = 1.0 - w0 - w1;
    const double size = glm::length(O) + glm::length(A) + glm::length(B - A) + glm::length(C - A) + std::abs(t);
    const double delta = 64.0 * 0x1p-24 * size / std::abs(cosine);
    const double edge = std::min({w0, w1, w2}) * area2 / std::max({glm::length(B - A), glm::length(C - B), glm::length(A - C)});
    if (std::abs(edge) < delta || std::abs(t) < delta) {
      ++band;
      continue;
    }
    const bool ref_hit = t > 0.0 && w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0;
    float th = 0.0f;
    const bool got = tri.intersect({o, d}, 0.0f, infinity, th);
    ASSERT_EQ(got, ref_hit) << "ray " << i << ": t " << t << " barycentrics " << w0 << " " << w1 << " " << w2;
    if (got) {
      ++hits;
      EXPECT_NEAR(th, t, delta) << i;
    }
  }
  EXPECT_GT(hits, rays / 5);
  EXPECT_LT(band, rays / 50) << band << " of " << rays;
  std::printf("%d rays, %d hits, %d in the band\n", rays, hits, band);
}

TEST(Triangles, AreWatertightAtSharedEdgesAndVertices) {
  // A 16 x 16 grid of squares, two triangles each, in the plane z = z0 at
  // x, y in [c, c + 16]; rays from random points above aimed exactly at
  // grid vertices and at points of shared edges (and at centres, for
  // contrast) must hit one of the triangles, far from the origin too, where
  // a test that is not watertight loses rays between triangles.
  for (const float c : {0.0f, 1000.0f, 10000.0f}) {
    auto mesh = std::make_shared<triangle_mesh>();
    const int n = 16;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) mesh->p.push_back({c + float(i), c + float(j), 0.5f * c});
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const auto v = static_cast<std::uint32_t>(j * (n + 1) + i);
        mesh->indices.insert(mesh->indices.end(), {v, v + 1, v + n + 2, v, v + n + 2, v + n + 1});
      }
    const std::vector<triangle> tris = triangles_of(mesh);
    pcg32 rng(7, static_cast<std::uint64_t>(c));
    int misses = 0, shots = 0;
    for (int k = 0; k < 40000; ++k) {
      // Vertex, edge point (on a grid line or the diagonal) or centre.
      const int i = 1 + static_cast<int>(rng.uniform() * (n - 2)), j = 1 + static_cast<int>(rng.uniform() * (n - 2));
      vec3 target{c + float(i), c + float(j), 0.5f * c};
      const float f = rng.uniform();
      switch (k % 4) {
        case 1: target.x += f; break;                  // horizontal edge
        case 2: target.y += f; break;                  // vertical edge
        case 3: target.x += f, target.y += f; break;   // the diagonal
        default: break;                                // the vertex
      }
      const vec3 o = target + vec3((rng.uniform() - 0.5f) * 50.0f, (rng.uniform() - 0.5f) * 50.0f, 1.0f + 30.0f * rng.uniform());
      const ray r{o, glm::normalize(target - o)};
      bool hit = false;
      for (const triangle& t : tris) {
        float th;
        hit = hit || t.intersect(r, 0.0f, infinity, th);
      }
      ++shots;
      misses += !hit;
    }
    EXPECT_EQ(misses, 0) << misses << " of " << shots << " rays fell through the grid at " << c;
  }
}

TEST(Triangles, RaysLeavingAHitPointDoNotMeetTheTriangleAgain) {
  // Hit points on triangles at 1 to 1e4 from the origin, rays spawned from
  // spawn_origin to either side, down to grazing angles (1e-4 rad above the
  // plane): none meets the triangle it leaves (tmin = 0).
  pcg32 rng(11, 3);
  int checked = 0;
  for (const float scale : {1.0f, 1e3f, 1e4f})
    for (int k = 0; k < 20000; ++k) {
      const vec3 offset = random_in_box(rng, scale);
      const vec3 a = offset + random_in_box(rng, 1), b = offset + random_in_box(rng, 1), c = offset + random_in_box(rng, 1);
      const auto mesh = one_triangle(a, b, c);
      const triangle tri{mesh, 0};
      if (!(tri.area() > 1e-3f)) continue;
      const vec3 o = (a + b + c) / 3.0f + tri.normal() * 2.0f + random_in_box(rng, 0.3f);
      const vec3 target = 0.5f * a + 0.3f * b + 0.2f * c;
      const ray r{o, glm::normalize(target - o)};
      hit_record rec;
      if (!tri.hit(r, 0.0f, infinity, rec)) continue;
      // A direction on either side, at an elevation from 1e-4 to pi/2 rad.
      const vec3 n = rec.n;
      onb frame(n);
      const float elevation = std::pow(10.0f, -4.0f + 4.2f * rng.uniform());
      const float phi = two_pi * rng.uniform();
      vec3 dir = frame.to_world({std::cos(elevation) * std::cos(phi), std::cos(elevation) * std::sin(phi),
                                  std::min(std::sin(elevation), 1.0f)});
      if (rng.uniform() < 0.5f) dir -= 2.0f * glm::dot(dir, n) * n;  // the other side
      dir = glm::normalize(dir);
      float t;
      ASSERT_FALSE(tri.intersect({rec.spawn_origin(dir), dir}, 0.0f, infinity, t))
          << "self-intersection at scale " << scale << " t " << t << " elevation " << elevation;
      ++checked;
    }
  EXPECT_GT(checked, 50000);
}

TEST(Triangles, OrientationAsPbrt) {
  const auto m = one_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  EXPECT_EQ(triangle({m, 0}).normal(), vec3(0, 0, 1));  // (p1 - p0) x (p2 - p0)
  auto r = std::make_shared<triangle_mesh>(*m);
  r->reverse_orientation = true;
  EXPECT_EQ(triangle({r, 0}).normal(), vec3(0, 0, -1));
  auto s = std::make_shared<triangle_mesh>(*m);
  s->n = {vec3(0, 0, -1), vec3(0, 0.1f, -1), vec3(0.1f, 0, -1)};  // shading normals below: the normal faces them
  EXPECT_EQ(triangle({s, 0}).normal(), vec3(0, 0, -1));
  hit_record rec;
  ASSERT_TRUE(triangle({m, 0}).hit({{0.2f, 0.2f, 1}, {0, 0, -1}}, 0.0f, infinity, rec));
  EXPECT_TRUE(rec.front_face);
  EXPECT_NEAR(rec.t, 1.0f, 1e-6f);
  EXPECT_EQ(rec.p.z, 0.0f);
  EXPECT_FALSE(triangle({m, 0}).hit({{0.6f, 0.6f, 1}, {0, 0, -1}}, 0.0f, infinity, rec));  // beyond the hypotenuse
  // Degenerate triangles are never hit.
  const auto flat = one_triangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0});
  EXPECT_FALSE(triangle({flat, 0}).hit({{0.5f, 1, 0}, {0, -1, 0}}, 0.0f, infinity, rec));
}

namespace {

struct tri_case {
  const char* name;
  vec3 a, b, c, o;
};

const tri_case tri_cases[] = {
    {"below", {-1, 2, -1}, {1, 2, -1}, {0, 2, 1.5f}, {0.1f, 0, 0.2f}},
    {"close", {-1, 2, -1}, {1, 2, -1}, {0, 2, 1.5f}, {0.1f, 1.9f, 0.0f}},
    {"grazing", {-1, 2, -1}, {1, 2, -1}, {0, 2, 1.5f}, {3.0f, 1.99f, 0.5f}},
    {"far_sliver", {0, 0, 0}, {100, 0, 0}, {50, 0.05f, 1}, {40, -300, 10}},
};

triangle_area_sampler sampler_of(const tri_case& c) {
  // The mesh is kept alive by the sampler's triangle.
  return triangle_area_sampler(triangle{one_triangle(c.a, c.b, c.c), 0});
}

}  // namespace

TEST(TriangleAreaSampler, TripletAgreesAndInverseRoundTrips) {
  for (const tri_case& c : tri_cases) {
    const triangle_area_sampler s = sampler_of(c);
    pcg32 rng(5, 9);
    int n = 0;
    for (int i = 0; i < 20000; ++i) {
      const vec2 u = rng.uniform2();
      light_sample ls;
      if (!s.sample(c.o, u, ls)) continue;
      ++n;
      ASSERT_TRUE(std::isfinite(ls.pdf) && ls.pdf > 0.0f) << c.name;
      const float p = s.pdf(c.o, ls.dir);
      EXPECT_NEAR(p, ls.pdf, 2e-3f * ls.pdf) << c.name << " u " << u.x << " " << u.y;
      const vec2 back = triangle_to_square(square_to_triangle(u));
      EXPECT_NEAR(back.x, u.x, 2e-6f);
      EXPECT_NEAR(back.y, u.y, 2e-4f);
    }
    EXPECT_EQ(n, 20000) << c.name << ": the observer is in front";
    // Behind the light: nothing.
    light_sample ls;
    const vec3 behind = c.o - 2.0f * glm::dot(c.o - c.a, s.n) * s.n;
    EXPECT_FALSE(s.sample(behind, {0.3f, 0.3f}, ls));
    EXPECT_EQ(s.pdf(behind, glm::normalize((c.a + c.b + c.c) / 3.0f - behind)), 0.0f);
  }
}

TEST(TriangleAreaSampler, ExpectedInversePdfIsTheSolidAngle) {
  for (const tri_case& c : tri_cases) {
    const triangle_area_sampler s = sampler_of(c);
    const double omega =
        test::solid_angle_triangle(glm::dvec3(c.o), glm::dvec3(s.p0), glm::dvec3(s.p1), glm::dvec3(s.p2));
    // Stratified over the square (256 x 256 jittered), so that the heavy
    // tail of 1/pdf near a close observer averages well.
    pcg32 rng(17, 2);
    double sum = 0.0;
    const int k = 256;
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) {
        light_sample ls;
        ASSERT_TRUE(s.sample(c.o, {(i + rng.uniform()) / k, (j + rng.uniform()) / k}, ls));
        sum += 1.0 / ls.pdf;
      }
    EXPECT_NEAR(sum / (k * k), omega, 0.01 * omega) << c.name;
  }
}

TEST(TriangleAreaSampler, ChiSquare) {
  std::uint64_t seed = 40;
  for (const tri_case& c : {tri_cases[0], tri_cases[2], tri_cases[3]}) {
    const triangle_area_sampler s = sampler_of(c);
    // A cap about the direction to the centroid that holds the three vertices.
    const dvec3 o(c.o);
    const dvec3 axis = glm::normalize(dvec3((s.p0 + s.p1 + s.p2) / 3.0f) - o);
    double one_minus_cos = 0.0;
    for (const vec3& v : {s.p0, s.p1, s.p2}) one_minus_cos = std::max(one_minus_cos, 1.0 - glm::dot(axis, glm::normalize(dvec3(v) - o)));
    one_minus_cos = std::min(2.0, one_minus_cos * 1.01 + 1e-9);
    const test::chi2_result r = test::chi2_test_directions(
        [&](pcg32& rng, vec3& dir) {
          light_sample ls;
          if (!s.sample(c.o, rng.uniform2(), ls)) return false;
          dir = ls.dir;
          return true;
        },
        [&](const vec3& dir) { return s.pdf(c.o, dir); }, axis, one_minus_cos,
        {.sample_count = 1000000, .seed = seed++, .zero_pdf_fraction = test::rim_miss_fraction(one_minus_cos)});
    EXPECT_TRUE(r.passed) << c.name << "\n" << r.report;
  }
}
