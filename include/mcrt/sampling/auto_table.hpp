#pragma once
// The `auto` choice of a planar light, tabulated. The rule of
// auto_strategy.hpp costs tens of ns per shading point (a delta-method test,
// then quadratures of 4 and 12 points), as much as a third of a direct-light
// path in a simple scene. The table makes the choice a lookup: the space
// around the light is cut into cells of the receiver's position (in the
// light's frame: two lateral coordinates and the height over its plane) and
// of its normal (octahedral map in the light's frame), and each cell holds
// the rule's choice at the cell's centre, computed once, when a lookup
// first meets the cell (lazy_choice_cells). The choice is thus a function
// of (light, o, n) alone, piecewise constant, so sample(), pdf() and the
// true density agree as for every strategy; only where a cell straddles
// the rule's boundary does a point get its neighbour's choice.
//
// Coordinates: a rectangle, an ellipse and their rule are symmetric under
// x -> -x (with n's x component) and y -> -y along its two axes, so their
// table holds the quadrant x, y >= 0 and a receiver elsewhere is reflected
// into it first; a triangle's table (not symmetric) holds both signs, with
// twice the lateral cells. Lateral |x| / (|x| + s_i) in [0, 1) (x / (|x| +
// s_i) in (-1, 1) without the symmetry) with s_i the light's half
// extent along axis i (a rectangle's half edge, an ellipse's semi-axis, the
// half edge of a triangle's rectangle of the same covariance; at least a
// quarter of the other one's, for slivers), and height h / (h + s_h) in
// [0, 1) with s_h = sqrt(e_1 e_2) of the half extents, so that cells are
// fine near the light, where the choice changes, and cover every distance
// (far receivers share the outermost cells, where the rule's choice no
// longer changes with distance: the variances fall as (size / distance)^2).
// Normals: the octahedral map (Meyer et al. 2010, "On floating-point normal
// vectors", EGSR) of n in the light's frame, its pole facing the light
// (-n_l), onto [-1, 1]^2 in an odd number of cells, so that a receiver
// facing the light squarely (a floor under a ceiling light, the commonest)
// falls in the cell centred on its own normal. (With the pole at the map's
// folded corners, the corner cells' centres were 5.7 degrees off it: under
// a sliver of aspect 100 that tilt across its length moved the choice, and
// the table agreed with the rule at half the floor's receivers;
// ChoiceBesideASliver.)
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <new>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#endif

#include "mcrt/core/fast_math.hpp"
#include "mcrt/core/math.hpp"
#include "mcrt/sampling/light_sample.hpp"

namespace mcrt {

// The cells of a tabulated choice, each holding the rule's choice at the
// cell's centre, evaluated when a lookup first meets the cell: a scene
// pays for the cells its receivers fall in (a few thousand in a room, of
// the table's million), not for the whole table (~0.1 s per planar light
// to fill). A cell's byte is 0 until evaluated, then 1 + the choice.
// The choice is a pure function of the cell, so threads that meet a cell
// at once compute and store the same byte: relaxed atomics suffice, and
// an image does not depend on which thread met a cell first. Shared by the
// copies of a light.
class lazy_choice_cells {
 public:
  // The rule's choice at the centre of cell i.
  using fill_fn = std::function<light_sampling(std::size_t)>;

  lazy_choice_cells() = default;
  lazy_choice_cells(std::size_t count, fill_fn fill) : s_(std::make_shared<state>(count, std::move(fill))) {}

  light_sampling operator[](std::size_t i) const {
    const std::atomic_ref<std::uint8_t> cell(s_->bytes()[i]);
    std::uint8_t v = cell.load(std::memory_order_relaxed);
    if (v == 0) [[unlikely]] {
      v = static_cast<std::uint8_t>(1 + static_cast<int>(s_->fill(i)));
      cell.store(v, std::memory_order_relaxed);
    }
    return static_cast<light_sampling>(v - 1);
  }

 private:
  struct state {
    // The cells are allocated when a lookup first needs them (a light whose
    // choice the pilot finds not to pay is never looked up: a scene of many
    // such lights pays no table), as zeroed pages the system maps when
    // first touched (an anonymous mapping; calloc elsewhere), so a table
    // costs the pages its met cells lie in, not the megabyte of a planar
    // light's table. (calloc itself zeroes a large block with memset once
    // the C library has raised its mapping threshold after a free: with a
    // mesh's thousands of tables that was most of the set-up's time.)
    state(std::size_t n, fill_fn f) : count(n), fill(std::move(f)) {}
    ~state() {
      if (std::uint8_t* p = cells.load(std::memory_order_relaxed)) release(p, count);
    }
    static std::uint8_t* zeroed(std::size_t n) {
#if defined(__unix__) || defined(__APPLE__)
      void* p = mmap(nullptr, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      return p == MAP_FAILED ? nullptr : static_cast<std::uint8_t*>(p);
#else
      return static_cast<std::uint8_t*>(std::calloc(n, 1));
#endif
    }
    static void release(std::uint8_t* p, std::size_t n) {
#if defined(__unix__) || defined(__APPLE__)
      munmap(p, n);
#else
      (void)n;
      std::free(p);
#endif
    }
    state(const state&) = delete;
    state& operator=(const state&) = delete;
    std::uint8_t* bytes() {
      std::uint8_t* p = cells.load(std::memory_order_acquire);
      if (p) [[likely]] return p;
      std::uint8_t* fresh = zeroed(count);
      if (!fresh) throw std::bad_alloc();
      // The first thread's block stands; another's is given back.
      if (cells.compare_exchange_strong(p, fresh, std::memory_order_acq_rel, std::memory_order_acquire)) return fresh;
      release(fresh, count);
      return p;
    }
    std::size_t count;
    std::atomic<std::uint8_t*> cells{nullptr};  // 0 bytes: not yet evaluated
    fill_fn fill;
  };
  std::shared_ptr<state> s_;
};

class planar_auto_table {
 public:
  // Cells per coordinate: lateral (over the quadrant), height, and each of
  // the normal's two.
  // (Without the symmetry, 2 lateral_cells over both signs.)
  static constexpr int lateral_cells = 16, height_cells = 16, normal_cells = 17;
  static constexpr std::size_t cell_count =
      std::size_t(lateral_cells) * lateral_cells * height_cells * normal_cells * normal_cells;

  planar_auto_table() = default;

  // centre, the two half-extent vectors (orthogonal) and the unit normal of
  // the light's front; choose(o, n) the rule to tabulate (kept by the
  // table, which evaluates it at a cell's centre when a lookup first meets
  // the cell). symmetric: the light and the rule are symmetric about both
  // axes (header).
  template <class Rule>
  planar_auto_table(const vec3& centre, const vec3& half1, const vec3& half2, const vec3& normal, Rule choose,
                    bool symmetric = true)
      : c_(centre), nl_(normal), symmetric_(symmetric), lateral_(symmetric ? lateral_cells : 2 * lateral_cells),
        position_cells_(std::size_t(lateral_) * lateral_ * height_cells) {
    const float e1 = glm::length(half1), e2 = glm::length(half2);
    u1_ = half1 / e1;
    u2_ = half2 / e2;
    sh_ = std::sqrt(e1 * e2);
    // The lateral scales at least a quarter of the larger half extent: the
    // choice changes over the light's length and the receiver's height, not
    // over a sliver's width; at its own width a sliver's cells (aspect 100:
    // all of |y| > 15 widths in the last cell) would hand every receiver
    // beside it the choice at one distance (ChoiceBesideASliver).
    s1_ = std::max(e1, 0.25f * e2);
    s2_ = std::max(e2, 0.25f * e1);
    cells_ = lazy_choice_cells(position_cells_ * normal_cells * normal_cells, [frame = *this, choose = std::move(choose)](std::size_t i) {
      return choose(frame.cell_receiver(i), frame.cell_normal(i));
    });
  }

  // The tabulated choice at o for the unit normal n; area where o is not
  // in front of the light (h <= 0: nothing is sampled there).
  light_sampling lookup(const vec3& o, const vec3& n) const {
    const vec3 d = o - c_;
    const float h = glm::dot(d, nl_);
    if (!(h > 0.0f)) return light_sampling::area;
    const float x0 = glm::dot(d, u1_), y0 = glm::dot(d, u2_);
    // Reflected into the quadrant x, y >= 0, n with it (where symmetric).
    const float sx = symmetric_ ? std::copysign(1.0f, x0) : 1.0f, sy = symmetric_ ? std::copysign(1.0f, y0) : 1.0f;
    const float x = sx * x0, y = sy * y0;
    const float nx = sx * glm::dot(n, u1_), ny = sy * glm::dot(n, u2_);
    const float nz = -glm::dot(n, nl_);  // > 0 facing the light: the map's centre (header)
    // The four divisions as one packed one.
    const std::array<float, 4> inv =
        fast_math::reciprocal4(std::abs(nx) + std::abs(ny) + std::abs(nz), std::abs(x) + s1_, std::abs(y) + s2_, h + sh_);
    float a = nx * inv[0], b = ny * inv[0];
    if (nz < 0.0f) {
      const float a0 = a;
      a = std::copysign(1.0f - std::abs(b), a0);
      b = std::copysign(1.0f - std::abs(a0), b);
    }
    const float lo = symmetric_ ? 0.0f : -1.0f;
    const int ix = cell(x * inv[1], lateral_, lo, 1.0f);
    const int iy = cell(y * inv[2], lateral_, lo, 1.0f);
    const int ih = cell(h * inv[3], height_cells, 0.0f, 1.0f);
    const int ia = cell(a, normal_cells, -1.0f, 1.0f), ib = cell(b, normal_cells, -1.0f, 1.0f);
    return cells_[index(ix, iy, ih, ia, ib)];
  }

 private:
  // The normal's cells outermost: the receivers of one wall (one normal)
  // meet the cells of one 4 KB block (16 KB without the symmetry), a few
  // pages per room (position cells: 16 x 16 x 16 bytes, or 32 x 32 x 16).
  std::size_t index(int ix, int iy, int ih, int a, int b) const {
    return (std::size_t(a) * normal_cells + b) * position_cells_ + (std::size_t(ix) * lateral_ + iy) * height_cells + ih;
  }
  // The centre of cell i: its receiver (light's frame: the quadrant x, y >=
  // 0 in front of the light) and its unit normal.
  vec3 cell_receiver(std::size_t i) const {
    const std::size_t position = i % position_cells_;
    const int ih = int(position % height_cells), iy = int(position / height_cells % lateral_),
              ix = int(position / (std::size_t(height_cells) * lateral_));
    const float lo = symmetric_ ? 0.0f : -1.0f;
    const float x = expand(centre_of(ix, lateral_, lo, 1.0f), s1_);
    const float y = expand(centre_of(iy, lateral_, lo, 1.0f), s2_);
    const float h = expand(centre_of(ih, height_cells, 0.0f, 1.0f), sh_);
    return c_ + x * u1_ + y * u2_ + h * nl_;
  }
  vec3 cell_normal(std::size_t i) const {
    const std::size_t normal = i / position_cells_;
    const int b = int(normal % normal_cells), a = int(normal / normal_cells);
    const vec3 nloc =
        octahedral_decode(centre_of(a, normal_cells, -1.0f, 1.0f), centre_of(b, normal_cells, -1.0f, 1.0f));
    return glm::normalize(nloc.x * u1_ + nloc.y * u2_ - nloc.z * nl_);
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
  bool symmetric_ = true;
  int lateral_ = lateral_cells;  // cells per lateral coordinate
  std::size_t position_cells_ = std::size_t(lateral_cells) * lateral_cells * height_cells;
  lazy_choice_cells cells_;
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
// sampling. 64 KB per sphere light, filled as receivers meet its cells;
// the lookup is a division and a square root where the rule
// (auto_strategy.hpp) takes tens of ns off the horizon.
class sphere_auto_table {
 public:
  static constexpr int distance_cells = 256, cosine_cells = 256;

  sphere_auto_table() = default;

  // The sphere's centre and radius; choose(o, n) the rule to tabulate (kept
  // by the table and evaluated at a cell's centre when a lookup first
  // meets the cell).
  template <class Rule>
  sphere_auto_table(const vec3& centre, float radius, Rule choose) : c_(centre), r2_(radius * radius) {
    cells_ = lazy_choice_cells(std::size_t(distance_cells) * cosine_cells,
                               [centre, radius, choose = std::move(choose)](std::size_t k) {
                                 const int i = int(k / cosine_cells), j = int(k % cosine_cells);
                                 const float t = (float(i) + 0.5f) / float(distance_cells);
                                 // The centre is along -x from o, n at the cell's cosine to it.
                                 const vec3 o = centre + vec3(radius / std::sqrt(t), 0.0f, 0.0f);
                                 const float cs = -1.0f + 2.0f * (float(j) + 0.5f) / float(cosine_cells);
                                 const vec3 n(-cs, std::sqrt(std::max(1.0f - cs * cs, 0.0f)), 0.0f);
                                 return choose(o, n);
                               });
  }

  // The tabulated choice at o for the normal n (of any length); area inside
  // the sphere.
  light_sampling lookup(const vec3& o, const vec3& n) const {
    const vec3 v = c_ - o;
    const float d2 = glm::dot(v, v);
    const float t = r2_ / d2;
    if (!(t < 1.0f)) return light_sampling::area;
    const float cs = glm::dot(v, n) / std::sqrt(d2 * glm::dot(n, n));
    const int i = std::min(int(t * float(distance_cells)), distance_cells - 1);
    const float f = (cs + 1.0f) * (0.5f * float(cosine_cells));
    const int j = f >= 0.0f ? std::min(int(f), cosine_cells - 1) : 0;  // NaN (n = 0) and rounding clamped
    return cells_[std::size_t(i) * cosine_cells + j];
  }

 private:
  vec3 c_{0.0f};
  float r2_ = 1.0f;
  lazy_choice_cells cells_;
};

}  // namespace mcrt
