#pragma once
// Pearson's chi-square goodness-of-fit test of a direction sampler against
// the density it claims, after Mitsuba 3's ChiSquareTest
// (src/python/python/chi2.py, Jakob et al.): histogram the samples on a grid,
// integrate the pdf over the same grid, pool cells whose expected count is
// below 5, and reject when the p-value is below the significance level.
//
// Domain and grid. Directions are binned on a spherical cap
//   {d : 1 - dot(d, axis) <= cap_one_minus_cos},  cap_one_minus_cos in (0, 2]
// (2 is the whole sphere), on a grid uniform in u = 1 - cos(theta) and in
// phi around the axis. Since d(omega) = du dphi, every cell has the same solid
// angle. u is computed as |d - axis|^2 / 2 in double, which has no
// cancellation, so caps down to ~1e-9 sr are resolved; a direction given in
// float carries its own rounding (~6e-8 rad per component), which is the
// limit for tiny caps about an axis that is not a coordinate axis.
//
// Expected counts are sample_count times the integral of the pdf over each
// cell, computed in double by adaptive quadrature (detail::cell_integrator):
// a 5 x 5 trapezoidal rule on the cell is compared with the same rule on its
// four quarters, and quarters are refined until the two agree to 1e-3 of the
// cell's mass; quarters across which the pdf jumps (a light's edge) are
// refined to 1/32 of a cell regardless, and quarters whose nodes all see
// pdf 0 although samples fell there (the light is a sliver thinner than the
// node spacing) are refined towards those samples. The pdf is evaluated
// only at interior points of cells, never on the grid lines.
//
// Significance. The whole test suite is held to a 1% family-wise false
// rejection rate: with at most chi2_max_tests_in_suite (= 256) chi-square
// tests in the suite, the Sidak correction gives each test the level
//   alpha = 1 - (1 - 0.01)^(1/256) ~= 3.93e-5.
// A test also fails, whatever the p-value, when sample() returns false, when
// a sample is not a finite direction, falls outside the cap or has pdf 0 (or
// non-finite) in its own direction, when the pdf is negative or not finite
// somewhere on the cap, or when the pdf's integral over the cap differs from
// 1 by more than chi2_mass_tolerance.
//
// The p-value is the chi-square survival function Q(dof/2, chi2/2), the
// regularized upper incomplete gamma function, by Boost.Math's gamma_q.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "mcrt/core/math.hpp"
#include "mcrt/core/rng.hpp"

#include <boost/math/special_functions/gamma.hpp>

namespace mcrt::test {

// Upper bound on the number of chi-square tests in the whole suite; the
// Sidak correction below is computed for this many tests.
inline constexpr int chi2_max_tests_in_suite = 256;
// Family-wise significance level of the suite.
inline constexpr double chi2_family_significance = 0.01;
// Mitsuba's pooling threshold: cells expecting fewer samples are merged.
inline constexpr double chi2_pool_threshold = 5.0;
// Allowed |integral of the pdf over the cap - 1|.
inline constexpr double chi2_mass_tolerance = 1e-3;

// Per-test level 1 - (1 - 0.01)^(1/256), computed without cancellation.
inline double chi2_per_test_significance() {
  return -std::expm1(std::log1p(-chi2_family_significance) / chi2_max_tests_in_suite);
}

struct chi2_options {
  std::size_t sample_count = 1'000'000;
  int res_theta = 0, res_phi = 0;  // 0: chosen automatically from sample_count
  std::uint64_t seed = 1;
  // Fraction of the samples allowed to have pdf 0 in their own direction
  // before the test fails; 0 by default. A float direction is only within
  // ~1e-7 rad of the exact one, so near the rim of a distant light it may
  // miss the light; see rim_miss_fraction(). Such samples are left out of
  // the histogram and counted in the report.
  double zero_pdf_fraction = 0.0;
  // chi2_test_unit_square: relative tolerance of the adaptive Gauss rule that
  // integrates the density over each cell. A density computed from a float
  // pdf() carries ~1e-7 relative rounding noise, which no rule can integrate
  // below: at a tighter tolerance the rule subdivides every cell to its depth
  // limit (4^8 sub-cells), which costs hours and no accuracy. Expected
  // counts need only ~1e-5 relative accuracy for a chi-square test of 1e6
  // samples (the statistic's own noise is ~1e-3 of it).
  double quadrature_tolerance = 1e-7;
  // chi2_test_unit_square: depth limit of that rule's subdivision (4^depth
  // sub-cells at most per cell). A density with a jump inside the square
  // (float directions that round off the light's rim get pdf 0) refines along
  // the jump to this depth in every cell it crosses.
  int quadrature_max_depth = 8;
};

struct chi2_result {
  bool passed = false;  // p_value >= per-test significance, no sample outside the cap or at pdf 0, pdf mass ~1
  double p_value = 0, statistic = 0;
  int dof = 0;
  double pdf_integral = 0;  // integral of pdf over the cap (should be ~1)
  std::string report;       // human readable: why it failed, worst cells (observed vs expected)
};

// P(X >= statistic) for X chi-square distributed with dof degrees of
// freedom; defined below.
inline double chi2_survival(double statistic, int dof);

namespace detail {

// Orthonormal frame around a unit axis in double (Duff et al. 2017).
struct cap_frame {
  dvec3 t, b, a;
  explicit cap_frame(const dvec3& axis) : a(axis) {
    const double sign = std::copysign(1.0, axis.z);
    const double p = -1.0 / (sign + axis.z);
    const double q = axis.x * axis.y * p;
    t = dvec3(1.0 + sign * axis.x * axis.x * p, sign * q, -sign * axis.x);
    b = dvec3(q, sign + axis.y * axis.y * p, -axis.y);
  }
  // Unit direction with 1 - cos(theta) = u, azimuth phi.
  dvec3 direction(double u, double phi) const {
    const double sin_theta = std::sqrt(std::max(u * (2.0 - u), 0.0));
    return sin_theta * (std::cos(phi) * t + std::sin(phi) * b) + (1.0 - u) * a;
  }
  // Azimuth in [0, 2 pi) of a unit direction.
  double azimuth(const dvec3& d) const {
    const double phi = std::atan2(glm::dot(d, b), glm::dot(d, t));
    return phi < 0.0 ? phi + 2.0 * std::numbers::pi : phi;
  }
};

// Calls a pdf that takes either a vec3 or a dvec3.
template <class Pdf, class V>
double call_pdf(Pdf& pdf, const V& d) {
  if constexpr (std::is_invocable_v<Pdf&, const V&>) {
    return static_cast<double>(pdf(d));
  } else if constexpr (std::is_invocable_v<Pdf&, const dvec3&>) {
    return static_cast<double>(pdf(dvec3(d)));
  } else {
    return static_cast<double>(pdf(vec3(d)));
  }
}

// A sample's position in the (1 - cos theta, phi) coordinates of the grid.
struct grid_point {
  double u, phi;
};

// Adaptive integration of the pdf over cells [u0,u1] x [p0,p1] of the
// (1 - cos theta, phi) grid, i.e. over solid angle (d omega = du dphi).
//
// The basic rule is the trapezoidal rule on 5 x 5 nodes in (sqrt(1 - cos
// theta), phi). A (sub)cell is split in four and its quarters integrated
// again when
//   - the quarters' sum differs from the cell's rule by more than the
//     tolerance (halved at each level), up to depth 10; once they agree,
//     the sum is Richardson-extrapolated;
//   - a quarter's nodes see both 0 and non-zero values, or values more than
//     4 times apart: a jump of the pdf (a light's edge) runs through it.
//     Such quarters are refined to depth 5 whatever the first test says,
//     since two node rules can agree by chance on a step, most often when
//     the edge is parallel to a grid line (a cone seen about its axis);
//     nodes next to the sides make sure that a jump is seen by every
//     quarter it crosses;
//   - a quarter's nodes are all 0 but it holds samples of the histogram,
//     whose pdf is known to be non-zero: the support is a sliver thinner
//     than the node spacing (a grazing or thin light crossing the pole of
//     the cap, where cells are thin wedges). It is followed down to depth
//     20, and once found refined by the first test for 5 more levels, to 1%
//     of its own mass.
// Positions of the samples are given per cell for the last test and
// reordered in place.
template <class Pdf>
class cell_integrator {
 public:
  cell_integrator(Pdf& pdf, const cap_frame& frame) : pdf_(pdf), frame_(frame) {}

  // Integral over the cell; rel_tol relative to the cell's own mass,
  // abs_tol an absolute floor (probability units); [first, last) are the
  // samples that fell in the cell.
  double integrate(double u0, double u1, double p0, double p1, double rel_tol, double abs_tol, grid_point* first,
                   grid_point* last) {
    const double t0 = std::sqrt(u0), t1 = std::sqrt(u1);
    const node_rule coarse = rule(t0, t1, p0, p1);
    const double tol = std::max(rel_tol * std::abs(coarse.value), abs_tol);
    return refine({t0, t1, p0, p1}, coarse, tol, 0, max_depth, false, first, last);
  }

  bool bad_value() const { return bad_; }
  dvec3 bad_direction() const { return bad_dir_; }
  double bad_pdf() const { return bad_pdf_; }
  std::size_t evaluations() const { return evals_; }

 private:
  static constexpr int m = 4;                 // intervals per axis of the basic rule
  static constexpr double edge_inset = 1e-6;  // relative distance of the outer nodes from the sides
  static constexpr int max_depth = 10;        // tolerance-driven refinement
  static constexpr int jump_depth = 5;        // refinement of quarters with a jump
  static constexpr int sliver_depth = 20;     // refinement towards samples in empty quarters
  static constexpr int sliver_extra_depth = 5;  // further refinement of a sliver once found
  static constexpr double sliver_rel_tol = 1e-2;
  static constexpr double jump_ratio = 4.0;

  struct box {
    double t0, t1, p0, p1;  // t = sqrt(1 - cos theta)
  };
  struct node_rule {
    double value = 0.0;
    bool jump = false;
  };

  double eval(const dvec3& d) {
    ++evals_;
    const double p = call_pdf(pdf_, d);
    if (!std::isfinite(p) || p < 0.0) {
      if (!bad_) {
        bad_ = true;
        bad_dir_ = d;
        bad_pdf_ = p;
      }
      return 0.0;
    }
    return p;
  }

  // Trapezoidal rule on (m + 1) x (m + 1) nodes that reach to within
  // edge_inset of the sides (as Mitsuba's tabulate_pdf): a jump that crosses
  // the (sub)cell separates some of its nodes, and cannot hide between a
  // side and the first node.
  // The rule works in t = sqrt(1 - cos theta) (so du = 2 t dt), which is
  // ~theta / sqrt(2): near the pole of the cap, where cells are thin wedges,
  // a feature at angular distance theta from the pole sits at u ~ theta^2,
  // squeezed towards u = 0, but at t ~ theta.
  node_rule rule(double t0, double t1, double p0, double p1) {
    constexpr int k = m + 1;
    double sin_t[k], cos_u[k], cos_p[k], sin_p[k], wt[k], wp[k];
    for (int i = 0; i < k; ++i) {
      const double x = edge_inset + (1.0 - 2.0 * edge_inset) * i / m;
      const double t = t0 + x * (t1 - t0), u = t * t;
      sin_t[i] = std::sqrt(std::max(u * (2.0 - u), 0.0));
      cos_u[i] = 1.0 - u;
      const double phi = p0 + x * (p1 - p0);
      cos_p[i] = std::cos(phi);
      sin_p[i] = std::sin(phi);
      wp[i] = (i == 0 || i == m) ? 0.5 : 1.0;
      wt[i] = wp[i] * 2.0 * t;
    }
    double sum = 0.0, lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (int j = 0; j < k; ++j) {
      const dvec3 radial = cos_p[j] * frame_.t + sin_p[j] * frame_.b;
      double row = 0.0;
      for (int i = 0; i < k; ++i) {
        const double v = eval(sin_t[i] * radial + cos_u[i] * frame_.a);
        row += wt[i] * v;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      sum += wp[j] * row;
    }
    return {sum * (t1 - t0) * (p1 - p0) / (m * m), hi > jump_ratio * lo};
  }

  double refine(const box& b, const node_rule& coarse, double tol, int depth, int depth_limit, bool sliver,
                grid_point* first, grid_point* last) {
    const double tm = 0.5 * (b.t0 + b.t1), pm = 0.5 * (b.p0 + b.p1);
    const box child[4] = {{b.t0, tm, b.p0, pm}, {tm, b.t1, b.p0, pm}, {b.t0, tm, pm, b.p1}, {tm, b.t1, pm, b.p1}};
    node_rule q[4];
    double fine = 0.0;
    for (int i = 0; i < 4; ++i) {
      q[i] = rule(child[i].t0, child[i].t1, child[i].p0, child[i].p1);
      fine += q[i].value;
    }
    // Samples per quarter, in the order of child[].
    const double um = tm * tm;
    grid_point* const mid_p = std::partition(first, last, [&](const grid_point& g) { return g.phi < pm; });
    grid_point* const split[5] = {first,
                                  std::partition(first, mid_p, [&](const grid_point& g) { return g.u < um; }),
                                  mid_p,
                                  std::partition(mid_p, last, [&](const grid_point& g) { return g.u < um; }),
                                  last};
    // Below a sliver found by following samples, the tolerance is relative
    // to the sliver's own mass: 1% of a piece that the regular rule missed.
    const double tol_here = sliver ? std::max(tol, sliver_rel_tol * std::abs(fine)) : tol;
    const bool converged = depth >= depth_limit || std::abs(fine - coarse.value) <= tol_here;
    const auto needs_sliver = [&](int i) {
      return q[i].value == 0.0 && split[i] != split[i + 1] && depth < sliver_depth;
    };
    const auto needs_jump = [&](int i) { return q[i].jump && depth < jump_depth; };
    if (converged && !needs_sliver(0) && !needs_sliver(1) && !needs_sliver(2) && !needs_sliver(3) &&
        !needs_jump(0) && !needs_jump(1) && !needs_jump(2) && !needs_jump(3)) {
      // Richardson extrapolation of the trapezoidal rule's h^2 error: the
      // errors of a convex or concave pdf (t^3 / h for a grazing light)
      // all have one sign and would otherwise add up over the cap.
      return fine + (fine - coarse.value) / 3.0;
    }
    double sum = 0.0;
    for (int i = 0; i < 4; ++i) {
      if (needs_sliver(i)) {
        sum += refine(child[i], q[i], 0.5 * tol_here, depth + 1, depth + 1 + sliver_extra_depth, true, split[i],
                      split[i + 1]);
      } else if (!converged || needs_jump(i)) {
        sum += refine(child[i], q[i], 0.5 * tol_here, depth + 1, depth_limit, sliver, split[i], split[i + 1]);
      } else {
        sum += q[i].value;
      }
    }
    return sum;
  }

  Pdf& pdf_;
  const cap_frame& frame_;
  bool bad_ = false;
  dvec3 bad_dir_{0.0};
  double bad_pdf_ = 0.0;
  std::size_t evals_ = 0;
};

// Pearson's statistic with Mitsuba's pooling (math::chi2): cells in
// increasing order of expected count; cells below chi2_pool_threshold are
// accumulated until the pool reaches it. Empty cells that expect nothing are
// skipped. bins is the number of terms of the statistic.
struct pool_info {
  std::size_t pooled_in = 0, pooled_out = 0, zero_expected_hit = 0;
};
// Sets res.statistic, res.dof (bins - 1) and res.p_value.
inline pool_info pooled_statistic(const std::vector<double>& observed, const std::vector<double>& expected,
                                  chi2_result& res) {
  const std::size_t cells = observed.size();
  std::vector<std::size_t> order(cells);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t i, std::size_t j) { return expected[i] < expected[j]; });
  double stat = 0.0, pool_obs = 0.0, pool_exp = 0.0;
  int bins = 0;
  pool_info pi;
  std::size_t& pooled_in = pi.pooled_in;
  std::size_t& pooled_out = pi.pooled_out;
  std::size_t& zero_expected_hit = pi.zero_expected_hit;
  for (const std::size_t c : order) {
    const double o = observed[c], e = expected[c];
    if (e == 0.0 && o == 0.0) continue;
    if (e == 0.0) ++zero_expected_hit;
    if (e < chi2_pool_threshold || pool_exp > 0.0 || pool_obs > 0.0) {
      pool_obs += o;
      pool_exp += e;
      ++pooled_in;
      if (pool_exp >= chi2_pool_threshold) {
        stat += sqr(pool_obs - pool_exp) / pool_exp;
        pool_obs = pool_exp = 0.0;
        ++pooled_out;
        ++bins;
      }
    } else {
      stat += sqr(o - e) / e;
      ++bins;
    }
  }
  if (pool_exp > 0.0 && bins == 0) {  // everything expects fewer than 5 samples
    stat += sqr(pool_obs - pool_exp) / pool_exp;
    ++bins;
  }
  res.statistic = stat;
  res.dof = bins - 1;
  res.p_value = res.dof >= 1 ? chi2_survival(stat, res.dof) : 0.0;
  return pi;
}

// The failures every test shares: sample() returning false, a density whose
// integral over the domain is not 1, too few degrees of freedom, a p-value
// below alpha. Appends one line per failure; false if any.
inline bool shared_verdict(std::ostringstream& rep, const chi2_result& res, std::size_t n_false,
                           std::size_t sample_count, const char* domain, double alpha) {
  bool ok = true;
  if (n_false > 0) {
    ok = false;
    rep << "FAIL: sample() returned false for " << n_false << " of " << sample_count << " samples\n";
  }
  if (!(std::abs(res.pdf_integral - 1.0) <= chi2_mass_tolerance)) {
    ok = false;
    rep << "FAIL: the density integrates to " << res.pdf_integral << " over " << domain << ", not 1\n";
  }
  if (res.dof < 1) {
    ok = false;
    rep << "FAIL: too few degrees of freedom (" << res.dof << ")\n";
  }
  if (!(res.p_value >= alpha)) {
    ok = false;
    rep << "FAIL: null hypothesis rejected, p-value " << res.p_value << " < " << alpha << "\n";
  }
  return ok;
}

inline void report_pooling(std::ostringstream& rep, const pool_info& pi) {
  if (pi.pooled_in > 0)
    rep << "pooled " << pi.pooled_in << " cells expecting < " << chi2_pool_threshold << " samples into "
        << pi.pooled_out << " bins\n";
  if (pi.zero_expected_hit > 0)
    rep << pi.zero_expected_hit << " cells with integrated density 0 received samples (pooled)\n";
}

inline std::string format_direction(const dvec3& d) {
  std::ostringstream s;
  s.precision(9);
  s << "(" << d.x << ", " << d.y << ", " << d.z << ")";
  return s.str();
}

}  // namespace detail

// Regularized upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a).
inline double regularized_gamma_q(double a, double x) { return boost::math::gamma_q(a, x); }

// P(X >= statistic) for X chi-square distributed with dof degrees of freedom.
inline double chi2_survival(double statistic, int dof) {
  return regularized_gamma_q(0.5 * dof, 0.5 * std::max(statistic, 0.0));
}

// Grid resolution chosen from the sample count: about 100 samples per cell
// for a uniform density, odd counts (as Mitsuba) so that no grid line falls
// on a symmetry plane of the cap, twice as many cells in phi as in u.
inline void chi2_resolution(std::size_t sample_count, int& res_theta, int& res_phi) {
  if (res_theta <= 0 && res_phi <= 0) {
    const int n = static_cast<int>(std::lround(std::sqrt(static_cast<double>(sample_count) / 200.0)));
    res_theta = std::clamp(n | 1, 3, 1001);
  } else if (res_theta <= 0) {
    res_theta = std::max(1, res_phi / 2);
  }
  if (res_phi <= 0) res_phi = 2 * res_theta + 1;
}

// Fraction of samples that may miss a light because their direction was
// rounded to float, for a light that fills a cap of 1 - cos theta =
// cap_one_minus_cos: the band within eps = 2^-20 rad (a few roundings of the
// direction and of the hit point, 2^-24 each) of the rim of a disk of
// angular radius theta, 2 eps / theta of it. Significant only for distant
// lights (theta ~ 1e-4 gives ~2e-2).
inline double rim_miss_fraction(double cap_one_minus_cos) {
  const double theta = 2.0 * std::asin(std::min(1.0, std::sqrt(0.5 * cap_one_minus_cos)));
  return 2.0 * 0x1p-20 / theta;
}

// Bins directions on an equal-solid-angle grid over the spherical cap
// {d : 1 - dot(d, axis) <= cap_one_minus_cos} and tests them against pdf
// with Pearson's chi-square test (see the top of this header).
//   sample: bool(pcg32& rng, vec3& dir), draws one unit direction;
//   pdf:    double(const vec3& dir) or double(const dvec3& dir), density
//           per unit solid angle. At a sample, pdf receives the direction
//           exactly as sample() returned it; on the integration grid, unit
//           directions computed in double (rounded if pdf takes a vec3).
template <class Sample, class Pdf>
chi2_result chi2_test_directions(Sample&& sample, Pdf&& pdf, const dvec3& axis, double cap_one_minus_cos,
                                 const chi2_options& opt = {}) {
  using std::numbers::pi;
  chi2_result res;
  std::ostringstream rep;
  rep.precision(6);

  const double axis_len = glm::length(axis);
  if (!(cap_one_minus_cos > 0.0 && cap_one_minus_cos <= 2.0) || !(axis_len > 0.0) || !std::isfinite(axis_len) ||
      opt.sample_count == 0) {
    rep << "FAIL: invalid arguments (cap_one_minus_cos = " << cap_one_minus_cos << ", |axis| = " << axis_len
        << ", sample_count = " << opt.sample_count << ")\n";
    res.report = rep.str();
    return res;
  }
  const dvec3 a = axis / axis_len;
  const double cap = cap_one_minus_cos;
  const bool whole_sphere = cap >= 2.0;
  const detail::cap_frame frame(a);

  int nt = opt.res_theta, np = opt.res_phi;
  chi2_resolution(opt.sample_count, nt, np);
  const std::size_t cells = static_cast<std::size_t>(nt) * static_cast<std::size_t>(np);
  const double du = cap / nt, dphi = 2.0 * pi / np;

  // ---- histogram of the samples
  std::vector<double> observed(cells, 0.0);
  std::vector<detail::grid_point> positions;  // of the binned samples
  std::vector<std::uint32_t> cell_of;
  positions.reserve(opt.sample_count);
  cell_of.reserve(opt.sample_count);
  pcg32 rng(opt.seed, 0x5851f42d4c957f2dULL);
  std::size_t n_false = 0, n_nonfinite = 0, n_outside = 0, n_zero_pdf = 0;
  dvec3 first_outside{0.0}, first_zero{0.0}, first_nonfinite{0.0};
  double first_outside_u = 0.0, first_zero_pdf = 0.0;
  for (std::size_t i = 0; i < opt.sample_count; ++i) {
    vec3 d(0.0f);
    if (!sample(rng, d)) {
      ++n_false;
      continue;
    }
    dvec3 dd(d);
    const double len = glm::length(dd);
    if (!std::isfinite(len) || !(len > 0.0)) {
      if (n_nonfinite++ == 0) first_nonfinite = dd;
      continue;
    }
    dd /= len;
    const double u = 0.5 * glm::dot(dd - a, dd - a);  // 1 - cos theta, cancellation-free
    if (!whole_sphere && !(u <= cap)) {
      if (n_outside++ == 0) {
        first_outside = dd;
        first_outside_u = u;
      }
      continue;
    }
    const double p = detail::call_pdf(pdf, d);
    if (!(p > 0.0) || !std::isfinite(p)) {
      if (n_zero_pdf++ == 0) {
        first_zero = dd;
        first_zero_pdf = p;
      }
      continue;
    }
    const double phi = frame.azimuth(dd);
    const int iu = std::min(static_cast<int>(u / du), nt - 1);
    const int ip = std::min(static_cast<int>(phi / dphi), np - 1);
    const std::size_t cell = static_cast<std::size_t>(iu) * np + ip;
    observed[cell] += 1.0;
    positions.push_back({u, phi});
    cell_of.push_back(static_cast<std::uint32_t>(cell));
  }
  // Positions grouped by cell (counting sort): cell c owns
  // points[start[c], start[c + 1]).
  std::vector<std::size_t> start(cells + 1, 0);
  for (const std::uint32_t c : cell_of) ++start[c + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<detail::grid_point> points(positions.size());
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < positions.size(); ++i) points[next[cell_of[i]]++] = positions[i];
  }
  positions = {};
  cell_of = {};

  // ---- expected counts
  std::vector<double> expected(cells, 0.0);
  detail::cell_integrator<std::remove_reference_t<Pdf>> integ(pdf, frame);
  const double abs_floor = 1e-4 / static_cast<double>(cells);
  double mass = 0.0;
  for (int iu = 0; iu < nt; ++iu) {
    const double u0 = iu * du, u1 = (iu + 1 == nt) ? cap : (iu + 1) * du;
    for (int ip = 0; ip < np; ++ip) {
      const double p0 = ip * dphi, p1 = (ip + 1 == np) ? 2.0 * pi : (ip + 1) * dphi;
      const std::size_t c = static_cast<std::size_t>(iu) * np + ip;
      const double m = integ.integrate(u0, u1, p0, p1, 1e-3, abs_floor, points.data() + start[c],
                                       points.data() + start[c + 1]);
      mass += m;
      expected[c] = m * static_cast<double>(opt.sample_count);
    }
  }
  res.pdf_integral = mass;

  // ---- pooling and the statistic
  const detail::pool_info pool = detail::pooled_statistic(observed, expected, res);
  const double alpha = chi2_per_test_significance();

  // ---- verdict
  bool ok = detail::shared_verdict(rep, res, n_false, opt.sample_count, "the cap", alpha);
  if (n_nonfinite > 0) {
    ok = false;
    rep << "FAIL: " << n_nonfinite << " samples are not finite nonzero directions, first "
        << detail::format_direction(first_nonfinite) << "\n";
  }
  if (n_outside > 0) {
    ok = false;
    rep << "FAIL: " << n_outside << " samples fall outside the cap (1 - cos <= " << cap << "), first "
        << detail::format_direction(first_outside) << " with 1 - cos = " << first_outside_u << "\n";
  }
  if (static_cast<double>(n_zero_pdf) > opt.zero_pdf_fraction * static_cast<double>(opt.sample_count)) {
    ok = false;
    rep << "FAIL: " << n_zero_pdf << " samples have pdf 0 or non-finite in their own direction, first "
        << detail::format_direction(first_zero) << " with pdf " << first_zero_pdf << "\n";
  }
  if (integ.bad_value()) {
    ok = false;
    rep << "FAIL: pdf is negative or not finite at " << detail::format_direction(integ.bad_direction()) << ": "
        << integ.bad_pdf() << "\n";
  }
  res.passed = ok;

  rep << (ok ? "passed" : "failed") << ": chi2 = " << res.statistic << ", dof = " << res.dof << ", p-value = " << res.p_value
      << " (level " << alpha << " = 1% family-wise over " << chi2_max_tests_in_suite << " tests, Sidak)\n";
  rep << "grid " << nt << " (1 - cos) x " << np << " (phi) over the cap 1 - cos <= " << cap << " about "
      << detail::format_direction(a) << ", " << opt.sample_count << " samples, pdf integral " << mass << " ("
      << integ.evaluations() << " pdf evaluations)\n";
  if (n_zero_pdf > 0 && ok)
    rep << n_zero_pdf << " samples with pdf 0 in their own direction, within the allowed fraction "
        << opt.zero_pdf_fraction << ", first " << detail::format_direction(first_zero) << "\n";
  detail::report_pooling(rep, pool);

  // Worst unpooled cells by their share of the statistic.
  std::vector<std::size_t> worst;
  for (std::size_t c = 0; c < cells; ++c)
    if (expected[c] >= chi2_pool_threshold) worst.push_back(c);
  const auto contribution = [&](std::size_t c) { return sqr(observed[c] - expected[c]) / expected[c]; };
  const std::size_t shown = std::min<std::size_t>(worst.size(), 6);
  std::partial_sort(worst.begin(), worst.begin() + static_cast<std::ptrdiff_t>(shown), worst.end(),
                    [&](std::size_t i, std::size_t j) { return contribution(i) > contribution(j); });
  if (shown > 0) rep << "worst cells (1 - cos range, phi range in degrees: observed vs expected, chi2 term):\n";
  for (std::size_t k = 0; k < shown; ++k) {
    const std::size_t c = worst[k];
    const auto iu = static_cast<int>(c / static_cast<std::size_t>(np)), ip = static_cast<int>(c % np);
    rep << "  [" << iu * du << ", " << (iu + 1) * du << "] x [" << ip * dphi * 180.0 / pi << ", "
        << (ip + 1) * dphi * 180.0 / pi << "]: " << observed[c] << " vs " << expected[c] << ", " << contribution(c)
        << "\n";
  }
  res.report = rep.str();
  return res;
}

// The same test on the light's own parameter square instead of directions:
// for slivers (grazing views, thin ellipses) and tiny lights, whose cones are
// far narrower than any cell of a direction grid can resolve, while the
// light itself, parametrized by its uniform-area map, is a plain square.
//   sample:  bool(pcg32& rng, dvec2& uv), the unit-square coordinates (by
//            the light's area map) of the point a sample hits, computed in
//            double from the sampler's double internals;
//   density: double(const dvec2& uv), the density the sampler claims, per
//            unit of uv: its pdf per unit solid angle times the solid angle
//            per unit uv (A |cos| / d^2 for an area-uniform map).
// Expected counts by tensor Gauss-Legendre (8 x 8 nodes) on each cell,
// refined into quarters until two levels agree to 1e-7 of the cell's mass
// (the density is smooth on the light away from the observer's foot, which
// the configurations keep at a distance). The density's integral over the
// square must be 1 within chi2_mass_tolerance: with the solid angle
// computed by the sampler, this checks that solid angle too. Same pooling,
// significance and failure rules as chi2_test_directions.
template <class Sample, class Density>
chi2_result chi2_test_unit_square(Sample&& sample, Density&& density, const chi2_options& opt = {}) {
  chi2_result res;
  std::ostringstream rep;
  rep.precision(6);
  int n = opt.res_theta > 0 ? opt.res_theta
                            : std::clamp(static_cast<int>(std::lround(std::sqrt(opt.sample_count / 100.0))) | 1, 3, 1001);
  const std::size_t cells = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  const double du = 1.0 / n;

  std::vector<double> observed(cells, 0.0);
  pcg32 rng(opt.seed, 0x5851f42d4c957f2dULL);
  std::size_t n_false = 0, n_outside = 0;
  dvec2 first_outside{0.0};
  for (std::size_t i = 0; i < opt.sample_count; ++i) {
    dvec2 uv;
    if (!sample(rng, uv)) {
      ++n_false;
      continue;
    }
    if (!(uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0)) {
      if (n_outside++ == 0) first_outside = uv;
      continue;
    }
    const int iu = std::min(static_cast<int>(uv.x * n), n - 1), iv = std::min(static_cast<int>(uv.y * n), n - 1);
    observed[static_cast<std::size_t>(iu) * n + iv] += 1.0;
  }

  // 8-point Gauss-Legendre nodes and weights on [-1, 1].
  static constexpr double gx[4] = {0.18343464249564980494, 0.52553240991632898582, 0.79666647741362673959,
                                   0.96028985649753623168};
  static constexpr double gw[4] = {0.36268378337836198297, 0.31370664587788728734, 0.22238103445337447054,
                                   0.10122853629037625915};
  bool bad = false;
  dvec2 bad_at{0.0};
  double bad_value = 0.0;
  const auto rule = [&](double u0, double u1, double v0, double v1) {
    const double hu = 0.5 * (u1 - u0), hv = 0.5 * (v1 - v0), cu = u0 + hu, cv = v0 + hv;
    double sum = 0.0;
    for (int i = 0; i < 8; ++i) {
      const double xu = cu + (i < 4 ? -gx[i] : gx[i - 4]) * hu, wu = gw[i < 4 ? i : i - 4];
      for (int j = 0; j < 8; ++j) {
        const double xv = cv + (j < 4 ? -gx[j] : gx[j - 4]) * hv, wv = gw[j < 4 ? j : j - 4];
        const double f = density(dvec2(xu, xv));
        if (!(f >= 0.0) || !std::isfinite(f)) {
          if (!bad) bad_at = {xu, xv}, bad_value = f;
          bad = true;
          continue;
        }
        sum += wu * wv * f;
      }
    }
    return sum * hu * hv;
  };
  const auto adaptive = [&](auto&& self, double u0, double u1, double v0, double v1, double whole, int depth) -> double {
    const double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
    const double q[4] = {rule(u0, um, v0, vm), rule(um, u1, v0, vm), rule(u0, um, vm, v1), rule(um, u1, vm, v1)};
    const double parts = q[0] + q[1] + q[2] + q[3];
    if (depth >= opt.quadrature_max_depth || std::abs(parts - whole) <= opt.quadrature_tolerance * std::abs(parts) + 1e-16) return parts;
    return self(self, u0, um, v0, vm, q[0], depth + 1) + self(self, um, u1, v0, vm, q[1], depth + 1) +
           self(self, u0, um, vm, v1, q[2], depth + 1) + self(self, um, u1, vm, v1, q[3], depth + 1);
  };
  std::vector<double> expected(cells, 0.0);
  double mass = 0.0;
  for (int iu = 0; iu < n; ++iu)
    for (int iv = 0; iv < n; ++iv) {
      const double u0 = iu * du, u1 = (iu + 1) * du, v0 = iv * du, v1 = (iv + 1) * du;
      const double m = adaptive(adaptive, u0, u1, v0, v1, rule(u0, u1, v0, v1), 0);
      mass += m;
      expected[static_cast<std::size_t>(iu) * n + iv] = m * static_cast<double>(opt.sample_count);
    }
  res.pdf_integral = mass;

  const detail::pool_info pool = detail::pooled_statistic(observed, expected, res);
  const double alpha = chi2_per_test_significance();

  bool ok = detail::shared_verdict(rep, res, n_false, opt.sample_count, "the square", alpha);
  if (n_outside > 0) {
    ok = false;
    rep << "FAIL: " << n_outside << " samples fall outside the unit square, first (" << first_outside.x << ", "
        << first_outside.y << ")\n";
  }
  if (bad) {
    ok = false;
    rep << "FAIL: density negative or not finite at (" << bad_at.x << ", " << bad_at.y << "): " << bad_value << "\n";
  }
  res.passed = ok;
  rep << (ok ? "passed" : "failed") << ": chi2 = " << res.statistic << ", dof = " << res.dof << ", p-value = " << res.p_value
      << " (level " << alpha << "), grid " << n << " x " << n << " on the light's square, " << opt.sample_count
      << " samples, density integral " << mass << "\n";
  detail::report_pooling(rep, pool);
  res.report = rep.str();
  return res;
}

}  // namespace mcrt::test
