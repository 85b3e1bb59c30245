#pragma once
// A bounding volume hierarchy over lights, for choosing one light among many
// by its importance at a shading point (Conty Estevez & Kulla 2018,
// "Importance Sampling of Many Lights with Adaptive Tree Splitting", sec. 4;
// pbrt-v4's BVHLightSampler and LightBounds, src/pbrt/lightsamplers.h/.cpp,
// "Physically Based Rendering", 4th ed., sec. 12.6.3).
//
// Every node bounds the lights below it by a box, a cone holding their
// emitting normals (axis w, half-angle theta_o), the angle theta_e beyond a
// normal to which they emit (pi/2 for a lambertian surface) and their total
// flux phi. The tree is built top-down as pbrt-v4 builds it: at each node
// the lights are split at the cheapest of 11 bucket boundaries per axis by
// the cost phi M_Omega(theta_o, theta_e) K_r SA(box) of each side (Conty
// Estevez & Kulla, eq. 2 to 4), down to one light per leaf. The lights of a
// subtree are contiguous in order(), so a node also names the range of them.
//
// The hierarchy holds geometry only; what a node is worth at a point (the
// importance) is the caller's (render/light_selection.hpp), so one tree
// serves every way of choosing.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "mcrt/core/math.hpp"
#include "mcrt/core/onb.hpp"
#include "mcrt/geometry/aabb.hpp"

namespace mcrt {

namespace light_bvh_detail {

// sqrt of a value that rounding may have left slightly below 0 (1 - cos^2
// of a unit dot product): 0 there instead of NaN (pbrt-v4's SafeSqrt).
inline float safe_sqrt(float x) { return std::sqrt(std::max(x, 0.0f)); }
// acos of a value rounding may have left slightly outside [-1, 1].
inline float safe_acos(float x) { return std::acos(std::clamp(x, -1.0f, 1.0f)); }

// Rotates v about the unit axis k by the angle theta (Rodrigues' formula).
inline vec3 rotate(const vec3& v, const vec3& k, float theta) {
  const float c = std::cos(theta), s = std::sin(theta);
  return v * c + glm::cross(k, v) * s + k * (glm::dot(k, v) * (1.0f - c));
}

}  // namespace light_bvh_detail

// A cone of directions about the unit axis w with half-angle acos(cos_theta):
// cos_theta = -1 is every direction.
struct direction_cone {
  vec3 w{0.0f, 0.0f, 1.0f};
  float cos_theta = 1.0f;

  static direction_cone entire_sphere() { return {vec3(0.0f, 0.0f, 1.0f), -1.0f}; }
};

// The smallest cone holding both (pbrt-v4's Union(DirectionCone,
// DirectionCone), vecmath.cpp; Conty Estevez & Kulla, Algorithm 1).
inline direction_cone unite(const direction_cone& a, const direction_cone& b) {
  using namespace light_bvh_detail;
  const float theta_a = safe_acos(a.cos_theta), theta_b = safe_acos(b.cos_theta);
  const float theta_d = safe_acos(glm::dot(a.w, b.w));
  if (std::min(theta_d + theta_b, pi) <= theta_a) return a;
  if (std::min(theta_d + theta_a, pi) <= theta_b) return b;
  const float theta_o = 0.5f * (theta_a + theta_d + theta_b);
  if (theta_o >= pi) return direction_cone::entire_sphere();
  // a's axis turned towards b's by theta_o - theta_a.
  const vec3 k = glm::cross(a.w, b.w);
  const float k2 = glm::dot(k, k);
  // Axes exactly opposite (or too close for a rotation axis): the whole sphere.
  if (!(k2 > 0.0f)) return direction_cone::entire_sphere();
  const vec3 w = glm::normalize(rotate(a.w, k / std::sqrt(k2), theta_o - theta_a));
  // Widened by 1e-5 rad, over the float rounding of the rotation and the
  // angles (measured up to 6e-7 rad), so that the cone holds both.
  constexpr float guard = 1e-5f;
  if (theta_o + guard >= pi) return direction_cone::entire_sphere();
  return {w, std::cos(theta_o + guard)};
}

// What a node knows of its lights (pbrt-v4's LightBounds, one-sided: a
// two-sided light is two lights here, one per side).
struct light_bounds {
  aabb box;
  direction_cone normals;     // the emitting normals' cone (theta_o)
  float cos_theta_e = 0.0f;   // cos of the emission's spread beyond a normal: pi/2 for a lambertian emitter
  float phi = 0.0f;           // flux (here: pi * area * luminance of the radiance)
  vec3 centre{0.0f};          // one light's centre on its surface (its centroid; a sphere's centre)
};

inline light_bounds unite(const light_bounds& a, const light_bounds& b) {
  if (!(a.phi > 0.0f)) return b;
  if (!(b.phi > 0.0f)) return a;
  light_bounds u;
  u.box = a.box;
  u.box.grow(b.box);
  u.normals = unite(a.normals, b.normals);
  u.cos_theta_e = std::min(a.cos_theta_e, b.cos_theta_e);
  u.phi = a.phi + b.phi;
  return u;
}

class light_bvh {
 public:
  struct node {
    light_bounds bounds;
    std::uint32_t second = 0;       // an inner node's second child (the first is the next node)
    std::uint32_t first = 0;        // its lights: order()[first, first + count)
    std::uint32_t count = 0;
    std::uint32_t parent = none;
    aabb ray_box;  // bounds.box widened for ray tests (widened()), holding its children's
    bool leaf() const { return count == 1; }
  };
  static constexpr std::uint32_t none = 0xffffffffu;

  light_bvh() = default;

  // Builds the hierarchy over items (one per light; an item of zero flux is
  // left out: it is never chosen).
  explicit light_bvh(const std::vector<light_bounds>& items) {
    leaf_of_.assign(items.size(), none);
    std::vector<std::uint32_t> ids;
    for (std::uint32_t i = 0; i < items.size(); ++i)
      if (items[i].phi > 0.0f && !items[i].box.empty()) ids.push_back(i);
    if (ids.empty()) return;
    // Halving from this depth on adds at most bit_width(n) levels: the tree
    // stays within max_depth for any count of lights.
    halve_from_ = std::min<std::size_t>(max_depth - 24, max_depth - 1 - std::bit_width(ids.size()));
    nodes_.reserve(2 * ids.size());
    order_.reserve(ids.size());
    slots_.reserve(ids.size());
    build(items, ids, 0, static_cast<std::uint32_t>(ids.size()), none, 0);
    build_proxies();
    // Children follow their parent, so a walk backwards meets each node's
    // children before it: an inner node's ray box grows to hold its
    // children's, and a ray that meets a light's ray box meets every ray box
    // above it (the slab test is monotone in a box's faces), which lets
    // light_selection reach a cluster's lights through its subtree.
    for (std::size_t i = nodes_.size(); i-- > 0;) {
      node& nd = nodes_[i];
      nd.ray_box = widened(nd.bounds.box);
      if (!nd.leaf()) {
        nd.ray_box.grow(nodes_[i + 1].ray_box);
        nd.ray_box.grow(nodes_[nd.second].ray_box);
      }
    }
  }

  // A box widened by 1e-6 of its coordinates' magnitudes on each axis, for
  // the ray tests of light_selection::pdf (which widens it by the ray
  // origin's magnitude too): a ray that meets a light whose box is flat (a
  // polygon in a coordinate plane) is not lost to the slab test's rounding.
  static aabb widened(const aabb& b) {
    aabb w;
    for (int a = 0; a < 3; ++a) {
      const float pad = 1e-6f * (std::abs(b.lo[a]) + std::abs(b.hi[a]));
      w.lo[a] = b.lo[a] - pad;
      w.hi[a] = b.hi[a] + pad;
    }
    return w;
  }

  // The depth no tree exceeds (the traversals' stacks): past max_depth - 24
  // a range is halved instead of split by cost (earlier for more than 2^23
  // lights: halve_from_), so no tree is deeper.
  static constexpr std::size_t max_depth = 96;

  // What a selection needs of each light to weigh it against the others of
  // a small subtree, in the leaves' order (slot i: order()[i]), beside each
  // other in memory: its box, its centre, emitting normal and flux, and the
  // square of its box's half diagonal (its size).
  struct slot {
    aabb box;
    vec3 centre{0.0f};
    vec3 normal{0.0f, 0.0f, 1.0f};
    float phi = 0.0f;
    float r2 = 0.0f;
    bool all_directions = false;  // emits every way (a sphere): no normal
  };

  // A node's lights as one planar emitter (render/light_selection.hpp,
  // bvh's weight of a node): their flux spread evenly over the rectangle
  // (corner, e1, e2) that holds their boxes' corners projected on the plane
  // through their flux-weighted centroid, normal to their flux-weighted
  // mean emitting normal. planar is false where there is no such normal
  // (a sphere among the lights, or normals that cancel to less than half
  // their flux: the lights face every way).
  struct proxy {
    vec3 corner{0.0f}, e1{0.0f}, e2{0.0f};
    vec3 normal{0.0f, 0.0f, 1.0f};
    vec3 centre{0.0f};
    float inv_area = 0.0f;  // 1 / |e1| |e2|
    float r2 = 0.0f;        // the square of the rectangle's half diagonal
    bool planar = false;

    // The rectangle's corners in order around it (corner, + e1, + e1 + e2, + e2).
    std::array<vec3, 4> corners() const { return {corner, corner + e1, corner + e1 + e2, corner + e2}; }
  };

  bool empty() const { return nodes_.empty(); }
  const std::vector<slot>& slots() const { return slots_; }
  const std::vector<proxy>& proxies() const { return proxies_; }
  const std::vector<node>& nodes() const { return nodes_; }
  // The items in the leaves' order (a subtree's are contiguous).
  const std::vector<std::uint32_t>& order() const { return order_; }
  // The leaf holding item i, or none (an item left out).
  std::uint32_t leaf_of(std::size_t i) const { return i < leaf_of_.size() ? leaf_of_[i] : none; }

  // The surface-area-orientation cost of a cluster (Conty Estevez & Kulla,
  // eq. 2 and 4; pbrt-v4's BVHLightSampler::EvaluateCost): flux times the
  // measure M_Omega of the directions its normals' cone and emission spread
  // reach, times the box's area, times K_r, which favours splits across a
  // long box.
  static float cost(const light_bounds& b, const aabb& parent_box, int dim) {
    using namespace light_bvh_detail;
    const float theta_o = safe_acos(b.normals.cos_theta), theta_e = safe_acos(b.cos_theta_e);
    const float theta_w = std::min(theta_o + theta_e, pi);
    const float sin_o = safe_sqrt(1.0f - b.normals.cos_theta * b.normals.cos_theta);
    const float m_omega = 2.0f * pi * (1.0f - b.normals.cos_theta) +
                          0.5f * pi * (2.0f * theta_w * sin_o - std::cos(theta_o - 2.0f * theta_w) -
                                       2.0f * theta_o * sin_o + b.normals.cos_theta);
    const vec3 d = parent_box.hi - parent_box.lo;
    const float kr = std::max({d.x, d.y, d.z}) / d[dim];
    return b.phi * m_omega * kr * b.box.surface_area();
  }

 private:
  std::uint32_t build(const std::vector<light_bounds>& items, std::vector<std::uint32_t>& ids, std::uint32_t begin,
                      std::uint32_t end, std::uint32_t parent, std::size_t depth) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    nodes_[index].parent = parent;
    if (end - begin == 1) {
      const std::uint32_t item = ids[begin];
      nodes_[index].bounds = items[item];
      nodes_[index].first = static_cast<std::uint32_t>(order_.size());
      nodes_[index].count = 1;
      order_.push_back(item);
      leaf_of_[item] = index;
      const light_bounds& b = items[item];
      const vec3 half = 0.5f * (b.box.hi - b.box.lo);
      slots_.push_back({b.box, b.centre, b.normals.w, b.phi, glm::dot(half, half), b.normals.cos_theta < 0.0f});
      return index;
    }
    light_bounds all;
    aabb centroids;
    for (std::uint32_t i = begin; i < end; ++i) {
      all = unite(all, items[ids[i]]);
      centroids.grow(items[ids[i]].box.centroid());
    }
    // The cheapest bucket boundary over the three axes (12 buckets each).
    constexpr int buckets = 12;
    float best_cost = std::numeric_limits<float>::infinity();
    int best_dim = -1, best_split = -1;
    // The bucket of a centroid; NaN (hi - lo overflows for centroids near
    // -FLT_MAX and FLT_MAX) goes to the first: converting NaN or an
    // out-of-range value to int is undefined, so the clamp is taken in float.
    const auto bucket_of = [&](std::uint32_t id, int dim) {
      const float lo = centroids.lo[dim], hi = centroids.hi[dim];
      const float f = float(buckets) * ((items[id].box.centroid()[dim] - lo) / (hi - lo));
      return f >= 1.0f ? (f < float(buckets) ? static_cast<int>(f) : buckets - 1) : 0;
    };
    for (int dim = 0; dim < 3 && depth < halve_from_; ++dim) {
      if (!(centroids.hi[dim] > centroids.lo[dim])) continue;
      std::array<light_bounds, buckets> bk{};
      for (std::uint32_t i = begin; i < end; ++i) {
        light_bounds& b = bk[bucket_of(ids[i], dim)];
        b = unite(b, items[ids[i]]);
      }
      // below: buckets 0..s, grown by one bucket per split (the same unions
      // in the same order as uniting them anew for each s); above: buckets
      // s + 1.. united in ascending order for each s (unite is not
      // associative in float, so the tree is the one this order gives).
      light_bounds below;
      for (int s = 0; s + 1 < buckets; ++s) {
        below = unite(below, bk[s]);
        light_bounds above;
        for (int b = s + 1; b < buckets; ++b) above = unite(above, bk[b]);
        if (!(below.phi > 0.0f) || !(above.phi > 0.0f)) continue;
        const float c = cost(below, all.box, dim) + cost(above, all.box, dim);
        if (c > 0.0f && c < best_cost) {
          best_cost = c;
          best_dim = dim;
          best_split = s;
        }
      }
    }
    std::uint32_t mid;
    if (best_dim < 0) {
      // Every centroid in one place (or no split with a finite cost): the
      // range halved, as pbrt-v4 does.
      mid = begin + (end - begin) / 2;
    } else {
      const auto it = std::partition(ids.begin() + begin, ids.begin() + end,
                                     [&](std::uint32_t id) { return bucket_of(id, best_dim) <= best_split; });
      mid = static_cast<std::uint32_t>(it - ids.begin());
      if (mid == begin || mid == end) mid = begin + (end - begin) / 2;
    }
    nodes_[index].first = static_cast<std::uint32_t>(order_.size());
    build(items, ids, begin, mid, index, depth + 1);
    const std::uint32_t second = build(items, ids, mid, end, index, depth + 1);
    node& n = nodes_[index];
    n.second = second;
    n.count = end - begin;
    n.bounds = unite(nodes_[index + 1].bounds, nodes_[second].bounds);
    return index;
  }

  // Each node's proxy (struct proxy), from its lights' slots.
  void build_proxies() {
    proxies_.assign(nodes_.size(), proxy{});
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      const node& nd = nodes_[i];
      proxy& q = proxies_[i];
      vec3 normal_sum(0.0f), centre_sum(0.0f);
      float phi = 0.0f;
      bool sphere = false;
      for (std::uint32_t k = nd.first; k < nd.first + nd.count; ++k) {
        const slot& s = slots_[k];
        sphere = sphere || s.all_directions;
        normal_sum += s.phi * s.normal;
        centre_sum += s.phi * s.centre;
        phi += s.phi;
      }
      if (!(phi > 0.0f)) continue;
      q.centre = centre_sum / phi;
      const float len = glm::length(normal_sum);
      if (sphere || !(len >= 0.5f * phi)) continue;
      q.normal = normal_sum / len;
      // A frame of the plane.
      const onb frame(q.normal);
      const vec3 &t = frame.u, &u = frame.v;
      float t0 = infinity, t1 = -infinity, u0 = infinity, u1 = -infinity;
      for (std::uint32_t k = nd.first; k < nd.first + nd.count; ++k) {
        const aabb& box = slots_[k].box;
        for (int c = 0; c < 8; ++c) {
          const vec3 v(c & 1 ? box.hi.x : box.lo.x, c & 2 ? box.hi.y : box.lo.y, c & 4 ? box.hi.z : box.lo.z);
          const float x = glm::dot(v - q.centre, t), y = glm::dot(v - q.centre, u);
          t0 = std::min(t0, x), t1 = std::max(t1, x), u0 = std::min(u0, y), u1 = std::max(u1, y);
        }
      }
      const float area = (t1 - t0) * (u1 - u0);
      if (!(area > 0.0f) || !std::isfinite(area)) continue;
      q.corner = q.centre + t0 * t + u0 * u;
      q.e1 = (t1 - t0) * t;
      q.e2 = (u1 - u0) * u;
      q.inv_area = 1.0f / area;
      q.r2 = 0.25f * ((t1 - t0) * (t1 - t0) + (u1 - u0) * (u1 - u0));
      q.planar = true;
    }
  }

  std::vector<node> nodes_;
  std::size_t halve_from_ = max_depth - 24;  // the depth from which ranges are halved (the constructor)
  std::vector<std::uint32_t> order_;
  std::vector<std::uint32_t> leaf_of_;
  std::vector<slot> slots_;
  std::vector<proxy> proxies_;
};

}  // namespace mcrt
