// The bounding volume hierarchy (accel/bvh.hpp) against brute force: over
// random triangle soups, the closest hit (its t and its primitive) and the
// any-hit query of shadow segments are the same as testing every primitive,
// for rays in random directions and along the coordinate axes (zero
// direction components: the slab test's 0 * inf), from outside and inside the
// scene's box; and the tree's invariants: its order is a permutation, every
// node's box holds its children's and its primitives', leaves hold at most
// max_leaf_size, its depth fits the traversal's stack, also for degenerate
// inputs (every primitive in one place, coordinates spread over 30 decades);
// rays with NaN and infinite components through trees of identical and huge
// bounds; and a tree whose traversal nodes take huge-page storage.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <memory>

#include "mcrt/accel/bvh.hpp"
#include "mcrt/render/scene.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/geometry/triangle_leaf.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/warp.hpp"

using namespace mcrt;

namespace {

struct soup {
  std::vector<vec3> a, b, c;
  std::vector<aabb> bounds() const {
    std::vector<aabb> out(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) out[i].grow(a[i]), out[i].grow(b[i]), out[i].grow(c[i]);
    return out;
  }
  float hit(std::uint32_t i, const ray& r, float tmax) const {
    const auto h = intersect_triangle(r, tmax, a[i], b[i], c[i]);
    return h ? h->t : infinity;
  }
};

soup random_soup(pcg32& rng, int n, float extent, float size) {
  soup s;
  for (int i = 0; i < n; ++i) {
    const vec3 centre{(rng.uniform() - 0.5f) * extent, (rng.uniform() - 0.5f) * extent, (rng.uniform() - 0.5f) * extent};
    const auto jitter = [&] {
      return vec3{(rng.uniform() - 0.5f) * size, (rng.uniform() - 0.5f) * size, (rng.uniform() - 0.5f) * size};
    };
    s.a.push_back(centre + jitter());
    s.b.push_back(centre + jitter());
    s.c.push_back(centre + jitter());
  }
  return s;
}

// Every invariant of the tree; returns its depth.
int check_tree(const bvh& t, const std::vector<aabb>& bounds) {
  std::vector<std::uint32_t> sorted = t.order();
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < sorted.size(); ++i) EXPECT_EQ(sorted[i], i) << "the order is not a permutation";
  int max_depth = 0;
  std::vector<int> seen(bounds.size(), 0);
  const std::function<void(std::uint32_t, int)> walk = [&](std::uint32_t k, int depth) {
    max_depth = std::max(max_depth, depth);
    const bvh::node& nd = t.nodes()[k];
    const auto inside = [&](const vec3& lo, const vec3& hi) {
      return glm::all(glm::greaterThanEqual(lo, nd.lo)) && glm::all(glm::lessThanEqual(hi, nd.hi));
    };
    if (nd.count > 0) {
      EXPECT_LE(nd.count, bvh::max_leaf_size);
      for (std::uint32_t i = 0; i < nd.count; ++i) {
        const std::uint32_t prim = t.order()[nd.offset + i];
        ++seen[prim];
        EXPECT_TRUE(inside(bounds[prim].lo, bounds[prim].hi)) << "primitive outside its leaf";
      }
      return;
    }
    const bvh::node &first = t.nodes()[k + 1], &second = t.nodes()[nd.offset];
    EXPECT_TRUE(inside(first.lo, first.hi) && inside(second.lo, second.hi)) << "child outside its parent";
    walk(k + 1, depth + 1);
    walk(nd.offset, depth + 1);
  };
  if (!t.empty()) walk(0, 1);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "primitive " << i << " in " << seen[i] << " leaves";
  return max_depth;
}

// Closest hit and any-hit of the tree against brute force for `rays` rays.
void expect_same_as_brute_force(const soup& s, const bvh& tree, pcg32& rng, int rays, float extent,
                                double min_hits = 0.2, double min_blocked = 0.1) {
  const std::size_t n = s.a.size();
  int hits = 0, blocked = 0;
  for (int k = 0; k < rays; ++k) {
    const vec3 o{(rng.uniform() - 0.5f) * 1.5f * extent, (rng.uniform() - 0.5f) * 1.5f * extent,
                 (rng.uniform() - 0.5f) * 1.5f * extent};
    vec3 d = square_to_uniform_sphere(rng.uniform2());
    if (k % 2 == 1) {  // towards a random primitive's centroid, so that many rays hit
      const std::size_t i = static_cast<std::size_t>(rng.uniform() * float(n));
      const vec3 to = (s.a[i] + s.b[i] + s.c[i]) / 3.0f - o;
      if (glm::length(to) > 0.0f) d = glm::normalize(to);
    }
    if (k % 5 == 0) {  // along an axis: two zero components
      d = vec3(0.0f);
      d[k % 3] = (k % 2) ? 1.0f : -1.0f;
    }
    const ray r{o, d};
    float brute_t = infinity;
    std::int64_t brute_i = -1;
    for (std::uint32_t i = 0; i < n; ++i) {
      const float t = s.hit(i, r, brute_t);
      if (t < brute_t) brute_t = t, brute_i = i;
    }
    float tree_t = infinity;
    const std::int64_t tree_i = tree.closest(r, 0.0f, tree_t, [&](std::uint32_t i, float, float tmax) { return s.hit(i, r, tmax); });
    ASSERT_EQ(tree_t, brute_t) << "ray " << k;
    if (tree_i != brute_i) {  // only a tie may name another primitive
      ASSERT_GE(tree_i, 0);
      EXPECT_EQ(s.hit(static_cast<std::uint32_t>(tree_i), r, infinity), brute_t) << "ray " << k;
    }
    hits += brute_i >= 0;
    // A shadow segment to a random point: blocked iff some hit lies before it.
    const float seg = rng.uniform() * 2.0f * extent;
    bool brute_any = false;
    for (std::uint32_t i = 0; i < n && !brute_any; ++i) brute_any = s.hit(i, r, seg) < seg;
    const bool tree_any = tree.any(r, 0.0f, seg, [&](std::uint32_t i, float, float tmax) { return s.hit(i, r, tmax) < tmax; });
    ASSERT_EQ(tree_any, brute_any) << "ray " << k;
    blocked += brute_any;
  }
  // Enough hits and blocked segments for the comparison to mean something.
  EXPECT_GT(hits, min_hits * rays);
  EXPECT_GT(blocked, min_blocked * rays);
}

// The leaf queries (closest_leaf, any_leaf) of a tree built with
// leaf_block 4, its triangles copied in the leaves' order and tested a leaf
// at a time by triangle_leaf.hpp (as the scene and the Embree bench do),
// against brute force: the same t, and a triangle of that t.
void expect_leaf_queries_as_brute_force(const soup& s, pcg32& rng, int rays, float extent) {
  const std::size_t n = s.a.size();
  bvh tree(s.bounds(), triangle_leaf_width);
  check_tree(tree, s.bounds());
  std::vector<triangle_vertices> tv(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = tree.order()[k];
    tv[k] = {{s.a[i], s.b[i], s.c[i]}, i};
  }
  tree.renumber_in_order();
  int hits = 0;
  for (int k = 0; k < rays; ++k) {
    const vec3 o{(rng.uniform() - 0.5f) * 1.5f * extent, (rng.uniform() - 0.5f) * 1.5f * extent,
                 (rng.uniform() - 0.5f) * 1.5f * extent};
    vec3 d = square_to_uniform_sphere(rng.uniform2());
    if (k % 2 == 1) {
      const std::size_t i = static_cast<std::size_t>(rng.uniform() * float(n)) % n;
      const vec3 to = (s.a[i] + s.b[i] + s.c[i]) / 3.0f - o;
      if (glm::length(to) > 0.0f) d = glm::normalize(to);
    }
    if (k % 5 == 0) {
      d = vec3(0.0f);
      d[k % 3] = (k % 2) ? 1.0f : -1.0f;
    }
    const ray r{o, d};
    float brute_t = infinity;
    for (std::uint32_t i = 0; i < n; ++i) brute_t = std::min(brute_t, s.hit(i, r, brute_t));
    const watertight_ray wr(r);
    float tree_t = infinity;
    triangle_hit h;
    const std::int64_t slot = tree.closest_leaf(r, 0.0f, tree_t, [&](std::uint32_t first, std::uint32_t count, float t0, float& t1) {
      EXPECT_LE(count, std::uint32_t(triangle_leaf_width));
      const int j = closest_in_leaf(wr, t0, t1, &tv[first], int(count), h);
      return j < 0 ? std::int64_t(-1) : std::int64_t(first) + j;
    });
    ASSERT_EQ(tree_t, brute_t) << "ray " << k;
    ASSERT_EQ(slot >= 0, brute_t < infinity);
    if (slot >= 0) {
      EXPECT_EQ(s.hit(tv[std::size_t(slot)].tag, r, infinity), brute_t);
      EXPECT_EQ(h.t, brute_t);
      ++hits;
    }
    const float seg = rng.uniform() * 2.0f * extent;
    bool brute_any = false;
    for (std::uint32_t i = 0; i < n && !brute_any; ++i) brute_any = s.hit(i, r, seg) < seg;
    const bool tree_any = tree.any_leaf(r, 0.0f, seg, [&](std::uint32_t first, std::uint32_t count, float t0, float t1) {
      return any_in_leaf(wr, t0, t1, &tv[first], int(count));
    });
    ASSERT_EQ(tree_any, brute_any) << "ray " << k;
  }
  EXPECT_GT(hits, rays / 5);
}

}  // namespace

TEST(Bvh, ClosestAndAnyHitAreThoseOfBruteForce) {
  pcg32 rng(1, 2);
  for (const int leaf_block : {1, triangle_leaf_width})
    for (const int n : {1, 2, 5, 100, 3000}) {
      const soup s = random_soup(rng, n, 10.0f, n > 100 ? 1.0f : 4.0f);
      const std::vector<aabb> b = s.bounds();
      const bvh tree(b, leaf_block);
      check_tree(tree, b);
      expect_same_as_brute_force(s, tree, rng, 3000, 10.0f);
    }
}

TEST(Bvh, LeafQueriesAreThoseOfBruteForce) {
  pcg32 rng(21, 2);
  for (const int n : {1, 3, 4, 5, 100, 3000}) {
    const soup s = random_soup(rng, n, 10.0f, n > 100 ? 1.0f : 4.0f);
    expect_leaf_queries_as_brute_force(s, rng, 3000, 10.0f);
  }
}

TEST(Bvh, DegenerateInputs) {
  pcg32 rng(3, 4);
  // Every primitive in one place: the build halves by count.
  soup same;
  for (int i = 0; i < 1000; ++i) same.a.push_back({0, 0, 0}), same.b.push_back({1, 0, 0}), same.c.push_back({0, 1, 0});
  const bvh t1(same.bounds());
  EXPECT_LE(check_tree(t1, same.bounds()), 12);
  float t = infinity;
  EXPECT_GE(t1.closest({{0.2f, 0.2f, 1}, {0, 0, -1}}, 0.0f, t, [&](std::uint32_t i, float, float tmax) { return same.hit(i, {{0.2f, 0.2f, 1}, {0, 0, -1}}, tmax); }), 0);
  EXPECT_EQ(t, 1.0f);
  // Coordinates spread over 30 decades along a line: a lopsided tree must
  // still fit the traversal's stack.
  soup line;
  for (int i = 0; i < 4000; ++i) {
    const float x = std::pow(1.02f, float(i)) * 1e-5f;
    line.a.push_back({x, 0, 0}), line.b.push_back({x, 1, 0}), line.c.push_back({x, 0, 1});
  }
  const bvh t2(line.bounds());
  EXPECT_LE(check_tree(t2, line.bounds()), 128);
  expect_same_as_brute_force(line, t2, rng, 1000, 2.0f, 0.05, 0.05);
  // No primitives.
  const bvh t3(std::vector<aabb>{});
  float t_empty = infinity;
  EXPECT_EQ(t3.closest({{0, 0, 0}, {0, 0, 1}}, 0.0f, t_empty, [](std::uint32_t, float, float) { return 0.0f; }), -1);
  EXPECT_FALSE(t3.any({{0, 0, 0}, {0, 0, 1}}, 0.0f, infinity, [](std::uint32_t, float, float) { return true; }));
}

// Rays with NaN and infinite components (origin, direction, tmin, tmax)
// through trees of ordinary, identical and huge bounds (vertices at
// +-FLT_MAX): every query returns what testing every primitive returns,
// and visits each leaf at most once (the traversal's stack holds each node
// once: a ray whose slab test turns NaN must not enter a node's unused
// lanes, which name the root; that overflowed the stack once).
TEST(Bvh, NonFiniteRaysAndExtremeBounds) {
  pcg32 rng(31, 7);
  constexpr float big = std::numeric_limits<float>::max(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<soup> soups;
  soups.push_back(random_soup(rng, 3000, 10.0f, 1.0f));
  soup same;  // 1000 identical triangles
  for (int i = 0; i < 1000; ++i) same.a.push_back({0, 0, 0}), same.b.push_back({1, 0, 0}), same.c.push_back({0, 1, 0});
  soups.push_back(same);
  soup huge = random_soup(rng, 500, 10.0f, 1.0f);  // ordinary triangles beside ones reaching +-FLT_MAX
  for (int i = 0; i < 200; ++i) {
    const float x = (rng.uniform() - 0.5f) * 10.0f;
    huge.a.push_back({x, 0, 0});
    huge.b.push_back({i % 2 ? big : -big, 1, 0});
    huge.c.push_back({x, i % 3 ? big : -big, 1});
  }
  soups.push_back(huge);
  soup all_huge;  // every box [-FLT_MAX, FLT_MAX]^3
  for (int i = 0; i < 300; ++i)
    all_huge.a.push_back({-big, -big, -big}), all_huge.b.push_back({big, big, big}), all_huge.c.push_back({big, -big, big});
  soups.push_back(all_huge);
  const std::array<float, 10> values{0.0f, -0.0f, 1.0f, -1.0f, 0.5f, big, -big, infinity, -infinity, nan};
  for (const soup& s : soups) {
    const std::vector<aabb> b = s.bounds();
    for (const int leaf_block : {1, triangle_leaf_width}) {
      const bvh tree(b, leaf_block);
      EXPECT_LE(check_tree(tree, b), 128);
      const std::size_t leaves = std::count_if(tree.nodes().begin(), tree.nodes().end(), [](const bvh::node& nd) { return nd.count > 0; });
      for (int k = 0; k < 4000; ++k) {
        const auto pick = [&] { return values[static_cast<std::size_t>(rng.uniform() * float(values.size())) % values.size()]; };
        // Each component ordinary or one of the extreme values.
        vec3 o{(rng.uniform() - 0.5f) * 15.0f, (rng.uniform() - 0.5f) * 15.0f, (rng.uniform() - 0.5f) * 15.0f};
        vec3 d = square_to_uniform_sphere(rng.uniform2());
        for (int a = 0; a < 3; ++a) {
          if (rng.uniform() < 0.3f) o[a] = pick();
          if (rng.uniform() < 0.3f) d[a] = pick();
        }
        const float tmin = rng.uniform() < 0.1f ? pick() : 0.0f;
        const float tmax0 = rng.uniform() < 0.2f ? pick() : infinity;
        const ray r{o, d};
        float brute_t = tmax0;
        std::int64_t brute_i = -1;
        for (std::uint32_t i = 0; i < s.a.size(); ++i) {
          const float t = s.hit(i, r, brute_t);
          if (t < brute_t && t > tmin) brute_t = t, brute_i = i;
        }
        std::vector<int> visits(s.a.size(), 0);
        float tree_t = tmax0;
        const std::int64_t tree_i = tree.closest(r, tmin, tree_t, [&](std::uint32_t i, float t0, float tmax) {
          ++visits[i];
          const float t = s.hit(i, r, tmax);
          return t > t0 ? t : infinity;
        });
        for (std::size_t i = 0; i < visits.size(); ++i) ASSERT_LE(visits[i], 1) << "primitive visited twice, ray " << k;
        ASSERT_EQ(tree_i >= 0, brute_i >= 0) << "ray " << k;
        if (brute_i >= 0) {
          ASSERT_EQ(tree_t, brute_t) << "ray " << k;
        }
        std::size_t leaf_visits = 0;
        tree.any(r, tmin, tmax0, [&](std::uint32_t, float, float) {
          ++leaf_visits;
          return false;
        });
        ASSERT_LE(leaf_visits, s.a.size()) << "ray " << k;
        std::size_t leaf_calls = 0;
        float t_leaf = tmax0;
        tree.closest_leaf(r, tmin, t_leaf, [&](std::uint32_t, std::uint32_t, float, float&) {
          ++leaf_calls;
          return std::int64_t(-1);
        });
        ASSERT_LE(leaf_calls, leaves) << "ray " << k;
        leaf_calls = 0;
        tree.any_leaf(r, tmin, tmax0, [&](std::uint32_t, std::uint32_t, float, float) {
          ++leaf_calls;
          return false;
        });
        ASSERT_LE(leaf_calls, leaves) << "ray " << k;
      }
    }
  }
}

TEST(Bvh, TraversalTestsFewPrimitivesPerRay) {
  // On 20000 small triangles a ray should test a few dozen, not thousands:
  // the tree is a hierarchy, not a list.
  pcg32 rng(5, 6);
  const soup s = random_soup(rng, 20000, 100.0f, 1.0f);
  const bvh tree(s.bounds());
  check_tree(tree, s.bounds());
  long long tests = 0;
  const int rays = 2000;
  for (int k = 0; k < rays; ++k) {
    const ray r{{(rng.uniform() - 0.5f) * 100.0f, (rng.uniform() - 0.5f) * 100.0f, -80.0f},
                glm::normalize(vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, 1.0f))};
    float t = infinity;
    tree.closest(r, 0.0f, t, [&](std::uint32_t i, float, float tmax) {
      ++tests;
      return s.hit(i, r, tmax);
    });
  }
  const double per_ray = double(tests) / rays;
  std::printf("primitives tested per ray: %.1f of %zu\n", per_ray, s.a.size());
  EXPECT_LT(per_ray, 200.0);
}

// A tree whose traversal nodes pass 2 MiB (large_array_allocator's huge-page
// storage on Linux) traverses as brute force tests; that storage itself is
// aligned and keeps what is written to it.
TEST(Bvh, LargeTreeInHugePageStorage) {
  pcg32 rng(9, 10);
  const soup s = random_soup(rng, 60000, 100.0f, 1.5f);
  const bvh tree(s.bounds());
  ASSERT_GT(tree.wide_node_count() * 128, std::size_t(2) << 20);
  expect_same_as_brute_force(s, tree, rng, 200, 100.0f, 0.05, 0.05);
  std::vector<std::uint32_t, large_array_allocator<std::uint32_t>> v(std::size_t(3) << 20);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint32_t>(i * 7);
  v.resize(v.size() + 5, 1);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % 64, 0u);
  for (std::size_t i = 0; i < (std::size_t(3) << 20); i += 4099) ASSERT_EQ(v[i], static_cast<std::uint32_t>(i * 7));
  EXPECT_EQ(v.back(), 1u);
}

// The scene's accelerated path (build_accelerator: the hierarchy, with each
// triangle's vertices copied beside its entry and surface_at filled from the
// test's barycentrics) against the general one, the per-type lists: for
// random scenes of every list shape, each ray gives the same hit or miss,
// the same t, point, normal, side, material and uv.
TEST(SceneAccelerator, HitsAreThoseOfTheLists) {
  mcrt::pcg32 rng(77, 3);
  int hits = 0, sides = 0;
  for (int s = 0; s < 40; ++s) {
    mcrt::scene sc;
    for (int m = 0; m < 4; ++m) sc.materials.push_back(mcrt::lambertian{});
    auto mesh = std::make_shared<mcrt::triangle_mesh>();
    const auto r3 = [&] { return mcrt::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0f - 2.0f; };
    for (int i = 0; i < 30; ++i) {
      const auto k = static_cast<std::uint32_t>(mesh->p.size());
      const mcrt::vec3 c = r3();
      for (int v = 0; v < 3; ++v) mesh->p.push_back(c + 0.4f * r3()), mesh->uv.push_back({rng.uniform(), rng.uniform()});
      mesh->indices.insert(mesh->indices.end(), {k, k + 1, k + 2});
    }
    // Orientation by pbrt-v4's rules: reversed meshes, and meshes whose
    // shading normals pick the front (random ones, either side).
    mesh->reverse_orientation = s % 3 == 1;
    if (s % 3 == 2)
      for (std::size_t v = 0; v < mesh->p.size(); ++v) mesh->n.push_back(glm::normalize(r3() + mcrt::vec3(1e-3f)));
    for (const mcrt::triangle& t : mcrt::triangles_of(mesh)) sc.add(t, 0);
    for (int i = 0; i < 4; ++i) {
      sc.add(mcrt::sphere{r3(), 0.1f + 0.3f * rng.uniform()}, 1);
      sc.add(mcrt::rect::make(r3(), 0.8f * mcrt::vec3(1, 0.2f, 0), 0.6f * mcrt::vec3(-0.2f, 1, 0.3f)), 2);
      sc.add(mcrt::ellipse::make(r3(), {0.3f, 0, 0}, {0, 0.2f, 0.1f}), 3);
    }
    mcrt::box b;
    b.lo = r3() * 0.2f;
    b.hi = b.lo + 0.5f;
    b.xf = mcrt::rigid_y::make(30.0f, r3());
    b.flip = s % 2 == 1;
    sc.add(b, 1);
    mcrt::sphere inside_out{r3(), 0.3f};
    inside_out.flip = true;
    sc.add(inside_out, 2);
    const mcrt::scene lists = sc;
    sc.build_accelerator();
    ASSERT_TRUE(sc.accelerated());
    ASSERT_FALSE(lists.accelerated());
    for (int i = 0; i < 500; ++i) {
      const mcrt::ray r{r3() * 1.5f, mcrt::square_to_uniform_sphere(rng.uniform2())};
      mcrt::hit_record a, c;
      const bool ha = lists.hit(r, 1e-4f, mcrt::infinity, a), hc = sc.hit(r, 1e-4f, mcrt::infinity, c);
      ASSERT_EQ(ha, hc) << "scene " << s << " ray " << i;
      if (!ha) continue;
      ++hits;
      EXPECT_EQ(a.t, c.t);
      EXPECT_EQ(a.p, c.p);
      EXPECT_EQ(a.n, c.n);
      EXPECT_EQ(a.front_face, c.front_face);
      EXPECT_EQ(a.material, c.material);
      EXPECT_EQ(a.uv, c.uv);
      EXPECT_EQ(a.offset, c.offset);
      // hit_side (shadow rays): the same t, material and side, both ways.
      for (const mcrt::scene* w : std::initializer_list<const mcrt::scene*>{&lists, &sc}) {
        mcrt::hit_record side;
        ASSERT_TRUE(w->hit_side(r, 1e-4f, mcrt::infinity, side));
        EXPECT_EQ(side.t, a.t);
        EXPECT_EQ(side.material, a.material);
        EXPECT_EQ(side.front_face, a.front_face) << "scene " << s << " ray " << i;
        ++sides;
      }
    }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_EQ(sides, 2 * hits);
}
