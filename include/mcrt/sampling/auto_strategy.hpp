#pragma once
// `auto`: for each light and shading point, the light-sampling strategy
// (area, solid angle, projected solid angle) expected to give the lowest
// error for the time, chosen from quantities known at that point. The
// choice depends on (light, o, n) only, so sample(), the pdf returned with
// a sample, pdf() and the true density agree as they do for the chosen
// strategy: the auto strategy's density at o is exactly that strategy's.
// At a camera ray's first surface the renderer passes the pixel's
// footprint, and the choice is the dearest over it on o's plane
// (auto_footprint.hpp): a function of (light, o, n, pixel), fixed along a
// path, with the same agreement.
//
// The rule. A light sample's share of a pixel's error is modelled as
// (cost_s + c_rest) (v_s + v_rest): cost_s the strategy's own time per
// sample (sample + pdf, Google Benchmark, bench/bench_samplers_*.cpp),
// c_rest the rest of the path's time per light sample (rays, materials),
// v_s the relative variance of the strategy's estimate of the direct light
// of the unoccluded light of constant radiance on a diffuse receiver at the
// point, and v_rest the relative variance everything else adds (visibility,
// the pixel's footprint, the indirect light). The strategy with the
// smallest product is taken (efficiency = 1 / (error x time)); where v_rest
// comes from the image's measured noise (auto_params), the first-order form
// of the image's own product, cost_s / t + v_s / v_rest. v_s from the
// geometry at a few points of the light (planar_rule: a delta-method test
// at the centre, a 4-point rule, then a 9-point (rectangle) or 12-point
// (disk) rule; auto_model for a sphere: 8 points of its visible cap):
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
// costs from the sampler benchmarks (sample + pdf) or, for nee, which
// takes a light sample's pdf with it, inside renders
// (bench/strategy_costs.py); the default c_rest, where `mcrt render` does
// not model it from its pilot (render/rest_cost.hpp), from the
// error-against-time study (cornell_rect, nee, sobol: ms per spp of area
// and solid-angle sampling, 318 and 451 ns per path at 1.13 light samples
// per path, leave 265 ns per light sample for the rest); a fixed v_rest =
// 4 is the value, of those tried (0.25, 1, 4, 16), with the best worst case
// over the thesis's scenes, and `mcrt render` measures the image's noise
// instead (docs/auto.md, which also says how far this rule is from the
// best fixed strategy).
//
// Where a receiver is close to a planar light (nearer to it than the
// rule's points are to each other) g peaks near the light's nearest point
// and no fixed quadrature sees the peak; the model then integrates v_area
// about the peak (planar_rule::peak_v_area; auto_choice::v_area), and takes
// the light's exact projected solid angle (Lambert's) instead of the rule's
// mean of g, which its middle point on the peak makes many times too large
// (5x, 20x, 126x at 0.1, 0.05, 0.02 of a rectangle's size below its
// middle). auto_sampler evaluates the rule of a light once per cell of a
// table of receiver positions and normals (auto_table.hpp; for a sphere,
// of distances and normals' angles to its centre), so a shading point
// pays a lookup, not the rule (and each cell the rule once, when a
// receiver first falls in it); and where even that
// does not pay at the surfaces the image sees, the light takes its
// cheapest strategy everywhere (auto_sampler::table_gain).
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <tuple>
#include <utility>
#include <variant>
#include <vector>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "mcrt/core/onb.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/auto_footprint.hpp"
#include "mcrt/sampling/auto_table.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"
#include "mcrt/sampling/projected_spherical_cap.hpp"
#include "mcrt/sampling/projected_spherical_ellipse.hpp"
#include "mcrt/sampling/projected_triangle.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "mcrt/sampling/sphere_area.hpp"
#include "mcrt/sampling/sphere_cone.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"

namespace mcrt {

// The two parameters of the rule that describe the rest of the renderer
// rather than the light (the defaults: the header's measurements; `mcrt
// render --auto-rest-cost --auto-rest-variance` sets them).
//
// v_rest either is one number for every point (rest_variance), or follows
// from the image's noise (image_variance > 0): the image's error x time is
// least where each light sample takes the strategy with the least
// t_s / t + D^2 v_s / V (first order in one point's change of the product
// of the image's error and time; t the time per light sample, D the
// light's contribution to the pixel, V the image's mean variance per pixel
// sample), i.e. t_s / t + v_s / v_rest with v_rest = V / D^2 at the point
// (auto_choice::score).
// D is taken as a diffuse receiver's radiance, rho L Omega_proj / pi, with
// L the light's radiance, rho the receivers' albedo and Omega_proj the
// light's projected solid angle at the point: close to a bright light, where its own noise
// would dominate the pixel, v_rest is small and the dearer strategies
// pay; where the image's noise is elsewhere (the edges of a light seen by
// the camera, shadows, indirect light), v_rest is large and area sampling
// is kept. `mcrt render` measures V, and rho as the root mean square of the
// albedos the camera sees, by a pilot (render/noise_pilot.hpp).
struct auto_params {
  float rest_cost = 265.0f;      // c_rest, ns per light sample
  float rest_variance = 4.0f;    // v_rest, where image_variance is 0
  float image_variance = 0.0f;   // V: mean variance of a pixel sample (radiance^2); 0: use rest_variance
  float radiance = 1.0f;         // L: the light's radiance (mean of its channels)
  float albedo = 1.0f;           // rho: the receivers' albedo (root mean square)
  // The integrator takes each light sample's pdf with the sample and
  // evaluates no light pdf apart (nee): the strategies' costs inside such
  // renders (auto_costs::*_nee); otherwise (the mixture, mis) sample + pdf.
  bool pdf_with_sample = false;

  // v_rest at a point where the light's projected solid angle is omega_proj
  // (infinite where the light gives nothing: no strategy helps there; also
  // beyond 1e30, where the rule's products (cost + c_rest)(v + v_rest)
  // would overflow and every strategy's v is negligible anyway).
  float rest_variance_at(float omega_proj) const {
    if (!(image_variance > 0.0f)) return rest_variance;
    const float d = albedo * radiance * omega_proj * inv_pi;
    const float v = image_variance / (d * d);
    if (!(v < 1e30f)) return std::numeric_limits<float>::infinity();
    return std::max(v, std::numeric_limits<float>::min());  // > 0: the rule divides by it
  }
};

// Time per light sample (ns, sample + pdf) of each strategy of a shape.
struct auto_costs {
  struct shape_costs {
    float area, solid_angle, projected_solid_angle;
    float of(light_sampling s) const {
      return s == light_sampling::area ? area : s == light_sampling::solid_angle ? solid_angle : projected_solid_angle;
    }
  };
  static constexpr shape_costs rect{17.0f, 135.0f, 800.0f};
  static constexpr shape_costs ellipse{31.0f, 763.0f, 1700.0f};
  // Spheres: the projected spherical cap is dearer where the cap crosses the
  // horizon (a numerical inversion) than above it (closed form).
  static constexpr shape_costs sphere_above{74.0f, 54.0f, 100.0f};
  static constexpr shape_costs sphere_crossing{74.0f, 54.0f, 600.0f};
  // Triangles (BM_SampleTriangleArea, ...SolidAngle, ...ProjectedSolidAngle/Up
  // on the machine of the other shapes' costs, 84, 535 and 799 ns; the area
  // sampler's pdf intersects the triangle in double). Solid angle's since
  // scaled by 0.69, what its set-up's inlined cross products took off the
  // benchmark on another machine (350 -> 241 ns, interleaved; docs/samplers.md
  // has that machine's table).
  static constexpr shape_costs triangle{84.0f, 368.0f, 799.0f};
  // With nee, a light sample's time inside a render: the cheapest
  // strategy's cost as above, the others' by what they add to a render's
  // time per light sample (bench/strategy_costs.py: nee, Sobol, one thread,
  // the size and distance families' scenes, direct and global light,
  // medians: rectangle +77 / +354 ns (direct), +79 / +365 (global) for solid
  // angle / projected solid angle; ellipse +344 / +728, +347 / +745; sphere:
  // area +21 / +16, projected cap +16 / +19 over the cone). They are 0.4-0.7
  // of the sample + pdf benchmarks' differences: no pdf, and the sampler's
  // work overlaps the path's. The sphere's crossing case, rare in those
  // scenes, is the benchmark's difference scaled as the cap above it's.
  static constexpr shape_costs rect_nee{17.0f, 95.0f, 377.0f};
  static constexpr shape_costs ellipse_nee{31.0f, 376.0f, 766.0f};
  static constexpr shape_costs sphere_above_nee{74.0f, 54.0f, 72.0f};
  static constexpr shape_costs sphere_crossing_nee{74.0f, 54.0f, 268.0f};
  static const shape_costs& rect_for(const auto_params& p) { return p.pdf_with_sample ? rect_nee : rect; }
  static const shape_costs& ellipse_for(const auto_params& p) { return p.pdf_with_sample ? ellipse_nee : ellipse; }
  // Triangles with nee: the sample + pdf benchmarks' costs as well (not
  // measured inside renders; the rectangle's and the ellipse's in-render
  // differences are 0.4-0.7 of those, so nee's choice leans, if anything,
  // towards area sampling).
  static const shape_costs& triangle_for(const auto_params&) { return triangle; }
  static const shape_costs& sphere_for(bool above, const auto_params& p) {
    if (p.pdf_with_sample) return above ? sphere_above_nee : sphere_crossing_nee;
    return above ? sphere_above : sphere_crossing;
  }
  // What a light sample pays for the choice itself (the table's lookup and
  // the dispatch to the chosen sampler), beyond the chosen strategy's cost:
  // `auto` held to area sampling everywhere against area sampling, 1
  // thread, interleaved (bench/ab_render.sh, nee, sobol): 5.5 ns per path
  // on size_rect_1of16 (direct, 256 spp), 22 ns per path of about 3.5 light
  // samples on size_rect_x4 (global, 64 spp). auto_sampler::table_gain.
  static constexpr float table_lookup = 6.0f;
};

// A surface point the image sees (position, unit normal on the viewer's
// side), as the noise pilot finds them at its pixels' centres: where
// auto_sampler::table_gain weighs the table's choices against their cost.
struct auto_receiver {
  vec3 p, n;
};
// The box about a set of receivers, for a screen's one test of a group
// (planar_rule::area_wins_beyond).
struct auto_receiver_bounds {
  vec3 lo{std::numeric_limits<float>::infinity()}, hi{-std::numeric_limits<float>::infinity()};
};
// A set of receivers in groups of `group` neighbours (in the order of a
// Morton curve through their box), each with its box: a screen tests a
// light against a group's box once, and against the receivers of the
// groups that bound does not settle (auto_sampler::cheapest_at_every).
// One box about all receivers would be too coarse: a scene's lights lie
// inside the box of the surfaces it sees.
struct auto_receiver_groups {
  static constexpr std::size_t group = 8;
  std::vector<auto_receiver> receivers;     // reordered
  std::vector<auto_receiver_bounds> boxes;  // of receivers [group k, group (k + 1))

  explicit auto_receiver_groups(std::span<const auto_receiver> rs) {
    auto_receiver_bounds all;
    for (const auto_receiver& r : rs) all.lo = glm::min(all.lo, r.p), all.hi = glm::max(all.hi, r.p);
    // 10 bits per axis, interleaved.
    const auto spread = [](std::uint32_t x) {
      x &= 0x3ffu;
      x = (x | (x << 16)) & 0x030000ffu;
      x = (x | (x << 8)) & 0x0300f00fu;
      x = (x | (x << 4)) & 0x030c30c3u;
      return (x | (x << 2)) & 0x09249249u;
    };
    const vec3 extent = glm::max(all.hi - all.lo, vec3(std::numeric_limits<float>::min()));
    std::vector<std::pair<std::uint32_t, std::uint32_t>> keys(rs.size());
    for (std::size_t i = 0; i < rs.size(); ++i) {
      const vec3 q = glm::clamp((rs[i].p - all.lo) / extent, 0.0f, 1.0f) * 1023.0f;
      keys[i] = {spread(std::uint32_t(q.x)) | (spread(std::uint32_t(q.y)) << 1) | (spread(std::uint32_t(q.z)) << 2),
                 static_cast<std::uint32_t>(i)};
    }
    std::sort(keys.begin(), keys.end());
    receivers.reserve(rs.size());
    for (const auto& k : keys) receivers.push_back(rs[k.second]);
    for (std::size_t first = 0; first < receivers.size(); first += group) {
      auto_receiver_bounds b;
      for (std::size_t i = first; i < std::min(first + group, receivers.size()); ++i)
        b.lo = glm::min(b.lo, receivers[i].p), b.hi = glm::max(b.hi, receivers[i].p);
      boxes.push_back(b);
    }
  }
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

  // The weighted sums of a planar light's points, formed by planar_rule
  // (with cos(theta_l) = h / r, h the receiver's height over the plane,
  // which cancels from both ratios and is left out of every sum); g_peak
  // the peak of g / h the rule's points miss, 0 where they resolve it.
  void set_sums(float sg, float sg2, float sw, float swc, float swc2, float g_peak) {
    sg_ = sg, sg2_ = sg2, sw_ = sw, swc_ = swc, swc2_ = swc2, g_peak_ = g_peak;
  }

  // The light's projected solid angle at the point is the quadrature's mean
  // of g times the area the points cover (area_scale; for a planar light
  // its area times the receiver's height, h being left out of the sums).
  void set_area_scale(float area_scale) { omega_proj_ = area_scale * sg_; }
  // Where g peaks between the rule's points (peaked()), its mean is as far
  // off as its variance: there the exact Omega_proj (Lambert's, from the
  // projected-solid-angle sampler) sets omega_proj() and the mean of g the
  // peak's bound is taken against (v_area), mean_g = Omega_proj /
  // area_scale (elsewhere the quadrature's mean).
  void set_exact_omega_proj(float omega_proj, float area_scale) {
    omega_proj_ = omega_proj, mean_g_ = omega_proj / area_scale;
  }
  // v_area where g peaks between the rule's points, integrated about the
  // peak (planar_rule::peak_v_area): v_area() takes it there.
  void set_peak_v_area(float v) { v_peak_ = v; }
  float omega_proj() const { return omega_proj_; }
  float rest_variance(const auto_params& p) const { return p.rest_variance_at(omega_proj_); }

  // Relative variances of the area and solid-angle estimates (header).
  // v_area: the quadrature's, unless g at the light's nearest point exceeds
  // twice the quadrature's mean and the rule's points do not resolve the
  // peak (planar_rule::model sets g_peak only then): then the receiver is
  // close to the light, g peaks at the nearest point, and a fixed rule
  // misses the peak. There the fine rule integrates v_area about the peak
  // (planar_rule::peak_v_area, set_peak_v_area; within 4 % of the exact
  // value). Without it (the coarse rule) the peak's variance for a
  // receiver facing the light, (q - 1) / 3 with q = g_peak / E[g] (for g =
  // delta^2 / r^4 over a large light E_A[g^2] / E_A[g]^2 = A / (3 pi
  // delta^2) = q / 3), stands in; at q = 2 both forms give 1/3 (g linear
  // from 0 to 2 E[g]). That is the largest of the peak's shapes: over a
  // large light E_A[g^2] / E_A[g]^2 is 4 sqrt(3) q / 27 for a receiver whose
  // normal lies in the light's plane, and beside the light (farther from
  // its edge than from its plane) 5 q / 24 facing it, 5 q / 32 with the
  // normal in the plane; on the walls under a large ceiling light the
  // bound is 1.6-1.8 times the true v_area (tests/test_auto_strategy.cpp,
  // PeakVarianceIntegrated), which is why the fine rule integrates instead.
  float v_area() const {
    if (!(sg_ > 0.0f)) return 0.0f;
    if (peaked() && v_peak_ >= 0.0f) return v_peak_;
    const float v = excess_ratio(sg2_, 1.0f, sg_);
    const float mean = mean_g_ > 0.0f ? mean_g_ : sg_;
    return peaked() ? std::max(v, (g_peak_ / mean - 1.0f) * (1.0f / 3.0f)) : v;
  }
  bool peaked() const { return g_peak_ > 2.0f * sg_; }
  // What the BSDF's samples add to a light's estimate with mis (power
  // heuristic, cosine-weighted BSDF sampling), whatever the light's
  // strategy, relative: exact where the light sample's density is
  // proportional to the BSDF's (projected solid angle: p_l = cos /
  // Omega_proj, p_b = cos / pi, so the light sample's weighted value is a
  // constant, and the BSDF's sample is a Bernoulli that meets the light
  // with probability 1 / k, k = pi / Omega_proj, and then carries pi L /
  // (k^2 + 1)): pi^2 k (1 - 1 / k) / (k^2 + 1)^2, 0.39 for a light filling
  // half the projected hemisphere, ~pi^2 / k^3 for a small one. The
  // strategies' own v (v_of) leave it out: it is nearly the same for each
  // and cancels from the choice at a point, but it bounds how far a choice
  // can lower the light's noise (render/choice_gain_pilot.hpp).
  float v_bsdf_mis() const {
    if (!(omega_proj_ > 0.0f)) return 0.0f;
    const float k = std::max(pi / omega_proj_, 1.0f), k2 = k * k;
    return pi * pi * k * (1.0f - 1.0f / k) / ((k2 + 1.0f) * (k2 + 1.0f));
  }
  // The modelled relative variance of strategy s (projected solid angle's is 0).
  float v_of(light_sampling s) const {
    return s == light_sampling::area ? v_area() : s == light_sampling::solid_angle ? v_solid_angle() : 0.0f;
  }
  // The choice under params p with costs c: its noise D^2 v / V, V the
  // image variance of params `own` (v over own's v_rest, as noise_share),
  // and its cost (ns).
  std::pair<float, float> noise_and_cost(const auto_costs::shape_costs& c, const auto_params& p,
                                         const auto_params& own) const {
    const light_sampling s = choose(c, p);
    return {v_of(s) / rest_variance(own), c.of(s)};
  }
  float v_solid_angle() const {
    if (!(swc_ > 0.0f)) return 0.0f;
    return excess_ratio(sw_, swc2_, swc_);
  }
  // a b / d^2 - 1, at least 0 (d > 0): in float, or in double where d^2
  // underflows a float (the sums leave out h, the receiver's height over a
  // planar light, but for a receiver facing it g / h still scales with h:
  // below about 1e-19 of the light's size d^2 would be 0 and the ratio NaN).
  static float excess_ratio(float a, float b, float d) {
    const float d2 = d * d;
    if (d2 >= std::numeric_limits<float>::min()) return std::max(a * b / d2 - 1.0f, 0.0f);
    return static_cast<float>(std::max(double(a) * b / (double(d) * d) - 1.0, 0.0));
  }

  // Whether area sampling is the choice even with v_area and v_sa taken
  // `factor` times larger than modelled (and lit at all).
  // Never where g peaks (near the light, see v_area): a coarse rule's
  // mean is too rough there for the peak's size.
  bool area_wins_even_if(float factor, const auto_costs::shape_costs& c, const auto_params& p) const {
    if (!(sg_ > 0.0f)) return true;
    if (peaked()) return false;
    return area_wins(factor * v_area(), rest_variance(p), c, p);
  }

  // Whether area sampling with variance v_area beats both other strategies
  // even at no variance of their own, v_rest being vr.
  static bool area_wins(float v_area, float vr, const auto_costs::shape_costs& c, const auto_params& p) {
    const float area = score(c.area, v_area, vr, c, p);
    return area <= score(c.solid_angle, 0.0f, vr, c, p) && area <= score(c.projected_solid_angle, 0.0f, vr, c, p);
  }

  // The modelled error x time of a strategy of cost `cost` and variance v
  // where v_rest is vr (smaller is better; only comparisons matter).
  //  * v_rest fixed: the local product (cost + c_rest)(v + vr);
  //  * v_rest from the image's noise (auto_params): the image's, to first
  //    order in one point's change: cost / t + v / vr, t the time per light
  //    sample, taken as c_rest plus the shape's cheapest strategy's cost.
  //    (The local product would add a cross term cost v / (c_rest vr) that
  //    wrongly favours the dearest, variance-free strategy where vr is small.)
  // Where vr is infinite (nothing to gain at the point) only the cost counts
  // (both forms' limit; the product itself would be infinite for all).
  // (In the first form a point's scores are in the image's units, so that
  // they add up over points: auto_sampler::table_gain.)
  static float score(float cost, float v, float vr, const auto_costs::shape_costs& c, const auto_params& p) {
    const bool infinite = vr == std::numeric_limits<float>::infinity();
    if (p.image_variance > 0.0f) {
      const float time = cost / (p.rest_cost + std::min({c.area, c.solid_angle, c.projected_solid_angle}));
      return infinite ? time : time + v / vr;
    }
    return infinite ? cost : (cost + p.rest_cost) * (v + vr);
  }

  // The score of strategy s at the point, with `extra` ns added to its cost
  // per light sample (the choice's own, auto_costs::table_lookup).
  float score_of(light_sampling s, float extra, const auto_costs::shape_costs& c, const auto_params& p) const {
    const float vr = sg_ > 0.0f ? rest_variance(p) : std::numeric_limits<float>::infinity();
    switch (s) {
      case light_sampling::area: return score(c.area + extra, v_area(), vr, c, p);
      case light_sampling::solid_angle: return score(c.solid_angle + extra, v_solid_angle(), vr, c, p);
      default: return score(c.projected_solid_angle + extra, 0.0f, vr, c, p);
    }
  }

  // The cheapest strategy: the choice where v_rest is infinite (the light
  // gives the point nothing, or the image's noise is all elsewhere).
  static light_sampling cheapest(const auto_costs::shape_costs& c) {
    if (c.area <= c.solid_angle && c.area <= c.projected_solid_angle) return light_sampling::area;
    return c.solid_angle <= c.projected_solid_angle ? light_sampling::solid_angle : light_sampling::projected_solid_angle;
  }

  // The strategy with the least modelled error x time (score); the cheapest
  // where no quadrature point is lit (nothing to gain).
  light_sampling choose(const auto_costs::shape_costs& c, const auto_params& p = {}) const {
    if (!(sg_ > 0.0f)) return cheapest(c);
    const float vr = rest_variance(p);
    const float area = score(c.area, v_area(), vr, c, p);
    const float sa = score(c.solid_angle, v_solid_angle(), vr, c, p);
    const float psa = score(c.projected_solid_angle, 0.0f, vr, c, p);
    if (area <= sa && area <= psa) return light_sampling::area;
    return sa <= psa ? light_sampling::solid_angle : light_sampling::projected_solid_angle;
  }

 private:
  vec3 o_, n_;
  float sg_ = 0.0f, sg2_ = 0.0f, sw_ = 0.0f, swc_ = 0.0f, swc2_ = 0.0f, g_peak_ = 0.0f;
  float omega_proj_ = 0.0f, mean_g_ = 0.0f;
  float v_peak_ = -1.0f;  // v_area integrated about g's peak (< 0: not done)
};

// The rule of a planar light (rectangle, ellipse or triangle), with what depends on
// the light alone computed once: its centre and half-axes for the delta
// method, the quadrature points of the coarse and the fine rule (SoA, so
// the per-point work is a few packed operations), and how to clamp a
// point of the plane onto the light (for the peak of g).
//
// Per point of the light, with d = p - o, r^2 = d . d and h the receiver's
// height over the plane (cos(theta_l) = h / r): g = cos+(theta) cos(theta_l)
// / r^2 = h (d . n)+ / r^4, the solid angle per unit area w = h / r^3; h
// cancels from v_area and v_sa and is dropped.
class planar_rule {
 public:
  static constexpr int coarse_points = 4, fine_points = 12;

  explicit planar_rule(const rect& r, const auto_costs::shape_costs& c = auto_costs::rect)
      : costs_(c), center_(r.corner + 0.5f * (r.e1 + r.e2)), E1_(r.e1), E2_(r.e2), nl_(r.n), k_(1.0f / 12.0f),
        area_(glm::length(glm::cross(r.e1, r.e2))), kind_(kind::rect), corner_(r.corner), dual1_(r.e1_dual), dual2_(r.e2_dual),
        exact_(rect_projected_solid_angle_sampler(r)) {
    // Coarse: 2x2 Gauss points, 1/2 -+ 1/(2 sqrt 3). Fine: 3x3 Gauss-Legendre
    // points (exact for degree 5 in each coordinate), 1/2 -+ sqrt(3/5)/2 and
    // 1/2, weights 5/18, 8/18, 5/18; three padding points of weight 0.
    constexpr float lo = 0.5f - 0.28867513f, hi = 0.5f + 0.28867513f;
    int k = 0;
    for (const float s : {lo, hi})
      for (const float t : {lo, hi}) set(coarse_, k++, r.corner + s * r.e1 + t * r.e2, 0.25f);
    const float edge = std::max(glm::length(r.e1), glm::length(r.e2));
    coarse_spacing_ = 0.57735027f * edge, fine_spacing_ = 0.38729833f * edge;
    constexpr float x[3] = {0.5f - 0.38729833f, 0.5f, 0.5f + 0.38729833f};
    constexpr float w[3] = {5.0f / 18.0f, 8.0f / 18.0f, 5.0f / 18.0f};
    k = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) set(fine_, k++, r.corner + x[i] * r.e1 + x[j] * r.e2, w[i] * w[j]);
    for (; k < fine_points; ++k) set(fine_, k, center_, 0.0f);
    reach_ = 0.5f * std::max(glm::length(r.e1 + r.e2), glm::length(r.e1 - r.e2));
  }
  explicit planar_rule(const ellipse& e, const auto_costs::shape_costs& c = auto_costs::ellipse)
      : costs_(c), center_(e.center), E1_(e.a1), E2_(e.a2), nl_(e.n), k_(0.25f),
        area_(pi * glm::length(e.a1) * glm::length(e.a2)), kind_(kind::ellipse),
        corner_(e.center), dual1_(e.a1_dual), dual2_(e.a2_dual), exact_(ellipse_projected_solid_angle_sampler(e)) {
    // Coarse: one ring of four points at rho = 1/sqrt(2). Fine: three rings
    // by area (rho^2 = 1/2 -+ sqrt(3/5)/2 and 1/2, the 3-point Gauss rule in
    // rho^2, weights 5/18, 8/18, 5/18) of four points each, the middle ring
    // turned by 45 degrees. Both exact for quadratics.
    constexpr float kd = 0.70710678f;
    // Neighbouring points: the coarse ring's, a semi-axis apart; the fine
    // rule's outer ring's, 0.94 sqrt(2) semi-axes apart.
    const float semi = std::max(glm::length(e.a1), glm::length(e.a2));
    coarse_spacing_ = semi, fine_spacing_ = 1.3321343f * semi;
    int k = 0;
    for (const vec3& a : {kd * e.a1, -kd * e.a1, kd * e.a2, -kd * e.a2}) set(coarse_, k++, e.center + a, 0.25f);
    constexpr float rho[3] = {0.33571069f, 0.70710678f, 0.94196515f};
    constexpr float w[3] = {5.0f / 72.0f, 8.0f / 72.0f, 5.0f / 72.0f};  // per point (four per ring)
    const vec3 axis_dirs[4] = {e.a1, e.a2, -e.a1, -e.a2};
    const vec3 diagonal_dirs[4] = {kd * (e.a1 + e.a2), kd * (e.a2 - e.a1), -kd * (e.a1 + e.a2), kd * (e.a1 - e.a2)};
    k = 0;
    for (int ring = 0; ring < 3; ++ring)
      for (int i = 0; i < 4; ++i) set(fine_, k++, e.center + rho[ring] * (ring == 1 ? diagonal_dirs[i] : axis_dirs[i]), w[ring]);
    reach_ = semi;
  }
  // A triangle (its back side where `back`, the other half of a two-sided
  // light). The delta method's E1, E2 are the edges of the rectangle with
  // the triangle's covariance about its centroid, Sigma = (1/12) sum_i
  // d_i d_i^T (d_i the vertices' offsets from the centroid): along its
  // principal axes, E_i = sqrt(12 lambda_i) e_i. Coarse: the degree-2 rule
  // of the three points (2/3, 1/6, 1/6) (Strang & Fix). Fine: Dunavant's
  // 12-point rule of degree 6 ("High degree efficient symmetrical Gaussian
  // quadrature rules for the triangle", IJNME 21, 1985, table: p = 6).
  explicit planar_rule(const triangle& t, bool back = false, const auto_costs::shape_costs& c = auto_costs::triangle)
      : costs_(c), k_(1.0f / 12.0f), area_(t.area()), kind_(kind::triangle), exact_(triangle_projected_solid_angle_sampler(t, back)) {
    const vec3 v[3] = {t.vertex(0), t.vertex(1), t.vertex(2)};
    center_ = (v[0] + v[1] + v[2]) / 3.0f;
    reach_ = std::sqrt(std::max({glm::dot(v[0] - center_, v[0] - center_), glm::dot(v[1] - center_, v[1] - center_),
                                 glm::dot(v[2] - center_, v[2] - center_)}));
    nl_ = back ? -t.normal() : t.normal();
    corner_ = center_;
    // The covariance in a frame of the plane, then its principal axes.
    const onb frame(nl_);
    double sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (const vec3& p : v) {
      const double x = glm::dot(p - center_, frame.u), y = glm::dot(p - center_, frame.v);
      sxx += x * x / 12.0, syy += y * y / 12.0, sxy += x * y / 12.0;
    }
    const double mean = 0.5 * (sxx + syy), dev = std::hypot(0.5 * (sxx - syy), sxy);
    const double l1 = mean + dev, l2 = std::max(mean - dev, 0.0), th = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
    const vec3 e1 = float(std::cos(th)) * frame.u + float(std::sin(th)) * frame.v;
    const vec3 e2 = glm::cross(nl_, e1);
    // A degenerate triangle has no area and is never a light; the floor
    // keeps E2's direction defined for a sliver.
    E1_ = float(std::sqrt(12.0 * l1)) * e1;
    E2_ = float(std::max(std::sqrt(12.0 * l2), 1e-30)) * e2;
    dual1_ = e1, dual2_ = e2;  // the unit axes of the triangle's own frame
    for (int i = 0; i < 3; ++i) tri_[i] = {glm::dot(v[i] - center_, e1), glm::dot(v[i] - center_, e2)};
    // Counter-clockwise in (e1, e2): the half-planes' tests take the inside on the left.
    const vec2 a = tri_[1] - tri_[0], b = tri_[2] - tri_[0];
    if (a.x * b.y - a.y * b.x < 0.0f) std::swap(tri_[1], tri_[2]);
    int k = 0;
    const auto at = [&](float b0, float b1, float b2) { return b0 * v[0] + b1 * v[1] + b2 * v[2]; };
    for (int i = 0; i < 3; ++i) {
      const float b[3] = {i == 0 ? 2.0f / 3.0f : 1.0f / 6.0f, i == 1 ? 2.0f / 3.0f : 1.0f / 6.0f,
                          i == 2 ? 2.0f / 3.0f : 1.0f / 6.0f};
      set(coarse_, k++, at(b[0], b[1], b[2]), 1.0f / 3.0f);
    }
    set(coarse_, k, center_, 0.0f);
    struct orbit {
      float a, b, c, w;  // barycentrics and the weight of each point
      bool six;          // all six permutations (else the three rotations of (a, b, b))
    };
    constexpr orbit fine[3] = {{0.501426509658179f, 0.249286745170910f, 0.249286745170910f, 0.116786275726379f, false},
                               {0.873821971016996f, 0.063089014491502f, 0.063089014491502f, 0.050844906370207f, false},
                               {0.053145049844817f, 0.310352451033784f, 0.636502499121399f, 0.082851075618374f, true}};
    k = 0;
    for (const orbit& o : fine) {
      set(fine_, k++, at(o.a, o.b, o.c), o.w);
      set(fine_, k++, at(o.b, o.c, o.a), o.w);
      set(fine_, k++, at(o.c, o.a, o.b), o.w);
      if (o.six) {
        set(fine_, k++, at(o.a, o.c, o.b), o.w);
        set(fine_, k++, at(o.c, o.b, o.a), o.w);
        set(fine_, k++, at(o.b, o.a, o.c), o.w);
      }
    }
    coarse_spacing_ = nearest_neighbour_spacing(coarse_, 3);
    fine_spacing_ = nearest_neighbour_spacing(fine_, fine_points);
  }

  // First-order (delta-method) v_area at the light's centre (offsets s E1 +
  // t E2 over the light, variances k each: 1/12 for a rectangle's edges,
  // 1/4 for an ellipse's semi-axes): log g = log(n . d) - 4 log r + const,
  // d = p - o, so v_area ~ k ((grad log g . E1)^2 + (grad log g . E2)^2)
  // with grad log g = n / (n . d) - 4 d / r^2. Valid (true, with v_area)
  // only where each part of the gradient changes log g by at most 0.3
  // across the light, and so does the second-order term of -4 log r
  // (-2 log(1 + |s|^2 / r^2) ~ -2 |s|^2 / r^2 at offset s, at most
  // (|E1|^2 + |E2|^2) / (2 r^2) at a corner), so that the first-order term
  // is all that matters (within a factor 2 on the test receivers:
  // tests/test_auto_strategy.cpp). Without the second-order test a light
  // long against its distance passes where the gradient vanishes (right
  // under a sliver's middle, ModelVariancesLongSliver), and area sampling
  // would be taken at v_area ~ 0 where it is ~1.
  // One division: the gradient's parts over the common denominator
  // (n . d) r^2. omega_proj: the light's area times g at its centre.
  bool delta_v_area(const vec3& o, const vec3& n, float& v_area) const {
    float omega_proj;
    return delta_v_area(o, n, v_area, omega_proj);
  }
  bool delta_v_area(const vec3& o, const vec3& n, float& v_area, float& omega_proj) const {
    const float h = glm::dot(o - center_, nl_);
    if (!(h > 0.0f)) return false;  // behind the light
    const vec3 d = center_ - o;
    const float r2 = glm::dot(d, d), nd = glm::dot(n, d);
    if (!(nd > 0.0f) || !(r2 > 0.0f)) return false;
    const float n1 = glm::dot(n, E1_), n2 = glm::dot(n, E2_);
    const float d1 = 4.0f * glm::dot(d, E1_), d2 = 4.0f * glm::dot(d, E2_);
    if (!(0.5f * (std::abs(n1) + std::abs(n2)) <= 0.3f * nd) || !(0.5f * (std::abs(d1) + std::abs(d2)) <= 0.3f * r2) ||
        !(0.5f * (glm::dot(E1_, E1_) + glm::dot(E2_, E2_)) <= 0.3f * r2))
      return false;
    const float inv = 1.0f / (nd * r2);
    const float g1 = (n1 * r2 - d1 * nd) * inv, g2 = (n2 * r2 - d2 * nd) * inv;
    v_area = k_ * (g1 * g1 + g2 * g2);
    omega_proj = area_ * h * nd / (r2 * r2);  // A g(centre) = A h (n . d) / r^4
    return true;
  }

  const auto_costs::shape_costs& costs() const { return costs_; }
  // Whether the rule's first test alone (the delta method) takes area
  // sampling at (o, n), or o is behind the light (nothing is sampled).
  bool first_test_takes_area(const vec3& o, const vec3& n, const auto_params& p) const {
    if (!(glm::dot(o - center_, nl_) > 0.0f)) return true;
    float v, omega;
    return delta_v_area(o, n, v, omega) && auto_choice::area_wins(2.0f * v, p.rest_variance_at(omega), costs_, p);
  }
  // The frame the rule's table takes (auto_table.hpp): centre, the two
  // (equivalent) edges or semi-axes, the front normal, and whether the
  // light is symmetric about both axes (not a triangle).
  const vec3& centre() const { return center_; }
  const vec3& axis1() const { return E1_; }
  const vec3& axis2() const { return E2_; }
  const vec3& normal() const { return nl_; }
  bool symmetric() const { return kind_ != kind::triangle; }
  // Half of axis_i for a rectangle or a triangle, axis_i for an ellipse.
  float half_scale() const { return kind_ == kind::ellipse ? 1.0f : 0.5f; }
  auto_choice coarse(const vec3& o, const vec3& n) const { return model(coarse_, o, n); }

  // Area sampling's relative variance E_A[g^2] / E_A[g]^2 - 1 at a receiver
  // whose g peaks between the rule's points, integrated about o's foot F on
  // the light's plane (height h > 0) instead of over the light's surface:
  // in polar coordinates (rho, phi) about F with rho = h tan(u), u the
  // angle from the plane's normal at o,
  //   g dA   = cos+(theta) sin(u) du dphi              (Lambert: cos dw),
  //   g^2 dA = cos+(theta)^2 cos^3(u) sin(u) du dphi / h^2,
  // cos(theta) = a cos(u) + b sin(u), a = n . (-n_l), b = n . e_phi. Both
  // are smooth in (u, phi) wherever the peak is, and their integrals over
  // u along a ray from F are closed forms (polynomials in sin and cos, the
  // part below the receiver's horizon clipped off), so only phi is summed:
  // `angles` midpoints over the rays from F that meet the light (all of
  // them where F lies on it, the light's span seen from F otherwise). Then
  // v = A I2 / (h^2 I1^2) - 1 (I1, I2 the two integrals, A the light's
  // area; I1 is Omega_proj). With 12 angles within 4 % of the exact v_area
  // on the test receivers (tests/test_auto_strategy.cpp; 5.4 % with 8, at
  // a receiver under the light with its normal across it).
  // Double precision: A / h^2 is as large as the peak is narrow.
  // omega_proj, where given, receives I1 (the light's projected solid angle).
  double peak_v_area(const vec3& o, const vec3& n, double* omega_proj = nullptr, int angles = 12) const {
    const double la = glm::length(E1_), lb = glm::length(E2_);
    const glm::dvec3 u1 = glm::dvec3(E1_) / la, u2 = glm::dvec3(E2_) / lb, nl(nl_), nd(n);
    const bool rect = kind_ != kind::ellipse;  // a triangle: its equivalent rectangle's frame
    const double ha = rect ? 0.5 * la : la, hb = rect ? 0.5 * lb : lb;  // half-extents (semi-axes)
    const glm::dvec3 q = glm::dvec3(o) - glm::dvec3(center_);
    const double h = glm::dot(q, nl);
    if (!(h > 0.0)) return 0.0;
    const double fx = glm::dot(q, u1), fy = glm::dot(q, u2);  // F in the light's frame
    const double a = -glm::dot(nd, nl), nx = glm::dot(nd, u1), ny = glm::dot(nd, u2);
    // The interval [r0, r1] of rho along direction (dx, dy) inside the light.
    const auto chord = [&](double dx, double dy, double& r0, double& r1) {
      if (kind_ == kind::triangle) {
        // Three half-planes, the inside on each edge's left.
        r0 = 0.0, r1 = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 3; ++k) {
          const glm::dvec2 q(tri_[k]), e = glm::dvec2(tri_[(k + 1) % 3]) - q;
          const double c0 = e.x * (fy - q.y) - e.y * (fx - q.x), cd = e.x * dy - e.y * dx;
          if (cd == 0.0) {
            if (c0 < 0.0) return false;
            continue;
          }
          const double t = -c0 / cd;
          if (cd > 0.0) r0 = std::max(r0, t);
          else r1 = std::min(r1, t);
        }
        return r1 > r0;
      }
      if (rect) {
        r0 = 0.0, r1 = std::numeric_limits<double>::infinity();
        for (const auto& [f, d, e] : {std::tuple{fx, dx, ha}, std::tuple{fy, dy, hb}}) {
          if (d == 0.0) {
            if (std::abs(f) > e) return false;
            continue;
          }
          const double t0 = (-e - f) / d, t1 = (e - f) / d;
          r0 = std::max(r0, std::min(t0, t1)), r1 = std::min(r1, std::max(t0, t1));
        }
        return r1 > r0;
      }
      const double A = dx * dx / (ha * ha) + dy * dy / (hb * hb), B = fx * dx / (ha * ha) + fy * dy / (hb * hb),
                   C = fx * fx / (ha * ha) + fy * fy / (hb * hb) - 1.0;
      const double disc = B * B - A * C;
      if (!(disc > 0.0)) return false;
      const double s = std::sqrt(disc);
      r0 = std::max((-B - s) / A, 0.0), r1 = (-B + s) / A;
      return r1 > r0;
    };
    // The directions from F that meet the light, phi0 to phi0 + span:
    // every one where F is on it, the midpoints starting at a direction in
    // which the receiver's horizon crosses the plane (b = 0), so that with
    // an even number of angles both such directions, where the clipped
    // integrands have a kink in phi, fall between two midpoints' cells;
    // otherwise those between the extreme directions to its corners
    // (rectangle) or its tangent points (ellipse), as angles from the
    // direction to its centre (the light is convex and F outside it, so
    // they span less than pi).
    double phi0 = std::atan2(ny, nx) + 0.5 * std::numbers::pi, span = 2.0 * std::numbers::pi;
    const bool inside = kind_ == kind::triangle ? inside_triangle(fx, fy)
                        : rect ? std::abs(fx) <= ha && std::abs(fy) <= hb
                               : (fx * fx) / (ha * ha) + (fy * fy) / (hb * hb) <= 1.0;
    // The angle of the direction from F to (px, py) from the direction to
    // the light's centre, c, in [-pi, pi] (the light is convex and F
    // outside it: its points lie within pi of c).
    const double c = std::atan2(-fy, -fx);
    const auto angle_from_centre = [&](double px, double py) {
      double t = std::atan2(py - fy, px - fx) - c;
      if (t > std::numbers::pi) t -= 2.0 * std::numbers::pi;
      if (t < -std::numbers::pi) t += 2.0 * std::numbers::pi;
      return t;
    };
    if (!inside && kind_ != kind::triangle) {  // a triangle's directions: by its edges, below
      double lo = 0.0, hi = 0.0;
      const auto extend = [&](double px, double py) {
        const double t = angle_from_centre(px, py);
        lo = std::min(lo, t), hi = std::max(hi, t);
      };
      if (rect) {
        for (const double sx : {-1.0, 1.0})
          for (const double sy : {-1.0, 1.0}) extend(sx * ha, sy * hb);
      } else {
        // Tangent points (ha cos t, hb sin t): (fx / ha) cos t + (fy / hb) sin t = 1.
        const double al = fx / ha, be = fy / hb, psi = std::atan2(be, al), w = std::acos(1.0 / std::hypot(al, be));
        for (const double t : {psi - w, psi + w}) extend(ha * std::cos(t), hb * std::sin(t));
      }
      phi0 = c + lo, span = hi - lo;
    }
    // The integrals over u of cos+(theta) sin(u) and cos+(theta)^2 cos^3(u)
    // sin(u) (their antiderivatives F1, F2).
    const auto F1 = [&](double b, double u) {
      const double s = std::sin(u);
      return 0.5 * a * s * s + b * (0.5 * u - 0.25 * std::sin(2.0 * u));
    };
    const auto F2 = [&](double b, double u) {
      const double c = std::cos(u), c2 = c * c, c4 = c2 * c2, c6 = c4 * c2, s2u = std::sin(2.0 * u);
      const double cos4_sin2 = u / 16.0 - std::sin(4.0 * u) / 64.0 + s2u * s2u * s2u / 48.0;  // of cos^4 sin^2
      return -a * a * c6 / 6.0 + 2.0 * a * b * cos4_sin2 + b * b * (c6 / 6.0 - c4 / 4.0);
    };
    double i1 = 0.0, i2 = 0.0;
    // The integrals along the ray from F in direction (dx, dy), weighted.
    const auto ray = [&](double dx, double dy, double weight) {
      double r0, r1;
      if (!chord(dx, dy, r0, r1)) return;
      const double b = nx * dx + ny * dy;
      // cos(theta) = R cos(u - delta) > 0 for |u - delta| < pi / 2.
      const double delta = std::atan2(b, a);
      const double u0 = std::max(std::atan2(r0, h), delta - 0.5 * std::numbers::pi);
      const double u1e = std::min(std::atan2(r1, h), delta + 0.5 * std::numbers::pi);
      if (!(u1e > u0)) return;
      i1 += weight * (F1(b, u1e) - F1(b, u0)), i2 += weight * (F2(b, u1e) - F2(b, u0));
    };
    if (kind_ == kind::triangle) {
      // A triangle: phi parametrised by the point P(s) = A + s (B - A) of
      // an edge, dphi = |(P - F) x (B - A)| / |P - F|^2 ds, with 6
      // Gauss-Legendre points per piece (in tau, below). The pieces: the sectors
      // between the directions to consecutive vertices (each swept by that
      // edge; all three where F is on the triangle, the two about the
      // middle vertex's direction otherwise), each split where the
      // receiver's horizon crosses the plane (b = 0, the integrands' kink).
      // Midpoints in phi would miss a sliver's long chords: seen from F
      // on a sliver of aspect 100 they fill a few hundredths of a radian
      // about its far vertices, between two of 12 angles (v_area 10-15x
      // too large; in s they are the edge's length: ModelVariancesLongSliver).
      constexpr double gx[3] = {0.2386191860831969, 0.6612093864662645, 0.9324695142031521};
      constexpr double gw[3] = {0.4679139345726910, 0.3607615730481386, 0.1713244923791704};
      const glm::dvec2 F(fx, fy), hz(-ny, nx);  // hz: the horizon's direction in the plane
      const auto piece = [&](const glm::dvec2& A, const glm::dvec2& B, double s0, double s1) {
        // In s the points would be as sparse near o as far from it (a
        // sliver's edge 30 times o's height long: 6 points 5 heights apart,
        // the peak between them); in tau = atan((s - s_F) / c), c = sqrt(h^2
        // + d^2) / |B - A| (s_F and d the foot of F on the edge's line and
        // F's distance to it), the angle along the edge as o sees it, the
        // integrand is smooth: s = s_F + c tan(tau), ds = c (1 + tan^2) dtau.
        const glm::dvec2 e = B - A;
        const double ee = glm::dot(e, e);
        if (!(ee > 0.0)) return;
        const double sf = glm::dot(F - A, e) / ee, dist = std::abs((F - A).x * e.y - (F - A).y * e.x) / std::sqrt(ee);
        const double c = std::sqrt((h * h + dist * dist) / ee);
        const double t0 = std::atan((s0 - sf) / c), t1 = std::atan((s1 - sf) / c);
        for (int k = 0; k < 6; ++k) {
          const double x = (k & 1) ? gx[k / 2] : -gx[k / 2], w = gw[k / 2];
          const double tau = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * x, tn = std::tan(tau);
          const double sk = sf + c * tn, ds = 0.5 * (t1 - t0) * w * c * (1.0 + tn * tn);
          const glm::dvec2 d = A + sk * e - F;
          const double d2 = glm::dot(d, d);
          if (!(d2 > 0.0)) continue;
          ray(d.x / std::sqrt(d2), d.y / std::sqrt(d2), ds * std::abs(d.x * e.y - d.y * e.x) / d2);
        }
      };
      const auto edge = [&](const glm::dvec2& A, const glm::dvec2& B) {
        // s where P(s) - F is along the horizon: (A - F + s e) x hz = 0.
        const glm::dvec2 e = B - A, q = A - F;
        const double den = e.x * hz.y - e.y * hz.x, sh = den != 0.0 ? -(q.x * hz.y - q.y * hz.x) / den : -1.0;
        if (sh > 0.0 && sh < 1.0) piece(A, B, 0.0, sh), piece(A, B, sh, 1.0);
        else piece(A, B, 0.0, 1.0);
      };
      const glm::dvec2 V[3] = {glm::dvec2(tri_[0]), glm::dvec2(tri_[1]), glm::dvec2(tri_[2])};
      if (inside) {
        for (int k = 0; k < 3; ++k) edge(V[k], V[(k + 1) % 3]);
      } else {
        // The middle vertex: the one whose direction lies between the others'.
        double t[3];
        for (int k = 0; k < 3; ++k) t[k] = angle_from_centre(V[k].x, V[k].y);
        int m = 0;
        for (int k = 0; k < 3; ++k)
          if ((t[k] - t[(k + 1) % 3]) * (t[k] - t[(k + 2) % 3]) <= 0.0) m = k;
        edge(V[m], V[(m + 1) % 3]), edge(V[m], V[(m + 2) % 3]);
      }
    } else {
      const double dphi = span / angles;
      for (int k = 0; k < angles; ++k) {
        const double phi = phi0 + (k + 0.5) * dphi;
        ray(std::cos(phi), std::sin(phi), dphi);
      }
    }
    if (omega_proj) *omega_proj = i1;
    if (!(i1 > 0.0)) return 0.0;
    return std::max(double(area_) * i2 / (h * h * i1 * i1) - 1.0, 0.0);
  }
  auto_choice fine(const vec3& o, const vec3& n) const { return model(fine_, o, n); }

  // The choice: the delta method, where valid, then the coarse rule
  // (within a factor 4 of the variances on the test receivers); where even
  // twice, resp. four times, their v_area leaves area sampling the best,
  // that is the choice; otherwise the fine rule decides.
  light_sampling choose(const vec3& o, const vec3& n, const auto_params& p) const {
    if (takes_area_before_fine(o, n, p)) return light_sampling::area;
    return fine(o, n).choose(costs_, p);
  }
  // Whether choose's first two tests (the delta method, then the coarse
  // model) take area sampling at (o, n), before the fine model.
  // (A bound needing no model comes first: area_wins_beyond at o's
  // distance from the light's bounding sphere.)
  bool takes_area_before_fine(const vec3& o, const vec3& n, const auto_params& p) const {
    return area_wins_beyond(glm::length(o - center_) - reach_, p) || first_test_takes_area(o, n, p) ||
           coarse(o, n).area_wins_even_if(4.0f, costs_, p);
  }
  // Whether area sampling wins at every receiver at least `dist` from
  // every point of the light, by a bound rather than a model: with g =
  // cos+(theta) cos(theta_l) / r^2 <= 1 / dist^2 at each point of the light,
  // area sampling's relative variance v satisfies v Omega_proj^2 <= (v + 1)
  // Omega_proj^2 = A^2 E_A[g^2] <= A^2 / dist^4, so that v / v_rest = v
  // (rho L Omega_proj / pi)^2 / V <= (rho L A / (pi dist^2))^2 / V
  // (auto_params::rest_variance_at) whatever the receiver's normal. Where
  // area sampling wins even at twice that (the first test's margin) against
  // variance-free alternatives, it is the choice. Only with v_rest from the
  // image's noise (image_variance > 0); false where dist <= 0.
  bool area_wins_beyond(float dist, const auto_params& p) const {
    if (!(p.image_variance > 0.0f) || !(dist > 0.0f)) return false;
    const float d = p.albedo * p.radiance * area_ * inv_pi / (dist * dist);
    const float w = d * d / p.image_variance;
    return w < 1e30f && auto_choice::area_wins(2.0f * w, 1.0f, costs_, p);
  }
  // The least distance from the light to a point of the box b (a bound:
  // the distance from the light's bounding sphere about its centre; <= 0
  // where they meet).
  float distance_beyond(const auto_receiver_bounds& b) const {
    const vec3 d = glm::max(glm::max(b.lo - center_, center_ - b.hi), vec3(0.0f));
    return glm::length(d) - reach_;
  }

 private:
  template <int N>
  struct points {
    std::array<float, N> x{}, y{}, z{}, w{};
  };
  template <int N>
  static void set(points<N>& pts, int k, const vec3& p, float w) {
    pts.x[k] = p.x, pts.y[k] = p.y, pts.z[k] = p.z, pts.w[k] = w;
  }
  // The largest distance from one of the first `count` points to its nearest neighbour.
  template <int N>
  static float nearest_neighbour_spacing(const points<N>& pts, int count) {
    float spacing = 0.0f;
    for (int i = 0; i < count; ++i) {
      float nearest = std::numeric_limits<float>::infinity();
      for (int j = 0; j < count; ++j)
        if (j != i) {
          const vec3 d(pts.x[i] - pts.x[j], pts.y[i] - pts.y[j], pts.z[i] - pts.z[j]);
          nearest = std::min(nearest, glm::length(d));
        }
      spacing = std::max(spacing, nearest);
    }
    return spacing;
  }
  // Whether (x, y) of the triangle's frame (about its centroid) lies in it.
  bool inside_triangle(double x, double y) const {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 q(tri_[k]), e = glm::dvec2(tri_[(k + 1) % 3]) - q;
      if (e.x * (y - q.y) - e.y * (x - q.x) < 0.0) return false;
    }
    return true;
  }

  // The point of the plane x clamped onto the light: to the rectangle or
  // the triangle (its nearest point), or pulled radially into the ellipse
  // (nearest to within its eccentricity: only the peak's size matters).
  vec3 clamp_to_light(const vec3& x) const {
    const vec3 q = x - corner_;
    float s = glm::dot(q, dual1_), t = glm::dot(q, dual2_);
    if (kind_ == kind::triangle) {
      if (inside_triangle(s, t)) return corner_ + s * dual1_ + t * dual2_;
      const vec2 f(s, t);
      vec2 best = tri_[0];
      float best_d2 = std::numeric_limits<float>::infinity();
      for (int k = 0; k < 3; ++k) {
        const vec2 a = tri_[k], e = tri_[(k + 1) % 3] - a;
        const float ee = glm::dot(e, e);
        const float u = ee > 0.0f ? std::clamp(glm::dot(f - a, e) / ee, 0.0f, 1.0f) : 0.0f;
        const vec2 c = a + u * e;
        const float d2 = glm::dot(f - c, f - c);
        if (d2 < best_d2) best_d2 = d2, best = c;
      }
      return corner_ + best.x * dual1_ + best.y * dual2_;
    }
    if (kind_ == kind::rect) return corner_ + std::clamp(s, 0.0f, 1.0f) * E1_ + std::clamp(t, 0.0f, 1.0f) * E2_;
    const float rho2 = s * s + t * t;
    if (rho2 > 1.0f) {
      const float k = 1.0f / std::sqrt(rho2);
      s *= k, t *= k;
    }
    return corner_ + s * E1_ + t * E2_;
  }

  // Sums over four points of the light at once (x, y, z, weight; the
  // weights of the peak's candidates are 0): the terms of
  // auto_choice::set_sums, and the largest g / h. Packed (SSE) where
  // available: one division and one square root for the four.
  // g, w and cos+(theta) are clamped to the largest float (NaN too): for
  // a point of the light within about 1e-10 of its size from o (the peak's
  // candidates right under o, h tiny) 1 / r^4 overflows, or r^2 underflows
  // to 0, and a candidate's weight 0 times infinity would make every sum
  // NaN (and the receiver look unlit).
  struct sums {
    float sg = 0.0f, sg2 = 0.0f, sw = 0.0f, swc2 = 0.0f, g_max = 0.0f;
  };
  static void accumulate4(const float* x, const float* y, const float* z, const float* wt, const vec3& o,
                          const vec3& n, sums& s) {
#if defined(__SSE2__)
    const __m128 dx = _mm_sub_ps(_mm_loadu_ps(x), _mm_set1_ps(o.x)), dy = _mm_sub_ps(_mm_loadu_ps(y), _mm_set1_ps(o.y)),
                 dz = _mm_sub_ps(_mm_loadu_ps(z), _mm_set1_ps(o.z));
    const __m128 r2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 dn = _mm_max_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, _mm_set1_ps(n.x)), _mm_mul_ps(dy, _mm_set1_ps(n.y))),
                   _mm_mul_ps(dz, _mm_set1_ps(n.z))),
        _mm_setzero_ps());
    const __m128 inv_r2 = _mm_div_ps(_mm_set1_ps(1.0f), r2), inv_r = _mm_sqrt_ps(inv_r2);
    // (minps returns its second operand where the first is NaN.)
    const __m128 big = _mm_set1_ps(std::numeric_limits<float>::max());
    const __m128 g = _mm_min_ps(_mm_mul_ps(dn, _mm_mul_ps(inv_r2, inv_r2)), big);  // g / h
    const __m128 w = _mm_min_ps(_mm_mul_ps(inv_r2, inv_r), big);  // solid angle per unit area / h
    const __m128 c = _mm_min_ps(_mm_mul_ps(dn, inv_r), big);  // cos+(theta)
    const __m128 W = _mm_loadu_ps(wt), Wg = _mm_mul_ps(W, g);
    alignas(16) float t[4][4];
    _mm_store_ps(t[0], Wg);
    _mm_store_ps(t[1], _mm_mul_ps(Wg, g));
    _mm_store_ps(t[2], _mm_mul_ps(W, w));
    _mm_store_ps(t[3], _mm_mul_ps(Wg, c));  // W g cos+(theta)
    alignas(16) float gm[4];
    _mm_store_ps(gm, g);
    s.sg += (t[0][0] + t[0][1]) + (t[0][2] + t[0][3]);
    s.sg2 += (t[1][0] + t[1][1]) + (t[1][2] + t[1][3]);
    s.sw += (t[2][0] + t[2][1]) + (t[2][2] + t[2][3]);
    s.swc2 += (t[3][0] + t[3][1]) + (t[3][2] + t[3][3]);
    s.g_max = std::max({s.g_max, gm[0], gm[1], gm[2], gm[3]});
#else
    for (int i = 0; i < 4; ++i) {
      const float dx = x[i] - o.x, dy = y[i] - o.y, dz = z[i] - o.z;
      const float r2 = dx * dx + dy * dy + dz * dz;
      const float dn = std::max(dx * n.x + dy * n.y + dz * n.z, 0.0f);
      const float inv_r2 = 1.0f / r2, inv_r = std::sqrt(inv_r2);
      constexpr float big = std::numeric_limits<float>::max();  // fmin: the other operand where one is NaN
      const float g = std::fmin(dn * inv_r2 * inv_r2, big), w = std::fmin(inv_r2 * inv_r, big);
      const float c = std::fmin(dn * inv_r, big);
      s.sg += wt[i] * g, s.sg2 += wt[i] * g * g, s.sw += wt[i] * w, s.swc2 += wt[i] * g * c;
      s.g_max = std::max(s.g_max, g);
    }
#endif
  }

  // The model over the points pts, with the peak of g / h (auto_choice::
  // v_area): for a receiver at height h over the plane, g peaks at o's
  // foot on the plane when n faces the light, and h / sqrt(3) along n's
  // part in the plane from there when n lies in it (x / (x^2 + h^2)^2
  // peaks there); both candidates, each clamped onto the light, enter as
  // points of weight 0 whose largest g is the peak.
  template <int N>
  auto_choice model(const points<N>& pts, const vec3& o, const vec3& n) const {
    static_assert(N % 4 == 0);
    auto_choice ch(o, n);
    const float h = glm::dot(o - center_, nl_);
    if (!(h > 0.0f)) return ch;  // behind the light: nothing lit
    sums s;
    for (int i = 0; i < N; i += 4) accumulate4(&pts.x[i], &pts.y[i], &pts.z[i], &pts.w[i], o, n, s);
    const float g_quad_max = s.g_max;
    const vec3 foot = o - h * nl_;
    const float nn = glm::dot(n, nl_), t2 = 1.0f - nn * nn;  // |n's part in the plane|^2
    const vec3 a = clamp_to_light(foot);
    const vec3 b = t2 > 0.0f ? clamp_to_light(foot + (0.57735027f * h / std::sqrt(t2)) * (n - nn * nl_)) : a;
    const float px[4] = {a.x, b.x, a.x, b.x}, py[4] = {a.y, b.y, a.y, b.y}, pz[4] = {a.z, b.z, a.z, b.z};
    constexpr float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    s.g_max = 0.0f;
    accumulate4(px, py, pz, zero, o, n, s);
    // g's peak is about as wide as o's distance to the light's nearest
    // point; where that is at least the spacing of the rule's points, they
    // resolve it, and the rule's own variance stands (the peak's bound is
    // for a peak that falls between them).
    const float spacing = N == coarse_points ? coarse_spacing_ : fine_spacing_;
    const bool resolved = glm::dot(o - a, o - a) >= spacing * spacing;
    ch.set_sums(s.sg, s.sg2, s.sw, s.sg, s.swc2, resolved ? 0.0f : std::max(s.g_max, g_quad_max));
    ch.set_area_scale(area_ * h);
    // Where the points miss g's peak, the exact Omega_proj (a few hundred
    // ns to a few us, at the few cells near the light where this happens)
    // and v_area integrated about the peak (peak_v_area, 1-2 us); the
    // fine rule's only (the coarse one's choice is never taken there:
    // area_wins_even_if).
    if (N == fine_points && ch.peaked()) {
      double omega_peak = 0.0;
      const double v = peak_v_area(o, n, &omega_peak);
      // The sampler's exact Omega_proj; where it is not finite (the
      // ellipse's, for o within about 1e-10 of its size from its plane),
      // the peak integral's I1 (12 angles, as its v_area).
      const double exact = std::visit([&](const auto& e) { return e.projected_solid_angle(o, n); }, exact_);
      const double omega = exact > 0.0 && std::isfinite(exact) ? exact : omega_peak;
      if (omega > 0.0) ch.set_exact_omega_proj(static_cast<float>(omega), area_ * h);
      // At most the largest float: A / h^2 overflows it where o all but
      // touches the light (h below about 1e-19 of its size), and v_area
      // enters the rule's float scores.
      ch.set_peak_v_area(static_cast<float>(std::min(v, double(std::numeric_limits<float>::max()))));
    }
    return ch;
  }

  auto_costs::shape_costs costs_;
  vec3 center_, E1_, E2_, nl_;
  float k_;
  float area_;  // the light's area
  float reach_ = 0.0f;  // the largest distance from the centre to a point of the light
  float coarse_spacing_ = 0.0f, fine_spacing_ = 0.0f;  // largest distance between neighbouring points of each rule
  enum class kind : std::uint8_t { rect, ellipse, triangle };
  kind kind_;
  // rect: corner and e_i / |e_i|^2; ellipse: centre and a_i / |a_i|^2;
  // triangle: centroid and its frame's unit axes (those of E1, E2).
  vec3 corner_, dual1_, dual2_;
  std::array<vec2, 3> tri_{};  // a triangle's vertices in that frame, counter-clockwise
  points<coarse_points> coarse_;
  points<fine_points> fine_;
  // The light's projected-solid-angle sampler, for its exact Omega_proj.
  std::variant<rect_projected_solid_angle_sampler, ellipse_projected_solid_angle_sampler,
               triangle_projected_solid_angle_sampler>
      exact_;
};

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
  ch.set_area_scale(2.0f * pi * s.radius * s.radius * (1.0f - s.radius / d));  // the visible cap's area
  return ch;
}

// The planar rules as functions of (light, o, n) (each builds the light's
// rule; auto_sampler keeps it instead).
inline auto_choice auto_model_coarse(const rect& r, const vec3& o, const vec3& n) { return planar_rule(r).coarse(o, n); }
inline auto_choice auto_model_coarse(const ellipse& e, const vec3& o, const vec3& n) {
  return planar_rule(e).coarse(o, n);
}
inline auto_choice auto_model(const rect& r, const vec3& o, const vec3& n) { return planar_rule(r).fine(o, n); }
inline auto_choice auto_model(const ellipse& e, const vec3& o, const vec3& n) { return planar_rule(e).fine(o, n); }
inline bool delta_v_area(const rect& r, const vec3& o, const vec3& n, float& v) {
  return planar_rule(r).delta_v_area(o, n, v);
}
inline bool delta_v_area(const ellipse& e, const vec3& o, const vec3& n, float& v) {
  return planar_rule(e).delta_v_area(o, n, v);
}
inline light_sampling choose_strategy(const rect& r, const vec3& o, const vec3& n, const auto_params& p = {}) {
  return planar_rule(r, auto_costs::rect_for(p)).choose(o, n, p);
}
inline light_sampling choose_strategy(const ellipse& e, const vec3& o, const vec3& n, const auto_params& p = {}) {
  return planar_rule(e, auto_costs::ellipse_for(p)).choose(o, n, p);
}
inline auto_choice auto_model_coarse(const triangle& t, const vec3& o, const vec3& n) { return planar_rule(t).coarse(o, n); }
inline auto_choice auto_model(const triangle& t, const vec3& o, const vec3& n) { return planar_rule(t).fine(o, n); }
inline bool delta_v_area(const triangle& t, const vec3& o, const vec3& n, float& v) {
  return planar_rule(t).delta_v_area(o, n, v);
}
inline light_sampling choose_strategy(const triangle& t, const vec3& o, const vec3& n, const auto_params& p = {}) {
  return planar_rule(t, false, auto_costs::triangle_for(p)).choose(o, n, p);
}
// Spheres: a cap above the horizon whose cosine varies little is the
// cone's without the quadrature. To first order in the cap's size v_sa =
// tan^2(theta_c) sin^2(alpha) / 4 (cos theta = cos theta_c cos beta + sin
// theta_c sin beta cos phi, E[beta^2] = alpha^2 / 2 over the cone); where
// even twice that leaves the cone ahead of the projected cap, the cone it
// is (area sampling, dearer, is not ahead of the cone there: its estimate
// also carries the spread of cos theta_l over the visible cap, 1/3 and more).
inline bool sphere_above_horizon(const sphere& s, const vec3& o, const vec3& n) {
  return glm::dot(s.center - o, n) >= s.radius * glm::length(n);
}
inline light_sampling choose_strategy(const sphere& s, const vec3& o, const vec3& n, const auto_params& p = {}) {
  const vec3 v = s.center - o;
  const float h = glm::dot(v, n), r2 = s.radius * s.radius, d2 = glm::dot(v, v);
  const bool above = sphere_above_horizon(s, o, n);
  const auto_costs::shape_costs& c = auto_costs::sphere_for(above, p);
  if (above) {
    const float v_sa = r2 * (d2 - h * h) / (4.0f * d2 * h * h);  // tan^2(theta_c) sin^2(alpha) / 4
    // Omega_proj = pi sin^2(alpha) cos(theta_c) for a cap above the horizon.
    const float vr = p.rest_variance_at(pi * r2 / d2 * h / std::sqrt(d2));
    if (auto_choice::score(c.solid_angle, 2.0f * v_sa, vr, c, p) <=
        auto_choice::score(c.projected_solid_angle, 0.0f, vr, c, p))
      return light_sampling::solid_angle;
  }
  return auto_model(s, o, n).choose(c, p);
}

// The per-light rule auto_sampler uses. Planar lights: the rule above,
// tabulated over cells of the receiver's position and normal (auto_table.hpp:
// a lookup per shading point instead of the rule's tens of ns).
class tabulated_planar_rule {
 public:
  // (Each rule is made in its shared storage at once: a temporary rule
  // copied there would copy the variant of its exact sampler, which GCC 12
  // at -O3 flags, falsely, as reading alternatives that are not there.)
  tabulated_planar_rule(const rect& r, const auto_params& p)
      : tabulated_planar_rule(std::make_shared<const planar_rule>(r, auto_costs::rect_for(p)),
                              r.corner + 0.5f * (r.e1 + r.e2), 0.5f * r.e1, 0.5f * r.e2, r.n, p) {}
  tabulated_planar_rule(const ellipse& e, const auto_params& p)
      : tabulated_planar_rule(std::make_shared<const planar_rule>(e, auto_costs::ellipse_for(p)), e.center, e.a1,
                              e.a2, e.n, p) {}
  // A triangle (its back side where `back`): the table in the frame of its
  // rectangle of the same covariance, without the symmetry.
  tabulated_planar_rule(const triangle& t, const auto_params& p, bool back)
      : tabulated_planar_rule(std::make_shared<const planar_rule>(t, back, auto_costs::triangle_for(p)), p) {}

  light_sampling choose(const vec3& o, const vec3& n) const { return table_.lookup(o, n); }

  // The fine rule's model at (o, n): what gain and noise_share weigh. It
  // depends on the light and the point alone, not on the params.
  auto_choice model(const vec3& o, const vec3& n) const { return rule_->fine(o, n); }
  // The modelled gain (auto_choice::score, the fine rule's model m at o) of
  // the table's choice at (o, n), its lookup's cost included, over the
  // cheapest strategy (area sampling).
  float gain(const auto_choice& m, const vec3& o, const vec3& n) const {
    const auto_costs::shape_costs& c = rule_->costs();
    return m.score_of(auto_choice::cheapest(c), 0.0f, c, params_) -
           m.score_of(choose(o, n), auto_costs::table_lookup, c, params_);
  }
  light_sampling cheapest() const { return auto_choice::cheapest(rule_->costs()); }
  // The fine model m's choice under params p: its modelled noise D^2 v /
  // V (this rule's V) and cost (ns; auto_choice::noise_and_cost).
  std::pair<float, float> modelled(const auto_choice& m, const vec3&, const vec3&, const auto_params& p) const {
    return m.noise_and_cost(rule_->costs(), p, params_);
  }
  // Whether the rule's tests before its fine model take area sampling (the
  // cheapest) at every receiver: auto_sampler::cheapest_at_every. Triangles
  // only (the lights of meshes, often many; a rectangle's or an ellipse's
  // gate is table_gain's alone).
  bool cheapest_at_every(std::span<const auto_receiver> rs) const {
    if (rule_->symmetric()) return false;
    for (const auto_receiver& r : rs)
      if (!rule_->takes_area_before_fine(r.p, r.n, params_)) return false;
    return true;
  }
  // The same over receiver groups: a group whose box is far enough that
  // area sampling wins at any point of it by the bound alone
  // (planar_rule::area_wins_beyond, which each receiver's own tests take
  // first) passes without its receivers' tests.
  // With params p in place of the rule's own (the rule's tests depend on the
  // light and p alone: no rule needs building to screen a light with new
  // params).
  bool cheapest_at_every(const auto_receiver_groups& g) const { return cheapest_at_every(g, params_); }
  bool cheapest_at_every(const auto_receiver_groups& g, const auto_params& p) const {
    if (rule_->symmetric()) return false;
    for (std::size_t k = 0; k < g.boxes.size(); ++k) {
      if (rule_->area_wins_beyond(rule_->distance_beyond(g.boxes[k]), p)) continue;
      const std::size_t first = k * auto_receiver_groups::group;
      const std::size_t last = std::min(first + auto_receiver_groups::group, g.receivers.size());
      for (std::size_t i = first; i < last; ++i)
        if (!rule_->takes_area_before_fine(g.receivers[i].p, g.receivers[i].n, p)) return false;
    }
    return true;
  }
  // The light's own noise at the model's point with its cheapest strategy
  // (area sampling), relative to the image's: v_area / v_rest = D^2 v_area
  // / V, its share of V at the point (0 where it gives nothing).
  float noise_share(const auto_choice& m) const { return m.v_area() / m.rest_variance(params_); }
  float cheapest_cost() const {
    const auto_costs::shape_costs& c = rule_->costs();
    return std::min({c.area, c.solid_angle, c.projected_solid_angle});
  }

 private:
  tabulated_planar_rule(std::shared_ptr<const planar_rule> rule, const vec3& c, const vec3& h1, const vec3& h2,
                        const vec3& nl, const auto_params& p)
      : rule_(std::move(rule)), params_(p),
        table_(c, h1, h2, nl, [r = rule_, p](const vec3& o, const vec3& n) { return r->choose(o, n, p); }) {}
  tabulated_planar_rule(std::shared_ptr<const planar_rule> rule, const auto_params& p)
      : rule_(std::move(rule)), params_(p),
        table_(rule_->centre(), rule_->half_scale() * rule_->axis1(), rule_->half_scale() * rule_->axis2(),
               rule_->normal(), [r = rule_, p](const vec3& o, const vec3& n) { return r->choose(o, n, p); },
               rule_->symmetric()) {}
  // One rule, immutable, shared by the table's cells (which fill from it
  // lazily) and by copies of this: a light's variant holds a pointer, not
  // the rule's 680 bytes twice.
  std::shared_ptr<const planar_rule> rule_;
  auto_params params_;
  planar_auto_table table_;
};
// Spheres: the rule, tabulated over the receiver's distance and the
// normal's angle to the centre (auto_table.hpp), which is all it depends on.
class tabulated_sphere_rule {
 public:
  tabulated_sphere_rule(const sphere& s, const auto_params& p)
      : sphere_(s), params_(p),
        table_(s.center, s.radius, [s, p](const vec3& o, const vec3& n) { return choose_strategy(s, o, n, p); }) {}
  light_sampling choose(const vec3& o, const vec3& n) const { return table_.lookup(o, n); }

  // As tabulated_planar_rule's: the visible cap's model (auto_model).
  auto_choice model(const vec3& o, const vec3& n) const { return auto_model(sphere_, o, n); }
  // As tabulated_planar_rule::gain, over the cheapest strategy (the cone).
  float gain(const auto_choice& m, const vec3& o, const vec3& n) const {
    const auto_costs::shape_costs& c = auto_costs::sphere_for(sphere_above_horizon(sphere_, o, n), params_);
    return m.score_of(cheapest(), 0.0f, c, params_) - m.score_of(choose(o, n), auto_costs::table_lookup, c, params_);
  }
  // The same above the horizon and across it.
  light_sampling cheapest() const { return auto_choice::cheapest(auto_costs::sphere_for(true, params_)); }
  // As tabulated_planar_rule::modelled, with the costs above or across the horizon.
  std::pair<float, float> modelled(const auto_choice& m, const vec3& o, const vec3& n, const auto_params& p) const {
    return m.noise_and_cost(auto_costs::sphere_for(sphere_above_horizon(sphere_, o, n), p), p, params_);
  }
  // No screen for spheres (their rule is a lookup of two numbers).
  bool cheapest_at_every(std::span<const auto_receiver>) const { return false; }
  bool cheapest_at_every(const auto_receiver_groups&) const { return false; }
  bool cheapest_at_every(const auto_receiver_groups&, const auto_params&) const { return false; }
  // As tabulated_planar_rule::noise_share, with the cone (v_sa).
  float noise_share(const auto_choice& m) const { return m.v_solid_angle() / m.rest_variance(params_); }
  float cheapest_cost() const {
    const auto_costs::shape_costs& c = auto_costs::sphere_for(true, params_);
    return std::min({c.area, c.solid_angle, c.projected_solid_angle});
  }

 private:
  sphere sphere_;
  auto_params params_;
  sphere_auto_table table_;
};
template <class Shape>
struct auto_rule_of {
  using type = tabulated_planar_rule;
};
template <>
struct auto_rule_of<sphere> {
  using type = tabulated_sphere_rule;
};

// The strategy itself: the three samplers of one shape and the per-point
// choice (its rule built once per light). pdf per unit SOLID ANGLE: the
// chosen strategy's.
template <class Shape, class Area, class SolidAngle, class Projected>
struct auto_sampler {
  Shape shape;
  Area area;
  SolidAngle solid_angle;
  Projected projected;
  auto_params params;
  // A triangle's back side (the other half of a two-sided light; its
  // samplers' `back`). Rectangles and ellipses carry their side in the
  // shape, spheres have one.
  bool back = false;

  explicit auto_sampler(const Shape& s, const auto_params& p = {}, bool back_side = false)
      : shape(s), area(make<Area>(s, back_side)), solid_angle(make<SolidAngle>(s, back_side)),
        projected(make<Projected>(s, back_side)), params(p), back(back_side), rule_(make_rule(s, p, back_side)) {}

  // The same light with other params (its side kept).
  auto_sampler with_params(const auto_params& p) const { return auto_sampler(shape, p, back); }

  bool faces(const vec3& o) const { return area.faces(o); }

  light_sampling choice(const vec3& o, const vec3& n) const { return rule_.choose(o, n); }
  // At a camera ray's first surface: the dearest choice over the pixel's
  // footprint on the plane of (o, n), where fp has points on it
  // (auto_footprint.hpp); the per-point choice elsewhere.
  light_sampling choice(const vec3& o, const vec3& n, const auto_footprint* fp) const {
    if (fp) {
      const int plane = fp->plane_of(o, n);
      if (plane >= 0)
        return fp->dearest(this, plane, [&](const vec3& q, const vec3& m) { return rule_.choose(q, m); });
    }
    return rule_.choose(o, n);
  }

  // Whether the choice pays for itself at the receivers rs (the surfaces an
  // image's pixels see, from its noise pilot): the mean over them of the
  // modelled gain of the choice, its own cost per light sample included,
  // over the cheapest strategy everywhere (auto_choice::score: the mean is
  // the first-order change of the image's error x time). Where it does not
  // (a light far from or small to every receiver, or one whose noise is
  // lost in the image's), the light is better sampled by the cheapest
  // strategy (cheapest()) everywhere, without a choice per light sample
  // (render/light.hpp: use_cheapest_where_choice_does_not_pay). The pilot sees
  // a path's first surfaces only; a light sample at a deeper bounce is
  // taken to gain as much.
  // Defined where v_rest comes from the image's noise (image_variance > 0,
  // the scores' first form); infinite otherwise (the table is kept).
  float table_gain(std::span<const auto_receiver> rs) const {
    if (!(params.image_variance > 0.0f)) return std::numeric_limits<float>::infinity();
    return table_gain(rs, receiver_models(rs));
  }
  // The same with the rule's models at the receivers given (receiver_models,
  // of this light with any params: a caller that weighs several params at
  // the same receivers evaluates the models once).
  float table_gain(std::span<const auto_receiver> rs, std::span<const auto_choice> models) const {
    if (!(params.image_variance > 0.0f)) return std::numeric_limits<float>::infinity();
    double sum = 0.0;
    for (std::size_t i = 0; i < rs.size(); ++i) sum += rule_.gain(models[i], rs[i].p, rs[i].n);
    return rs.empty() ? 0.0f : static_cast<float>(sum / double(rs.size()));
  }
  // The rule's model at each receiver (the fine rule's for planar lights,
  // the visible cap's for spheres): the light's and the points' alone.
  std::vector<auto_choice> receiver_models(std::span<const auto_receiver> rs) const {
    std::vector<auto_choice> models;
    models.reserve(rs.size());
    for (const auto_receiver& r : rs) models.push_back(rule_.model(r.p, r.n));
    return models;
  }
  // Whether the rule's tests before its fine model (the delta method, a
  // few ns, then the coarse model where that does not decide) take the
  // cheapest strategy at every receiver in rs (or rs is behind the light):
  // a screen before table_gain's models, which cost the fine rule per
  // receiver. A light it passes gains nothing at rs by the rule's own early
  // exits (its choice is area at every one of them), and is sampled by its
  // cheapest strategy everywhere (settle_auto_lights): in a mesh of many
  // small emissive triangles most are, and the pilot's settling then costs
  // a few ns to the coarse model per light and receiver instead of the fine
  // rule's and the table's (with the delta method alone, 11 193 of 14 994
  // small emitters went through the fine models, all to end on area
  // sampling: 0.53 s). Triangles only (false for rectangles, ellipses and
  // spheres, whose gate is table_gain's).
  bool cheapest_at_every(std::span<const auto_receiver> rs) const { return rule_.cheapest_at_every(rs); }
  // The same over the receivers in groups (built once for many lights).
  bool cheapest_at_every(const auto_receiver_groups& g) const { return rule_.cheapest_at_every(g); }
  // ... and as if its params were p (what with_params(p) would screen).
  bool cheapest_at_every(const auto_receiver_groups& g, const auto_params& p) const {
    return rule_.cheapest_at_every(g, p);
  }
  // The shape's cheapest strategy (area for planar lights, the cone for
  // spheres), whose sampler is the member area or solid_angle.
  light_sampling cheapest() const { return rule_.cheapest(); }
  // Its modelled cost per light sample (auto_costs, ns).
  float cheapest_cost() const { return rule_.cheapest_cost(); }
  // The light's own share of the image's noise V with its cheapest
  // strategy, as modelled (independent samples): the mean over the
  // receivers rs of D^2 v_cheapest / V (the rules' noise_share). Defined
  // where v_rest comes from the image's noise; 0 otherwise.
  float noise_share(std::span<const auto_receiver> rs) const {
    if (!(params.image_variance > 0.0f) || rs.empty()) return 0.0f;  // before the models' work
    return noise_share(receiver_models(rs));
  }
  // The same from the rule's models at the receivers (receiver_models).
  float noise_share(std::span<const auto_choice> models) const {
    if (!(params.image_variance > 0.0f) || models.empty()) return 0.0f;
    double sum = 0.0;
    for (const auto_choice& m : models) sum += rule_.noise_share(m);
    return static_cast<float>(sum / double(models.size()));
  }
  // The mean over the models' receivers of D^2 v_bsdf_mis / V (this
  // light's V, as noise_share): the BSDF samples' part of its noise with
  // mis (0 with nee, whose light samples are all of it).
  double mis_floor(std::span<const auto_choice> models) const {
    if (params.pdf_with_sample || models.empty()) return 0.0;
    double sum = 0.0;
    for (const auto_choice& m : models) {
      const double x = m.v_bsdf_mis() / m.rest_variance(params);
      sum += std::isfinite(x) ? x : 0.0;
    }
    return sum / double(models.size());
  }
  // Means over rs of the modelled noise and cost of the choice under p
  // (render/choice_gain_pilot.hpp; with the cheapest strategy everywhere
  // they are noise_share and cheapest_cost).
  struct totals {
    double noise = 0.0, cost = 0.0;
  };
  totals modelled_totals(std::span<const auto_receiver> rs, std::span<const auto_choice> models,
                         const auto_params& p) const {
    totals t;
    if (rs.empty()) return t;
    for (std::size_t i = 0; i < rs.size(); ++i) {
      const auto [noise, cost] = rule_.modelled(models[i], rs[i].p, rs[i].n, p);
      t.noise += std::isfinite(noise) ? noise : 0.0;
      t.cost += cost;
    }
    t.noise /= double(rs.size()), t.cost /= double(rs.size());
    return t;
  }
  // Its sample (the choice's, where the choice is the cheapest strategy).
  bool sample_cheapest(const vec3& o, vec2 u, light_sample& s) const {
    return cheapest() == light_sampling::area ? area.sample(o, u, s) : solid_angle.sample(o, u, s);
  }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const { return sample(o, n, u, s, nullptr); }
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const { return pdf(o, n, dir, nullptr); }
  // The same with the choice over a pixel's footprint fp (choice above).
  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s, const auto_footprint* fp) const {
    switch (choice(o, n, fp)) {
      case light_sampling::area: return area.sample(o, u, s);
      case light_sampling::solid_angle: return solid_angle.sample(o, u, s);
      default: return projected.sample(o, n, u, s);
    }
  }
  // A direction whose area density is 0 misses the light (or o is behind
  // it): every strategy's density is 0 there, and no choice is made (most
  // directions a BSDF samples miss a light).
  float pdf(const vec3& o, const vec3& n, const vec3& dir, const auto_footprint* fp) const {
    const float pa = area.pdf(o, dir);
    if (!(pa > 0.0f)) return 0.0f;
    switch (choice(o, n, fp)) {
      case light_sampling::area: return pa;
      case light_sampling::solid_angle: return solid_angle.pdf(o, dir);
      default: return projected.pdf(o, n, dir);
    }
  }

 private:
  using rule_type = typename auto_rule_of<Shape>::type;
  template <class T>
  static T make(const Shape& s, bool back_side) {
    if constexpr (std::is_same_v<Shape, triangle>)
      return T(s, back_side);
    else
      return T{s};
  }
  static rule_type make_rule(const Shape& s, const auto_params& p, bool back_side) {
    if constexpr (std::is_same_v<Shape, triangle>)
      return rule_type(s, p, back_side);
    else
      return rule_type(s, p);
  }
  rule_type rule_;
};

using rect_auto_sampler =
    auto_sampler<rect, rect_area_sampler, rect_solid_angle_sampler, rect_projected_solid_angle_sampler>;
using ellipse_auto_sampler =
    auto_sampler<ellipse, ellipse_area_sampler, ellipse_solid_angle_sampler, ellipse_projected_solid_angle_sampler>;
using sphere_auto_sampler =
    auto_sampler<sphere, sphere_area_sampler, sphere_cone_sampler, sphere_projected_solid_angle_sampler>;
// Triangles: the rule per cell of a table without the symmetry; `back` for
// the back side of a two-sided light.
using triangle_auto_sampler = auto_sampler<triangle, triangle_area_sampler, triangle_solid_angle_sampler,
                                           triangle_projected_solid_angle_sampler>;

}  // namespace mcrt
