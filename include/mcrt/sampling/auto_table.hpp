#pragma once
// The `auto` choice of a planar light, tabulated. The rule of
// auto_strategy.hpp costs tens of ns per shading point (a delta-method test,
// then quadratures of 4 and 12 points), as much as a third of a direct-light
// path in a simple scene. The table makes the choice a lookup: the space
// around the light is cut into cells of the receiver's position (in the
// light's frame: two lateral coordinates and the height over its plane) and
// of its normal (octahedral map in the light's frame), and each cell holds
// the rule's choice at the cell's centre, computed once, when the light is
// made. The choice is thus a function of (light, o, n) alone, piecewise
// constant, so sample(), pdf() and the true density agree as for every
// strategy; only where a cell straddles the rule's boundary does a point
// get its neighbour's choice.
//
// Coordinates: the light and the rule are symmetric under x -> -x (with n's
// x component) and y -> -y along its two axes, so the table holds the
// quadrant x, y >= 0 and a receiver elsewhere is reflected into it first.
// Lateral |x| / (|x| + s_i) in [0, 1) with s_i the light's half
// extent along axis i (a rectangle's half edge, an ellipse's semi-axis), and
// height h / (h + s_h) in [0, 1) with s_h = sqrt(s_1 s_2), so that cells are
// fine near the light, where the choice changes, and cover every distance
// (far receivers share the outermost cells, where the rule's choice no
// longer changes with distance: the variances fall as (size / distance)^2).
// Normals: the octahedral map (Meyer et al. 2010, "On floating-point normal
// vectors", EGSR) of n in the light's frame onto [-1, 1]^2.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/core/math.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

// The cells of a tabulated choice (one byte each, a light_sampling), shared
// by the copies of a light, and whether they all hold one choice (then a
// lookup needs no cell).
class choice_cells {
 public:
  choice_cells() = default;
  explicit choice_cells(std::vector<std::uint8_t> cells)
      : cells_(std::make_shared<const std::vector<std::uint8_t>>(std::move(cells))) {
    const std::uint8_t first = cells_->front();
    uniform_ = std::all_of(cells_->begin(), cells_->end(), [&](std::uint8_t c) { return c == first; });
    uniform_choice_ = static_cast<light_sampling>(first);
  }

  bool uniform() const { return uniform_; }
  light_sampling uniform_choice() const { return uniform_choice_; }
  light_sampling operator[](std::size_t i) const { return static_cast<light_sampling>((*cells_)[i]); }

 private:
  std::shared_ptr<const std::vector<std::uint8_t>> cells_;
  bool uniform_ = false;
  light_sampling uniform_choice_ = light_sampling::area;
};

class planar_auto_table {
 public:
  // Cells per coordinate: lateral (over the quadrant), height, and each of
  // the normal's two.
  static constexpr int lateral_cells = 16, height_cells = 16, normal_cells = 16;
  static constexpr std::size_t cell_count =
      std::size_t(lateral_cells) * lateral_cells * height_cells * normal_cells * normal_cells;

  planar_auto_table() = default;

  // centre, the two half-extent vectors (orthogonal) and the unit normal of
  // the light's front; choose(o, n) the rule to tabulate.
  template <class Rule>
  planar_auto_table(const vec3& centre, const vec3& half1, const vec3& half2, const vec3& normal, const Rule& choose)
      : c_(centre), nl_(normal) {
    s1_ = glm::length(half1);
    s2_ = glm::length(half2);
    u1_ = half1 / s1_;
    u2_ = half2 / s2_;
    sh_ = std::sqrt(s1_ * s2_);
    std::vector<std::uint8_t> cells(cell_count);
    // The last cell of each position coordinate that holds another choice
    // than area (for the box of area_beyond_ below).
    int last[3] = {-1, -1, -1};
    for (int ix = 0; ix < lateral_cells; ++ix)
      for (int iy = 0; iy < lateral_cells; ++iy)
        for (int ih = 0; ih < height_cells; ++ih) {
          const float x = expand(centre_of(ix, lateral_cells, 0.0f, 1.0f), s1_);
          const float y = expand(centre_of(iy, lateral_cells, 0.0f, 1.0f), s2_);
          const float h = expand(centre_of(ih, height_cells, 0.0f, 1.0f), sh_);
          const vec3 o = c_ + x * u1_ + y * u2_ + h * nl_;
          for (int a = 0; a < normal_cells; ++a)
            for (int b = 0; b < normal_cells; ++b) {
              const vec3 nloc = octahedral_decode(centre_of(a, normal_cells, -1.0f, 1.0f),
                                                  centre_of(b, normal_cells, -1.0f, 1.0f));
              const vec3 n = glm::normalize(nloc.x * u1_ + nloc.y * u2_ + nloc.z * nl_);
              const light_sampling c = choose(o, n);
              cells[index(ix, iy, ih, a, b)] = static_cast<std::uint8_t>(c);
              if (c != light_sampling::area)
                last[0] = std::max(last[0], ix), last[1] = std::max(last[1], iy), last[2] = std::max(last[2], ih);
            }
        }
    // One choice in every cell (a light far from everything the image
    // holds, or an image whose noise is all elsewhere): no lookup needed.
    cells_ = choice_cells(std::move(cells));
    // The box (in the light's frame) outside which every cell holds area
    // sampling: the cells' upper ends, expanded, past the last cell of each
    // coordinate that holds another choice. Outside it a lookup needs the
    // receiver's position alone, not its normal or cell (most receivers,
    // when the dearer strategies pay only close to the light).
    auto upper_end = [](int last_cell, int k, float scale) {
      // Cell i covers t in [i / k, (i + 1) / k); the last cell reaches infinity.
      return last_cell + 1 >= k ? infinity : expand(float(last_cell + 1) / float(k), scale);
    };
    area_beyond_ = {upper_end(last[0], lateral_cells, s1_), upper_end(last[1], lateral_cells, s2_),
                    upper_end(last[2], height_cells, sh_)};
  }

  // Whether every cell holds the same choice (then lookup() is that choice
  // in front of the light, without the cell's computation).
  bool uniform() const { return cells_.uniform(); }

  // The box beyond which every receiver gets area sampling: |x|, |y| and h
  // (light's frame) from which on no cell holds another choice.
  const std::array<float, 3>& area_beyond() const { return area_beyond_; }

  // The tabulated choice at o for the unit normal n; area where o is not
  // in front of the light (h <= 0: nothing is sampled there).
  light_sampling lookup(const vec3& o, const vec3& n) const {
    const vec3 d = o - c_;
    const float h = glm::dot(d, nl_);
    if (!(h > 0.0f)) return light_sampling::area;
    if (cells_.uniform()) return cells_.uniform_choice();
    const float x0 = glm::dot(d, u1_), y0 = glm::dot(d, u2_);
    // Reflected into the quadrant x, y >= 0, n with it.
    const float x = std::abs(x0), y = std::abs(y0);
    if (x >= area_beyond_[0] || y >= area_beyond_[1] || h >= area_beyond_[2]) return light_sampling::area;
    const float nx = std::copysign(1.0f, x0) * glm::dot(n, u1_), ny = std::copysign(1.0f, y0) * glm::dot(n, u2_);
    const float nz = glm::dot(n, nl_);
    // The four divisions as one packed one.
    const std::array<float, 4> inv =
        fast_math::reciprocal4(std::abs(nx) + std::abs(ny) + std::abs(nz), x + s1_, y + s2_, h + sh_);
    float a = nx * inv[0], b = ny * inv[0];
    if (nz < 0.0f) {
      const float a0 = a;
      a = std::copysign(1.0f - std::abs(b), a0);
      b = std::copysign(1.0f - std::abs(a0), b);
    }
    const int ix = cell(x * inv[1], lateral_cells, 0.0f, 1.0f);
    const int iy = cell(y * inv[2], lateral_cells, 0.0f, 1.0f);
    const int ih = cell(h * inv[3], height_cells, 0.0f, 1.0f);
    const int ia = cell(a, normal_cells, -1.0f, 1.0f), ib = cell(b, normal_cells, -1.0f, 1.0f);
    return cells_[index(ix, iy, ih, ia, ib)];
  }

 private:
  static std::size_t index(int ix, int iy, int ih, int a, int b) {
    return (((std::size_t(ix) * lateral_cells + iy) * height_cells + ih) * normal_cells + a) * normal_cells + b;
  }
  // The cell of t in [lo, hi) cut into k (NaN and the ends clamped).
  static int cell(float t, int k, float lo, float hi) {
    const float f = (t - lo) / (hi - lo) * float(k);
    return f >= 0.0f ? std::min(int(f), k - 1) : 0;
  }
  static float centre_of(int i, int k, float lo, float hi) { return lo + (hi - lo) * (float(i) + 0.5f) / float(k); }
  // The inverse of t = x / (|x| + s).
  static float expand(float t, float s) { return s * t / (1.0f - std::abs(t)); }
  static vec3 octahedral_decode(float a, float b) {
    const float z = 1.0f - std::abs(a) - std::abs(b);
    if (z >= 0.0f) return {a, b, z};
    return {std::copysign(1.0f - std::abs(b), a), std::copysign(1.0f - std::abs(a), b), z};
  }

  vec3 c_{0.0f}, u1_{1, 0, 0}, u2_{0, 1, 0}, nl_{0, 0, 1};
  float s1_ = 1.0f, s2_ = 1.0f, sh_ = 1.0f;
  choice_cells cells_;
  std::array<float, 3> area_beyond_{0.0f, 0.0f, 0.0f};  // x, y, h beyond which every cell holds area
};

// The `auto` choice of a sphere, tabulated. By the sphere's symmetry the
// rule's choice at o for the normal n depends on two numbers: t = r^2 / d^2
// = sin^2(alpha) in (0, 1) (alpha the half-angle of the cone the sphere
// subtends, d the distance to its centre) and cos of the angle between n
// and the direction to the centre (the rule's quadrature, which sits in a
// frame turned about that direction, sees the rest only to within its own
// error). Cells are uniform in t, fine near the sphere where the choice
// changes, and in the cosine; each holds the rule's choice at its centre.
// Receivers inside the sphere (t >= 1: nothing of it is seen lit) get area
// sampling. 64 KB per sphere light; the lookup is a division and a square
// root where the rule (auto_strategy.hpp) takes tens of ns off the horizon.
class sphere_auto_table {
 public:
  static constexpr int distance_cells = 256, cosine_cells = 256;

  sphere_auto_table() = default;

  // The sphere's centre and radius; choose(o, n) the rule to tabulate.
  template <class Rule>
  sphere_auto_table(const vec3& centre, float radius, const Rule& choose) : c_(centre), r2_(radius * radius) {
    std::vector<std::uint8_t> cells(std::size_t(distance_cells) * cosine_cells);
    for (int i = 0; i < distance_cells; ++i) {
      const float t = (float(i) + 0.5f) / float(distance_cells);
      const vec3 o = centre + vec3(radius / std::sqrt(t), 0.0f, 0.0f);  // the centre is along -x from o
      for (int j = 0; j < cosine_cells; ++j) {
        const float cs = -1.0f + 2.0f * (float(j) + 0.5f) / float(cosine_cells);
        const vec3 n(-cs, std::sqrt(std::max(1.0f - cs * cs, 0.0f)), 0.0f);
        cells[std::size_t(i) * cosine_cells + j] = static_cast<std::uint8_t>(choose(o, n));
      }
    }
    cells_ = choice_cells(std::move(cells));
  }

  bool uniform() const { return cells_.uniform(); }

  // The tabulated choice at o for the normal n (of any length); area inside
  // the sphere.
  light_sampling lookup(const vec3& o, const vec3& n) const {
    const vec3 v = c_ - o;
    const float d2 = glm::dot(v, v);
    const float t = r2_ / d2;
    if (!(t < 1.0f)) return light_sampling::area;
    if (cells_.uniform()) return cells_.uniform_choice();
    const float cs = glm::dot(v, n) / std::sqrt(d2 * glm::dot(n, n));
    const int i = std::min(int(t * float(distance_cells)), distance_cells - 1);
    const float f = (cs + 1.0f) * (0.5f * float(cosine_cells));
    const int j = f >= 0.0f ? std::min(int(f), cosine_cells - 1) : 0;  // NaN (n = 0) and rounding clamped
    return cells_[std::size_t(i) * cosine_cells + j];
  }

 private:
  vec3 c_{0.0f};
  float r2_ = 1.0f;
  choice_cells cells_;
};

}  // namespace mcrt
