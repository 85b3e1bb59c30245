// The vector test of a leaf's triangles (geometry/triangle_leaf.hpp), a
// fast path of the watertight test, against the general path: testing the
// triangles one by one with intersect_triangle in the leaf's order, tmax
// lowered at each hit. Bit for bit the same closest triangle, t and
// barycentrics, and the same any-hit verdict, for leaves of 1 to 4
// triangles: random ones; fans and strips whose shared vertices and edges
// the rays pass exactly through (edge functions of 0, the scalar test's
// double recomputation); degenerate triangles; rays in a triangle's plane;
// tmax between the hits; coordinates far from the origin. And the vector
// part rejects what the rays miss (it is a filter, not a pass-through).
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/geometry/triangle_leaf.hpp"
#include "mcrt/sampling/warp.hpp"

using namespace mcrt;

namespace {

struct result {
  int index = -1;
  float tmax = 0.0f;
  triangle_hit hit{};
};

// The general path: one by one.
result one_by_one(const ray& r, float tmin, float tmax, const triangle_vertices* tris, int count) {
  result out{-1, tmax, {}};
  for (int j = 0; j < count; ++j) {
    const std::optional<triangle_hit> h = intersect_triangle(r, out.tmax, tris[j].p[0], tris[j].p[1], tris[j].p[2]);
    if (h && h->t > tmin && h->t < out.tmax) out = {j, h->t, *h};
  }
  return out;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

struct tally {
  long long cases = 0, hits = 0;
};

// The leaf test against one_by_one for ray r; counts cases and hits.
void expect_same(const ray& r, float tmin, float tmax, const std::vector<triangle_vertices>& tris, tally& t,
                 const char* what) {
  const watertight_ray wr(r);
  for (int count = 1; count <= triangle_leaf_width && count <= int(tris.size()); ++count) {
    const result general = one_by_one(r, tmin, tmax, tris.data(), count);
    float leaf_tmax = tmax;
    triangle_hit leaf_hit{-1.0f, -1.0f, -1.0f, -1.0f};
    const int leaf = closest_in_leaf(wr, tmin, leaf_tmax, tris.data(), count, leaf_hit);
    ASSERT_EQ(leaf, general.index) << what << ", count " << count;
    ASSERT_TRUE(same_bits(leaf_tmax, general.tmax)) << what << ": tmax " << leaf_tmax << " vs " << general.tmax;
    if (leaf >= 0) {
      ASSERT_TRUE(same_bits(leaf_hit.t, general.hit.t) && same_bits(leaf_hit.b0, general.hit.b0) &&
                  same_bits(leaf_hit.b1, general.hit.b1) && same_bits(leaf_hit.b2, general.hit.b2))
          << what;
      ++t.hits;
    }
    ASSERT_EQ(any_in_leaf(wr, tmin, tmax, tris.data(), count), general.index >= 0) << what << ", count " << count;
    ++t.cases;
  }
}

vec3 random_in(pcg32& rng, float extent) {
  return {(rng.uniform() - 0.5f) * extent, (rng.uniform() - 0.5f) * extent, (rng.uniform() - 0.5f) * extent};
}

}  // namespace

TEST(TriangleLeaf, RandomLeavesAsOneByOne) {
  pcg32 rng(11, 5);
  tally t;
  for (const float offset : {0.0f, 1e3f, 1e4f}) {
    for (int k = 0; k < 20000; ++k) {
      const vec3 centre = offset * vec3(1.0f, -0.7f, 0.4f) + random_in(rng, 2.0f);
      std::vector<triangle_vertices> tris(4);
      for (triangle_vertices& tv : tris)
        for (vec3& p : tv.p) p = centre + random_in(rng, 1.0f);
      // Aimed at a random point of a random triangle of the leaf, or anywhere.
      const triangle_vertices& aim = tris[static_cast<std::size_t>(rng.uniform() * 4.0f) % 4];
      const float u = rng.uniform(), v = rng.uniform() * (1.0f - u);
      const vec3 target = k % 3 == 0 ? centre + random_in(rng, 1.0f) : aim.p[0] + u * (aim.p[1] - aim.p[0]) + v * (aim.p[2] - aim.p[0]);
      const vec3 o = centre + random_in(rng, 6.0f);
      if (glm::length(target - o) == 0.0f) continue;
      const ray r{o, glm::normalize(target - o)};
      // tmax: unbounded, or between the hits.
      const float tmax = k % 4 == 1 ? rng.uniform() * 2.0f * glm::length(target - o) : infinity;
      expect_same(r, 0.0f, tmax, tris, t, "random leaf");
      if (HasFatalFailure()) return;
    }
  }
  EXPECT_GT(t.hits, t.cases / 5);
}

// Fans and strips: the rays pass exactly through shared vertices and
// through points of shared edges, where edge functions are 0 (or rounded
// to 0) and the scalar test recomputes in double; a ray through a shared
// edge or vertex hits at least one of the leaf's triangles (watertight).
TEST(TriangleLeaf, SharedVerticesAndEdgesAsOneByOne) {
  pcg32 rng(12, 6);
  tally t;
  long long through = 0, through_hit = 0;
  for (int k = 0; k < 20000; ++k) {
    const float scale = k % 2 ? 1.0f : 1e3f;
    const vec3 c = scale * random_in(rng, 4.0f);
    // A fan of four triangles around c (closed: the last shares its edge
    // with the first), in a random plane.
    const vec3 a = glm::normalize(random_in(rng, 2.0f) + vec3(1e-3f)), b0 = random_in(rng, 2.0f);
    const vec3 b = glm::normalize(b0 - glm::dot(b0, a) * a + vec3(1e-3f));
    std::array<vec3, 4> rim;
    for (int i = 0; i < 4; ++i) {
      const float phi = 0.5f * pi * float(i) + 0.3f * rng.uniform();
      rim[static_cast<std::size_t>(i)] = c + scale * (std::cos(phi) * a + std::sin(phi) * b);
    }
    std::vector<triangle_vertices> tris(4);
    for (std::size_t i = 0; i < 4; ++i) tris[i].p = {c, rim[i], rim[(i + 1) % 4]};
    // Through the shared centre, or a point on a shared edge (rounded to
    // float: on the edge up to rounding, where the sign decides).
    const std::size_t e = static_cast<std::size_t>(rng.uniform() * 4.0f) % 4;
    const float s = rng.uniform();
    const vec3 target = k % 3 == 0 ? c : c + s * (rim[e] - c);
    const vec3 o = target + scale * 3.0f * glm::normalize(random_in(rng, 2.0f) + vec3(1e-4f));
    const ray r{o, glm::normalize(target - o)};
    const result general = one_by_one(r, 0.0f, infinity, tris.data(), 4);
    ++through;
    through_hit += general.index >= 0;
    expect_same(r, 0.0f, infinity, tris, t, "through a shared vertex or edge");
    if (HasFatalFailure()) return;
  }
  // Watertight: a ray through a shared vertex or edge of a closed fan hits
  // (the leaf answers as the general path, so it hits too).
  EXPECT_EQ(through_hit, through);
}

TEST(TriangleLeaf, DegenerateAndGrazingAsOneByOne) {
  pcg32 rng(13, 7);
  tally t;
  for (int k = 0; k < 20000; ++k) {
    const vec3 p0 = random_in(rng, 2.0f), p1 = random_in(rng, 2.0f), p2 = random_in(rng, 2.0f);
    std::vector<triangle_vertices> tris(4);
    tris[0].p = {p0, p1, p2};
    tris[1].p = {p0, p1, p0 + 0.5f * (p1 - p0)};  // collinear: never hit
    tris[2].p = {p0, p0, p2};                     // a repeated vertex: never hit
    tris[3].p = {p0, p1, p2};                     // the same triangle twice: the first wins a tie
    // A ray in the triangle's plane (through two of its points), or through it.
    const float u = rng.uniform(), v = rng.uniform() * (1.0f - u);
    const vec3 inside = p0 + u * (p1 - p0) + v * (p2 - p0);
    vec3 o, d;
    if (k % 2) {
      o = p0 - 2.0f * (inside - p0);
      d = inside - o;
    } else {
      o = inside + random_in(rng, 4.0f);
      d = inside - o;
    }
    if (!(glm::length(d) > 0.0f)) continue;
    const ray r{o, glm::normalize(d)};
    expect_same(r, 0.0f, infinity, tris, t, "degenerate or grazing");
    if (HasFatalFailure()) return;
    const watertight_ray wr(r);
    float tm = infinity;
    triangle_hit h;
    const int j = closest_in_leaf(wr, 0.0f, tm, tris.data(), 4, h);
    EXPECT_NE(j, 1);
    EXPECT_NE(j, 2);
    EXPECT_NE(j, 3);
  }
  EXPECT_GT(t.hits, 0);
}

// The vector part is a filter: of random triangles that a ray misses it
// passes on (to the scalar test) only those it cannot decide, a small share.
TEST(TriangleLeaf, TheVectorPartRejectsMisses) {
#if !(defined(__FMA__) && defined(__SSE4_1__))
  GTEST_SKIP() << "built without FMA and SSE 4.1: every triangle goes to the scalar test";
#else
  pcg32 rng(14, 8);
  long long misses = 0, passed = 0;
  for (int k = 0; k < 20000; ++k) {
    std::vector<triangle_vertices> tris(4);
    for (triangle_vertices& tv : tris)
      for (vec3& p : tv.p) p = random_in(rng, 2.0f);
    const ray r{random_in(rng, 8.0f), square_to_uniform_sphere(rng.uniform2())};
    const watertight_ray wr(r);
    const unsigned m = detail::triangle_candidates(wr, infinity, tris.data(), 4);
    for (int j = 0; j < 4; ++j) {
      if (intersect_triangle(r, infinity, tris[std::size_t(j)].p[0], tris[std::size_t(j)].p[1], tris[std::size_t(j)].p[2]))
        ASSERT_TRUE(m >> j & 1u) << "the filter rejected a triangle the ray hits";
      else
        ++misses, passed += m >> j & 1u;
    }
  }
  EXPECT_GT(misses, 40000);
  EXPECT_LT(double(passed), 0.01 * double(misses));
#endif
}
