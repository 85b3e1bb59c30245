#pragma once
// Which light a next-event estimator samples at a shading point, and the
// density of that whole technique (choose a light, then sample it) per unit
// solid angle: the quantity both the shadow-ray estimate and the multiple
// importance sampling weights need (Veach 1997, sec. 9.2; pbrt-v4's
// LightSampler, "Physically Based Rendering", 4th ed., sec. 12.6).
//
// Only the scene's emitters take part (book 3's glass sphere, sampled by the
// mixture pdf but emitting nothing, gets no shadow rays). A light is chosen
//   - by power (the default of JSON scenes): P(k) = Phi_k / sum of Phi_j,
//     Phi the emitted flux, so a bright or large light gets more samples
//     than a dim one; or
//   - uniformly: P(k) = 1 / count; or
//   - by the light hierarchy (bvh, pbrt_bvh; accel/light_bvh.hpp): from the
//     root down, each child with the probability of its importance at the
//     point (render/light_importance.hpp), so P(k) is the product of the
//     choices on the way to light k. pbrt_bvh is pbrt-v4's BVHLightSampler
//     as it ships (its importance at every node down to the leaves, a
//     receiver of either side); bvh is mcrt's: at every node an estimate
//     of its lights' contribution (contribution_estimate: a planar proxy of
//     them, or a near cluster's lights' own weights), down to the first
//     node of at most `cluster_size` lights, and there one choice among
//     them by each light's own contribution (leaf_weight: as a point light
//     from its centre with its own normal, or exactly where it is near).
//     A box's importance bounds its cosines and guesses its distance; near
//     the point, where the contributions that matter are, that is what
//     misleads the choice (the variance each leaves: bench/
//     light_select_variance.cpp and light_select_floor.cpp, docs/
//     light-selection.md).
// With at most `linear_limit` emitters (or without the scene's light tree),
// power and uniform consider only the lights that can offer the point a
// sample (`faces`: a one-sided light seen from behind is left out, so no
// sample is wasted on it), by a walk over every emitter; with more, they
// are pbrt-v4's PowerLightSampler and UniformLightSampler (every emitter,
// facing or not), through the tree in O(log N) (bvh's importance leaves
// the lights that do not face the point out by itself).
//
// The technique's density at a direction is p_L(dir) = sum_k P(k) p_k(o, dir),
// the sum over every light: the shadow ray returns the radiance of whatever
// it meets first, so one light's sample may land on another light in front
// of it, and the estimate stays unbiased only with the density of the whole
// mixture (with one light the sum has one term). Through the tree the sum
// visits only the nodes whose boxes the ray from o along dir meets.
#include <algorithm>
#include <array>
#include <bit>
#include <cfloat>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>

#include "mcrt/accel/light_bvh.hpp"
#include "mcrt/render/light.hpp"
#include "mcrt/render/light_importance.hpp"
#include "mcrt/render/light_list.hpp"
#include "mcrt/render/scene.hpp"

namespace mcrt {

enum class light_choice { power, uniform, bvh, pbrt_bvh };

class light_selection {
 public:
  // Up to this many emitters, power and uniform walk them all (facing ones only).
  static constexpr std::size_t linear_limit = 8;
  // bvh: a node with at most this many lights has them chosen one by one
  // by their own importance (bench/light_select_variance.cpp measured 8 to
  // 128: see docs/light-selection.md).
  static constexpr std::uint32_t cluster_size = 32;
  // bvh: a node of at most this many lights that is near the point (within
  // sqrt(recurse_far) times its proxy's half diagonal) is weighed by the sum
  // of its children's weights (contribution_estimate).
  static constexpr std::uint32_t recurse_limit = 128;
  static constexpr float recurse_far = 4.0f;

  // o: the shading point; n: the unit normal of its surface (for the
  // cosine-aware strategies' densities and the importance). tree: the
  // scene's light hierarchy over `emitters` (scene::build_light_tree), or
  // null. both_sides: the surface transmits (bvh counts the light below its
  // horizon too).
  // Built at every vertex of every path: always inlined (GCC's and Clang's
  // always_inline; GCC left it out of line once the integrators grew, and
  // the call cost about 2 % of a Cornell box's render).
#if defined(__GNUC__) || defined(__clang__)
  [[gnu::always_inline]]
#endif
  light_selection(const light_list& lights, std::span<const emitter> emitters, const light_bvh* tree,
                  const vec3& o, const vec3& n, light_choice how, bool both_sides = false)
      : lights_(&lights), emitters_(emitters), o_(o), n_(n), how_(how), both_sides_(both_sides) {
    const bool hierarchical = how == light_choice::bvh || how == light_choice::pbrt_bvh;
    // One emitter: every choice is P = 1 where it faces the point.
    if (tree && !tree->empty() && emitters.size() > (hierarchical ? 1 : linear_limit)) {
      tree_ = tree;
      if (how == light_choice::bvh) {
        for (memo_entry& m : memo_) m.node = light_bvh::none;
        for (cluster_entry& c : clusters_) c.node = light_bvh::none;
      }
      return;
    }
    if (hierarchical && emitters.size() > 1) {
      if (!tree) throw std::logic_error("light_selection: bvh needs the scene's light tree (scene::build_light_tree)");
      // The tree holds the lights of positive flux; an empty one means that
      // no light has any (every L or scale 0): nothing to choose, as by power.
      return;
    }
    for (std::size_t i = 0; i < emitters_.size(); ++i)
      if (faces((*lights_)[emitters_[i].light], o_)) {
        if (i < mask_bits) facing_ |= std::uint64_t{1} << i;
        ++count_;
        total_ += emitters_[i].power;
      }
    // By power, lights of zero power are never chosen; when they are all the
    // facing lights, there is nothing to choose.
    if (how_ == light_choice::power && !(total_ > 0.0f)) count_ = 0;
  }
  light_selection(const light_list& lights, std::span<const emitter> emitters, const vec3& o, const vec3& n,
                  light_choice how)
      : light_selection(lights, emitters, nullptr, o, n, how) {}
  // A selection of nothing (empty(), pdf 0 everywhere): a placeholder to
  // assign a real selection to.
  light_selection() = default;

  template <class Scene>
#if defined(__GNUC__) || defined(__clang__)
  [[gnu::always_inline]]
#endif
  light_selection(const Scene& sc, const vec3& o, const vec3& n, light_choice how, bool both_sides = false)
      : light_selection(sc.lights, sc.emitters, &sc.light_tree, o, n, how, both_sides) {}

  bool empty() const { return tree_ ? false : count_ == 0; }
  // Whether the choice needs a random number (more than one candidate).
  bool needs_choice() const { return emitters_.size() > 1; }
  // Whether the choice goes through the light tree.
  bool hierarchical() const { return tree_ != nullptr; }

  const vec3& point() const { return o_; }
  const vec3& normal() const { return n_; }
  // The pixel's footprint at a camera ray's first surface (nullptr
  // elsewhere): the lights `auto` samples take one choice over it in
  // sample() and pdf() alike (sampling/auto_footprint.hpp).
  const auto_footprint* footprint() const { return footprint_; }
  void set_footprint(const auto_footprint* fp) { footprint_ = fp; }

  // Picks an emitter with u in [0, 1): its index in the scene's lights, or
  // -1 when there is none; prob is P(k).
  std::ptrdiff_t pick(float u, float& prob) const {
    if (tree_) return pick_tree(u, prob);
    if (count_ == 0) return -1;
    // One facing emitter (of power > 0 when chosen by power): P = 1, the
    // loops' answer without them.
    if (count_ == 1 && emitters_.size() == 1) {
      prob = 1.0f;
      return emitters_[0].light;
    }
    if (how_ == light_choice::uniform) {
      std::size_t k = std::min(static_cast<std::size_t>(u * static_cast<float>(count_)), count_ - 1);
      for (std::size_t i = 0; i < emitters_.size(); ++i) {
        if (!facing(i)) continue;
        if (k-- == 0) {
          prob = 1.0f / static_cast<float>(count_);
          return emitters_[i].light;
        }
      }
      return -1;
    }
    // By power: walk the cumulative sum; the last facing light with power
    // takes whatever rounding leaves over.
    const float target = u * total_;
    float acc = 0.0f;
    std::ptrdiff_t last = -1;
    float last_power = 0.0f;
    for (std::size_t i = 0; i < emitters_.size(); ++i) {
      const emitter& e = emitters_[i];
      if (!(e.power > 0.0f) || !facing(i)) continue;
      acc += e.power;
      last = e.light;
      last_power = e.power;
      if (target < acc) break;
    }
    prob = last_power / total_;
    return last;
  }

  // Through the tree: the weight at the point of node `index` of the
  // scene's light tree (light_bvh::nodes()) by which its parent chooses
  // it: bvh's estimate of its lights' contribution (contribution_estimate),
  // pbrt-v4's importance, or its flux or light count. For tools and tests.
  float node_weight_at(std::uint32_t index) const {
    return tree_ && index < tree_->nodes().size() ? node_weight(tree_->nodes()[index], index) : 0.0f;
  }

  // P(k) of the light with index k among the scene's lights (0 when it is
  // not an emitter the selection can choose).
  float probability(std::size_t k) const {
    // Where every light emits, emitter k is light k: no search.
    if (k < emitters_.size() && emitters_[k].light == k) return tree_ ? probability_tree(k) : probability_of(k);
    for (std::size_t i = 0; i < emitters_.size(); ++i)
      if (emitters_[i].light == k) return tree_ ? probability_tree(i) : probability_of(i);
    return 0.0f;
  }

  // Density per unit SOLID ANGLE at o of the whole technique, p_L(dir) =
  // sum_k P(k) p_k(o, dir). When the light `known` is known to have density
  // known_pdf at dir (the light dir was sampled from), that term is not
  // evaluated again.
  float pdf(const vec3& dir, std::ptrdiff_t known = -1, float known_pdf = 0.0f) const {
    if (tree_) return pdf_tree(dir, known, known_pdf);
    if (count_ == 0) return 0.0f;
    if (count_ == 1 && emitters_.size() == 1) {  // P = 1, as pick
      const std::size_t k = emitters_[0].light;
      return static_cast<std::ptrdiff_t>(k) == known ? known_pdf : mcrt::pdf((*lights_)[k], o_, n_, dir, footprint_);
    }
    float sum = 0.0f;
    for (std::size_t i = 0; i < emitters_.size(); ++i) {
      const emitter& e = emitters_[i];
      const float p = probability_of(i);
      if (!(p > 0.0f)) continue;
      sum += p * (static_cast<std::ptrdiff_t>(e.light) == known ? known_pdf
                                                                 : mcrt::pdf((*lights_)[e.light], o_, n_, dir, footprint_));
    }
    return sum;
  }

 private:
  using node = light_bvh::node;

  // Whether emitter i faces the point: the constructor's answer, kept for
  // the first mask_bits emitters, so pick and pdf do not ask each light again.
  static constexpr std::size_t mask_bits = 64;
  bool facing(std::size_t i) const {
    return i < mask_bits ? ((facing_ >> i) & 1u) != 0 : faces((*lights_)[emitters_[i].light], o_);
  }

  // P(k) of emitter i (its index in emitters_) without the tree.
  float probability_of(std::size_t i) const {
    if (count_ == 0 || !facing(i)) return 0.0f;
    return how_ == light_choice::uniform ? 1.0f / static_cast<float>(count_) : emitters_[i].power / total_;
  }

  // ---- through the tree ---------------------------------------------------
  // pick, probability and pdf form each P(k) by the same operations in the
  // same order (the product from the root down, node_weight and
  // cluster_weights), so the probability a sample returns, probability()
  // and the one pdf() multiplies by are the same float.

  // The lights of a bvh node small enough to be weighed one by one.
  bool is_cluster(const node& nd) const { return how_ == light_choice::bvh && nd.count <= cluster_size; }

  const emitter& item(std::uint32_t slot) const { return emitters_[tree_->order()[slot]]; }

  // bvh's weight of the light in `slot` within its cluster: its
  // contribution to a diffuse receiver at the point, as a point light,
  // phi cos+(theta_l) cos+(theta_r) / d^2 from its centre (cos_l = 1 for a
  // sphere; |cos theta_r| where the surface transmits); within 4 times its
  // size of the point, where that is far off, the exact pi L Omega_proj+
  // (light_importance.hpp; its bounds' estimate for a disk).
  float leaf_weight(std::uint32_t slot) const {
    const light_bvh::slot& s = tree_->slots()[slot];
    const vec3 v = s.centre - o_;
    const float d2 = glm::dot(v, v);
    if (d2 < 16.0f * s.r2) {
      const emitter& e = item(slot);
      const double x = exact_importance((*lights_)[e.light], e.power, o_, n_, both_sides_);
      if (x >= 0.0) return x < double(FLT_MAX) ? float(x) : FLT_MAX;
      light_bounds b;
      b.box = s.box;
      b.normals = s.all_directions ? direction_cone::entire_sphere() : direction_cone{s.normal, 1.0f};
      b.phi = s.phi;
      return bounds_importance(b, o_, n_, both_sides_);
    }
    return point_weight(s.phi, v, d2, s.normal, s.all_directions);
  }

  // Flux phi at v (from the point; d2 = |v|^2) emitting about `normal`
  // (every way: all_directions) as a point light to a diffuse receiver:
  // phi cos+(theta_l) cos+(theta_r) / d^2 (|cos theta_r| where the surface
  // transmits).
  float point_weight(float phi, const vec3& v, float d2, const vec3& normal, bool all_directions = false) const {
    const float inv_d = 1.0f / std::sqrt(d2);
    const float cos_l = all_directions ? 1.0f : -glm::dot(v, normal) * inv_d;
    const float c = glm::dot(v, n_) * inv_d;
    const float cos_r = both_sides_ ? std::abs(c) : c;
    if (!(cos_l > 0.0f) || !(cos_r > 0.0f)) return 0.0f;
    return phi * cos_l * cos_r / d2;
  }

  // A cluster's lights' weights (w[i] for slot first + i) and their sum.
  float cluster_weights(const node& nd, std::array<float, cluster_size>& w) const {
    float sum = 0.0f;
    for (std::uint32_t i = 0; i < nd.count; ++i) {
      w[i] = leaf_weight(nd.first + i);
      sum += w[i];
    }
    return sum;
  }

  // A cluster's weights at the point (w[i] for slot first + i) and their
  // sum, formed once: for its parent's choice (contribution_estimate), the
  // choice within it (pick), and the density at a sample of one of its
  // lights or at a direction that meets them (pdf, probability). The last
  // cluster_memo_size clusters weighed at the point are kept, the oldest
  // replaced first; the weights are the floats cluster_weights gives, so
  // every P(k) is formed alike whichever call weighed the cluster first.
  struct cluster_entry {
    std::uint32_t node;
    float sum;
    std::array<float, cluster_size> w;
  };
  static constexpr std::size_t cluster_memo_size = 4;
  const cluster_entry& weights_of(const node& nd, std::uint32_t index) const {
    for (const cluster_entry& c : clusters_)
      if (c.node == index) return c;
    cluster_entry& c = clusters_[next_cluster_];
    next_cluster_ = (next_cluster_ + 1) % cluster_memo_size;
    c.node = index;
    c.sum = cluster_weights(nd, c.w);
    return c;
  }

  // The weight at the point of node `index` (nd) under the selection's measure.
  float node_weight(const node& nd, std::uint32_t index) const {
    switch (how_) {
      case light_choice::power: return nd.bounds.phi;
      case light_choice::uniform: return static_cast<float>(nd.count);
      case light_choice::pbrt_bvh: return bounds_importance(nd.bounds, o_, n_, true);
      case light_choice::bvh:
      default: return memoized_estimate(nd, index);
    }
  }

  // contribution_estimate through the selection's memo (memo_): a near
  // node's estimate sums its children's, so the choices below it would
  // otherwise form the same estimates again, and pdf() those pick() formed.
  // The memo returns the float the estimate gave, so every P(k) is formed
  // alike whichever call formed it first.
  float memoized_estimate(const node& nd, std::uint32_t index) const {
    memo_entry& m = memo_[index & (memo_size - 1)];
    if (m.node == index) return m.w;
    // (The estimate may fill m with a node below this one meanwhile.)
    const float w = contribution_estimate(nd, index);
    m.node = index;
    m.w = w;
    return w;
  }

  // bvh's weight of a node: an estimate of its lights' whole unoccluded
  // contribution to a diffuse receiver at the point, in the unit of the
  // lights' own weights (leaf_weight), so that every choice weighs like
  // with like. With r the half diagonal of the node's planar proxy
  // (light_bvh::proxy) and d the distance to its lights' centroid:
  //   - d > r: the node as a point light, phi cos(theta_l) cos(theta_r) /
  //     d^2, with the proxy's normal (a node of at most recurse_limit
  //     lights only beyond 2 r);
  //   - a cluster nearer: the sum of its lights' weights, by which it then
  //     chooses among them;
  //   - a node of at most recurse_limit lights nearer: the sum of its two
  //     children's weights (memoized_estimate: each formed once per point);
  //   - a larger node nearer: its flux spread over the proxy's rectangle,
  //     phi Omega_proj+(rectangle) / area by Lambert's formula;
  //   - pbrt-v4's importance where the lights face every way (no proxy).
  // The distances (r for a large node's point light, 2 r for a smaller
  // one's) are the cheapest that kept the variance at 128 floor points of
  // the many-light scenes (bench/light_select_floor.cpp, mis): Lambert's
  // formula out to 4 r gave the same variance at 1.1-1.5 times the
  // selection's time; out to r/2 instead of r, 1.2-3.8 times the variance.
  // A proxy knows nothing of its lights' spread along its normal, nor of
  // how their normals spread; where lights are scattered in height, a
  // point light at the centroid of a node whose near lights face the point
  // can see it at grazing angles (cos theta_l ~ 0), and a rectangle at
  // their mean height puts their flux beside the point. Below
  // recurse_limit lights the children's sum avoids both: at the points
  // the camera sees on lights_100, the rendered variance (mis) fell 6.8
  // times, to that of the exact selection; on lights_1000 and
  // lights_10000 2.2 and 1.9 times, at equal or lower cost per sample
  // (the memo; docs/light-selection.md).
  // Each is 0 where pbrt-v4's importance, an upper bound of the cosines
  // over the node, is (cos+ at a surface that only reflects), and a
  // proxy's estimate is at least 1 % of that importance: its rectangle,
  // facing one way, could otherwise miss lights of the node that face the
  // point.
  // pbrt-v4's importance alone misjudges a large node near the point by
  // its bounds (cosines taken at their bounds over the box, the distance to
  // its centre); on an emissive curtain of 12 800 triangles with 27 small
  // lights (many_lights_mesh) it is 3.5-7 times the curtain's contribution
  // and 1-57 times the small lights'. The noise-free variance of the
  // choice (bench/light_select_variance.cpp) fell from 0.34 to 0.036 there,
  // and 1.5 to 0.29 under 14 994 small lights (docs/light-selection.md).
  float contribution_estimate(const node& nd, std::uint32_t index) const {
    const float bound = bounds_importance(nd.bounds, o_, n_, both_sides_);
    if (!(bound > 0.0f)) return 0.0f;
    const light_bvh::proxy& q = tree_->proxies()[index];
    const vec3 v = q.centre - o_;
    const float d2 = glm::dot(v, v);
    const bool recurse = nd.count <= recurse_limit;
    const bool far = q.planar && d2 > (recurse ? recurse_far : 1.0f) * q.r2;
    static_assert(cluster_size <= recurse_limit, "a cluster is weighed as a point light beyond 2 r only");
    if (nd.count <= cluster_size && !far) return weights_of(nd, index).sum;
    if (!q.planar) return bound;
    float estimate = 0.0f;
    if (far) {
      estimate = point_weight(nd.bounds.phi, v, d2, q.normal);
    } else if (recurse) {
      const std::vector<node>& nodes = tree_->nodes();
      estimate = memoized_estimate(nodes[index + 1], index + 1) + memoized_estimate(nodes[nd.second], nd.second);
      return estimate;
    } else if (glm::dot(o_ - q.corner, q.normal) > 0.0f) {
      const std::array<vec3, 4> r = q.corners();
      double omega = light_importance_detail::clipped_polygon_projected_solid_angle(r.data(), 4, o_, n_);
      if (both_sides_) omega += light_importance_detail::clipped_polygon_projected_solid_angle(r.data(), 4, o_, -n_);
      const double x = double(nd.bounds.phi) * q.inv_area * omega;
      estimate = x < double(FLT_MAX) ? float(x) : FLT_MAX;
    }
    return std::max(estimate, 0.01f * bound);
  }

  // The probabilities of an inner node's two children.
  void child_probabilities(const node& nd, std::uint32_t index, float& p1, float& p2) const {
    const std::vector<node>& nodes = tree_->nodes();
    const float w1 = node_weight(nodes[index + 1], index + 1);
    const float w2 = node_weight(nodes[nd.second], nd.second);
    const float total = w1 + w2;
    if (!(total > 0.0f) || !std::isfinite(total)) {
      p1 = p2 = 0.0f;
      return;
    }
    p1 = w1 / total;
    p2 = w2 / total;
  }

  // Chooses within a cluster by its weights; -1 if they are all 0.
  static int choose_in(const std::array<float, cluster_size>& w, std::uint32_t count, float sum, float u) {
    const float target = u * sum;
    float acc = 0.0f;
    int last = -1;
    for (std::uint32_t i = 0; i < count; ++i) {
      if (!(w[i] > 0.0f)) continue;
      acc += w[i];
      last = static_cast<int>(i);
      if (target < acc) break;
    }
    return last;
  }

  std::ptrdiff_t pick_tree(float u, float& prob) const {
    const std::vector<node>& nodes = tree_->nodes();
    std::uint32_t i = 0;
    float p = 1.0f;
    for (;;) {
      const node& nd = nodes[i];
      if (is_cluster(nd)) {
        const cluster_entry& m = weights_of(nd, i);
        if (!(m.sum > 0.0f) || !std::isfinite(m.sum)) return -1;
        const int c = choose_in(m.w, nd.count, m.sum, u);
        if (c < 0) return -1;
        prob = p * (m.w[static_cast<std::size_t>(c)] / m.sum);
        return item(nd.first + static_cast<std::uint32_t>(c)).light;
      }
      if (nd.leaf()) {
        // A tree of one light: chosen where its weight is positive.
        if (i == 0 && !(node_weight(nd, i) > 0.0f)) return -1;
        prob = p;
        return item(nd.first).light;
      }
      float p1, p2;
      child_probabilities(nd, i, p1, p2);
      if (!(p1 > 0.0f) && !(p2 > 0.0f)) return -1;
      // u is reused below, rescaled to [0, 1) within the branch taken.
      constexpr float one_minus_epsilon = 0x1.fffffep-1f;
      if (u < p1) {
        u = std::min(u / p1, one_minus_epsilon);
        p *= p1;
        i = i + 1;
      } else {
        u = std::min((u - p1) / p2, one_minus_epsilon);
        p *= p2;
        i = nd.second;
      }
    }
  }

  float probability_tree(std::size_t emitter_index) const {
    const std::uint32_t leaf = tree_->leaf_of(emitter_index);
    if (leaf == light_bvh::none) return 0.0f;
    const std::vector<node>& nodes = tree_->nodes();
    // The path from the root.
    std::array<std::uint32_t, light_bvh::max_depth + 1> path;
    std::size_t depth = 0;
    for (std::uint32_t i = leaf; i != light_bvh::none; i = nodes[i].parent) path[depth++] = i;
    float p = 1.0f;
    for (std::size_t d = depth; d-- > 0;) {
      const std::uint32_t i = path[d];
      const node& nd = nodes[i];
      if (is_cluster(nd)) {
        const cluster_entry& m = weights_of(nd, i);
        if (!(m.sum > 0.0f) || !std::isfinite(m.sum)) return 0.0f;
        const std::uint32_t c = nodes[leaf].first - nd.first;
        if (!(m.w[c] > 0.0f)) return 0.0f;
        return p * (m.w[c] / m.sum);
      }
      if (nd.leaf()) return (i == 0 && !(node_weight(nd, i) > 0.0f)) ? 0.0f : p;
      float p1, p2;
      child_probabilities(nd, i, p1, p2);
      p *= path[d - 1] == i + 1 ? p1 : p2;
      if (!(p > 0.0f)) return 0.0f;
    }
    return 0.0f;
  }

  // A ray from the point for the slab tests of pdf_tree: the reciprocal of
  // its direction and the offsets that move a box's faces to the origin,
  // widened by 1e-6 of the origin's coordinates (the boxes are widened by
  // 1e-6 of theirs: light_bvh::widened) and by 1e-30 more, so that a slab
  // met edge-on (0 times infinity) is never NaN.
  struct slab_ray {
    vec3 inv_d, lo_off, hi_off;
    slab_ray(const vec3& o, const vec3& dir) : inv_d(1.0f / dir) {
      for (int a = 0; a < 3; ++a) {
        const float pad = 1e-6f * std::abs(o[a]) + 1e-30f;
        lo_off[a] = -o[a] - pad;
        hi_off[a] = -o[a] + pad;
      }
    }
  };

  // Whether the ray meets the box widened for ray tests (ray_box of a
  // light_bvh node), for t >= 0.
  static bool meets(const aabb& b, const slab_ray& r) {
    float t0 = 0.0f, t1 = infinity;
    for (int a = 0; a < 3; ++a) {
      float tn = (b.lo[a] + r.lo_off[a]) * r.inv_d[a], tf = (b.hi[a] + r.hi_off[a]) * r.inv_d[a];
      if (tn > tf) std::swap(tn, tf);
      t0 = std::max(t0, tn);
      t1 = std::min(t1, tf);
    }
    return t0 <= t1;
  }

  // The lights of cluster node i whose ray boxes the ray meets, as bits
  // (bit c: slot first + c), found through the cluster's own subtree: a
  // node's ray box holds its children's (light_bvh), so a subtree the ray
  // misses holds no light it meets, and the set is the one a test of every
  // slot would give. The caller has met node i's box.
  std::uint32_t met_in_cluster(std::uint32_t i, const slab_ray& ray) const {
    static_assert(cluster_size <= 32, "a cluster's lights are bits of a 32-bit mask");
    const std::vector<node>& nodes = tree_->nodes();
    const std::uint32_t first = nodes[i].first;
    // Depth-first, a sibling waits on the stack at each level: at most
    // count - 1 of them in a cluster of count lights.
    std::array<std::uint32_t, cluster_size> stack;
    std::size_t top = 0;
    std::uint32_t met = 0;
    for (;;) {
      const node& nd = nodes[i];
      if (nd.leaf()) {
        met |= 1u << (nd.first - first);
      } else {
        const bool met1 = meets(nodes[i + 1].ray_box, ray), met2 = meets(nodes[nd.second].ray_box, ray);
        if (met1) {
          if (met2) stack[top++] = nd.second;
          i = i + 1;
          continue;
        }
        if (met2) {
          i = nd.second;
          continue;
        }
      }
      if (top == 0) return met;
      i = stack[--top];
    }
  }

  float light_pdf(std::uint32_t slot, const vec3& dir, std::ptrdiff_t known, float known_pdf) const {
    const std::uint32_t k = item(slot).light;
    return static_cast<std::ptrdiff_t>(k) == known ? known_pdf : mcrt::pdf((*lights_)[k], o_, n_, dir, footprint_);
  }

  float pdf_tree(const vec3& dir, std::ptrdiff_t known, float known_pdf) const {
    const std::vector<node>& nodes = tree_->nodes();
    const slab_ray ray(o_, dir);
    struct entry {
      std::uint32_t node;
      float p;
    };
    std::array<entry, light_bvh::max_depth + 2> stack;
    std::size_t top = 0;
    if (meets(nodes[0].ray_box, ray)) stack[top++] = {0, 1.0f};
    float sum = 0.0f;
    // Every node on the stack has a box the ray meets.
    while (top > 0) {
      const auto [i, p] = stack[--top];
      const node& nd = nodes[i];
      if (is_cluster(nd)) {
        const std::uint32_t met = met_in_cluster(i, ray);
        if (met == 0) continue;
        // The weights only where the ray meets one of the cluster's lights.
        const cluster_entry& m = weights_of(nd, i);
        if (!(m.sum > 0.0f) || !std::isfinite(m.sum)) continue;
        // The lights met, summed in slot order (as the choice orders them).
        for (std::uint32_t rest = met; rest != 0; rest &= rest - 1) {
          const auto c = static_cast<std::uint32_t>(std::countr_zero(rest));
          if (!(m.w[c] > 0.0f)) continue;
          sum += p * (m.w[c] / m.sum) * light_pdf(nd.first + c, dir, known, known_pdf);
        }
        continue;
      }
      if (nd.leaf()) {
        if (i == 0 && !(node_weight(nd, i) > 0.0f)) continue;
        sum += p * light_pdf(nd.first, dir, known, known_pdf);
        continue;
      }
      // The children's probabilities only where the ray meets a child.
      const bool met1 = meets(nodes[i + 1].ray_box, ray), met2 = meets(nodes[nd.second].ray_box, ray);
      if (!met1 && !met2) continue;
      float p1, p2;
      child_probabilities(nd, i, p1, p2);
      if (met2 && p2 > 0.0f) stack[top++] = {nd.second, p * p2};
      if (met1 && p1 > 0.0f) stack[top++] = {i + 1, p * p1};
    }
    return sum;
  }

  const light_list* lights_ = nullptr;
  std::span<const emitter> emitters_;
  const light_bvh* tree_ = nullptr;
  vec3 o_{0.0f}, n_{0.0f, 0.0f, 1.0f};
  const auto_footprint* footprint_ = nullptr;
  light_choice how_ = light_choice::power;
  bool both_sides_ = false;
  std::size_t count_ = 0;
  float total_ = 0.0f;
  std::uint64_t facing_ = 0;  // bit i: emitter i faces the point (i < mask_bits, without the tree)
  // bvh: node estimates formed at this point, by node index modulo
  // memo_size (set up by the constructor for bvh only).
  struct memo_entry {
    std::uint32_t node;
    float w;
  };
  static constexpr std::size_t memo_size = 64;
  mutable std::array<memo_entry, memo_size> memo_;
  // bvh: the clusters weighed at this point (weights_of; set up by the
  // constructor for bvh only) and the entry the next one replaces.
  mutable std::array<cluster_entry, cluster_memo_size> clusters_;
  mutable std::uint32_t next_cluster_ = 0;
};

}  // namespace mcrt
