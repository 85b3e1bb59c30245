#pragma once
// Exact sampling of ellipse and disk lights by PROJECTED solid angle: from
// a receiver at o with unit normal n, directions omega towards the light with
// density
//   p(omega) = max(0, n . omega) / Omega_proj   per unit SOLID ANGLE,
// Omega_proj the projected solid angle of the part of the light above the
// horizon of n. For an unoccluded light of constant radiance L seen from a
// diffuse receiver, L cos theta / p = L Omega_proj is the same for every
// sample: a zero-variance estimate of the direct light.
//
// Geometry. The cone of directions from o through the ellipse is reduced to
// the canonical spherical ellipse S of Guillen et al. 2017
// (spherical_ellipse.hpp, make_ellipse_cone): in the cone frame the light is
// the ellipse E = {(x, y): x^2/a^2 + y^2/b^2 <= 1} of the tangent plane Z = 1
// (directions (x, y, 1)), a >= b, and we write (xi, eta) = (x/a, y/b) for the
// unit disk it becomes. nu is n in the cone frame, A = 1 + a^2, B = 1 + b^2.
// The sampler never needs Omega itself (no elliptic integral): every
// quantity below is elementary.
//
// Projected solid angle as an area. Orthographic projection onto the plane of
// n maps the upper hemisphere onto the unit disk with d(area) = cos theta
// d(omega) (Nusselt's analogue), so Omega_proj is the area of the projection
// D of the visible part S+ = S cap {nu . omega >= 0}, and sampling by
// projected solid angle is sampling D uniformly. In polar coordinates
// (rho = sin theta, phi) about the disk's centre (the pole n), Green's
// theorem gives 2 area = oint_{dD} rho^2 dphi, and along any curve on the
// sphere rho^2 dphi = n . (omega x d omega) (the n-component of the vector
// of Lambert's / Arvo's irradiance formula, Arvo 1995, "Applications of
// Irradiance Tensors", eq. 2: Omega_proj = n . (1/2) oint omega x d omega).
// Meridians through the pole (great circles through n) contribute 0; the
// horizon (the rim of the disk) contributes its azimuth span. On the
// ellipse's boundary P(t) = (a cos t, b sin t, 1), t the eccentric angle,
//   n . (P x P') / |P|^2 dt = g(t) dt,
//   g(t) = (-nu_x b cos t - nu_y a sin t + nu_z a b) / (A cos^2 t + B sin^2 t),   (1)
// whose antiderivative is elementary (all three terms reduce to
// int dq / (quadratic in q) with q = t via tan, q = sin t, q = cos t):
//   int a b / (A c^2 + B s^2) dt = (a b / sqrt(A B)) Theta(t),  Theta = atan2(sqrt(B) s, sqrt(A) c)
//   int c / (A c^2 + B s^2) dt   = int ds / (A - d s^2),      d = a^2 - b^2
//   int s / (A c^2 + B s^2) dt   = -int dc / (B + d c^2).
// Over the whole boundary the last two vanish: an ellipse wholly above the
// horizon has
//   Omega_proj = pi nu_z a b / sqrt((1 + a^2)(1 + b^2)),                       (2)
// exact and free of cancellation (nu_z = n . cone axis; for a disk on its
// axis, pi R^2 / (R^2 + h^2), the disk's configuration factor). Over an arc
// from P to Q (unit-disk points (c, s)), with k = sqrt(d/A) < 1, j = sqrt(d/B),
// the differences are evaluated in forms that do not cancel:
//   int_{s_P}^{s_Q} ds/(A - d s^2) = (s_Q - s_P) / (A (1 - k s_Q)(1 + k s_P)) log1p(x) / x,
//       x = 2 k (s_Q - s_P) / ((1 - k s_Q)(1 + k s_P)),   1 -+ k s = (A c^2 + B s^2) / (A (1 +- k s)),
//   int_{c_Q}^{c_P} dc/(B + d c^2) = atan2(j (c_P - c_Q), 1 + j^2 c_P c_Q) / (j B)   (atan(y)/y form for small j),
// and Theta(Q) - Theta(P) by one atan2 of the two points scaled by (sqrt A,
// sqrt B), its branch fixed by what is known of the arc (see
// projected_theta_*).
//
// The map (polar about the pole n). u1 picks the azimuth phi about n, u2
// the radius along the meridian at phi: rho^2 uniform between the meridian's
// entry and exit rho_1^2, rho_2^2 (the area element of D is d(rho^2/2) dphi):
//   K(phi) = int^{phi} (rho_2^2 - rho_1^2) dphi = u1 K,   K = 2 Omega_proj,
//   rho^2  = rho_1^2 + u2 (rho_2^2 - rho_1^2).
// A meridian is a great circle through n, a line in the tangent plane; it
// cuts the unit disk of (xi, eta) in a chord with endpoints p+- = delta w +-
// h w_perp, from which the entry and exit follow, and K(phi) is the boundary
// integral of rho^2 dphi between them, in closed form by (1):
//   - n inside S (the light around the normal): rho_1 = 0, phi over [0, 2 pi);
//     K(phi) the integral along the far boundary from a reference meridian;
//   - n outside S: phi over the wedge [phi_a, phi_b] of azimuths of D (< pi
//     wide), bounded by the meridians tangent to the ellipse (or the
//     corners where the horizon cuts it); the entry p+ and exit p- of the
//     chord, and K(phi) the integral along dD from p+ round the wedge's
//     start to p- (the chord's arc on the side of smaller azimuths);
//   - the horizon cuts the ellipse (chord w_h . p = delta_h): the exit is on
//     the horizon where p- is below it, and the horizon's part of dD adds
//     its azimuth span.
// The orientation facts used: the ellipse's boundary with t increasing is dD
// traversed positively (both frames right-handed, the projection of the
// upper hemisphere orientation-preserving), azimuths in (phi - pi, phi) lie on
// the side m . omega < 0 of the meridian plane (m = n x e(phi)), so p+ is the
// entry and p- the exit (tested). u1 -> phi is solved by safeguarded Newton
// (bracket, bisection fallback) on f = K(phi) - u1 K, f' = rho_2^2 - rho_1^2,
// to |f| <= 1e-9 K (as the solid-angle solvers); outside S in the variable
// psi, phi = phi_mid + phi_half sin psi, which removes the square-root
// behaviour of the chord at tangent ends (the substitution of
// spherical_ellipse.hpp's parallel map), starting from its planar solution.
// The conditional is closed form: the point of the chord where sin^2 theta
// is the target, by one linear equation in the chord parameter.
//
// Conditioning, thresholds, fallbacks. Outside S the closed form K(phi) is
// the difference of the areas of the two fans from the pole to the exit and
// the entry arcs, each at most the wedge's azimuth span; for a small or thin
// light far from the normal, or one just above the horizon, the region
// between them is far smaller than either. The set-up computes
// kappa = (phi_b - phi_a) / K, the worst-case amplification of rounding in K(phi)
// (and in K itself where the horizon clips), and the limits are
// (projected_ellipse_limits):
//   - max_conditioning: kappa > 1e6 (rounding of ~1e-16 kappa in the
//     fraction u1 would reach the solver's 1e-9): the bilinear pre-warp
//     (bilinear_spherical_ellipse.hpp), exact pdf. For the lights this
//     catches unclipped (thin or tiny cones seen edge-on, receivers within
//     ~1e-6 of the light's plane) cos theta varies little over the light and
//     the pre-warp's density stays within a few % of cos theta / Omega_proj
//     (0.94 to 1.08 in tests/test_ellipse_projected_solid_angle.cpp); for a
//     sliver cut off by a grazing horizon (1e-4 of the radius visible:
//     kappa ~ 1e9) the pre-warp puts ~1e-6 of its samples above the horizon
//     and returns no sample for the rest: unbiased, but of high variance;
//   - min_clip_depth: a horizon that cuts less than 1e-12 (in the unit disk's
//     radius) off the ellipse is taken as tangent (the sliver below it holds
//     ~1e-30 of the projected solid angle), which keeps the visible arc
//     more than 1e-6 rad from a full turn, where its Theta could not be
//     told from the next turn's;
//   - min_projected: Omega_proj < 1e-30 sr (1 / Omega_proj overflows float):
//     the bilinear pre-warp;
//   - where make_ellipse_cone() gives up on the spherical map the bilinear
//     sampler's area fallback is used, except beyond max_tangent alone
//     (b > 1e6, an observer within 1e-6 of a light that fills its
//     hemisphere), which only limits the elliptic integrals of Omega, not
//     used here: there the exact map runs;
//   - a light wholly below the horizon (its highest point by the double test
//     of ellipse_below_horizon), an observer behind the light: no sample,
//     pdf 0.
// The mode depends only on (light, o, n), so sample(), pdf() and the true
// density always agree: cos theta / Omega_proj (0 below the horizon) in the
// exact mode, the bilinear pre-warp's density otherwise.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "mcrt/core/math.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/sampling/bilinear_spherical_ellipse.hpp"
#include "mcrt/sampling/ellipse_area.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/spherical_ellipse.hpp"

namespace mcrt {

struct projected_ellipse_limits {
  static constexpr double max_conditioning = 1e6;  // kappa = wedge span / K
  static constexpr double min_clip_depth = 1e-12;  // 1 + delta_h
  static constexpr double min_projected = 1e-30;   // sr
  // A meridian plane whose chord offset |delta| exceeds 1 by at most this
  // is taken as tangent to the unit disk (delta clamped to +-1): the
  // wedge's end meridians are tangent by construction and round to
  // |delta| = 1 +- a few ulps; one that misses by more does not meet D.
  static constexpr double chord_slack = 1e-12;
  // Newton stops once |K(phi) - u1 K| <= tolerance * K.
  static constexpr double tolerance = 1e-9;
  static constexpr int max_iterations = 60;
};

// none: no sample (behind the light, or the light wholly below the
// horizon); exact: the projected map; fallback: the bilinear pre-warp.
enum class projected_ellipse_mode : std::uint8_t { none, exact, fallback };

// The canonical cone and the normal, as the boundary integrals use them.
struct projected_ellipse_consts {
  double a = 0.0, b = 0.0;
  double A = 1.0, B = 1.0, sAB = 1.0;  // 1 + a^2, 1 + b^2, sqrt(A B)
  double k = 0.0, j = 0.0;             // sqrt(d / A), sqrt(d / B), d = a^2 - b^2
  double c0 = 0.0;                     // a b / sqrt(A B)
  dvec3 nu{0.0, 0.0, 1.0};

  projected_ellipse_consts() = default;
  projected_ellipse_consts(const spherical_ellipse& se, const dvec3& n) : a(se.a), b(se.b), nu(n) {
    A = 1.0 + a * a;
    B = 1.0 + b * b;
    const double sA = std::sqrt(A), sB = std::sqrt(B);
    sAB = sA * sB;
    const double d = (a - b) * (a + b);
    k = std::sqrt(d) / sA;
    j = std::sqrt(d) / sB;
    c0 = (a / sA) * (b / sB);
  }
};

// log1p(x) / x and atan(y) / y, 1 at 0.
inline double projected_log1pc(double x) { return x == 0.0 ? 1.0 : std::log1p(x) / x; }
inline double projected_atanc(double y) { return y == 0.0 ? 1.0 : std::atan(y) / y; }

// int_P^Q g dt (eq. 1) along an arc of the unit circle from P to Q, given
// dtheta = Theta(Q) - Theta(P) along it (the only part that depends on the
// arc, not just on its ends). See the header comment for the forms.
inline double projected_arc_integral(const projected_ellipse_consts& k, dvec2 p, dvec2 q, double dtheta) {
  // int_{s_P}^{s_Q} ds / (A - d s^2)
  const double s1 = p.y, s2 = q.y, ds = s2 - s1;
  const double one_minus_ks2 =
      s2 > 0.0 ? (k.A * q.x * q.x + k.B * s2 * s2) / (k.A * (1.0 + k.k * s2)) : 1.0 - k.k * s2;
  const double one_plus_ks1 =
      s1 < 0.0 ? (k.A * p.x * p.x + k.B * s1 * s1) / (k.A * (1.0 - k.k * s1)) : 1.0 + k.k * s1;
  const double den1 = one_minus_ks2 * one_plus_ks1;
  const double f1 = ds / (k.A * den1) * projected_log1pc(2.0 * k.k * ds / den1);
  // int_{c_Q}^{c_P} dc / (B + d c^2)
  const double c1 = p.x, c2 = q.x, dc = c1 - c2;
  const double den2 = 1.0 + k.j * k.j * c1 * c2;
  const double f2 = den2 > 0.0 ? dc / (k.B * den2) * projected_atanc(k.j * dc / den2)
                               : std::atan2(k.j * dc, den2) / (k.j * k.B);  // j > 1 here
  return -k.nu.x * k.b * f1 - k.nu.y * k.a * f2 + k.nu.z * k.c0 * dtheta;
}

// Theta(X) - Theta(mu) for X within less than pi (in t) of the unit vector
// mu: one atan2 of the two points scaled by (sqrt A, sqrt B), which maps the
// half-turns about mu onto themselves, so no branch is needed.
inline double projected_theta_rel(const projected_ellipse_consts& k, dvec2 mu, dvec2 x) {
  return std::atan2(k.sAB * (mu.x * x.y - mu.y * x.x), k.A * mu.x * x.x + k.B * mu.y * x.y);
}

// Theta(Q) - Theta(P) along the counter-clockwise arc from P to Q, known to
// turn by more (long_arc) or less than pi in t: Theta and t turn by more than
// pi together. The atan2 gives it modulo 2 pi; a value within rounding of 0
// or 2 pi is put on the side the arc's length says.
inline double projected_theta_chord(const projected_ellipse_consts& k, dvec2 p, dvec2 q, bool long_arc) {
  constexpr double two_pi = 2.0 * std::numbers::pi, half_pi = 0.5 * std::numbers::pi;
  const double t = std::atan2(k.sAB * (p.x * q.y - p.y * q.x), k.A * p.x * q.x + k.B * p.y * q.y);
  if (long_arc) return t < half_pi ? t + two_pi : t;
  return t < -half_pi ? t + two_pi : std::max(t, 0.0);
}

// The light seen from (o, n), set up once per sample or pdf.
struct projected_spherical_ellipse {
  projected_ellipse_mode mode = projected_ellipse_mode::none;
  ellipse_cone cone;
  projected_ellipse_consts k;
  dvec3 tau1{1.0, 0.0, 0.0}, tau2{0.0, 1.0, 0.0};  // azimuth 0 and pi/2 about nu (cone frame)
  double k_total = 0.0;  // oint_{dD} rho^2 dphi = 2 Omega_proj
  double kappa = 1.0;    // conditioning of K(phi) (header comment)
  bool inside = false;   // nu inside S
  bool clipped = false;  // the horizon cuts the ellipse
  // The horizon, where it clips: the visible side w_h . p > delta_h of the
  // unit disk, its corners (visible arc from p_in to p_out counter-
  // clockwise) with their Theta relative to w_h and their azimuths, and the
  // boundary integral over the visible arc.
  dvec2 wh{0.0};
  double dh = -1.0;
  dvec2 p_in{0.0}, p_out{0.0};
  double th_in = 0.0, th_out = 0.0, phi_in = 0.0, phi_out = 0.0, j_visible = 0.0;
  // Range of the azimuth: [0, 2 pi] inside, the wedge [phi_a, phi_b] outside.
  double phi_lo = 0.0, phi_hi = 0.0;
  // Inside, unclipped: the reference meridian phi = 0's chord (w0 . p = ~0),
  // its ends q- (azimuth 0) and q+ (azimuth pi), their Theta relative to
  // +-w0, and the integral over the half from q- to q+.
  dvec2 w0{0.0}, q_minus{0.0}, q_plus{0.0};
  double th_qm = 0.0, th_qp = 0.0, k_half = 0.0;

  double omega_proj() const { return 0.5 * k_total; }
  // Azimuth about nu of a cone-frame vector, in (-pi, pi].
  double azimuth(const dvec3& v) const { return std::atan2(glm::dot(tau2, v), glm::dot(tau1, v)); }
  // Cone-frame direction of a unit-disk point.
  dvec3 direction(dvec2 p) const { return {k.a * p.x, k.b * p.y, 1.0}; }
};

// The meridian at azimuth phi: its chord of the unit disk and the segment
// [near, far] of it that lies in D (tangent-plane points (x, y) of the cone
// frame, with alpha = nu . (x, y, 1) and beta = e . (x, y, 1)).
struct projected_meridian {
  double phi = 0.0;
  dvec3 e{0.0};
  dvec2 w{0.0};  // unit normal of the chord: its points p have w . p = delta
  double delta = 0.0;
  dvec2 p_plus{0.0}, p_minus{0.0};
  dvec2 near_xy{0.0}, far_xy{0.0};
  double alpha_n = 0.0, beta_n = 0.0, alpha_f = 0.0, beta_f = 0.0;
  double rho2_n = 0.0, rho2_f = 0.0;  // sin^2 theta at the ends
  double cos2_n = 1.0, cos2_f = 1.0;  // cos^2 theta at the ends
  bool far_horizon = false;
};

namespace detail {

inline dvec3 normalized_or(const dvec3& v, const dvec3& fallback) {
  const double l2 = glm::dot(v, v);
  // Below 1e-300 the square root's argument is denormal-adjacent and v has
  // no direction worth keeping: the fallback axis instead.
  return l2 > 1e-300 ? v / std::sqrt(l2) : fallback;
}

// The chord of the unit disk cut by the plane m . (a xi, b eta, 1) = 0.
// False when the plane misses the disk by more than rounding.
inline bool projected_chord(const projected_ellipse_consts& k, const dvec3& m, dvec2& w, double& delta, dvec2& pp,
                            dvec2& pm) {
  const dvec2 ww{k.a * m.x, k.b * m.y};
  const double len = std::hypot(ww.x, ww.y);
  if (!(len > 0.0)) return false;
  w = ww / len;
  delta = -m.z / len;
  if (!(std::abs(delta) < 1.0 + projected_ellipse_limits::chord_slack)) return false;
  delta = std::clamp(delta, -1.0, 1.0);
  const double h = std::sqrt((1.0 - delta) * (1.0 + delta));
  const dvec2 wp{-w.y, w.x};
  pp = delta * w + h * wp;
  pm = delta * w - h * wp;
  return true;
}

}  // namespace detail

// alpha, beta, rho^2, cos^2 of a tangent-plane point seen along the meridian e.
inline void projected_polar(const projected_ellipse_consts& k, const dvec3& e, dvec2 xy, double& alpha, double& beta,
                            double& rho2, double& cos2) {
  const dvec3 v{xy.x, xy.y, 1.0};
  alpha = glm::dot(k.nu, v);
  beta = glm::dot(e, v);
  const double l2 = alpha * alpha + beta * beta;
  rho2 = beta * beta / l2;
  cos2 = alpha * alpha / l2;
}

// The meridian at azimuth phi of a set-up in the exact mode; false where it
// does not meet D (only within rounding of the wedge's ends).
inline bool projected_meridian_at(const projected_spherical_ellipse& ps, double phi, projected_meridian& mer) {
  const projected_ellipse_consts& k = ps.k;
  // Outside, phi = mid + half sin psi may round past the wedge's ends, where
  // the horizon's corners decide which formula applies.
  if (!ps.inside) phi = std::clamp(phi, ps.phi_lo, ps.phi_hi);
  mer.phi = phi;
  const double cp = std::cos(phi), sp = std::sin(phi);
  mer.e = cp * ps.tau1 + sp * ps.tau2;
  const dvec3 m = cp * ps.tau2 - sp * ps.tau1;  // nu x e
  if (!detail::projected_chord(k, m, mer.w, mer.delta, mer.p_plus, mer.p_minus)) return false;
  const dvec2 pm_xy{k.a * mer.p_minus.x, k.b * mer.p_minus.y};
  if (ps.inside) {
    // Entry at the pole: the gnomonic image of nu.
    mer.near_xy = {k.nu.x / k.nu.z, k.nu.y / k.nu.z};
    mer.alpha_n = 1.0 / k.nu.z;
    mer.beta_n = 0.0;
    mer.rho2_n = 0.0;
    mer.cos2_n = 1.0;
    mer.far_horizon = ps.clipped && phi > ps.phi_out;
  } else {
    mer.near_xy = {k.a * mer.p_plus.x, k.b * mer.p_plus.y};
    projected_polar(k, mer.e, mer.near_xy, mer.alpha_n, mer.beta_n, mer.rho2_n, mer.cos2_n);
    mer.far_horizon = ps.clipped && phi >= ps.phi_out && phi <= ps.phi_in;
  }
  if (mer.far_horizon) {
    // Exit where the chord crosses the horizon (alpha = 0) on its way from
    // the entry to p-.
    const double am = glm::dot(k.nu, dvec3(pm_xy, 1.0));
    const double lam = std::clamp(mer.alpha_n / (mer.alpha_n - am), 0.0, 1.0);
    mer.far_xy = mer.near_xy + lam * (pm_xy - mer.near_xy);
    mer.alpha_f = 0.0;
    mer.beta_f = glm::dot(mer.e, dvec3(mer.far_xy, 1.0));
    mer.rho2_f = 1.0;
    mer.cos2_f = 0.0;
  } else {
    mer.far_xy = pm_xy;
    projected_polar(k, mer.e, mer.far_xy, mer.alpha_f, mer.beta_f, mer.rho2_f, mer.cos2_f);
  }
  return true;
}

// K(phi): the boundary integral of rho^2 dphi over D's part with azimuth
// below phi (header comment), for a meridian of projected_meridian_at().
inline double projected_partial(const projected_spherical_ellipse& ps, const projected_meridian& mer) {
  const projected_ellipse_consts& k = ps.k;
  const dvec2 pp = mer.p_plus, pm = mer.p_minus;
  if (ps.inside) {
    if (ps.clipped) {
      if (mer.far_horizon) return ps.j_visible + (mer.phi - ps.phi_out);
      return projected_arc_integral(k, ps.p_in, pm, projected_theta_rel(k, ps.wh, pm) - ps.th_in);
    }
    if (mer.phi <= std::numbers::pi)
      return projected_arc_integral(k, ps.q_minus, pm, projected_theta_rel(k, ps.w0, pm) - ps.th_qm);
    return ps.k_half + projected_arc_integral(k, ps.q_plus, pm, projected_theta_rel(k, -ps.w0, pm) - ps.th_qp);
  }
  // Outside: from the entry p+ along dD round the wedge's start to the exit.
  // The chord's arc on the side of smaller azimuths runs counter-clockwise
  // from p+ to p- and turns by 2 acos(-delta), more than pi iff delta > 0.
  if (!ps.clipped || mer.phi < ps.phi_out)
    return projected_arc_integral(k, pp, pm, projected_theta_chord(k, pp, pm, mer.delta > 0.0));
  if (mer.far_horizon)
    return projected_arc_integral(k, pp, ps.p_out, ps.th_out - projected_theta_rel(k, ps.wh, pp)) +
           (mer.phi - ps.phi_out);
  // The path crosses the whole horizon arc: the complement of the chord's
  // other arc (counter-clockwise from p- to p+, turning by 2 acos(delta)).
  return ps.k_total - projected_arc_integral(k, pm, pp, projected_theta_chord(k, pm, pp, mer.delta < 0.0));
}

// The set-up for (o, n); f = ellipse_frame(e).
inline projected_spherical_ellipse make_projected_spherical_ellipse(const ellipse& e, const ellipse_frame& f,
                                                                    const vec3& o, const vec3& n) {
  using lim = projected_ellipse_limits;
  constexpr double two_pi = 2.0 * std::numbers::pi;
  projected_spherical_ellipse ps;
  if (!e.faces(o) || ellipse_below_horizon(f, o, n)) return ps;  // none
  ps.mode = projected_ellipse_mode::fallback;
  ps.cone = make_ellipse_cone<newton_carlson_solver>(e, f, o);
  const ellipse_cone& cone = ps.cone;
  if (cone.mode == ellipse_cone_mode::none) {
    ps.mode = projected_ellipse_mode::none;
    return ps;
  }
  // The exact map needs the cone's frame and tangents, not Omega: beyond
  // max_tangent alone it still runs (header comment).
  const bool usable = cone.mode == ellipse_cone_mode::spherical ||
                      (cone.se.b > ellipse_cone_limits::max_tangent && std::isfinite(cone.se.a) &&
                       cone.se.a <= ellipse_cone_limits::max_ratio * cone.se.b && std::isfinite(cone.r00) &&
                       std::isfinite(cone.r11));
  if (!usable) return ps;
  const dvec3 nu = ellipse_cone_normal(cone, n);
  if (!all_finite(vec3(nu))) return ps;
  ps.k = projected_ellipse_consts(cone.se, nu);
  const projected_ellipse_consts& k = ps.k;

  // The horizon nu . (a xi, b eta, 1) = 0 in the unit disk: w_h . p = delta_h.
  const dvec2 wh{k.a * nu.x, k.b * nu.y};
  const double lh = std::hypot(wh.x, wh.y);
  // nu along the cone's axis (lh = 0): no horizon line in the disk; -2 (the
  // whole light above, nu.z > 0) or 2 (wholly below) stand for it.
  double dh = lh > 0.0 ? -nu.z / lh : (nu.z > 0.0 ? -2.0 : 2.0);
  if (!(dh < 1.0)) return ps;  // below by the cone's arithmetic, not by the world test: rounding; fallback
  ps.clipped = 1.0 + dh > lim::min_clip_depth;
  // nu inside S: (nu_x / a)^2 + (nu_y / b)^2 < nu_z^2 with nu_z > 0.
  const dvec2 un{nu.x / k.a, nu.y / k.b};
  ps.inside = nu.z > 0.0 && glm::dot(un, un) < nu.z * nu.z;

  const dvec3 ez{0.0, 0.0, 1.0};
  if (ps.clipped) {
    ps.wh = wh / lh;
    ps.dh = dh;
    const double hh = std::sqrt((1.0 - dh) * (1.0 + dh));
    const dvec2 wp{-ps.wh.y, ps.wh.x};
    ps.p_in = dh * ps.wh - hh * wp;
    ps.p_out = dh * ps.wh + hh * wp;
    ps.th_in = projected_theta_rel(k, ps.wh, ps.p_in);
    ps.th_out = projected_theta_rel(k, ps.wh, ps.p_out);
    ps.j_visible = projected_arc_integral(k, ps.p_in, ps.p_out, ps.th_out - ps.th_in);
    const dvec3 v_in = ps.direction(ps.p_in), v_out = ps.direction(ps.p_out);
    // The horizon's part of dD, counter-clockwise about nu from p_out to
    // p_in: less than pi (S lies in an open hemisphere).
    const double span_h = std::max(0.0, std::atan2(glm::dot(nu, glm::cross(v_out, v_in)), glm::dot(v_out, v_in)));
    ps.k_total = ps.j_visible + span_h;
    if (ps.inside) {
      ps.tau1 = detail::normalized_or(v_in - glm::dot(nu, v_in) * nu, ez);
      ps.tau2 = glm::cross(nu, ps.tau1);
      ps.phi_in = 0.0;
      ps.phi_out = two_pi - span_h;
    } else {
      // Azimuth 0 through a point inside D: half-way across the visible cap.
      const dvec3 r = ps.direction(0.5 * (1.0 + dh) * ps.wh);
      ps.tau1 = detail::normalized_or(r - glm::dot(nu, r) * nu, ez);
      ps.tau2 = glm::cross(nu, ps.tau1);
      ps.phi_in = ps.azimuth(v_in);
      ps.phi_out = ps.azimuth(v_out);
    }
  } else {
    ps.k_total = two_pi * nu.z * k.c0;  // eq. 2
    // Azimuth 0 towards the cone's axis (in D).
    dvec3 t1, t2;
    detail::onb_double(nu, t1, t2);
    ps.tau1 = detail::normalized_or(ez - nu.z * nu, t1);
    ps.tau2 = glm::cross(nu, ps.tau1);
  }
  if (!(ps.k_total >= 2.0 * lim::min_projected) || !std::isfinite(ps.k_total)) return ps;

  if (ps.inside) {
    ps.phi_lo = 0.0;
    ps.phi_hi = two_pi;
    if (!ps.clipped) {
      // The reference meridian phi = 0 passes through the cone's axis:
      // its chord is a diameter, and either half of the boundary turns by pi.
      const dvec3 m0 = ps.tau2;
      double d0;
      if (!detail::projected_chord(k, m0, ps.w0, d0, ps.q_plus, ps.q_minus)) return ps;
      ps.th_qm = projected_theta_rel(k, ps.w0, ps.q_minus);
      ps.th_qp = projected_theta_rel(k, -ps.w0, ps.q_plus);
      ps.k_half =
          projected_arc_integral(k, ps.q_minus, ps.q_plus, projected_theta_rel(k, ps.w0, ps.q_plus) - ps.th_qm);
    }
  } else {
    // The wedge: extreme azimuths over the visible tangent points (meridians
    // tangent to the ellipse: the polar line of nu, (nu_x/a) xi + (nu_y/b)
    // eta = nu_z, cuts the unit circle in them) and the horizon's corners.
    double lo = std::numbers::pi, hi = -std::numbers::pi;
    const auto take = [&](double phi) {
      lo = std::min(lo, phi);
      hi = std::max(hi, phi);
    };
    const double lu = std::hypot(un.x, un.y);
    const double dt = lu > 0.0 ? nu.z / lu : 2.0;
    if (std::abs(dt) < 1.0) {
      const dvec2 uh = un / lu, up{-uh.y, uh.x};
      const double ht = std::sqrt((1.0 - dt) * (1.0 + dt));
      for (double sgn : {-1.0, 1.0}) {
        const dvec2 t = dt * uh + sgn * ht * up;
        if (!ps.clipped || glm::dot(ps.wh, t) > ps.dh) take(ps.azimuth(ps.direction(t)));
      }
    }
    if (ps.clipped) {
      take(ps.phi_in);
      take(ps.phi_out);
    }
    if (!(lo < hi)) return ps;
    ps.phi_lo = lo;
    ps.phi_hi = hi;
    ps.kappa = (hi - lo) / ps.k_total;
    if (!(ps.kappa <= lim::max_conditioning)) return ps;
  }
  ps.mode = projected_ellipse_mode::exact;
  return ps;
}

// The planar initial guess of newton_carlson_solver: psi in [-pi/2, pi/2]
// with (2 psi + sin 2 psi + pi) / (2 pi) = u, the area fraction of a disk cut
// by the chord at sin psi.
inline double projected_planar_guess(double u) {
  constexpr double pi = std::numbers::pi, half_pi = 0.5 * pi;
  const double v = std::abs(2.0 * u - 1.0), sign = u < 0.5 ? -1.0 : 1.0;
  double psi = v < 0.5 ? 0.25 * pi * v : half_pi - std::cbrt(0.75 * pi * (1.0 - v));
  for (int i = 0; i < 2; ++i) {
    const double c = std::cos(psi), fp = 4.0 * c * c;
    if (!(fp > 1e-12)) break;
    psi = std::clamp(psi - (2.0 * psi + std::sin(2.0 * psi) - pi * v) / fp, 0.0, half_pi);
  }
  return sign * psi;
}

// u -> the meridian (solved by Newton) and the tangent-plane point of the
// cone frame; `iterations` (optional) counts the K(phi) evaluations.
inline bool projected_square_to_point(const projected_spherical_ellipse& ps, dvec2 u, dvec2& xy,
                                      int* iterations = nullptr) {
  using lim = projected_ellipse_limits;
  constexpr double half_pi = 0.5 * std::numbers::pi;
  const double u1 = std::clamp(u.x, 0.0, 1.0), u2 = std::clamp(u.y, 0.0, 1.0);
  const double goal = u1 * ps.k_total;
  // The Newton variable x: phi itself inside, psi outside.
  const double mid = 0.5 * (ps.phi_lo + ps.phi_hi), half = 0.5 * (ps.phi_hi - ps.phi_lo);
  double lo, hi, x;
  if (ps.inside) {
    lo = 0.0;
    hi = ps.phi_hi;
    x = u1 * ps.phi_hi;
  } else {
    lo = -half_pi;
    hi = half_pi;
    x = projected_planar_guess(u1);
  }
  const auto to_phi = [&](double v) { return ps.inside ? v : mid + half * std::sin(v); };
  projected_meridian mer;
  bool have = false;
  int it = 0;
  for (; it < lim::max_iterations; ++it) {
    const bool ok = projected_meridian_at(ps, to_phi(x), mer);
    if (!ok) {
      // Within rounding of a wedge's end: the end's value, and bisect.
      (x < 0.5 * (lo + hi) ? lo : hi) = x;
      x = 0.5 * (lo + hi);
      continue;
    }
    have = true;
    const double f = projected_partial(ps, mer) - goal;
    if (std::abs(f) <= lim::tolerance * ps.k_total) break;
    (f < 0.0 ? lo : hi) = x;
    const double dphi = ps.inside ? 1.0 : half * std::cos(x);
    const double fp = (mer.rho2_f - mer.rho2_n) * dphi;
    double next = x - f / fp;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == x) break;  // the bracket is down to one ulp
    x = next;
  }
  if (iterations) *iterations = it + 1;
  if (!have) return false;
  // The conditional: sin^2 theta = rho_1^2 + u2 (rho_2^2 - rho_1^2) (and
  // cos^2 theta likewise from the cos^2 of the ends, no cancellation); the
  // point of the segment where beta cos theta - alpha sin theta = 0, linear
  // in the segment's parameter.
  const double rho2 = mer.rho2_n + u2 * (mer.rho2_f - mer.rho2_n);
  const double cos2 = (1.0 - u2) * mer.cos2_n + u2 * mer.cos2_f;
  const double st = std::sqrt(rho2), ct = std::sqrt(cos2);
  const double dn = mer.beta_n * ct - mer.alpha_n * st, df = mer.beta_f * ct - mer.alpha_f * st;
  const double lam = dn - df != 0.0 ? std::clamp(dn / (dn - df), 0.0, 1.0) : 0.0;
  xy = mer.near_xy + lam * (mer.far_xy - mer.near_xy);
  return all_finite(vec3(xy.x, xy.y, 0.0));
}

// Direction (cone frame) -> u in [0,1]^2, for a direction in D.
inline dvec2 projected_point_to_square(const projected_spherical_ellipse& ps, const dvec3& v) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  double phi = ps.azimuth(v);
  if (ps.inside) {
    if (phi < 0.0) phi += two_pi;
  } else {
    phi = std::clamp(phi, ps.phi_lo, ps.phi_hi);
  }
  projected_meridian mer;
  if (!projected_meridian_at(ps, phi, mer)) return {phi > 0.5 * (ps.phi_lo + ps.phi_hi) ? 1.0 : 0.0, 0.5};
  const double u1 = projected_partial(ps, mer) / ps.k_total;
  const double alpha = glm::dot(ps.k.nu, v), beta = glm::dot(mer.e, v);
  const double rho2 = beta * beta / (alpha * alpha + beta * beta);
  const double span = mer.rho2_f - mer.rho2_n;
  const double u2 = span > 0.0 ? (rho2 - mer.rho2_n) / span : 0.5;
  return {std::clamp(u1, 0.0, 1.0), std::clamp(u2, 0.0, 1.0)};
}

// Light-sampling strategy: by projected solid angle from (o, n), exact
// (header comment); the bilinear pre-warp where the exact map is
// ill-conditioned; nothing behind the light or for a light wholly below the
// horizon of n.
struct ellipse_projected_solid_angle_sampler {
  ellipse shape;  // fixed after construction

  explicit ellipse_projected_solid_angle_sampler(const ellipse& e) : shape(e), fallback_(e) {}

  bool faces(const vec3& o) const { return shape.faces(o); }

  projected_spherical_ellipse setup(const vec3& o, const vec3& n) const {
    return make_projected_spherical_ellipse(shape, fallback_.frame(), o, n);
  }

  // The point on the light (ellipse coordinates) that sample() maps u to,
  // with its density per unit solid angle, in double (for tests; the
  // fallback's from the bilinear sampler's own).
  bool sample_point(const vec3& o, const vec3& n, vec2 u, dvec2& xe, double& pdf, int* iterations = nullptr) const {
    const projected_spherical_ellipse ps = setup(o, n);
    if (ps.mode == projected_ellipse_mode::none) return false;
    if (ps.mode == projected_ellipse_mode::fallback) return fallback_.sample_point(o, n, u, xe, pdf);
    dvec2 xy;
    if (!projected_square_to_point(ps, dvec2(u), xy, iterations)) return false;
    xe = ps.cone.ellipse_coords(xy);
    // The density at the sampled direction: 2 cos theta / K.
    const dvec3 v = ps.cone.to_world(dvec3(xy, 1.0));
    pdf = 2.0 * glm::dot(dvec3(n), v) / (glm::length(dvec3(n)) * glm::length(v) * ps.k_total);
    return true;
  }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    const projected_spherical_ellipse ps = setup(o, n);
    if (ps.mode == projected_ellipse_mode::none) return false;
    if (ps.mode == projected_ellipse_mode::fallback) return fallback_.sample(o, n, u, s);
    dvec2 xy;
    if (!projected_square_to_point(ps, dvec2(u), xy)) return false;
    dvec2 xe = ps.cone.ellipse_coords(xy);
    // The map lands inside the ellipse; rounding may leave it ~1e-12 out.
    const double r2 = glm::dot(xe, xe);
    if (r2 > 1.0) xe /= std::sqrt(r2);
    const ellipse_frame& f = fallback_.frame();
    const dvec3 v = f.center - dvec3(o) + xe.x * f.a1 + xe.y * f.a2;
    const double len = glm::length(v);
    s.dir = vec3(v / len);
    s.dist = static_cast<float>(len);
    // The density of the float direction, exactly as pdf() evaluates it (so
    // the two agree bit for bit); a direction that rounds onto or below the
    // horizon returns no sample.
    s.pdf = exact_pdf(n, s.dir, ps.k_total);
    return std::isfinite(s.pdf) && s.pdf > 0.0f && all_finite(s.dir);
  }

  // Density per unit SOLID ANGLE at o (normal n) of the unit direction dir:
  // cos theta / Omega_proj above the horizon, 0 below, in the exact mode.
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const {
    float t;
    if (!shape.faces(o) || !shape.intersect({o, dir}, 0.0f, infinity, t)) return 0.0f;
    const projected_spherical_ellipse ps = setup(o, n);
    if (ps.mode == projected_ellipse_mode::none) return 0.0f;
    if (ps.mode == projected_ellipse_mode::fallback) return fallback_.pdf(o, n, dir);
    return exact_pdf(n, dir, ps.k_total);
  }

  // The u that sample() maps to dir (dir must hit the visible part of the
  // ellipse); false where sample() has no sample for (o, n).
  bool invert(const vec3& o, const vec3& n, const vec3& dir, vec2& u) const {
    const projected_spherical_ellipse ps = setup(o, n);
    if (ps.mode == projected_ellipse_mode::none) return false;
    if (ps.mode == projected_ellipse_mode::fallback) return fallback_.invert(o, n, dir, u);
    u = vec2(projected_point_to_square(ps, ps.cone.to_cone(dvec3(dir))));
    return true;
  }

  // The light's projected solid angle at o for the normal n (sr,
  // projected): K / 2 of the exact mode; 0 where it has none (nothing
  // visible, or the fallback's receivers).
  double projected_solid_angle(const vec3& o, const vec3& n) const {
    const projected_spherical_ellipse ps = setup(o, n);
    return ps.mode == projected_ellipse_mode::exact ? ps.omega_proj() : 0.0;
  }

  const ellipse_frame& frame() const { return fallback_.frame(); }

 private:
  // cos theta / Omega_proj = 2 cos theta / K (0 at or below the horizon),
  // cos theta of the float direction in double.
  static float exact_pdf(const vec3& n, const vec3& dir, double k_total) {
    const dvec3 nd(n), dd(dir);
    const double cos_theta = glm::dot(nd, dd) / (glm::length(nd) * glm::length(dd));
    return cos_theta > 0.0 ? static_cast<float>(2.0 * cos_theta / k_total) : 0.0f;
  }

  ellipse_bilinear_solid_angle_sampler fallback_;
};

}  // namespace mcrt
