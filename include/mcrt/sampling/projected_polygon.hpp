#pragma once
// Sampling a convex spherical polygon that lies above a receiver's horizon in
// proportion to projected solid angle: density cos(theta) / Omega_proj per
// unit SOLID ANGLE (theta from the receiver's unit normal, the z axis here),
// i.e. uniform density 1 / Omega_proj per unit PROJECTED solid angle
// (d omega_perp = cos(theta) d omega). After Peters 2021, "BRDF Importance
// Sampling for Polygonal Lights" (ACM TOG 40(4), SIGGRAPH 2021), below
// [P21]: its projected-solid-angle sampler, with the inversion replaced by a
// safeguarded Newton iteration in double. The light strategy for rectangles,
// which clips the rectangle at the horizon and fills this structure, is in
// projected_rectangle.hpp. The one for triangles, projected_triangle.hpp,
// takes the closed forms of Omega_proj on the clipped polygon, the choice
// between them, the area fallback and the set-up of the map from
// projected_light_polygon at the end of this header, which evaluates them
// as projected_rectangle does.
//
// Geometry [P21]. Project the hemisphere orthographically onto the unit disk
// of the tangent plane: the projected solid angle of a set of directions is
// the area of its projection, and a point uniform in that area, lifted back
// to the hemisphere, is distributed with density cos(theta) / Omega_proj.
// An edge of the polygon, an arc of the great circle with unit normal m,
// projects onto an arc of the ellipse x^T (I + m_xy m_xy^T / m_z^2) x = 1,
// whose squared radius in the unit direction d of the disk is
//   r^2(d) = m_z^2 / (m_z^2 + (m_xy . d)^2),   z^2(d) = 1 - r^2(d) = (m_xy . d)^2 / (m_z^2 + (m_xy . d)^2)
// (m_z = n . m; r and z are the horizontal and vertical components of the
// point of the great circle above d). The area of the elliptic sector swept
// from the origin over an arc of angle gamma is (1/2) |m_z| gamma (the
// projection scales areas in the circle's plane by |m_z|), so the area of the
// whole projection is Lambert's formula (1760; Arvo 1995, "Applications of
// Irradiance Tensors", eq. 2):
//   Omega_proj = (1/2) sum_i m_z,i gamma_i,                              (L)
// with m_i the INWARD unit normals. An edge with m_z > 0 is an "outer" edge
// (the polygon lies between it and the zenith), m_z < 0 an "inner" one.
//
// Two cases [P21]. Central (the zenith inside the polygon: every m_z >= 0):
// the projection is the union of the elliptic sectors of the edges, each
// sampled in closed form (the arc angle from the edge's first vertex is
// 2 A / m_z for the sub-area A, then r^2 uniform in [0, r_edge^2]).
// Decentral: sort the vertices by azimuth; between consecutive vertex
// azimuths the projection is bounded by one inner and one outer arc, and
//   A(phi) = (1/2) int (r_out^2 - r_in^2) dphi
// is inverted for the azimuth (1-D, monotone) by Newton's method, then r^2
// is uniform between r_in^2 and r_out^2 along that azimuth.
//
// The sub-area swept by an edge from its vertex U (unit) to the azimuth of a
// direction d of the disk is (1/2) |m_z| gamma with
//   gamma = atan2(|U_xy x d|, |m_z| U_xy . d - sign(m_z) U_z (m_xy . d)),        (A)
// the angle between U and the point w = (|m_z| d, -sign(m_z) m_xy . d) of
// the great circle above d (|U x w| = |U_xy x d| since both lie in the
// circle's plane). Along a chord d(t) = (1 - t) b0 + t b1 between two unit
// azimuth directions every argument of (A) is linear in t, so the area is a
// sum of two terms atan2(y0 + t dy, x0 + t dx), whose derivative
// (dy x - y dx) / (x^2 + y^2) is rational: the Newton iteration costs two
// atan2 per step.
//
// Numerics. Lambert's sum (L) cancels when the polygon is small (terms
// O(eps), sum O(eps^2)) or hugs the horizon (a thin sliver above it: the
// inner and outer arcs nearly coincide with the horizon, terms O(1), sum
// O(delta^2)). The second case has a cancellation-free form: since the
// azimuth spans of the outer and inner edges of a decentral polygon cancel,
//   Omega_proj = sum_inner Z_i - sum_outer Z_i,  Z = (1/2) (Delta phi - |m_z| gamma) = (1/2) int z^2 dphi >= 0,  (Z)
// where z^2 is small near the horizon. Z is evaluated as (1/2) [(Delta phi -
// gamma) + (1 - |m_z|) gamma] with 1 - |m_z| = |n x m|^2 / (1 + |m_z|) and
// Delta phi - gamma the argument of a product of two complex numbers
// (below), so it keeps its relative precision for nearly horizontal edges.
// The caller (projected_rectangle.hpp) evaluates both forms' condition
// numbers and picks one ("complement" = the form (Z)), or falls back to
// another exact sampler; the map below evaluates sub-areas in the same form.
//
// Exactness. The Newton iteration stops at a residual of newton_tolerance
// times Omega_proj, or at the rounding floor of the closed form (the
// caller's condition number times DBL_EPSILON), whichever is larger; with
// the caller's bound on that condition number the first coordinate of the
// map is exact to better than 1e-9, far below a float's resolution, and so
// is the density.
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/core/math.hpp"

namespace mcrt {

namespace projected_polygon_detail {

inline double cross2(const dvec2& a, const dvec2& b) { return a.x * b.y - a.y * b.x; }
inline double dot2(const dvec2& a, const dvec2& b) { return a.x * b.x + a.y * b.y; }
// atan2 of a non-negative angle (y >= 0 up to rounding), in [0, pi].
inline double angle(double y, double x) { return fast_math::atan2_upper(std::max(y, 0.0), x); }
// atan2 with a sign, in (-pi, pi].
inline double signed_angle(double y, double x) { return std::copysign(fast_math::atan2_upper(std::abs(y), x), y); }
// Monotone stand-in for the angle of d from the unit direction ref, for
// directions in the closed half-plane ref . d >= 0: in [-1, 1], no division
// by zero except for d = 0 (then 0).
inline double pseudo_angle(const dvec2& ref, const dvec2& d) {
  const double a = std::max(dot2(ref, d), 0.0), c = cross2(ref, d);
  const double den = a + std::abs(c);
  return den > 0.0 ? c / den : 0.0;
}

}  // namespace projected_polygon_detail

// A convex spherical polygon above the horizon, in the receiver's frame (z
// the unit normal), and the map between the unit square and its projection.
// The caller fills count, v, m, gamma, one_minus_mz, term and complement,
// then calls prepare().
struct projected_polygon {
  static constexpr int max_vertices = 5;  // a rectangle clipped by a plane
  // The polygon counts as central if its edges with m_z < 0 (the zenith
  // just outside them) carry at most this fraction of the total in (L): the
  // central map then also covers the sliver between the zenith and those
  // edges, an error of the same relative size, far below float resolution.
  // A decentral polygon thus keeps its vertices away from the zenith, so
  // that their azimuths are defined.
  static constexpr double central_tolerance = 1e-12;
  // Newton's residual tolerance, relative to Omega_proj (see the header).
  static constexpr double newton_tolerance = 1e-12;
  static constexpr int newton_max_steps = 60;
  // Safety factor on the predicted residual of a last, unevaluated Newton
  // step (see sample_decentral).
  static constexpr double newton_margin = 100.0;

  int count = 0;
  std::array<dvec3, max_vertices> v{};              // unit vertex directions, z >= 0
  std::array<dvec3, max_vertices> m{};              // unit inward normal of edge i: v[i] -> v[i + 1 mod count]
  std::array<double, max_vertices> gamma{};         // arc angle of edge i
  std::array<double, max_vertices> one_minus_mz{};  // 1 - |m_z| of edge i, cancellation-free (form (Z))
  // Edge i's signed share of Omega_proj in the form used: (1/2) m_z gamma
  // (form (L)) or -sign(m_z) Z (form (Z)).
  std::array<double, max_vertices> term{};
  bool complement = false;  // sub-areas by the form (Z)
  double condition = 1.0;   // sum of |parts| / Omega_proj of the form used (sets Newton's floor)

  // Sets up the map; false if the polygon has no area to sample.
  bool prepare() {
    using namespace projected_polygon_detail;
    double neg = 0.0, pos = 0.0;
    for (int i = 0; i < count; ++i) (m[i].z < 0.0 ? neg : pos) += 0.5 * std::abs(m[i].z) * gamma[i];
    central_ = !complement && neg <= central_tolerance * pos;
    if (central_) {
      // The elliptic sectors of the edges in order around the zenith, each
      // with its Lambert term (negative ones, within the tolerance, dropped).
      double sum = 0.0, orient = 0.0;
      for (int i = 0; i < count; ++i) {
        cum_[i] = sum;
        sum += std::max(0.5 * m[i].z * gamma[i], 0.0);
        orient += cross2(xy(v[i]), xy(v[next(i)]));
      }
      total_ = sum;
      orient_ = orient >= 0.0 ? 1.0 : -1.0;
      return total_ > 0.0 && std::isfinite(total_);
    }
    // Decentral: the azimuths of all points of the polygon lie within 90
    // degrees of ref = m_xy of the edge whose plane passes farthest below
    // the zenith (m . u >= 0 and m_z < 0 give m_xy . u_xy >= -m_z u_z >= 0).
    int lowest = 0;
    for (int i = 1; i < count; ++i)
      if (m[i].z < m[lowest].z) lowest = i;
    ref_ = xy(m[lowest]);
    const double rl = glm::length(ref_);
    if (!(rl > 0.0)) return false;
    ref_ /= rl;
    for (int i = 0; i < count; ++i) {
      psi_[i] = pseudo_angle(ref_, xy(v[i]));
      order_[i] = i;
    }
    for (int i = 1; i < count; ++i)  // insertion sort by azimuth
      for (int j = i; j > 0 && psi_[order_[j]] < psi_[order_[j - 1]]; --j) std::swap(order_[j], order_[j - 1]);
    // A at the last sorted vertex: every term. A at the others is found
    // by sample() only as far as it needs (area_at_vertex).
    double sum = 0.0;
    for (int e = 0; e < count; ++e) sum += term[e];
    total_ = sum;
    return total_ > 0.0 && std::isfinite(total_);
  }

  bool central() const { return central_; }
  // The projected solid angle the map is normalised by (equal to the sum of
  // the terms up to rounding).
  double total() const { return total_; }

  // u in [0,1)^2 -> unit direction in the receiver's frame, z >= 0.
  dvec3 sample(dvec2 u) const {
    const double target = u.x * total_;
    return central_ ? sample_central(target, u.y) : sample_decentral(target, u.y);
  }

  // Unit direction (z > 0) within the polygon -> unit square; the inverse
  // of sample().
  dvec2 invert(const dvec3& dir) const {
    using namespace projected_polygon_detail;
    const dvec2 d = xy(dir);
    const double r2 = dot2(d, d);
    if (central_) {
      // The edge whose azimuth range holds d.
      int e = 0;
      double best = -infinity;
      for (int i = 0; i < count; ++i) {
        if (!(m[i].z > 0.0)) continue;
        const dvec2 a = unit(xy(v[i])), b = unit(xy(v[next(i)]));
        const double s = std::min(orient_ * cross2(a, d), orient_ * cross2(d, b));
        if (s > best) best = s, e = i;
      }
      const double t1 = (cum_[e] + partial(e, e, d)) / total_;
      const double g = dot2(xy(m[e]), d);
      const double u2 = r2 * (m[e].z * m[e].z + g * g / r2) / (m[e].z * m[e].z);  // r^2 / r_edge^2
      return {std::clamp(t1, 0.0, 1.0), std::clamp(u2, 0.0, 1.0)};
    }
    const double p = pseudo_angle(ref_, d);
    int j = 0;
    while (j + 2 < count && psi_[order_[j + 1]] <= p) ++j;
    sector sc;
    set_sector(j, sc);
    const double c0 = cross2(sc.b0, d), c1 = cross2(d, sc.b1);
    const double t = c0 + c1 > 0.0 ? std::clamp(c0 / (c0 + c1), 0.0, 1.0) : 0.0;
    double deriv;
    const double u1 = evaluate(sc, t, deriv) / total_;
    const radial rad = radial_at(sc, d / std::sqrt(r2));
    // (r^2 - r_in^2) / (r_out^2 - r_in^2), from the z components below 45
    // degrees of elevation, where they are the small ones.
    const double z2 = dir.z * dir.z;
    const double u2 = z2 < r2 ? (rad.z2_in - z2) / (rad.z2_in - rad.z2_out) : (r2 - rad.r2_in) / (rad.r2_out - rad.r2_in);
    return {std::clamp(u1, 0.0, 1.0), std::clamp(u2, 0.0, 1.0)};
  }

 private:
  static dvec2 xy(const dvec3& a) { return {a.x, a.y}; }
  int next(int i) const { return i + 1 == count ? 0 : i + 1; }
  // The endpoint of edge e with the smaller azimuth (decentral).
  int lo_vertex(int e) const { return psi_[next(e)] < psi_[e] ? next(e) : e; }

  // A at the azimuth of sorted vertex j (decentral): the edges wholly
  // before contribute their whole term, the one edge (of the other chain)
  // straddling the azimuth a partial one.
  double area_at_vertex(int j) const {
    const int k = order_[j];
    const dvec2 d = xy(v[k]);
    double a = 0.0;
    for (int e = 0; e < count; ++e) {
      const int lo = lo_vertex(e), hi = next(e) == lo ? e : next(e);
      if (psi_[hi] <= psi_[k])
        a += term[e];
      else if (psi_[lo] < psi_[k])
        a += partial(e, lo, d);
    }
    return a;
  }

  // Edge e's signed share of A from its vertex lo (unit, on the edge) to the
  // azimuth of d (any length): (1/2) m_z gamma by (A), or -sign(m_z) Z.
  double partial(int e, int lo, const dvec2& d) const {
    using namespace projected_polygon_detail;
    const dvec3& me = m[e];
    const dvec2 uxy = xy(v[lo]);
    const double y = cross2(uxy, d), dd = dot2(uxy, d), g = dot2(xy(me), d);
    const double sg = me.z < 0.0 ? -1.0 : 1.0, amz = std::abs(me.z);
    const double x = amz * dd - sg * v[lo].z * g;
    if (!complement) return 0.5 * me.z * angle(std::abs(y), x);
    const double xmd = -one_minus_mz[e] * dd - sg * v[lo].z * g;  // x - dd without cancellation
    return -sg * 0.5 * (signed_angle(std::abs(y) * xmd, dd * x + y * y) + one_minus_mz[e] * angle(std::abs(y), x));
  }

  // One straddling edge of a sector: the arguments of (A) along the chord,
  // y(t) = y0 + t dy, x(t) = x0 + t dx, and for the form (Z) the dot
  // product dd(t) and x(t) - dd(t).
  struct piece {
    double y0, dy, x0, dx, d0, dd, w0, dw, half_mz, omz, sg;
  };
  struct sector {
    dvec2 b0, b1;
    double base = 0.0;  // sum of the terms of the edges wholly before the sector
    int n = 0;
    std::array<piece, max_vertices> p{};
    std::array<int, max_vertices> edge{};
  };

  // The chord of sorted sector j and the edges straddling it.
  void set_sector(int j, sector& sc) const {
    const int k0 = order_[j], k1 = order_[j + 1];
    sc.b0 = unit(xy(v[k0]));
    sc.b1 = unit(xy(v[k1]));
    const double p0 = psi_[k0], p1 = psi_[k1];
    for (int e = 0; e < count; ++e) {
      const int lo = lo_vertex(e), hi = next(e) == lo ? e : next(e);
      if (psi_[hi] <= p0) {
        sc.base += term[e];
      } else if (psi_[lo] < p1) {
        const dvec3& me = m[e];
        const dvec2 uxy = xy(v[lo]), mxy = xy(me);
        const double sg = me.z < 0.0 ? -1.0 : 1.0, amz = std::abs(me.z), uz = v[lo].z;
        piece& pc = sc.p[sc.n];
        sc.edge[sc.n++] = e;
        const double ya = projected_polygon_detail::cross2(uxy, sc.b0), yb = projected_polygon_detail::cross2(uxy, sc.b1);
        const double da = projected_polygon_detail::dot2(uxy, sc.b0), db = projected_polygon_detail::dot2(uxy, sc.b1);
        const double ga = projected_polygon_detail::dot2(mxy, sc.b0), gb = projected_polygon_detail::dot2(mxy, sc.b1);
        const double xa = amz * da - sg * uz * ga, xb = amz * db - sg * uz * gb;
        const double wa = -one_minus_mz[e] * da - sg * uz * ga, wb = -one_minus_mz[e] * db - sg * uz * gb;
        pc = {ya, yb - ya, xa, xb - xa, da, db - da, wa, wb - wa, 0.5 * me.z, one_minus_mz[e], sg};
      }
    }
  }

  // A along the chord of sc at t, and dA/dt.
  double evaluate(const sector& sc, double t, double& deriv) const {
    using namespace projected_polygon_detail;
    double a = sc.base, da = 0.0;
    for (int i = 0; i < sc.n; ++i) {
      const piece& pc = sc.p[i];
      const double y = std::max(pc.y0 + t * pc.dy, 0.0), x = pc.x0 + t * pc.dx;
      const double r2 = x * x + y * y;
      if (r2 > 0.0) da += pc.half_mz * (pc.dy * x - y * pc.dx) / r2;
      if (!complement) {
        a += pc.half_mz * angle(y, x);
      } else {
        const double dd = pc.d0 + t * pc.dd, w = pc.w0 + t * pc.dw;
        a -= pc.sg * 0.5 * (signed_angle(y * w, dd * x + y * y) + pc.omz * angle(y, x));
      }
    }
    deriv = da;
    return a;
  }

  // Squared horizontal and vertical components of the inner and outer arcs
  // above the unit direction d (inner: the zenith, r = 0, if none).
  struct radial {
    double r2_in = 0.0, z2_in = 1.0, r2_out = 1.0, z2_out = 0.0;
  };
  radial radial_at(const sector& sc, const dvec2& d) const {
    radial rd;
    bool have_in = false, have_out = false;
    for (int i = 0; i < sc.n; ++i) {
      const dvec3& me = m[sc.edge[i]];
      const double g = projected_polygon_detail::dot2(xy(me), d), mz2 = me.z * me.z, den = mz2 + g * g;
      if (!(den > 0.0)) continue;
      const double r2 = mz2 / den, z2 = g * g / den;
      if (me.z < 0.0) {
        if (!have_in || r2 > rd.r2_in) rd.r2_in = r2, rd.z2_in = z2;  // the outermost inner arc
        have_in = true;
      } else {
        if (!have_out || r2 < rd.r2_out) rd.r2_out = r2, rd.z2_out = z2;  // the innermost outer arc
        have_out = true;
      }
    }
    return rd;
  }

  static dvec2 unit(const dvec2& a) {
    const double l = glm::length(a);
    return l > 0.0 ? a / l : dvec2(1.0, 0.0);
  }

  // The lifted point at squared radius (1 - u2) r_in^2 + u2 r_out^2 above d
  // (both squared components as convex combinations, so whichever is small
  // keeps its relative precision).
  static dvec3 lift(const dvec2& d, const radial& rd, double u2) {
    const double r2 = (1.0 - u2) * rd.r2_in + u2 * rd.r2_out;
    const double z2 = (1.0 - u2) * rd.z2_in + u2 * rd.z2_out;
    const dvec3 p(std::sqrt(std::max(r2, 0.0)) * d, std::sqrt(std::max(z2, 0.0)));
    return p / glm::length(p);
  }

  dvec3 sample_central(double target, double u2) const {
    int e = -1;
    for (int i = 0; i < count; ++i)
      if (m[i].z > 0.0 && gamma[i] > 0.0 && (e < 0 || cum_[i] <= target)) e = i;
    // Arc angle from v[e] whose elliptic sector has the remaining area,
    // then the point P of the great circle at that angle (rotating towards
    // v[e + 1] in the circle's plane).
    const double g = std::clamp(2.0 * (target - cum_[e]) / m[e].z, 0.0, gamma[e]);
    dvec3 w = glm::cross(m[e], v[e]);
    if (glm::dot(w, v[next(e)]) < 0.0) w = -w;
    w /= glm::length(w);
    double s, c;  // of g / 2 (g in [0, pi))
    fast_math::sincos_quadrant(0.5 * g, s, c);
    const dvec3 pt = (1.0 - 2.0 * s * s) * v[e] + (2.0 * s * c) * w;
    // r^2 uniform in [0, r_P^2]: the horizontal part scales by sqrt(u2),
    // z^2 = (1 - u2) + u2 z_P^2.
    const dvec3 p(std::sqrt(u2) * pt.x, std::sqrt(u2) * pt.y, std::sqrt((1.0 - u2) + u2 * pt.z * pt.z));
    return p / glm::length(p);
  }

  dvec3 sample_decentral(double target, double u2) const {
    // The sector of the target: A at the sorted vertices, kept monotone,
    // up to the first one beyond the target (the last one's is total_).
    int j = 0;
    double a0 = 0.0, a1 = total_;
    for (; j + 2 < count; ++j) {
      a1 = std::max(area_at_vertex(j + 1), a0);
      if (a1 > target) break;
      a0 = a1;
      a1 = total_;
    }
    sector sc;
    set_sector(j, sc);
    // Initial guess: A on the chord modelled by a quadratic with the exact
    // end slopes, scaled to the sector's area (the "quad" initialisation of
    // [P21] in spirit: the region between straight chords).
    const double span = a1 - a0;
    double t = 0.0;
    if (span > 0.0) {
      double f0, f1;
      evaluate_slope(sc, 0.0, f0);
      evaluate_slope(sc, 1.0, f1);
      const double frac = std::clamp((target - a0) / span, 0.0, 1.0);
      const double k = f0 + 0.5 * (f1 - f0);
      const double a = f0 / k, b = (f1 - f0) / k;  // model: a t + b t^2 / 2, a + b / 2 = 1
      const double disc = a * a + 2.0 * b * frac;
      const double den = a + std::sqrt(std::max(disc, 0.0));
      t = (k > 0.0 && disc >= 0.0 && den > 0.0) ? std::clamp(2.0 * frac / den, 0.0, 1.0) : frac;
      // Safeguarded Newton on A(t) = target within the bracket [0, 1].
      // Once two consecutive Newton steps have shown the quadratic
      // convergence |f_next| ~ C f^2 (C = |f| / f_prev^2 measured), a step
      // whose predicted residual C f^2 is below tol / newton_margin is
      // taken without evaluating A again.
      const double tol = std::max(newton_tolerance, 4.0 * DBL_EPSILON * condition) * total_;
      double lo = 0.0, hi = 1.0, f_prev = 0.0;
      for (int it = 0; it < newton_max_steps; ++it) {
        double deriv;
        const double f = evaluate(sc, t, deriv) - target;
        if (std::abs(f) <= tol) break;
        (f > 0.0 ? hi : lo) = t;
        double tn = t - f / deriv;
        const bool newton = tn > lo && tn < hi;  // false also for deriv = 0 and NaN
        if (!newton) tn = 0.5 * (lo + hi);
        const bool tiny = std::abs(tn - t) <= 4.0 * DBL_EPSILON * std::max(t, DBL_MIN);
        t = tn;
        if (tiny || hi - lo <= 4.0 * DBL_EPSILON) break;
        if (newton && f_prev != 0.0 && std::abs(f) < std::abs(f_prev) &&
            (std::abs(f) / (f_prev * f_prev)) * f * f * newton_margin <= tol)
          break;
        f_prev = newton ? f : 0.0;
      }
    }
    const dvec2 d = unit((1.0 - t) * sc.b0 + t * sc.b1);
    return lift(d, radial_at(sc, d), u2);
  }

  // dA/dt only (no angle).
  void evaluate_slope(const sector& sc, double t, double& deriv) const {
    double da = 0.0;
    for (int i = 0; i < sc.n; ++i) {
      const piece& pc = sc.p[i];
      const double y = std::max(pc.y0 + t * pc.dy, 0.0), x = pc.x0 + t * pc.dx;
      const double r2 = x * x + y * y;
      if (r2 > 0.0) da += pc.half_mz * (pc.dy * x - y * pc.dx) / r2;
    }
    deriv = da;
  }

  bool central_ = false;
  double total_ = 0.0, orient_ = 1.0;
  dvec2 ref_{1.0, 0.0};
  std::array<double, max_vertices> psi_{}, cum_{};  // cum_: central map only
  std::array<int, max_vertices> order_{};
};

namespace projected_polygon_detail {

// gamma - sin(gamma) for gamma in [0, pi], with sin(gamma) given: the
// series gamma^3/6 - gamma^5/120 + ... below 0.25 (truncation < 1e-17
// relative), the difference above (where it loses < 7 bits).
inline double arc_minus_chord(double g, double sin_g) {
  if (g >= 0.25) return g - sin_g;
  const double g2 = g * g;
  return g * g2 * (1.0 / 6.0 - g2 * (1.0 / 120.0 - g2 * (1.0 / 5040.0 - g2 * (1.0 / 362880.0 - g2 / 39916800.0))));
}

}  // namespace projected_polygon_detail

// The per-receiver state of a planar convex polygon light clipped at the
// receiver's horizon: steps 3 and 4 of projected_rectangle.hpp (whose
// header derives the forms, and whose class evaluates them the same way)
// for any such polygon of up to max_vertices vertices, as a base of Shape
// (which names it a friend; the triangle of projected_triangle.hpp). In
// the light's frame (ex, ey in its plane, ez its front normal, o at the
// origin, the plane z = -h). The shape clips itself and fills count_ and
// height_ (n . V_k, 0 for clip points), and offers vertex(k) (vertex k
// relative to the foot of o), vertex_difference(a, b) (vertex(b) -
// vertex(a), formed without cancellation) and on_horizon(k) (edge k runs
// along the horizon); it then evaluates per edge the arguments of its arc
// angle (Y = |V_k x V_k+1|, X = V_k . V_k+1), gamma_, m_z and the
// magnitude of m_z's parts, and calls choose(); the map needs
// prepare_map() after that.
template <class Shape>
class projected_light_polygon {
 public:
  enum class method : unsigned char { none, map, area };
  // Largest condition number of the map's form: a few times 1e6
  // DBL_EPSILON ~ 1e-9 relative (projected_rectangle.hpp, "Thresholds").
  static constexpr double max_condition = 1e6;
  // Below this condition number Lambert's sum itself is Omega_proj to a few
  // times 1e3 DBL_EPSILON < 1e-12 relative, and the cancellation-free form
  // (C) is not evaluated (a common light seen at a moderate distance).
  static constexpr double direct_condition = 1e3;
  static constexpr int max_vertices = projected_polygon::max_vertices;

  method how() const { return how_; }
  bool valid() const { return how_ != method::none; }
  // Whether sample_offset() can return a point (with_map given for the map).
  bool can_sample() const { return how_ == method::area || (how_ == method::map && map_ok_); }
  // Omega_proj of the visible part (sr, projected; 0 if nothing is visible).
  double projected_solid_angle() const { return omega_; }
  // Area of the visible part on the light (the area fallback's normaliser).
  double visible_area() const { return area_; }
  int vertex_count() const { return count_; }
  // Whether the map's sub-areas use the complement form (Z).
  bool complement() const { return complement_; }
  // Omega_proj by Lambert's sum, by (C) and by (Z) (0 if not computed).
  double omega_lambert() const { return omega_lambert_; }
  double omega_chord() const { return omega_chord_; }
  double omega_complement() const { return omega_z_; }
  // Condition numbers of Lambert's form, of (C), and of (Z) (0 if not computed).
  double condition_lambert() const { return cond_lambert_; }
  double condition_chord() const { return cond_chord_; }
  double condition_complement() const { return cond_z_; }
  double height() const { return h_; }
  const dvec3& normal() const { return nd_; }

  // Density per unit SOLID ANGLE of the unit direction dir whose ray meets
  // the light at distance t: cos(theta) / Omega_proj on the map,
  // t^3 / (h A_visible) on the area fallback, 0 below the horizon.
  double pdf_direction(const dvec3& dir, double t) const {
    if (how_ == method::none) return 0.0;
    const double c = glm::dot(dir, nd_);
    if (!(c > 0.0)) return 0.0;
    if (how_ == method::map) return c / omega_;
    return t * t * t / (h_ * area_);
  }

 protected:
  projected_light_polygon(const dvec3& ex, const dvec3& ey, const dvec3& ez) : ex_(ex), ey_(ey), ez_(ez) {}
  projected_light_polygon() = default;

  // The map's point for u, in the light plane relative to the foot of o;
  // false if its direction does not reach the plane.
  bool map_point(vec2 u, dvec2& p) const {
    const dvec3 x = poly_.sample(dvec2(u));
    const dvec3 dir = x.x * t_ + x.y * b_ + x.z * nd_;
    const double dz = -glm::dot(dir, ez_);
    if (!(dz > 0.0)) return false;
    const double t = h_ / dz;
    p = {t * glm::dot(dir, ex_), t * glm::dot(dir, ey_)};
    return true;
  }
  // Point o + v of the visible part -> unit square by the map.
  dvec2 map_invert(const dvec3& v) const {
    const dvec3 dir = v / glm::length(v);
    return poly_.invert({glm::dot(dir, t_), glm::dot(dir, b_), glm::dot(dir, nd_)});
  }
  dvec3 to_offset(const dvec2& p) const { return p.x * ex_ + p.y * ey_ - h_ * ez_; }
  const Shape& shape() const { return static_cast<const Shape&>(*this); }

  // Step 3 of projected_rectangle.hpp after the per-edge loop: Lambert's
  // sum (lambert, with the magnitudes of its parts lambert_mag), (C), (Z),
  // the choice. Ys, Xs, mzmags: the edges' arc arguments and m_z
  // magnitudes; edge_normals() fills mL_ (the inward unit normals in the
  // light frame) where the map or (Z) needs them.
  template <class EdgeNormals>
  void choose(bool with_map, double lambert, double lambert_mag, bool decentral,
              const std::array<double, max_vertices>& Ys, const std::array<double, max_vertices>& Xs,
              const std::array<double, max_vertices>& mzmags, EdgeNormals&& edge_normals) {
    using projected_polygon_detail::arc_minus_chord;
    const double hh = h_ * h_;
    const bool direct = lambert > 0.0 && lambert_mag <= direct_condition * lambert;
    if (with_map || !direct) edge_normals();
    double seg = 0.0, seg_mag = 0.0;
    if (!direct) {
      for (int k = 0; k < count_; ++k) {
        const double iR = 1.0 / std::sqrt(Xs[k] * Xs[k] + Ys[k] * Ys[k]);  // no overflow: squared lengths of the scene
        sin_[k] = Ys[k] * iR;
        cos_[k] = Xs[k] * iR;
        const double amc = arc_minus_chord(gamma_[k], sin_[k]);
        seg += 0.5 * mz_[k] * amc;
        seg_mag += 0.5 * mzmags[k] * amc;
      }
    }
    omega_lambert_ = lambert;
    cond_lambert_ = lambert_mag / lambert;
    // Visible area (for the fallback): a fan in the light plane.
    area_ = 0.0;
    for (int k = 1; k + 1 < count_; ++k) {
      const dvec2 a = shape().vertex_difference(0, k), b = shape().vertex_difference(0, k + 1);
      fan_[k] = 0.5 * std::abs(a.x * b.y - a.y * b.x);
      area_ += fan_[k];
    }
    if (!std::isfinite(area_)) area_ = 0.0;
    if (direct) {
      how_ = method::map;
      complement_ = false;
      omega_ = lambert;
      return;
    }
    // (C): the chord polygon's area vector from the fan of differences.
    dvec3 area_vec(0.0);
    {
      const dvec2 p0 = shape().vertex(0);
      const double l0 = std::sqrt(glm::dot(p0, p0) + hh);
      const dvec3 v0(p0.x / l0, p0.y / l0, -h_ / l0);
      dvec3 prev(0.0);
      for (int k = 1; k < count_; ++k) {
        const dvec2 pk = shape().vertex(k), dk = shape().vertex_difference(0, k);
        const double lk = std::sqrt(glm::dot(pk, pk) + hh);
        // v_k - v_0 = (V_k - V_0) / L_k - V_0 (L_k^2 - L_0^2) / (L_k L_0 (L_k + L_0)),
        // L_k^2 - L_0^2 = (P_k - P_0) . (P_k + P_0); V_0 = L_0 v0.
        const double dl = glm::dot(dk, pk + p0) / (lk * (lk + l0));
        const dvec3 dv = dvec3(dk.x / lk, dk.y / lk, 0.0) - dl * v0;
        if (k >= 2) area_vec += glm::cross(prev, dv);
        prev = dv;
      }
      area_vec *= 0.5;
    }
    const double chord = -glm::dot(nL_, area_vec);
    omega_chord_ = chord + seg;
    cond_chord_ = (glm::length(area_vec) + seg_mag) / omega_chord_;

    if (lambert > 0.0 && cond_lambert_ <= max_condition && omega_chord_ > 0.0) {
      how_ = method::map;
      complement_ = false;
      omega_ = omega_chord_;
      return;
    }
    if (decentral && complement_form() && cond_z_ <= max_condition) {
      how_ = method::map;
      complement_ = true;
      omega_ = omega_z_;
      return;
    }
    if (area_ > 0.0) {
      how_ = method::area;
      omega_ = omega_chord_ > 0.0 ? omega_chord_ : 0.0;
    }
  }

  // The complement form (Z) of every edge; false if it has no area.
  bool complement_form() {
    double sum = 0.0, mag = 0.0;
    for (int k = 0; k < count_; ++k) {
      const int kn = k + 1 == count_ ? 0 : k + 1;
      // 1 - |m_z| = |n x m|^2 / (1 + |m_z|), the cross product in the light frame.
      const double omz = glm::dot(glm::cross(nL_, mL_[k]), glm::cross(nL_, mL_[k])) / (1.0 + std::abs(mz_[k]));
      omz_[k] = shape().on_horizon(k) ? 0.0 : omz;
      const double zp = unit_height(k), zq = unit_height(kn), zz = zp * zq;
      const double s = sin_[k], c = cos_[k];
      // Delta phi - gamma = arg((P_xy . Q_xy + i |P_xy x Q_xy|) (cos g - i sin g)),
      // P_xy . Q_xy = c - zz, |P_xy x Q_xy| = s |m_z|.
      const double im = s * (zz - omz_[k] * c), re = (c - zz) * c + s * s * (1.0 - omz_[k]);
      const double a = std::atan2(im, re);
      const double zk = 0.5 * (a + omz_[k] * gamma_[k]);
      zterm_[k] = (mz_[k] < 0.0 ? 1.0 : -1.0) * zk;
      sum += zterm_[k];
      mag += 0.5 * (std::abs(a) + (2.0 * omz_[k] + zz) * gamma_[k]);
    }
    omega_z_ = sum;
    cond_z_ = mag / sum;
    return sum > 0.0 && std::isfinite(sum);
  }

  // z / |V| of vertex k (0 for clip points).
  double unit_height(int k) const {
    if (height_[k] == 0.0) return 0.0;
    const dvec2 p = shape().vertex(k);
    return height_[k] / std::sqrt(glm::dot(p, p) + h_ * h_);
  }

  // Step 4: the polygon in the receiver's frame (Duff et al. 2017 basis).
  void prepare_map() {
    const double sign = std::copysign(1.0, nd_.z);
    const double a = -1.0 / (sign + nd_.z), bb = nd_.x * nd_.y * a;
    t_ = {1.0 + sign * nd_.x * nd_.x * a, sign * bb, -sign * nd_.x};
    b_ = {bb, sign + nd_.y * nd_.y * a, -nd_.y};
    // The light's axes in the receiver's frame.
    const dvec3 EX(glm::dot(ex_, t_), glm::dot(ex_, b_), nL_.x), EY(glm::dot(ey_, t_), glm::dot(ey_, b_), nL_.y),
        EZ(glm::dot(ez_, t_), glm::dot(ez_, b_), nL_.z);
    poly_.count = count_;
    poly_.complement = complement_;
    poly_.condition = complement_ ? cond_z_ : cond_lambert_;
    for (int k = 0; k < count_; ++k) {
      const dvec2 p = shape().vertex(k);
      dvec3 v = p.x * EX + p.y * EY - h_ * EZ;
      if (height_[k] == 0.0) v.z = 0.0;  // clip points lie on the horizon
      poly_.v[k] = v / glm::length(v);
      dvec3 m = mL_[k].x * EX + mL_[k].y * EY + mL_[k].z * EZ;
      m.z = mz_[k];  // the value every classification used
      poly_.m[k] = m;
      poly_.gamma[k] = gamma_[k];
      poly_.one_minus_mz[k] = complement_ ? omz_[k] : 0.0;
      poly_.term[k] = complement_ ? zterm_[k] : 0.5 * mz_[k] * gamma_[k];
    }
    map_ok_ = poly_.prepare();
  }

  // Area fallback: uniform on the fan of triangles (v0, v_k, v_k+1) of the
  // visible polygon; a point relative to the foot of o.
  dvec2 fan_sample(dvec2 u) const {
    double target = u.x * area_;
    int k = 1;
    while (k + 2 < count_ && target > fan_[k]) target -= fan_[k++];
    const double s = std::sqrt(std::clamp(target / fan_[k], 0.0, 1.0));
    const dvec2 a = shape().vertex_difference(0, k), b = shape().vertex_difference(0, k + 1);
    return shape().vertex(0) + s * ((1.0 - u.y) * a + u.y * b);
  }
  dvec2 fan_invert(const dvec2& p) const {
    // The fan triangle whose barycentric coordinates (al, be) in the basis
    // (v_k - v_0, v_k+1 - v_0) are least negative; s = al + be, u2 = be / s.
    const dvec2 q = p - shape().vertex(0);
    double before = 0.0, best = -infinity, u1 = 1.0, u2 = 1.0;
    for (int k = 1; k + 1 < count_; ++k) {
      const dvec2 a = shape().vertex_difference(0, k), b = shape().vertex_difference(0, k + 1);
      const double det = a.x * b.y - a.y * b.x;
      const double al = (q.x * b.y - q.y * b.x) / det, be = (a.x * q.y - a.y * q.x) / det;
      const double inside = std::min({al, be, 1.0 - al - be});
      if (inside > best) {
        best = inside;
        const double s = std::clamp(al + be, 0.0, 1.0);
        u1 = (before + s * s * fan_[k]) / area_;
        u2 = al + be > 0.0 ? be / (al + be) : 0.0;
      }
      before += fan_[k];
    }
    return {std::clamp(u1, 0.0, 1.0), std::clamp(u2, 0.0, 1.0)};
  }

  dvec3 ex_{1.0, 0.0, 0.0}, ey_{0.0, 1.0, 0.0}, ez_{0.0, 0.0, 1.0};  // the light's frame
  double h_ = 0.0;
  dvec3 nd_{0.0, 0.0, 1.0}, nL_{0.0, 0.0, 1.0}, t_{1.0, 0.0, 0.0}, b_{0.0, 1.0, 0.0};
  int count_ = 0;
  std::array<dvec3, max_vertices> mL_{};
  std::array<double, max_vertices> height_{}, gamma_{}, sin_{}, cos_{}, mz_{}, omz_{}, zterm_{}, fan_{};
  double omega_ = 0.0, omega_lambert_ = 0.0, omega_chord_ = 0.0, omega_z_ = 0.0, area_ = 0.0;
  double cond_lambert_ = 0.0, cond_chord_ = 0.0, cond_z_ = 0.0;
  bool complement_ = false, map_ok_ = false;
  method how_ = method::none;
  projected_polygon poly_;
};

}  // namespace mcrt
