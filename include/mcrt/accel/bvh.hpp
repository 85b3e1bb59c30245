#pragma once
// A bounding volume hierarchy over any primitives: built by the binned
// surface area heuristic (MacDonald & Booth 1990, "Heuristics for ray
// tracing using space subdivision"; Wald 2007, "On fast construction of
// SAH-based bounding volume hierarchies"; pbrt-v4's BVHAggregate, with 32
// buckets as Embree's builders), a leaf priced by the tests it takes: one
// per primitive, or one per block of four where the caller tests a leaf's
// triangles as one vector (leaf_block, geometry/triangle_leaf.hpp; Embree's
// SAH block size). It is stored as compact nodes in depth-first order
// (32 bytes: the box, the second child's or the first primitive's index, a
// count and the split axis; Pharr et al., "Physically Based Rendering", 4th
// ed., sec. 7.3.4). For traversal that binary tree is collapsed into an
// 8-wide one (Dammertz, Hanika & Keller 2008, "Shallow bounding volume
// hierarchies for fast SIMD ray tracing of incoherent rays"; Wald, Benthin
// & Boulos 2008, "Getting rid of packets"; as Embree's BVH8): a 256-byte
// node holds its eight children's boxes side by side, a structure of
// arrays tested as one 8-wide vector. A ray visits the children it hits
// nearest first (by where it enters their boxes), asks the memory for
// every node it will visit as soon as it knows of it (the one it goes on
// with as well as those it puts aside), and skips, when it comes back to
// them, those it enters beyond its closest hit so far; shadow rays take the
// children in their node's order and stop at the first hit (Embree's
// traverseClosestHit and traverseAnyHit). On incoherent rays through a
// large mesh the traversal waits on memory, for nodes and primitives
// alike: the wide tree is a third as deep as the binary one, and its nodes
// live in huge pages where the system offers them (large_array_allocator).
//
// The hierarchy knows its primitives only through their bounds, at build
// time, and through a callback at traversal: it holds their order, so a
// primitive is named by its index in the caller's array.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "mcrt/core/math.hpp"
#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/aabb.hpp"

namespace mcrt {

// Storage for a large array that rays read at random (the wide tree's nodes;
// also fit for a caller's primitives in the tree's order): on Linux, from
// 2 MiB on, aligned to 2 MiB and advised as transparent huge pages
// (madvise MADV_HUGEPAGE; honoured where the system's setting is "madvise"
// or "always"), so that random reads miss the TLB far less, as Embree's own
// allocator does; elsewhere, and below that size, operator new.
template <class T>
struct large_array_allocator {
  using value_type = T;
  static constexpr std::size_t huge_page = std::size_t(2) << 20;
  static constexpr std::size_t alignment = alignof(T) > alignof(std::max_align_t) ? alignof(T) : alignof(std::max_align_t);

  large_array_allocator() = default;
  template <class U>
  large_array_allocator(const large_array_allocator<U>&) {}

  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
#if defined(__linux__)
    if (bytes >= huge_page) {
      void* p = std::aligned_alloc(huge_page, (bytes + huge_page - 1) / huge_page * huge_page);
      if (!p) throw std::bad_alloc();
      madvise(p, bytes, MADV_HUGEPAGE);
      return static_cast<T*>(p);
    }
#endif
    return static_cast<T*>(::operator new(bytes, std::align_val_t(alignment)));
  }
  void deallocate(T* p, std::size_t n) {
#if defined(__linux__)
    if (n * sizeof(T) >= huge_page) return std::free(p);
#endif
    (void)n;
    ::operator delete(p, std::align_val_t(alignment));
  }
  template <class U>
  bool operator==(const large_array_allocator<U>&) const {
    return true;
  }
};

class bvh {
 public:
  // Primitives per leaf at most; a node with at most this many becomes a
  // leaf where no split is expected to pay (pbrt-v4's maxPrimsInNode).
  static constexpr int max_leaf_size = 4;

  struct node {
    vec3 lo, hi;
    std::uint32_t offset = 0;  // leaf: its first primitive in order(); interior: the second child's node
    std::uint16_t count = 0;   // primitives of a leaf; 0 for an interior node
    std::uint8_t axis = 0;     // an interior node's split axis
    std::uint8_t pad = 0;
  };
  static_assert(sizeof(node) == 32);

  bvh() = default;

  // Builds over primitives 0 .. bounds.size() - 1. leaf_block: how many
  // primitives the caller's leaf test takes at the price of one (1: one by
  // one; 4: a vector test of a leaf's triangles, geometry/triangle_leaf.hpp),
  // by which the surface area heuristic prices a leaf (ceil(n / leaf_block)
  // tests, Embree's SAH block size).
  explicit bvh(const std::vector<aabb>& bounds, int leaf_block = 1) : leaf_block_(std::clamp(leaf_block, 1, max_leaf_size)) {
    order_.resize(bounds.size());
    for (std::size_t i = 0; i < bounds.size(); ++i) order_[i] = static_cast<std::uint32_t>(i);
    if (bounds.empty()) return;
    std::vector<vec3> centroids(bounds.size());
    for (std::size_t i = 0; i < bounds.size(); ++i) centroids[i] = bounds[i].centroid();
    nodes_.reserve(2 * bounds.size());
    build(bounds, centroids, 0, static_cast<std::uint32_t>(bounds.size()), 0);
    collapse(bounds);
  }

  bool empty() const { return nodes_.empty(); }
  // The binary tree as built (the traversal reads the wide tree made of it).
  const std::vector<node>& nodes() const { return nodes_; }
  // The primitives in the order the leaves reference them.
  const std::vector<std::uint32_t>& order() const { return order_; }
  // Children of a node of the traversal's wide tree.
  static constexpr int width = 8;
  // The nodes of the traversal's wide tree (32 bytes per child).
  std::size_t wide_node_count() const { return wide_.size(); }

  // For a caller that has stored its primitives in order() (leaf by leaf,
  // so that a leaf's primitives are adjacent in memory): from then on the
  // traversal names a primitive by its place in that order.
  void renumber_in_order() {
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<std::uint32_t>(i);
    in_order_ = true;
  }

  // The closest hit in (tmin, tmax), a leaf at a time: hit_leaf(first,
  // count, tmin, tmax) tests the primitives at places first .. first +
  // count - 1 of order() (after renumber_in_order, the caller's own places:
  // a leaf's primitives lie side by side), lowers tmax to the closest hit
  // it finds before tmax and returns that primitive's place, or -1.
  // Returns the place of the closest hit, or -1.
  template <class HitLeaf>
  std::int64_t closest_leaf(const ray& r, float tmin, float& tmax, HitLeaf&& hit_leaf) const {
    std::int64_t best = -1;
    traverse(r, tmin, tmax, [&](std::uint32_t first, std::uint32_t count, float& t_max) {
      const std::int64_t k = hit_leaf(first, count, tmin, t_max);
      if (k >= 0) best = k;
      return false;
    });
    return best;
  }

  // Whether any primitive is hit in (tmin, tmax), a leaf at a time:
  // any_leaf(first, count, tmin, tmax) returns true for a hit among the
  // places first .. first + count - 1 of order(); the traversal stops at
  // the first.
  template <class AnyLeaf>
  bool any_leaf(const ray& r, float tmin, float tmax, AnyLeaf&& any_leaf) const {
    return traverse<true>(r, tmin, tmax, [&](std::uint32_t first, std::uint32_t count, float& t_max) {
      return any_leaf(first, count, tmin, t_max);
    });
  }

  // The closest hit in (tmin, tmax): hit(i, tmin, tmax) tests primitive i
  // and returns its hit's t, or a value >= tmax (infinity) for none; tmax
  // is lowered to each hit found. Returns the primitive of the closest hit,
  // or -1.
  template <class Hit>
  std::int64_t closest(const ray& r, float tmin, float& tmax, Hit&& hit) const {
    std::int64_t best = -1;
    traverse(r, tmin, tmax, [&](std::uint32_t first, std::uint32_t count, float& t_max) {
      for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t prim = primitive(first + i);
        const float t = hit(prim, tmin, t_max);
        if (t < t_max) {
          t_max = t;
          best = prim;
        }
      }
      return false;
    });
    return best;
  }

  // Whether any primitive is hit in (tmin, tmax): hit(i, tmin, tmax) returns
  // true for a hit; the traversal stops at the first.
  template <class Hit>
  bool any(const ray& r, float tmin, float tmax, Hit&& hit) const {
    return traverse<true>(r, tmin, tmax, [&](std::uint32_t first, std::uint32_t count, float& t_max) {
      for (std::uint32_t i = 0; i < count; ++i)
        if (hit(primitive(first + i), tmin, t_max)) return true;
      return false;
    });
  }

 private:
  // A node of the traversal's wide tree: its children's boxes (lo x, y, z,
  // then hi x, y, z, each for the eight children; an unused child's box is
  // empty, lo = +inf and hi = -inf, which no ray enters), and for each child
  // a wide node's index (count 0) or a leaf's first primitive in order() and
  // its primitive count.
  struct alignas(64) wide_node {
    std::array<std::array<float, width>, 6> b;
    std::array<std::uint32_t, width> child;
    std::array<std::uint8_t, width> count;
    // Bit i for each child the node has. The slab test alone would let a
    // ray with a non-finite component (a NaN direction, an infinite origin:
    // (inf - inf) * inv is NaN, which never narrows the interval) enter the
    // empty boxes of the unused lanes too, whose child index 0 names the
    // root: the traversal would push it again and again, past any stack.
    // Masked, a node pushes at most its children but one, whatever the ray
    // holds, and the stack bound of collapse_node holds for every ray.
    std::uint8_t used = 0;
  };
  static_assert(sizeof(wide_node) == 32 * width);

  // The primitive at place k of order().
  std::uint32_t primitive(std::uint32_t k) const { return in_order_ ? k : order_[k]; }

  std::vector<node> nodes_;
  std::vector<wide_node, large_array_allocator<wide_node>> wide_;
  std::vector<std::uint32_t> order_;
  bool in_order_ = false;  // order_ is the identity (renumber_in_order)
  int leaf_block_ = 1;     // the primitives a leaf test takes at once (the constructor)
  std::vector<char> leaf_;  // while collapsing: which binary nodes become leaves
  // The most entries the traversal's stack can hold on this tree: on a path
  // from the root, each node's children but one (collapse_node's bound).
  std::uint32_t stack_bound_ = 0;

  static constexpr int bucket_count = 32;
  // The traversal's stack holds at most one node per level. Below this depth
  // the build halves by count, so no tree is deeper than it plus log2 of the
  // primitive count (<= 32): within the stack.
  static constexpr int balanced_below_depth = 96;
  static constexpr int stack_size = 128;
  // The wide tree is no deeper than the binary one, and a wide node pushes
  // at most width - 1 children beyond the one the traversal goes on with.
  static constexpr int wide_stack_size = (width - 1) * stack_size + width;
  // The stack of a tree whose bound is within it (every tree but lopsided
  // ones): a smaller frame for each ray.
  static constexpr int small_stack_size = 96;

  // Builds the subtree of order_[begin, end) and returns its node's index.
  std::uint32_t build(const std::vector<aabb>& bounds, const std::vector<vec3>& centroids, std::uint32_t begin,
                      std::uint32_t end, int depth) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    aabb box, centroid_box;
    for (std::uint32_t i = begin; i < end; ++i) {
      box.grow(bounds[order_[i]]);
      centroid_box.grow(centroids[order_[i]]);
    }
    const std::uint32_t n = end - begin;
    const auto make_leaf = [&] {
      node& nd = nodes_[index];
      nd.lo = box.lo;
      nd.hi = box.hi;
      nd.offset = begin;
      nd.count = static_cast<std::uint16_t>(n);
      return index;
    };
    const int axis = centroid_box.longest_axis();
    const float c0 = centroid_box.lo[axis], c1 = centroid_box.hi[axis];
    if (n == 1) return make_leaf();
    std::uint32_t mid = begin + n / 2;
    if (!(c1 > c0) || depth >= balanced_below_depth) {
      // Every centroid in one place (no split separates them), or deep enough
      // that the tree must stay within the traversal's stack: halves by count.
      if (n <= static_cast<std::uint32_t>(max_leaf_size)) return make_leaf();
    } else if (n <= 2 && leaf_block_ == 1) {
      std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                       [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
    } else {
      // Binned SAH: cost of a split after bucket k, relative cost of a
      // traversal step 1/2 as pbrt-v4 (leaf cost = its tests, primitives
      // in blocks of leaf_block_).
      const auto tests = [&](std::uint32_t count) {
        return float((count + static_cast<std::uint32_t>(leaf_block_) - 1) / static_cast<std::uint32_t>(leaf_block_));
      };
      std::array<aabb, bucket_count> bucket_box;
      std::array<std::uint32_t, bucket_count> bucket_n{};
      // The bucket of a centroid; a NaN position (c1 - c0 overflows to
      // infinity between centroids near -FLT_MAX and FLT_MAX, and inf / inf
      // is NaN) goes to the first bucket: converting NaN or a value out of
      // int's range to int is undefined, so the clamp is taken in float.
      const auto bucket_of = [&](std::uint32_t prim) {
        const float f = float(bucket_count) * ((centroids[prim][axis] - c0) / (c1 - c0));
        return f >= 1.0f ? (f < float(bucket_count) ? static_cast<int>(f) : bucket_count - 1) : 0;
      };
      for (std::uint32_t i = begin; i < end; ++i) {
        const int b = bucket_of(order_[i]);
        ++bucket_n[static_cast<std::size_t>(b)];
        bucket_box[static_cast<std::size_t>(b)].grow(bounds[order_[i]]);
      }
      std::array<float, bucket_count - 1> cost{};
      aabb below;
      std::uint32_t count_below = 0;
      for (int k = 0; k < bucket_count - 1; ++k) {
        below.grow(bucket_box[static_cast<std::size_t>(k)]);
        count_below += bucket_n[static_cast<std::size_t>(k)];
        cost[static_cast<std::size_t>(k)] = tests(count_below) * below.surface_area();
      }
      aabb above;
      std::uint32_t count_above = 0;
      for (int k = bucket_count - 1; k >= 1; --k) {
        above.grow(bucket_box[static_cast<std::size_t>(k)]);
        count_above += bucket_n[static_cast<std::size_t>(k)];
        cost[static_cast<std::size_t>(k - 1)] += tests(count_above) * above.surface_area();
      }
      int best = 0;
      for (int k = 1; k < bucket_count - 1; ++k)
        if (cost[static_cast<std::size_t>(k)] < cost[static_cast<std::size_t>(best)]) best = k;
      const float leaf_cost = tests(n);
      const float split_cost = 0.5f + cost[static_cast<std::size_t>(best)] / box.surface_area();
      if (n <= static_cast<std::uint32_t>(max_leaf_size) && !(split_cost < leaf_cost)) return make_leaf();
      const auto* split = std::partition(order_.data() + begin, order_.data() + end,
                                         [&](std::uint32_t prim) { return bucket_of(prim) <= best; });
      mid = static_cast<std::uint32_t>(split - order_.data());
      if (mid == begin || mid == end) mid = begin + n / 2;  // (rounding put every centroid on one side)
    }
    build(bounds, centroids, begin, mid, depth + 1);
    const std::uint32_t second = build(bounds, centroids, mid, end, depth + 1);
    node& nd = nodes_[index];
    nd.lo = box.lo;
    nd.hi = box.hi;
    nd.offset = second;
    nd.count = 0;
    nd.axis = static_cast<std::uint8_t>(axis);
    return index;
  }

  // The wide tree of the binary one: from the root, each wide node takes
  // the binary subtree's nodes down to eight children (opening, while fewer
  // than eight, the interior child of the largest surface area). A child
  // becomes a leaf where it is a binary leaf, or a subtree of at most
  // max_leaf_size primitives whose boxes would spare a ray entering it few
  // tests: their surface areas add up to at least merge_overlap times the
  // primitives' count times the subtree's (the tests a ray entering it makes
  // by the surface area heuristic's odds, at least that share of them all).
  // A mesh's neighbouring triangles are so merged, leaf by leaf adjacent in
  // the caller's memory, and save a node's read; scattered small shapes
  // keep their boxes.
  static constexpr float merge_overlap = 0.5f;

  void collapse(const std::vector<aabb>& bounds) {
    wide_.clear();
    if (nodes_.empty()) return;
    // Each binary node's primitives (a range of order_, as the build made it
    // depth first) and the sum of their boxes' surface areas.
    std::vector<std::uint32_t> count(nodes_.size());
    std::vector<float> area(nodes_.size());
    for (std::size_t k = nodes_.size(); k-- > 0;) {
      const node& nd = nodes_[k];
      if (nd.count > 0) {
        count[k] = nd.count;
        area[k] = 0.0f;
        for (std::uint32_t i = 0; i < nd.count; ++i) area[k] += bounds[order_[nd.offset + i]].surface_area();
      } else {
        count[k] = count[k + 1] + count[nd.offset];
        area[k] = area[k + 1] + area[nd.offset];
      }
    }
    leaf_.assign(nodes_.size(), 0);
    for (std::size_t k = 0; k < nodes_.size(); ++k) {
      const node& nd = nodes_[k];
      leaf_[k] = nd.count > 0 || (count[k] <= static_cast<std::uint32_t>(max_leaf_size) &&
                                  area[k] >= merge_overlap * float(count[k]) * aabb{nd.lo, nd.hi}.surface_area());
    }
    wide_.reserve(nodes_.size() / 3 + 1);
    std::uint32_t bound = 0;
    collapse_node(0, count, bound);
    stack_bound_ = bound + 1;
    leaf_ = {};
  }

  // A binary node's first primitive in order_.
  std::uint32_t first_primitive(std::uint32_t k) const {
    while (nodes_[k].count == 0) ++k;
    return nodes_[k].offset;
  }

  // Returns the wide node's index; bound: the most stack entries its
  // subtree's traversal adds beyond the one it started from.
  std::uint32_t collapse_node(std::uint32_t k, const std::vector<std::uint32_t>& count, std::uint32_t& bound) {
    std::array<std::uint32_t, width> slot{k};
    int n = 1;
    if (!leaf_[k]) {
      slot = {k + 1, nodes_[k].offset};
      n = 2;
    }
    while (n < width) {
      int open = -1;
      float open_area = -1.0f;
      for (int i = 0; i < n; ++i) {
        const node& c = nodes_[slot[static_cast<std::size_t>(i)]];
        if (leaf_[slot[static_cast<std::size_t>(i)]]) continue;
        const float a = aabb{c.lo, c.hi}.surface_area();
        if (a > open_area) open = i, open_area = a;
      }
      if (open < 0) break;
      const std::uint32_t c = slot[static_cast<std::size_t>(open)];
      slot[static_cast<std::size_t>(open)] = c + 1;
      slot[static_cast<std::size_t>(n++)] = nodes_[c].offset;
    }
    const auto index = static_cast<std::uint32_t>(wide_.size());
    wide_.emplace_back();
    std::uint32_t below = 0;
    for (int i = 0; i < width; ++i) {
      const auto u = static_cast<std::size_t>(i);
      std::uint32_t child = 0;
      std::uint8_t leaf_count = 0;
      vec3 lo{infinity}, hi{-infinity};
      if (i < n) {
        const node& c = nodes_[slot[u]];
        lo = c.lo;
        hi = c.hi;
        if (leaf_[slot[u]]) {
          child = first_primitive(slot[u]);
          leaf_count = static_cast<std::uint8_t>(count[slot[u]]);
        } else {
          std::uint32_t b = 0;
          child = collapse_node(slot[u], count, b);
          below = std::max(below, b);
        }
      }
      wide_node& w = wide_[index];
      for (int a = 0; a < 3; ++a) {
        w.b[static_cast<std::size_t>(a)][u] = lo[a];
        w.b[static_cast<std::size_t>(a + 3)][u] = hi[a];
      }
      w.child[u] = child;
      w.count[u] = leaf_count;
      if (i < n) w.used = static_cast<std::uint8_t>(w.used | (1u << i));
    }
    bound = static_cast<std::uint32_t>(n - 1) + below;
    return index;
  }

  // What the slab tests of one ray share: for each axis, the origin's
  // coordinate, the reciprocal direction, the reciprocal widened by
  // 1 + 2 gamma(3) for the far planes (so that rounding cannot reject a
  // box the ray grazes, PBRT 4th ed., sec. 6.8.2: fl(fl(p - o) fl(w / d))
  // takes as many roundings as pbrt's fl(fl(fl(p - o) / d) w)), and the
  // rows of a node's boxes that hold the axis's near and far planes.
  struct ray_slabs {
    std::array<float, 3> o, inv, inv_far;
    std::array<std::size_t, 3> near_row, far_row;
    explicit ray_slabs(const ray& r) {
      constexpr float widen = 1.0f + 2.0f * rounding_gamma(3);
      for (int a = 0; a < 3; ++a) {
        const auto u = static_cast<std::size_t>(a);
        o[u] = r.o[a];
        inv[u] = 1.0f / r.d[a];
        inv_far[u] = inv[u] * widen;
        const bool neg = inv[u] < 0.0f;
        near_row[u] = static_cast<std::size_t>(neg ? a + 3 : a);
        far_row[u] = static_cast<std::size_t>(neg ? a : a + 3);
      }
    }
  };

  // The slab test of a ray against a node's eight boxes: bit i of the
  // result for child i, t0[i] where the ray enters its box. A NaN distance
  // (0 * inf, a ray in a slab's plane) never narrows the interval.
  static unsigned hits_boxes(const wide_node& w, const ray_slabs& rs, float tmin, float tmax,
                             std::array<float, width>& t0) {
#if defined(__GNUC__) || defined(__clang__)
    // Every lane at once (GCC's and Clang's vector extensions: AVX, or
    // pairs of SSE or NEON vectors).
    using floatw = float __attribute__((vector_size(4 * width)));
    std::array<floatw, 3> near, far;
    for (std::size_t a = 0; a < 3; ++a) {
      floatw near_plane, far_plane;
      std::memcpy(&near_plane, w.b[rs.near_row[a]].data(), sizeof(floatw));
      std::memcpy(&far_plane, w.b[rs.far_row[a]].data(), sizeof(floatw));
      near[a] = (near_plane - rs.o[a]) * rs.inv[a];
      far[a] = (far_plane - rs.o[a]) * rs.inv_far[a];
    }
    // max(x, y) = x > y ? x : y, so a NaN in x leaves y; as a tree of two
    // levels (a NaN in y may then drop x too: the interval only widens, and
    // no box the ray meets is lost). Written out, not as functions of
    // vectors: without AVX such a function's ABI differs (GCC's -Wpsabi).
    const floatw tmin_w = floatw{} + tmin, tmax_w = floatw{} + tmax;
    const floatw lo01 = near[0] > near[1] ? near[0] : near[1], lo2 = near[2] > tmin_w ? near[2] : tmin_w;
    const floatw hi01 = far[0] < far[1] ? far[0] : far[1], hi2 = far[2] < tmax_w ? far[2] : tmax_w;
    const floatw lo = lo01 > lo2 ? lo01 : lo2;
    const floatw hi = hi01 < hi2 ? hi01 : hi2;
    std::memcpy(t0.data(), &lo, sizeof(floatw));
    const auto in = lo <= hi;
#if defined(__AVX__)
    if constexpr (width == 8) return static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<floatw>(in)));
#endif
    unsigned mask = 0;
    for (int i = 0; i < width; ++i) mask |= unsigned(in[i] & 1) << i;
    return mask;
#else
    std::array<float, width> t1;
    t0.fill(tmin);
    t1.fill(tmax);
    for (std::size_t a = 0; a < 3; ++a) {
      const std::array<float, width>&near_plane = w.b[rs.near_row[a]], &far_plane = w.b[rs.far_row[a]];
      for (std::size_t i = 0; i < width; ++i) {
        const float near = (near_plane[i] - rs.o[a]) * rs.inv[a];
        const float far = (far_plane[i] - rs.o[a]) * rs.inv_far[a];
        t0[i] = near > t0[i] ? near : t0[i];
        t1[i] = far < t1[i] ? far : t1[i];
      }
    }
    unsigned mask = 0;
    for (std::size_t i = 0; i < width; ++i) mask |= unsigned(t0[i] <= t1[i]) << i;
    return mask;
#endif
  }

  // Asks for every cache line of a wide node ahead of its visit.
  static void prefetch(const wide_node* w) {
#if defined(__GNUC__) || defined(__clang__)
    for (std::size_t b = 0; b < sizeof(wide_node); b += 64) __builtin_prefetch(reinterpret_cast<const char*>(w) + b);
#else
    (void)w;
#endif
  }

  // Visits the leaves front to back; visit(first, count, tmax), for the
  // places first .. first + count - 1 of order(), may lower tmax and
  // returns true to stop. AnyHit: a query that stops at the first hit and
  // never lowers tmax, for which the order of the visits does not matter:
  // the children are taken in their node's order, unsorted (Embree's
  // traverseAnyHit).
  template <bool AnyHit = false, class Visit>
  bool traverse(const ray& r, float tmin, float& tmax, Visit&& visit) const {
    if (wide_.empty()) return false;
    if (stack_bound_ <= static_cast<std::uint32_t>(small_stack_size))
      return traverse_with<small_stack_size, AnyHit>(r, tmin, tmax, visit);
    return traverse_with<wide_stack_size, AnyHit>(r, tmin, tmax, visit);
  }

  template <int StackSize, bool AnyHit, class Visit>
  bool traverse_with(const ray& r, float tmin, float& tmax, Visit& visit) const {
    const ray_slabs rs(r);
    struct entry {
      std::uint32_t child;
      std::uint32_t count;  // leaf: its primitives; 0: a wide node
      float t;              // where the ray enters its box
    };
    std::array<entry, StackSize> stack;
    int top = 0;
    // A child the traversal goes on with, or puts aside, has its node asked
    // for at once: the memory is on its way while the rest of this node is
    // dealt with.
    const auto ask = [&](const entry& c) {
      if (c.count == 0) prefetch(&wide_[c.child]);
      return c;
    };
    entry e{0, 0, tmin};
    while (true) {
      if (e.count > 0) {
        if (visit(e.child, e.count, tmax)) return true;
      } else {
        const wide_node& w = wide_[e.child];
        std::array<float, width> t0;
        unsigned mask = hits_boxes(w, rs, tmin, tmax, t0) & w.used;
        if (mask != 0) {
          const auto child = [&](unsigned i) { return ask(entry{w.child[i], w.count[i], t0[i]}); };
          const entry a = child(static_cast<unsigned>(std::countr_zero(mask)));
          mask &= mask - 1;
          if (mask == 0) {  // one child hit: on to it
            e = a;
            continue;
          }
          if constexpr (AnyHit) {
            // The first on, the others onto the stack as they come.
            e = a;
            do {
              stack[static_cast<std::size_t>(top++)] = child(static_cast<unsigned>(std::countr_zero(mask)));
              mask &= mask - 1;
            } while (mask != 0);
            continue;
          } else {
            const entry b = child(static_cast<unsigned>(std::countr_zero(mask)));
            mask &= mask - 1;
            if (mask == 0) {  // two: on to the nearer, the other waits
              const bool a_first = a.t <= b.t;
              stack[static_cast<std::size_t>(top++)] = a_first ? b : a;
              e = a_first ? a : b;
              continue;
            }
            // More: onto the stack, sorted so that the nearest is on top,
            // and on to it.
            const int base = top;
            const auto insert = [&](const entry& c) {
              int k = top++;
              for (; k > base && stack[static_cast<std::size_t>(k - 1)].t < c.t; --k)
                stack[static_cast<std::size_t>(k)] = stack[static_cast<std::size_t>(k - 1)];
              stack[static_cast<std::size_t>(k)] = c;
            };
            insert(a);
            insert(b);
            do {
              insert(child(static_cast<unsigned>(std::countr_zero(mask))));
              mask &= mask - 1;
            } while (mask != 0);
            e = stack[static_cast<std::size_t>(--top)];
            continue;
          }
        }
      }
      if constexpr (AnyHit) {
        // Every waiting child is entered before tmax, which never falls.
        if (top == 0) return false;
        e = stack[static_cast<std::size_t>(--top)];
      } else {
        // The next waiting child that the ray enters before its closest hit
        // so far.
        do {
          if (top == 0) return false;
          e = stack[static_cast<std::size_t>(--top)];
        } while (e.t > tmax);
      }
    }
  }
};

}  // namespace mcrt
