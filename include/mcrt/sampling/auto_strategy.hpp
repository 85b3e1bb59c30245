#pragma once
// `auto`: for each light and shading point, the light-sampling strategy
// (area, solid angle, projected solid angle) expected to give the lowest
// error for the time, chosen from quantities known at that point. The
// choice depends on (light, o, n) only, so sample(), the pdf returned with
// a sample, pdf() and the true density agree as they do for the chosen
// strategy: the auto strategy's density at o is exactly that strategy's.
//
// The rule. A light sample's share of a pixel's error is modelled as
// (cost_s + c_rest) (v_s + v_rest): cost_s the strategy's own time per
// sample (sample + pdf, Google Benchmark, bench/bench_samplers_*.cpp),
// c_rest the rest of the path's time per light sample (rays, materials),
// v_s the relative variance of the strategy's estimate of the direct light
// of the unoccluded light of constant radiance on a diffuse receiver at the
// point, and v_rest the relative variance everything else adds (visibility,
// the pixel's footprint, the indirect light). The strategy with the
// smallest product is taken (efficiency = 1 / (error x time)). v_s from the
// geometry at four points of the light, a rule exact for cubic (rectangle)
// or quadratic (disk) variation over the light's surface:
//  * area: the estimate is L A g, g = cos+(theta) cos(theta_l) / r^2, so
//    v_area = E_A[g^2] / E_A[g]^2 - 1 (uniform on the surface);
//  * solid angle: the estimate is L Omega cos+(theta), so v_sa = E_w[c^2] /
//    E_w[c]^2 - 1, c = cos+(theta), weighted by w = cos(theta_l) / r^2 (the
//    solid angle per unit area);
//  * projected solid angle: 0 (the estimate is L Omega_proj).
// Below the receiver's horizon cos+ is 0: a light partly below it raises
// v_area and v_sa (their samples there are wasted), not v_psa.
//
// The constants (struct auto_costs) are measurements: the strategies'
// costs from the README's cost tables, c_rest from the error-against-time
// study (cornell_rect, nee, sobol: ms per spp of area and solid-angle
// sampling, 318 and 451 ns per path at 1.13 light samples per path, leave
// 265 ns per light sample for the rest), v_rest = 0.25 the value, of those
// tried (0.25, 1, 4), with the best worst case over the study's scenes
// (README, "Choosing per shading point", which also says how far this rule
// is from the best fixed strategy).
#include <algorithm>

#include "mcrt/core/onb.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"
#include "mcrt/sampling/projected_spherical_cap.hpp"
#include "mcrt/sampling/projected_spherical_ellipse.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "mcrt/sampling/sphere_area.hpp"
#include "mcrt/sampling/sphere_cone.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"

namespace mcrt {

// The two parameters of the rule that describe the rest of the renderer
// rather than the light (the defaults: the header's measurements; `mcrt
// render --auto-rest-cost --auto-rest-variance` sets them).
struct auto_params {
  float rest_cost = 265.0f;      // c_rest, ns per light sample
  float rest_variance = 0.25f;   // v_rest
};

// Time per light sample (ns, sample + pdf) of each strategy of a shape.
struct auto_costs {
  struct shape_costs {
    float area, solid_angle, projected_solid_angle;
  };
  static constexpr shape_costs rect{17.0f, 135.0f, 800.0f};
  static constexpr shape_costs ellipse{31.0f, 763.0f, 1700.0f};
  // Spheres: the projected spherical cap is dearer where the cap crosses the
  // horizon (a numerical inversion) than above it (closed form).
  static constexpr shape_costs sphere_above{74.0f, 54.0f, 100.0f};
  static constexpr shape_costs sphere_crossing{74.0f, 54.0f, 600.0f};
};

// The variance model at one point: v_area and v_sa from the geometry at the
// quadrature points, then the choice. add() takes a point of the light p
// (equal weights) with cos(theta_l) at it.
class auto_choice {
 public:
  auto_choice(const vec3& o, const vec3& n) : o_(o), n_(n) {}

  // A point p of the light with cos(theta_l) there and its quadrature
  // weight (the weights sum to 1).
  void add(const vec3& p, float cos_light, float weight) {
    const vec3 d = p - o_;
    const float r2 = glm::dot(d, d);
    if (!(r2 > 0.0f) || !(cos_light > 0.0f)) return;
    const float w = cos_light / r2;                                    // solid angle per unit area
    const float c = std::max(glm::dot(d, n_), 0.0f) / std::sqrt(r2);  // cos+(theta)
    const float g = c * w;
    sg_ += weight * g, sg2_ += weight * g * g, sw_ += weight * w, swc_ += weight * w * c, swc2_ += weight * w * c * c;
  }

  // Relative variances of the area and solid-angle estimates (header).
  float v_area() const {
    if (!(sg_ > 0.0f)) return 0.0f;
    return std::max(sg2_ / (sg_ * sg_) - 1.0f, 0.0f);
  }
  float v_solid_angle() const {
    if (!(swc_ > 0.0f)) return 0.0f;
    return std::max(sw_ * swc2_ / (swc_ * swc_) - 1.0f, 0.0f);
  }

  // Whether area sampling is the choice even with v_area and v_sa taken
  // `factor` times larger than modelled (and lit at all).
  bool area_wins_even_if(float factor, const auto_costs::shape_costs& c, const auto_params& p) const {
    if (!(sg_ > 0.0f)) return true;
    const float area = (c.area + p.rest_cost) * (factor * v_area() + p.rest_variance);
    return area <= (c.solid_angle + p.rest_cost) * p.rest_variance &&
           area <= (c.projected_solid_angle + p.rest_cost) * p.rest_variance;
  }

  // The strategy with the least modelled (cost + c_rest)(variance + v_rest);
  // area where no quadrature point is lit (nothing to gain, cheapest).
  light_sampling choose(const auto_costs::shape_costs& c, const auto_params& p = {}) const {
    if (!(sg_ > 0.0f)) return light_sampling::area;
    const float cr = p.rest_cost, vr = p.rest_variance;
    const float area = (c.area + cr) * (v_area() + vr);
    const float sa = (c.solid_angle + cr) * (v_solid_angle() + vr);
    const float psa = (c.projected_solid_angle + cr) * vr;
    if (area <= sa && area <= psa) return light_sampling::area;
    return sa <= psa ? light_sampling::solid_angle : light_sampling::projected_solid_angle;
  }

 private:
  vec3 o_, n_;
  float sg_ = 0.0f, sg2_ = 0.0f, sw_ = 0.0f, swc_ = 0.0f, swc2_ = 0.0f;
};

// The model at o (normal n) for each shape, from its four quadrature
// points, and the choice.
// The coarse rules: 2x2 Gauss points on a rectangle, one ring of four
// points at rho = 1/sqrt(2) on an ellipse (both exact for quadratics).
inline auto_choice auto_model_coarse(const rect& r, const vec3& o, const vec3& n) {
  constexpr float lo = 0.5f - 0.28867513f, hi = 0.5f + 0.28867513f;  // 1/2 -+ 1/(2 sqrt 3)
  auto_choice ch(o, n);
  for (const float s : {lo, hi})
    for (const float t : {lo, hi}) {
      const vec3 p = r.corner + s * r.e1 + t * r.e2;
      ch.add(p, glm::dot(o - p, r.n) / glm::length(o - p), 0.25f);
    }
  return ch;
}
inline auto_choice auto_model_coarse(const ellipse& e, const vec3& o, const vec3& n) {
  constexpr float k = 0.70710678f;
  auto_choice ch(o, n);
  for (const vec3& a : {k * e.a1, -k * e.a1, k * e.a2, -k * e.a2}) {
    const vec3 p = e.center + a;
    ch.add(p, glm::dot(o - p, e.n) / glm::length(o - p), 0.25f);
  }
  return ch;
}

inline auto_choice auto_model(const rect& r, const vec3& o, const vec3& n) {
  // 3x3 Gauss-Legendre points on the rectangle (exact for degree 5 in each
  // coordinate): 1/2 -+ sqrt(3/5)/2 and 1/2, weights 5/18, 8/18, 5/18.
  constexpr float x[3] = {0.5f - 0.38729833f, 0.5f, 0.5f + 0.38729833f};
  constexpr float w[3] = {5.0f / 18.0f, 8.0f / 18.0f, 5.0f / 18.0f};
  auto_choice ch(o, n);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const vec3 p = r.corner + x[i] * r.e1 + x[j] * r.e2;
      ch.add(p, glm::dot(o - p, r.n) / glm::length(o - p), w[i] * w[j]);
    }
  return ch;
}
inline auto_choice auto_model(const ellipse& e, const vec3& o, const vec3& n) {
  // Three rings by area (rho^2 = 1/2 -+ sqrt(3/5)/2 and 1/2, the 3-point
  // Gauss rule in rho^2, weights 5/18, 8/18, 5/18) of four points each, the
  // middle ring turned by 45 degrees.
  constexpr float rho[3] = {0.33571069f, 0.70710678f, 0.94196515f};
  constexpr float w[3] = {5.0f / 72.0f, 8.0f / 72.0f, 5.0f / 72.0f};  // per point (four per ring)
  constexpr float k = 0.70710678f;
  const vec3 axis_dirs[4] = {e.a1, e.a2, -e.a1, -e.a2};
  const vec3 diagonal_dirs[4] = {k * (e.a1 + e.a2), k * (e.a2 - e.a1), -k * (e.a1 + e.a2), k * (e.a1 - e.a2)};
  auto_choice ch(o, n);
  for (int ring = 0; ring < 3; ++ring)
    for (int i = 0; i < 4; ++i) {
      const vec3 p = e.center + rho[ring] * (ring == 1 ? diagonal_dirs[i] : axis_dirs[i]);
      ch.add(p, glm::dot(o - p, e.n) / glm::length(o - p), w[ring]);
    }
  return ch;
}
// The visible cap (the part of the surface facing o: cos beta >= r / d at
// the centre, beta from the direction to o), uniform by area in cos beta:
// two rings at the 2-point Gauss nodes in cos beta of four points each, the
// second turned by 45 degrees. o inside the sphere: nothing lit.
inline auto_choice auto_model(const sphere& s, const vec3& o, const vec3& n) {
  auto_choice ch(o, n);
  const vec3 v = o - s.center;
  const float d = glm::length(v);
  if (!(d > s.radius)) return ch;
  const onb frame(v / d);
  const float mid = 0.5f * (1.0f + s.radius / d), half = 0.5f * (1.0f - s.radius / d);
  constexpr float node = 0.57735027f, k = 0.70710678f;  // 1/sqrt(3)
  for (int ring = 0; ring < 2; ++ring) {
    const float cb = mid + (ring == 0 ? -node : node) * half, sb = std::sqrt(std::max(1.0f - cb * cb, 0.0f));
    for (const vec2 t : {vec2(1, 0), vec2(0, 1), vec2(-1, 0), vec2(0, -1)}) {
      const vec2 a = ring == 0 ? t : k * vec2(t.x - t.y, t.x + t.y);
      const vec3 m = frame.to_world(vec3(sb * a.x, sb * a.y, cb));  // unit outward normal at the point
      const vec3 p = s.center + s.radius * m;
      ch.add(p, glm::dot(o - p, m) / glm::length(o - p), 0.125f);
    }
  }
  return ch;
}

// First-order (delta-method) variances at the centre of a planar light
// with centre c and axes E1, E2 (offsets s E1 + t E2 over the light with
// variances k each: 1/12 for a rectangle's edges, 1/4 for an ellipse's
// semi-axes): log g = log(n . d) - 4 log r + const, d = p - o, so
// v_area ~ k ((grad log g . E1)^2 + (grad log g . E2)^2) with grad log g =
// n / (n . d) - 4 d / r^2. Valid (true, with v_area) only where each part
// of the gradient changes log g by at most 0.3 across the light, so that
// the first-order term is all that matters (within a factor 2 on the test
// receivers: tests/test_auto_strategy.cpp).
inline bool delta_v_area(const vec3& c, const vec3& E1, const vec3& E2, float k, const vec3& o, const vec3& n,
                         float& v_area) {
  const vec3 d = c - o;
  const float r2 = glm::dot(d, d), nd = glm::dot(n, d);
  if (!(nd > 0.0f) || !(r2 > 0.0f)) return false;
  const float inv_nd = 1.0f / nd, inv_r2 = 1.0f / r2;
  const float n1 = glm::dot(n, E1) * inv_nd, n2 = glm::dot(n, E2) * inv_nd;
  const float d1 = 4.0f * glm::dot(d, E1) * inv_r2, d2 = 4.0f * glm::dot(d, E2) * inv_r2;
  if (!(0.5f * (std::abs(n1) + std::abs(n2)) <= 0.3f) || !(0.5f * (std::abs(d1) + std::abs(d2)) <= 0.3f)) return false;
  const float g1 = n1 - d1, g2 = n2 - d2;
  v_area = k * (g1 * g1 + g2 * g2);
  return true;
}
inline bool delta_v_area(const rect& r, const vec3& o, const vec3& n, float& v) {
  if (!(glm::dot(o - r.corner, r.n) > 0.0f)) return false;  // behind the light
  return delta_v_area(r.corner + 0.5f * (r.e1 + r.e2), r.e1, r.e2, 1.0f / 12.0f, o, n, v);
}
inline bool delta_v_area(const ellipse& e, const vec3& o, const vec3& n, float& v) {
  if (!(glm::dot(o - e.center, e.n) > 0.0f)) return false;
  return delta_v_area(e.center, e.a1, e.a2, 0.25f, o, n, v);
}

// The choice. Planar lights try two cheap estimates first: the delta
// method, where valid, then the 2x2 Gauss rule (within a factor 4 of the
// variances on the test receivers); where even twice, resp. four times,
// their v_area leaves area sampling the best, that is the choice;
// otherwise the finer rule decides.
template <class Planar>
light_sampling choose_planar(const Planar& l, const vec3& o, const vec3& n, const auto_costs::shape_costs& c,
                             const auto_params& p) {
  float v_delta;
  if (delta_v_area(l, o, n, v_delta)) {
    const float area = (c.area + p.rest_cost) * (2.0f * v_delta + p.rest_variance);
    if (area <= (c.solid_angle + p.rest_cost) * p.rest_variance &&
        area <= (c.projected_solid_angle + p.rest_cost) * p.rest_variance)
      return light_sampling::area;
  }
  const auto_choice coarse = auto_model_coarse(l, o, n);
  if (coarse.area_wins_even_if(4.0f, c, p)) return light_sampling::area;
  return auto_model(l, o, n).choose(c, p);
}
inline light_sampling choose_strategy(const rect& r, const vec3& o, const vec3& n, const auto_params& p = {}) {
  return choose_planar(r, o, n, auto_costs::rect, p);
}
inline light_sampling choose_strategy(const ellipse& e, const vec3& o, const vec3& n, const auto_params& p = {}) {
  return choose_planar(e, o, n, auto_costs::ellipse, p);
}
// Spheres: a cap above the horizon whose cosine varies little is the
// cone's without the quadrature. To first order in the cap's size v_sa =
// tan^2(theta_c) sin^2(alpha) / 4 (cos theta = cos theta_c cos beta + sin
// theta_c sin beta cos phi, E[beta^2] = alpha^2 / 2 over the cone); where
// even twice that leaves the cone ahead of the projected cap, the cone it
// is (area sampling, dearer, is not ahead of the cone there: its estimate
// also carries the spread of cos theta_l over the visible cap, 1/3 and more).
inline light_sampling choose_strategy(const sphere& s, const vec3& o, const vec3& n, const auto_params& p = {}) {
  const vec3 v = s.center - o;
  const float h = glm::dot(v, n), r2 = s.radius * s.radius, d2 = glm::dot(v, v);
  const bool above = h >= s.radius * glm::length(n);
  const auto_costs::shape_costs& c = above ? auto_costs::sphere_above : auto_costs::sphere_crossing;
  if (above) {
    const float v_sa = r2 * (d2 - h * h) / (4.0f * d2 * h * h);  // tan^2(theta_c) sin^2(alpha) / 4
    if ((c.solid_angle + p.rest_cost) * (2.0f * v_sa + p.rest_variance) <=
        (c.projected_solid_angle + p.rest_cost) * p.rest_variance)
      return light_sampling::solid_angle;
  }
  return auto_model(s, o, n).choose(c, p);
}

// The strategy itself: the three samplers of one shape and the per-point
// choice. pdf per unit SOLID ANGLE: the chosen strategy's.
template <class Shape, class Area, class SolidAngle, class Projected>
struct auto_sampler {
  Shape shape;
  Area area;
  SolidAngle solid_angle;
  Projected projected;
  auto_params params;

  explicit auto_sampler(const Shape& s, const auto_params& p = {})
      : shape(s), area{s}, solid_angle{s}, projected{s}, params(p) {}

  bool faces(const vec3& o) const { return area.faces(o); }

  light_sampling choice(const vec3& o, const vec3& n) const { return choose_strategy(shape, o, n, params); }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    switch (choice(o, n)) {
      case light_sampling::area: return area.sample(o, u, s);
      case light_sampling::solid_angle: return solid_angle.sample(o, u, s);
      default: return projected.sample(o, n, u, s);
    }
  }
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const {
    switch (choice(o, n)) {
      case light_sampling::area: return area.pdf(o, dir);
      case light_sampling::solid_angle: return solid_angle.pdf(o, dir);
      default: return projected.pdf(o, n, dir);
    }
  }
};

using rect_auto_sampler =
    auto_sampler<rect, rect_area_sampler, rect_solid_angle_sampler, rect_projected_solid_angle_sampler>;
using ellipse_auto_sampler =
    auto_sampler<ellipse, ellipse_area_sampler, ellipse_solid_angle_sampler, ellipse_projected_solid_angle_sampler>;
using sphere_auto_sampler =
    auto_sampler<sphere, sphere_area_sampler, sphere_cone_sampler, sphere_projected_solid_angle_sampler>;

}  // namespace mcrt
