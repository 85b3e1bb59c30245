#pragma once
// A bounding volume hierarchy over any primitives: built by the binned
// surface area heuristic (MacDonald & Booth 1990, "Heuristics for ray
// tracing using space subdivision"; Wald 2007, "On fast construction of
// SAH-based bounding volume hierarchies"; pbrt-v4's BVHAggregate with 12
// buckets), stored as compact nodes in depth-first order (32 bytes: the box,
// the second child's or the first primitive's index, a count and the split
// axis; Pharr et al., "Physically Based Rendering", 4th ed., sec. 7.3.4),
// and traversed front to back (the near child first by the ray's direction
// along the node's split axis), with an early exit for shadow rays.
//
// The hierarchy knows its primitives only through their bounds, at build
// time, and through a callback at traversal: it holds their order, so a
// primitive is named by its index in the caller's array.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "mcrt/core/math.hpp"
#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/aabb.hpp"

namespace mcrt {

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

  // Builds over primitives 0 .. bounds.size() - 1.
  explicit bvh(const std::vector<aabb>& bounds) {
    order_.resize(bounds.size());
    for (std::size_t i = 0; i < bounds.size(); ++i) order_[i] = static_cast<std::uint32_t>(i);
    if (bounds.empty()) return;
    std::vector<vec3> centroids(bounds.size());
    for (std::size_t i = 0; i < bounds.size(); ++i) centroids[i] = bounds[i].centroid();
    nodes_.reserve(2 * bounds.size());
    build(bounds, centroids, 0, static_cast<std::uint32_t>(bounds.size()), 0);
  }

  bool empty() const { return nodes_.empty(); }
  const std::vector<node>& nodes() const { return nodes_; }
  // The primitives in the order the leaves reference them.
  const std::vector<std::uint32_t>& order() const { return order_; }

  // For a caller that has stored its primitives in order() (leaf by leaf,
  // so that a leaf's primitives are adjacent in memory): from then on the
  // traversal names a primitive by its place in that order.
  void renumber_in_order() {
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<std::uint32_t>(i);
  }

  // The closest hit in (tmin, tmax): hit(i, tmin, tmax) tests primitive i
  // and returns its hit's t, or a value >= tmax (infinity) for none; tmax
  // is lowered to each hit found. Returns the primitive of the closest hit,
  // or -1.
  template <class Hit>
  std::int64_t closest(const ray& r, float tmin, float& tmax, Hit&& hit) const {
    std::int64_t best = -1;
    traverse(r, tmin, tmax, [&](std::uint32_t prim, float& t_max) {
      const float t = hit(prim, tmin, t_max);
      if (t < t_max) {
        t_max = t;
        best = prim;
      }
      return false;
    });
    return best;
  }

  // Whether any primitive is hit in (tmin, tmax): hit(i, tmin, tmax) returns
  // true for a hit; the traversal stops at the first.
  template <class Hit>
  bool any(const ray& r, float tmin, float tmax, Hit&& hit) const {
    return traverse(r, tmin, tmax, [&](std::uint32_t prim, float& t_max) { return hit(prim, tmin, t_max); });
  }

 private:
  std::vector<node> nodes_;
  std::vector<std::uint32_t> order_;

  static constexpr int bucket_count = 12;
  // The traversal's stack holds at most one node per level. Below this depth
  // the build halves by count, so no tree is deeper than it plus log2 of the
  // primitive count (<= 32): within the stack.
  static constexpr int balanced_below_depth = 96;
  static constexpr int stack_size = 128;

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
    } else if (n <= 2) {
      std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                       [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
    } else {
      // Binned SAH: cost of a split after bucket k, relative cost of a
      // traversal step 1/2 as pbrt-v4 (leaf cost = primitives).
      std::array<aabb, bucket_count> bucket_box;
      std::array<std::uint32_t, bucket_count> bucket_n{};
      const auto bucket_of = [&](std::uint32_t prim) {
        const int b = static_cast<int>(bucket_count * ((centroids[prim][axis] - c0) / (c1 - c0)));
        return std::clamp(b, 0, bucket_count - 1);
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
        cost[static_cast<std::size_t>(k)] = float(count_below) * below.surface_area();
      }
      aabb above;
      std::uint32_t count_above = 0;
      for (int k = bucket_count - 1; k >= 1; --k) {
        above.grow(bucket_box[static_cast<std::size_t>(k)]);
        count_above += bucket_n[static_cast<std::size_t>(k)];
        cost[static_cast<std::size_t>(k - 1)] += float(count_above) * above.surface_area();
      }
      int best = 0;
      for (int k = 1; k < bucket_count - 1; ++k)
        if (cost[static_cast<std::size_t>(k)] < cost[static_cast<std::size_t>(best)]) best = k;
      const float leaf_cost = float(n);
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

  // The slab test against a node's box, with the far distance widened by
  // 2 gamma(3) so that rounding cannot reject a box the ray grazes (PBRT
  // 4th ed., sec. 6.8.2).
  static bool hits_box(const node& nd, const vec3& o, const vec3& inv_d, const std::array<int, 3>& neg, float tmin,
                       float tmax) {
    const float* lo = &nd.lo.x;
    const float* hi = &nd.hi.x;
    float t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
      const float near = ((neg[static_cast<std::size_t>(a)] ? hi[a] : lo[a]) - o[a]) * inv_d[a];
      float far = ((neg[static_cast<std::size_t>(a)] ? lo[a] : hi[a]) - o[a]) * inv_d[a];
      far *= 1.0f + 2.0f * rounding_gamma(3);
      t0 = near > t0 ? near : t0;  // (NaN from 0 * inf leaves t0 as it is)
      t1 = far < t1 ? far : t1;
      if (t0 > t1) return false;
    }
    return true;
  }

  // Visits the leaves' primitives front to back; visit(prim, tmax) may
  // lower tmax and returns true to stop.
  template <class Visit>
  bool traverse(const ray& r, float tmin, float& tmax, Visit&& visit) const {
    if (nodes_.empty()) return false;
    const vec3 inv_d = 1.0f / r.d;
    const std::array<int, 3> neg = {inv_d.x < 0.0f, inv_d.y < 0.0f, inv_d.z < 0.0f};
    std::array<std::uint32_t, stack_size> stack;
    int top = 0;
    std::uint32_t current = 0;
    while (true) {
      const node& nd = nodes_[current];
      if (hits_box(nd, r.o, inv_d, neg, tmin, tmax)) {
        if (nd.count > 0) {
          for (std::uint32_t i = 0; i < nd.count; ++i)
            if (visit(order_[nd.offset + i], tmax)) return true;
          if (top == 0) break;
          current = stack[static_cast<std::size_t>(--top)];
        } else if (neg[nd.axis]) {  // the second child is nearer
          stack[static_cast<std::size_t>(top++)] = current + 1;
          current = nd.offset;
        } else {
          stack[static_cast<std::size_t>(top++)] = nd.offset;
          current = current + 1;
        }
      } else {
        if (top == 0) break;
        current = stack[static_cast<std::size_t>(--top)];
      }
    }
    return false;
  }
};

}  // namespace mcrt
