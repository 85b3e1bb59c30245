#pragma once
// All the axis-aligned rectangles of a scene as one collection, intersected
// eight at a time: the rectangles are stored in blocks of eight lanes
// (structure of arrays), and each lane picks the ray's coordinates along its
// own axes with one-hot weights, so every step is the same arithmetic for
// all lanes and the compiler vectorises the loops (no intrinsics). A Cornell
// box's six rectangles cost one block test instead of six branchy ones.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "mcrt/geometry/axis_rect.hpp"

namespace mcrt {

// One axis-aligned rectangle with its axis known at run time, and its
// material: what a hit on a lane of the set reports.
struct any_axis_rect {
  int axis = 1;  // normal axis; in-plane axes (axis+1)%3 and (axis+2)%3
  float a0 = 0, a1 = 1, b0 = 0, b1 = 1, k = 0;
  bool flip = false;
  std::uint32_t material = 0;

  void surface(const ray& r, float t, hit_record& rec) const {
    rec.t = t;
    rec.p = r.at(t);
    // Exactly on the plane, so no error bound: a ray leaving it has t = 0
    // for this plane, which the test's t > tmin = 0 rejects.
    rec.p[axis] = k;
    rec.offset = 0.0f;
    rec.n = vec3(0.0f);
    rec.n[axis] = flip ? -1.0f : 1.0f;
    rec.front_face = (r.d[axis] < 0.0f) != flip;
  }
};

// The rectangle as an axis-aligned one, if both its edges lie exactly along
// coordinate axes (each edge has one non-zero component, the two along
// different axes); nullopt for every other rectangle. A normal along an axis
// is not enough: a rectangle turned in a coordinate plane has one, and its
// extent is not the box from corner to corner + e1 + e2.
inline std::optional<any_axis_rect> as_axis_rect(const rect& r, std::uint32_t material) {
  // The axis an edge lies along, or -1 where it has more than one non-zero
  // component (or none).
  const auto along = [](const vec3& e) {
    int axis = -1;
    for (int i = 0; i < 3; ++i) {
      if (e[i] == 0.0f) continue;
      if (axis >= 0) return -1;
      axis = i;
    }
    return axis;
  };
  const int i1 = along(r.e1), i2 = along(r.e2);
  if (i1 < 0 || i2 < 0 || i1 == i2) return std::nullopt;
  const int axis = 3 - i1 - i2;  // the normal's axis
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  const vec3 far = r.corner + r.e1 + r.e2;  // exact along a and b: one edge adds to each
  return any_axis_rect{axis,
                       std::min(r.corner[a], far[a]),
                       std::max(r.corner[a], far[a]),
                       std::min(r.corner[b], far[b]),
                       std::max(r.corner[b], far[b]),
                       r.corner[axis],
                       r.n[axis] < 0.0f,
                       material};
}

class axis_rect_set {
 public:
  static constexpr int lanes = 8;

  template <int Axis>
  void add(const axis_rect<Axis>& s, std::uint32_t material) {
    add(any_axis_rect{Axis, s.a0, s.a1, s.b0, s.b1, s.k, s.flip, material});
  }

  void add(const any_axis_rect& s) {
    const std::size_t i = members_.size();
    members_.push_back(s);
    if (i % lanes == 0) blocks_.push_back(empty_block());
    block& b = blocks_.back();
    const std::size_t l = i % lanes;
    b.k[l] = s.k;
    b.a0[l] = s.a0;
    b.a1[l] = s.a1;
    b.b0[l] = s.b0;
    b.b1[l] = s.b1;
    for (int c = 0; c < 3; ++c) {
      b.n[c][l] = c == s.axis ? 1.0f : 0.0f;
      b.u[c][l] = c == (s.axis + 1) % 3 ? 1.0f : 0.0f;
      b.v[c][l] = c == (s.axis + 2) % 3 ? 1.0f : 0.0f;
    }
  }

  std::size_t size() const { return members_.size(); }
  bool empty() const { return members_.empty(); }
  const any_axis_rect& operator[](std::size_t i) const { return members_[i]; }

  // The nearest hit in (tmin, tmax) among all rectangles: its t and member.
  bool intersect(const ray& r, float tmin, float tmax, float& t, const any_axis_rect*& member) const {
    bool found = false;
    for (std::size_t bi = 0; bi < blocks_.size(); ++bi) {
      const block& b = blocks_[bi];
      std::array<float, lanes> tl;
      for (int l = 0; l < lanes; ++l) {
        // The ray's coordinate along the lane's normal and in-plane axes.
        const float on = r.o.x * b.n[0][l] + r.o.y * b.n[1][l] + r.o.z * b.n[2][l];
        const float dn = r.d.x * b.n[0][l] + r.d.y * b.n[1][l] + r.d.z * b.n[2][l];
        const float ou = r.o.x * b.u[0][l] + r.o.y * b.u[1][l] + r.o.z * b.u[2][l];
        const float du = r.d.x * b.u[0][l] + r.d.y * b.u[1][l] + r.d.z * b.u[2][l];
        const float ov = r.o.x * b.v[0][l] + r.o.y * b.v[1][l] + r.o.z * b.v[2][l];
        const float dv = r.d.x * b.v[0][l] + r.d.y * b.v[1][l] + r.d.z * b.v[2][l];
        const float tt = (b.k[l] - on) / dn;  // +-inf or NaN when parallel: fails the tests below
        const float pu = ou + tt * du, pv = ov + tt * dv;
        const bool inside = (tt > tmin) & (tt < tmax) & (pu >= b.a0[l]) & (pu <= b.a1[l]) & (pv >= b.b0[l]) &
                            (pv <= b.b1[l]);
        tl[static_cast<std::size_t>(l)] = inside ? tt : infinity;
      }
      // The least of the lanes as a tree of pairs (no lane is NaN, so the
      // order of the minima does not matter): a chain of log2(lanes) steps
      // instead of lanes.
      float best = min_of(tl);
      if (best < tmax) {
        int l = 0;
        while (tl[static_cast<std::size_t>(l)] != best) ++l;
        tmax = best;
        t = best;
        member = &members_[bi * lanes + static_cast<std::size_t>(l)];
        found = true;
      }
    }
    return found;
  }

 private:
  template <std::size_t N>
  static float min_of(const std::array<float, N>& v) {
    if constexpr (N == 1) {
      return v[0];
    } else {
      std::array<float, N / 2> half;
      for (std::size_t i = 0; i < N / 2; ++i) half[i] = std::min(v[i], v[i + N / 2]);
      return min_of(half);
    }
  }

  struct block {
    float k[lanes], a0[lanes], a1[lanes], b0[lanes], b1[lanes];
    float n[3][lanes], u[3][lanes], v[3][lanes];  // one-hot weights of the lane's axes
  };

  // Unused lanes have an empty extent ([+inf, -inf]) and never report a hit.
  static block empty_block() {
    block b{};
    for (int l = 0; l < lanes; ++l) {
      b.a0[l] = b.b0[l] = infinity;
      b.a1[l] = b.b1[l] = -infinity;
      b.n[1][l] = 1.0f;
      b.u[2][l] = 1.0f;
      b.v[0][l] = 1.0f;
    }
    return b;
  }

  std::vector<block> blocks_;
  std::vector<any_axis_rect> members_;
};

}  // namespace mcrt
