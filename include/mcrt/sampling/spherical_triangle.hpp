#pragma once
// Sampling a triangle uniformly in the solid angle it subtends: the
// area-preserving map from the unit square to the spherical triangle of
// Arvo 1995, "Stratified Sampling of Spherical Triangles" (SIGGRAPH 95,
// pp. 437-438), below [Arvo95]; its inverse and its pdf, in the layout of
// warp.hpp, and the light-sampling strategy triangle_solid_angle_sampler with
// the interface of light_sample.hpp.
//
// The map [Arvo95, sec. 2]. Spherical triangle ABC (the directions from the
// observer o to the vertices p0, p1, p2), angle alpha at A, sides b = |AC|,
// c = |AB| (arc lengths), area Omega.
//  * First stage: the sub-triangle A B C' with C' on the arc AC and area
//    u1 Omega. [Arvo95] solves for cos |AC'| from Girard's formula (eq. 1)
//    and the cosine laws for angles (eqs. 2, 3).
//  * Second stage: the point P on the arc B C' at the angle theta from B with
//    1 - cos theta = u2 (1 - cos |BC'|) (the arcs from B sweep the
//    sub-triangle, and the area element along one of them is sin theta
//    dtheta).
// The density is 1 / Omega per unit SOLID ANGLE.
//
// Numerics. Every quantity is formed in double from the vertices' offsets
// p_i - o and the edges p_j - p_i, which are exact in double (differences of
// floats whose magnitudes are within 2^29 of each other; otherwise rounded
// by 2^-53 of the larger). Where [Arvo95], and code following it, cancel,
// this header uses equivalent closed forms instead; none of them switches to
// another density:
//  * the triple product a.((p1 - p0) x (p2 - p0)), the signed volume that
//    gives the facing side, Omega's numerator and sin alpha, is evaluated
//    with error-free transformations (triple_product), and the cross
//    products with an FMA (cross): rounded in plain double they would be
//    off by ~eps |a| / h relative for an observer at the height h;
//  * Omega is not Girard's alpha + beta + gamma - pi (eq. 1), which loses all
//    digits for small triangles. The free function triangle_solid_angle is
//    Van Oosterom & Strackee 1983 ("The Solid Angle of a Plane Triangle",
//    IEEE Trans. Biomed. Eng. 30(2)): tan(Omega / 2) = |a.(b x c)| / (abc +
//    (a.b)c + (a.c)b + (b.c)a), one atan2, with the triple product from the
//    edges; its denominator, though, cancels where two vertex directions are
//    nearly opposite (o close to the plane and to the interior of an edge),
//    with an error ~eps |a||b||c| / |den + i num|. spherical_triangle uses
//    the equivalent included-angle form of the next item with E = Omega,
//    which has no such cancellation and is the one the first stage inverts;
//    2 pi - Omega comes from the same atan2 with its denominator negated;
//  * the first stage in closed form. The area E of a spherical triangle with
//    sides x, y and included angle alpha satisfies (e.g. Todhunter,
//    "Spherical Trigonometry", 1886, art. 103)
//      tan(E/2) = tan(x/2) tan(y/2) sin alpha / (1 + tan(x/2) tan(y/2) cos alpha),
//    so the sub-triangle of area E = u1 Omega at A with the side c fixed
//    has its other side b' = |AC'| at
//      tan(b'/2) = sin(E/2) / (tan(c/2) sin(alpha - E/2)),           (*)
//    with sin(alpha - E/2) = sin alpha cos(E/2) - cos alpha sin(E/2) by the
//    addition theorem (E/2 < alpha always: the triangle lies inside the lune
//    of angle alpha, area 2 alpha). No 1 - cos, no Arvo's sin(A' - alpha)
//    (which rounds the sub-area u1 Omega against alpha), no acos; sin alpha
//    comes from the triple product, (a x e_ab) x (a x e_ac) = a (a.(e_ab x
//    e_ac)), so it keeps its relative precision for slivers;
//  * the second stage by half angles: sin^2(theta/2) = u2 sin^2(|BC'|/2),
//    i.e. tan(theta/2) = sqrt(u2) / sqrt(cot^2(|BC'|/2) + 1 - u2), with
//    cot(|BC'|/2) from a cross and a dot product (cot_half_angle);
//  * both stages end on the plane of the triangle, not on the sphere: the
//    ray at the angle phi from the direction of a vertex v towards the
//    point v + t e of an edge meets it at (plane geometry in the plane of o,
//    v and e)
//      t = |v|^2 sin phi / (|v x e| cos phi - (e.v) sin phi),          (**)
//    (v the vertex's offset from o), with sin phi and cos phi formed from
//    tan(phi/2) as 2 y / (1 + y^2), (1 - y^2) / (1 + y^2) without a
//    division by the half-angle's cosine. C' is the point p0 + t (p2 - p0)
//    of the edge, P the point p1 + s (C' - p1) of the segment from p1: the
//    sample is the convex combination (1 - s) p1 + s ((1 - t) p0 + t p2), so
//    it lies on the triangle whatever the rounding once t and s are clamped
//    to [0, 1].
// The inverse follows the same path backwards: the barycentric coordinates
// of the ray's hit (triple products), t and s from them, u1 = E / Omega with
// E from the included-angle form for the side b' = |AC'|, u2 the ratio of
// the two sin^2 of half angles.
//
// Accuracy (tests/test_spherical_triangle.cpp). Omega to a few ulp from
// 1e-11 sr to 2 pi - 6e-7 sr, for slivers and observers 1e-7 of the size
// from the plane (at most 4 ulp measured over random extremes against a
// 50-digit reference), 2 pi - Omega likewise. The map's directions agree
// with Arvo's formulas evaluated in 50 digits to 16 eps (1 + L / h) rad (L
// the largest distance to a vertex, h the height): a point of the plane is
// formed from coordinates of the size of the triangle, so near the foot of
// a low observer its direction carries ~eps L / h, 8e-9 rad at h = 1e-7 L,
// below the rounding of the float direction the sampler returns.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>

#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/light_sample.hpp"

// Not inlined: the per-observer set-up, the triple product and the ray test
// (below) must give
// bitwise the same Omega and the same hit decision in sample() and pdf() (and
// wherever else they are called), so that a sample's pdf equals pdf() of its
// direction. Inlined into different callers, a compiler may contract a * b + c
// into FMAs differently (GCC's default for GNU C++ is -ffp-contract=fast),
// and a direction at the rim would hit in one and miss in the other.
#if defined(__GNUC__)
#define MCRT_NOINLINE __attribute__((noinline))
#else
#define MCRT_NOINLINE
#endif

namespace mcrt {

namespace spherical_triangle_detail {

// cot(theta/2) of the angle theta between two vectors u, v from |u x v|,
// |u| |v| and u.v: (|u||v| + u.v) / |u x v| when u.v >= 0, otherwise the
// equal |u x v| / (|u||v| - u.v); either way a sum of non-negative terms
// (the first form cancels for theta near pi, the second for theta near 0).
inline double cot_half_angle(double cross_len, double len_product, double dot) {
  return dot >= 0.0 ? (len_product + dot) / cross_len : cross_len / (len_product - dot);
}
// tan(theta/2), the reciprocal, by the same rule.
inline double tan_half_angle(double cross_len, double len_product, double dot) {
  return dot >= 0.0 ? cross_len / (len_product + dot) : (len_product - dot) / cross_len;
}
// sin^2(theta/2) = (1 - cos theta) / 2 by the same rule: |u x v|^2 /
// (2 |u||v| (|u||v| + u.v)) when u.v >= 0, (|u||v| - u.v) / (2 |u||v|)
// otherwise.
inline double sin2_half_angle(double cross_len, double len_product, double dot) {
  return dot >= 0.0 ? cross_len * cross_len / (2.0 * len_product * (len_product + dot))
                    : (len_product - dot) / (2.0 * len_product);
}

// The numerator |a.(b x c)| and denominator of Van Oosterom & Strackee's
// tan(Omega/2) for the offsets a, b, c (lengths la, lb, lc) and the triple
// product `triple` formed from the edges.
struct vos_terms {
  double num, den;
};
inline vos_terms van_oosterom_strackee(const dvec3& a, const dvec3& b, const dvec3& c, double la, double lb,
                                       double lc, double triple) {
  return {std::abs(triple),
          la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la};
}

// The error-free transformations below need every product and sum rounded
// by itself: GCC contracts a * b + c into one FMA across statements by
// default (-ffp-contract=fast for GNU C++), which would fold the product
// into the following sum and lose exactly the error term they recover. So
// these few functions are compiled with contraction off (GCC's per-function
// optimize pragma; Clang contracts only within one expression by default,
// and the pragma inside each function keeps it off even under
// -ffp-contract=fast). They are then not inlined into code compiled with
// other flags, one call per set-up.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#endif
#if defined(__clang__)
#define MCRT_NO_FP_CONTRACT _Pragma("clang fp contract(off)")
#else
#define MCRT_NO_FP_CONTRACT
#endif

// Error-free transformations (Ogita, Rump & Oishi 2005, "Accurate Sum and
// Dot Product", SIAM J. Sci. Comput. 26(6), algs. 3.1 and 3.3 with an FMA):
// x y = p + e and x + y = s + e exactly.
inline void two_product(double x, double y, double& p, double& e) {
  MCRT_NO_FP_CONTRACT
  p = x * y;
  e = std::fma(x, y, -p);
}
inline void two_sum(double x, double y, double& s, double& e) {
  MCRT_NO_FP_CONTRACT
  s = x + y;
  const double z = s - x;
  e = (x - (s - z)) + (y - z);
}

// a.(e x f) to a few ulp of the result: each 2x2 minor as an unevaluated
// sum hi + lo (two_product, two_sum), then the dot product with a in
// compensated arithmetic (Ogita-Rump-Oishi's Dot2). A triple product
// rounded in plain double is off by ~eps |a| |e x f|: relative eps |a| / h
// for an observer at the height h above the plane, which the density and
// the facing decision would inherit.
MCRT_NOINLINE inline double triple_product(const dvec3& a, const dvec3& e, const dvec3& f) {
  MCRT_NO_FP_CONTRACT
  const auto minor = [](double u, double v, double w, double z, double& hi, double& lo) {
    double p1, e1, p2, e2, es;
    two_product(u, v, p1, e1);
    two_product(w, z, p2, e2);
    two_sum(p1, -p2, hi, es);
    lo = es + (e1 - e2);
  };
  double hi[3], lo[3];
  minor(e.y, f.z, e.z, f.y, hi[0], lo[0]);
  minor(e.z, f.x, e.x, f.z, hi[1], lo[1]);
  minor(e.x, f.y, e.y, f.x, hi[2], lo[2]);
  const double ai[3] = {a.x, a.y, a.z};
  double sum = 0.0, err = 0.0;
  for (int i = 0; i < 3; ++i) {
    double p, pe, s, se;
    two_product(ai[i], hi[i], p, pe);
    two_sum(sum, p, s, se);
    sum = s;
    err += pe + se + ai[i] * lo[i];
  }
  return sum + err;
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif
#undef MCRT_NO_FP_CONTRACT

// The next two are outside the contraction-off region: they contract nothing
// (std::fma is explicit, and no plain product meets a sum), and GCC does not
// inline a function compiled with other optimize options into its callers,
// which made each cross product a call (a quarter of the sampler's time).

// u v - w z to within 1.5 ulp of the result whatever the cancellation
// (Kahan's algorithm with an FMA; Jeannerod, Louvet & Muller 2013).
inline double difference_of_products(double u, double v, double w, double z) {
  const double wz = w * z;
  return std::fma(u, v, -wz) + std::fma(-w, z, wz);
}

// u x v with every component to 1.5 ulp. The plain formula loses the
// relative precision of u x v when u and v are nearly parallel (an observer
// close to the line of an edge: the vertex offset and the edge).
inline dvec3 cross(const dvec3& u, const dvec3& v) {
  return {difference_of_products(u.y, v.z, u.z, v.y), difference_of_products(u.z, v.x, u.x, v.z),
          difference_of_products(u.x, v.y, u.y, v.x)};
}

// (p0 - o).((p1 - p0) x (p2 - p0)): negative where o is on the side the
// winding normal (p1 - p0) x (p2 - p0) points to. The offsets and edges are
// exact in double (differences of floats), the product accurate
// (triple_product). One function for the sampler's facing test and the
// set-up, so both decide alike.
inline double orientation_triple(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2) {
  return triple_product(p0 - o, p1 - p0, p2 - p0);
}

// dir.(b x c), dir.(c x a), dir.(a x b) for the offsets a, b, c of the
// vertices p0, p1, p2, the cross products formed from the edges: b x c =
// b x (p2 - p1), c x a = c x (p0 - p2), a x b = a x (p1 - p0). They are the
// barycentric coordinates of the hit of the ray along dir times
// dir.((p1 - p0) x (p2 - p0)).
inline void edge_triple_products(const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& p0, const dvec3& p1,
                                 const dvec3& p2, const dvec3& dir, double& g0, double& g1, double& g2) {
  g0 = glm::dot(dir, cross(b, p2 - p1));
  g1 = glm::dot(dir, cross(c, p0 - p2));
  g2 = glm::dot(dir, cross(a, p1 - p0));
}

// Whether the ray o + t dir, t > 0, meets the triangle (edges included),
// and where (t_hit), for the offsets a, b, c = p_i - o and the triple
// product `triple` = orientation_triple(o, p0, p1, p2), nonzero: inside,
// the three edge_triple_products have its sign. One function (not inlined,
// see MCRT_NOINLINE) for spherical_triangle::hits and the sampler's pdf().
MCRT_NOINLINE inline bool ray_hits_triangle(const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& p0,
                                            const dvec3& p1, const dvec3& p2, double triple, const dvec3& dir,
                                            double& t_hit) {
  double g0, g1, g2;
  edge_triple_products(a, b, c, p0, p1, p2, dir, g0, g1, g2);
  const double sg = triple > 0.0 ? 1.0 : -1.0;
  g0 *= sg, g1 *= sg, g2 *= sg;
  const double g = g0 + g1 + g2;  // = sg dir.((p1 - p0) x (p2 - p0))
  if (!(g0 >= 0.0 && g1 >= 0.0 && g2 >= 0.0 && g > 0.0)) return false;
  t_hit = std::abs(triple) / g;
  return std::isfinite(t_hit) && t_hit > 0.0;
}

}  // namespace spherical_triangle_detail

// Solid angle (sr) of the triangle p0 p1 p2 seen from o, by Van Oosterom &
// Strackee 1983 (see the header comment), in [0, 2 pi); relative error a
// few ulp from the smallest solid angles to near 2 pi, except next to the
// interior of an edge, where the denominator cancels (header comment;
// spherical_triangle::solid_angle() has no such exception).
inline double triangle_solid_angle(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2) {
  const dvec3 a = p0 - o, b = p1 - o, c = p2 - o;
  const double triple = spherical_triangle_detail::orientation_triple(o, p0, p1, p2);
  const auto t = spherical_triangle_detail::van_oosterom_strackee(a, b, c, glm::length(a), glm::length(b),
                                                                  glm::length(c), triple);
  return 2.0 * std::atan2(t.num, t.den);
}

// Per-observer set-up of the spherical triangle of p0 p1 p2 seen from o, the
// map [Arvo95] between it and the unit square, and its inverse. Two-sided:
// valid wherever o is off the triangle's plane (the strategy below adds the
// one-sided rule). The vertex order fixes the map: A = p0, B = p1, C = p2.
class spherical_triangle {
 public:
  MCRT_NOINLINE spherical_triangle(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2)
      : p0_(p0), p1_(p1), p2_(p2) {
    using namespace spherical_triangle_detail;
    a_ = p0 - o, b_ = p1 - o, c_ = p2 - o;
    eab_ = p1 - p0, eac_ = p2 - p0;
    la_ = glm::length(a_), lb_ = glm::length(b_), lc_ = glm::length(c_);
    triple_ = orientation_triple(o, p0, p1, p2);
    // In the plane, a degenerate triangle, or NaN: no spherical triangle.
    if (!(std::abs(triple_) > 0.0) || !std::isfinite(triple_) || !(la_ > 0.0 && lb_ > 0.0 && lc_ > 0.0)) return;
    // The angle alpha at A between the planes (o, A, B) and (o, A, C), with
    // normals a x e_ab and a x e_ac; their cross product is a (a.(e_ab x
    // e_ac)), so sin alpha = |a| |triple| / (|a x e_ab| |a x e_ac|), with
    // the relative precision of the triple product also for slivers.
    const dvec3 nab = cross(a_, eab_), nac = cross(a_, eac_);
    const double lnab = glm::length(nab);
    lnac_ = glm::length(nac);
    const double inv = 1.0 / (lnab * lnac_);
    sin_alpha_ = la_ * std::abs(triple_) * inv;
    cos_alpha_ = glm::dot(nab, nac) * inv;
    tan_half_c_ = tan_half_angle(lnab, la_ * lb_, glm::dot(a_, b_));  // c = |AB|
    const double tan_half_b = tan_half_angle(lnac_, la_ * lc_, glm::dot(a_, c_));  // b = |AC|
    eac_dot_a_ = glm::dot(eac_, a_);
    // Omega from the two sides at A and the angle between them (the formula
    // of the header comment with E = Omega), equal to Van Oosterom-Strackee's
    // and computed from the same accurate triple product, but without its
    // denominator abc + (a.b)c + (a.c)b + (b.c)a, which cancels where two
    // vertex directions are nearly opposite (o close to the plane and to the
    // interior of an edge). The same formula inverts the first stage.
    omega_ = 2.0 * half_sub_area(tan_half_b, false);
    // 2 pi - Omega, accurate near 2 pi. sample_offset reads it only where
    // u1 Omega / 2 > pi / 2, so only for Omega > pi; below, 2 pi - Omega >=
    // pi holds its relative precision anyway, and one atan2 is saved.
    omega_complement_ = omega_ > std::numbers::pi ? 2.0 * half_sub_area(tan_half_b, true)
                                                  : 2.0 * std::numbers::pi - omega_;
    valid_ = omega_ > 0.0 && std::isfinite(omega_) && std::isfinite(omega_complement_) &&
             std::isfinite(sin_alpha_) && std::isfinite(cos_alpha_) && tan_half_c_ > 0.0 &&
             std::isfinite(tan_half_c_);
  }

  // Whether o is off the plane of a non-degenerate triangle.
  bool valid() const { return valid_; }
  // Solid angle subtended at o, in sr (0 when !valid()).
  double solid_angle() const { return omega_; }
  // (p0 - o).((p1 - p0) x (p2 - p0)): its sign tells o's side.
  double triple() const { return triple_; }
  // Density per unit SOLID ANGLE of the map, 1 / Omega (0 when !valid()).
  double pdf() const { return valid_ ? 1.0 / omega_ : 0.0; }

  // u in [0,1]^2 -> the point of the triangle minus o, in double. The
  // direction (normalised) is uniform in the spherical triangle.
  dvec3 sample_offset(dvec2 u) const {
    using namespace spherical_triangle_detail;
    constexpr double half_pi = 0.5 * std::numbers::pi;
    // ---- First stage, (*): E = u1 Omega, tan(b'/2) = sin(E/2) / M with
    // M = tan(c/2) sin(alpha - E/2).
    const double half = 0.5 * u.x * omega_;
    double sh, ch;  // sin(E/2), cos(E/2)
    if (half <= half_pi) {
      sh = std::sin(half), ch = std::cos(half);
    } else {
      // pi - E/2 = (2 pi - Omega + (1 - u1) Omega) / 2, a sum of non-negative
      // terms: sin(E/2) keeps its relative precision as E/2 nears pi.
      const double rest = 0.5 * (omega_complement_ + (1.0 - u.x) * omega_);
      sh = std::sin(rest), ch = -std::cos(rest);
    }
    const double m = tan_half_c_ * (sin_alpha_ * ch - cos_alpha_ * sh);
    // (**) on the edge p0 -> p2 (v = a, e = e_ac), with tan(b'/2) = sh / m:
    // sin b' ~ 2 sh m, cos b' ~ m^2 - sh^2 (the common factor cancels).
    double t = 1.0;
    // Guard: m > 0 and a positive denominator hold exactly (E/2 < alpha and
    // b' <= b, whose ray meets the edge in front of o); rounding can break
    // them only next to b' = b, the edge's end t = 1, which they default to.
    if (m > 0.0) {
      const double num = 2.0 * sh * m * la_ * la_;
      const double den = lnac_ * (m * m - sh * sh) - 2.0 * sh * m * eac_dot_a_;
      if (den > 0.0) t = std::min(num / den, 1.0);  // clamp: C' on the edge (rounding past p2)
    }
    // ---- Second stage: P on the segment p1 -> C', sin^2(theta/2) =
    // u2 sin^2(theta_max/2), theta_max = |BC'|. With r = cot(theta_max/2):
    // tan(theta/2) = Y / Z, Y = sqrt(u2), Z = sqrt(r^2 + 1 - u2), so
    // sin theta ~ 2 Y Z, cos theta ~ Z^2 - Y^2 = r^2 + 1 - 2 u2.
    const dvec3 q = a_ + t * eac_;   // C' - o
    const dvec3 e2 = t * eac_ - eab_;  // C' - p1
    const double ln2 = glm::length(spherical_triangle_detail::cross(b_, e2));
    // Guard: b x (C' - p1) = 0 only with o on the line p1 C', i.e. in the
    // plane, which valid() excludes; kept against rounding: P = p1.
    if (!(ln2 > 0.0)) return b_;
    const double r = cot_half_angle(ln2, lb_ * glm::length(q), glm::dot(b_, q));
    const double yz2 = 2.0 * std::sqrt(u.y) * std::sqrt(r * r + (1.0 - u.y));  // 2 Y Z
    // (**) on the segment p1 -> C' (v = b, e = e2); same guard as above.
    double s = 1.0;
    const double den = ln2 * (r * r + (1.0 - 2.0 * u.y)) - yz2 * glm::dot(e2, b_);
    if (den > 0.0) s = std::min(yz2 * lb_ * lb_ / den, 1.0);  // clamp: P on the segment
    return b_ + s * e2;
  }

  // The unit direction of sample_offset(u).
  dvec3 sample_direction(dvec2 u) const { return glm::normalize(sample_offset(u)); }

  // The inverse: a vector v from o whose ray meets the triangle -> u. A ray
  // that misses by rounding is taken to the nearest point of the edge it
  // crosses (barycentric coordinates clamped to >= 0).
  dvec2 invert_offset(const dvec3& v) const {
    using namespace spherical_triangle_detail;
    if (!valid_) return {0.0, 0.0};
    double w0, w1, w2;
    barycentric(v, w0, w1, w2);
    // Clamp: project a hit outside by rounding back onto the triangle.
    w0 = std::max(w0, 0.0), w1 = std::max(w1, 0.0), w2 = std::max(w2, 0.0);
    const double sum = w0 + w1 + w2;
    if (!(sum > 0.0)) return {0.0, 0.0};
    w0 /= sum, w1 /= sum, w2 /= sum;
    // P = (1 - s) p1 + s ((1 - t) p0 + t p2): s = w0 + w2, t = w2 / s.
    const double s = w0 + w2;
    if (!(s > 0.0)) return {0.0, 0.0};  // P = p1: any u1, u2 = 0
    const double t = std::min(w2 / s, 1.0);
    const dvec3 q = a_ + t * eac_, e2 = t * eac_ - eab_;
    const double lq = glm::length(q);
    // u1 = E / Omega, E the area of A B C' by the first stage's formula
    // from b' = |AC'| (a x q = t a x e_ac).
    const double u1 =
        2.0 * half_sub_area(tan_half_angle(t * lnac_, la_ * lq, glm::dot(a_, q)), false) / omega_;
    // u2 = sin^2(theta/2) / sin^2(theta_max/2); b x (P - o) = s b x e2.
    const dvec3 p = b_ + s * e2;
    const double ln2 = glm::length(spherical_triangle_detail::cross(b_, e2));
    const double top = sin2_half_angle(s * ln2, lb_ * glm::length(p), glm::dot(b_, p));
    const double bottom = sin2_half_angle(ln2, lb_ * lq, glm::dot(b_, q));
    const double u2 = bottom > 0.0 ? top / bottom : 0.0;
    // Clamp: rounding may put either a hair outside [0, 1].
    return {std::clamp(u1, 0.0, 1.0), std::clamp(u2, 0.0, 1.0)};
  }

  // Whether the ray o + t dir, t > 0, meets the triangle (edges included),
  // and where: t_hit. In double, from the signs of the triple products
  // dir.(b x c), dir.(c x a), dir.(a x b), which are the barycentric
  // coordinates of the hit times dir.(winding normal).
  bool hits(const dvec3& dir, double& t_hit) const {
    return valid_ && spherical_triangle_detail::ray_hits_triangle(a_, b_, c_, p0_, p1_, p2_, triple_, dir, t_hit);
  }

 private:
  // Half the area E of the spherical triangle with the sides |AB| = c and
  // y (tan(y/2) given) enclosing alpha at A:
  // tan(E/2) = x sin alpha / (1 + x cos alpha), x = tan(y/2) tan(c/2); by
  // atan2, so E/2 in [0, pi); with complement, pi - E/2 (the denominator
  // negated), accurate as E/2 nears pi.
  double half_sub_area(double tan_half_y, bool complement) const {
    const double x = tan_half_y * tan_half_c_;
    const double den = 1.0 + x * cos_alpha_;
    return std::atan2(x * sin_alpha_, complement ? -den : den);
  }

  // Barycentric coordinates (w0, w1, w2) of the hit of the ray o + t v with
  // the triangle's plane (unclamped; they sum to 1).
  void barycentric(const dvec3& v, double& w0, double& w1, double& w2) const {
    double g0, g1, g2;
    spherical_triangle_detail::edge_triple_products(a_, b_, c_, p0_, p1_, p2_, v, g0, g1, g2);
    const double g = g0 + g1 + g2;
    w0 = g0 / g, w1 = g1 / g, w2 = g2 / g;
  }

  dvec3 p0_, p1_, p2_;
  dvec3 a_{0.0}, b_{0.0}, c_{0.0}, eab_{0.0}, eac_{0.0};
  double la_ = 0.0, lb_ = 0.0, lc_ = 0.0, lnac_ = 0.0;  // |a|, |b|, |c|, |a x e_ac|
  double triple_ = 0.0, omega_ = 0.0, omega_complement_ = 0.0;
  double sin_alpha_ = 0.0, cos_alpha_ = 0.0, tan_half_c_ = 0.0, eac_dot_a_ = 0.0;
  bool valid_ = false;
};

// The map of [Arvo95] as free functions of the observer and the vertices
// (A = p0, B = p1, C = p2), after warp.hpp: u -> unit direction, its density
// per unit SOLID ANGLE 1 / Omega (0 where o is in the triangle's plane; the
// same for every direction into the triangle), and the inverse.
inline dvec3 square_to_spherical_triangle(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2,
                                          dvec2 u) {
  return spherical_triangle(o, p0, p1, p2).sample_direction(u);
}
inline double square_to_spherical_triangle_pdf(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2) {
  return spherical_triangle(o, p0, p1, p2).pdf();
}
inline dvec2 spherical_triangle_to_square(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2,
                                          const dvec3& dir) {
  return spherical_triangle(o, p0, p1, p2).invert_offset(dir);
}

// Light-sampling strategy: uniform in the solid angle of one triangle of a
// mesh, by spherical_triangle, with the density 1 / Omega per unit solid
// angle everywhere on the triangle (no fallback). One-sided as
// triangle_area_sampler: an observer behind the front side (the side
// triangle::normal() points to) or in the plane gets no sample and pdf 0.
// The side is decided in double from the exact offsets
// (orientation_triple), so that it agrees with the spherical triangle's
// orientation; triangle_area_sampler's float test can decide otherwise only
// within the float rounding of o and the vertices (~1e-7 of the
// coordinates) of the plane.
struct triangle_solid_angle_sampler {
  triangle shape;
  // Fixed after construction: the vertices and the front normal.
  vec3 p0{0.0f}, p1{0.0f}, p2{0.0f}, n{0.0f, 0.0f, 1.0f};

  // back: sample the triangle's back side instead (the other half of a
  // two-sided light).
  explicit triangle_solid_angle_sampler(const triangle& t, bool back = false)
      : shape(t), p0(t.vertex(0)), p1(t.vertex(1)), p2(t.vertex(2)), n(back ? -t.normal() : t.normal()) {
    const dvec3 w = glm::cross(dvec3(p1) - dvec3(p0), dvec3(p2) - dvec3(p0));
    front_sign_ = glm::dot(w, dvec3(n)) < 0.0 ? 1.0 : -1.0;
  }

  bool faces(const vec3& o) const {
    return front_sign_ * spherical_triangle_detail::orientation_triple(dvec3(o), dvec3(p0), dvec3(p1), dvec3(p2)) > 0.0;
  }

  bool sample(const vec3& o, vec2 u, light_sample& s) const {
    const spherical_triangle st = set_up(o);
    if (!st.valid() || !(front_sign_ * st.triple() > 0.0)) return false;
    const dvec3 v = st.sample_offset(dvec2(u));
    double t_hit = 0.0;
    s.dir = to_float_direction(v);
    if (!st.hits(dvec3(s.dir), t_hit)) {
      // The point v lies on the triangle, but its direction rounded to float
      // may miss it by a hair at the rim: move the point towards the
      // centroid in growing steps (2^-20, 2^-16, .., 2^-4 of the way, then
      // all of it) until the float direction hits. Only samples within the
      // rounding of a float direction (~1e-7 rad) of the rim move, by about
      // that much; the density stays 1 / Omega.
      const dvec3 centroid = (dvec3(p0) + dvec3(p1) + dvec3(p2)) / 3.0 - dvec3(o);
      bool hit = false;
      for (double lambda = 0x1p-20; lambda <= 1.0 && !hit; lambda = lambda < 0.25 ? 16.0 * lambda : 2.0 * lambda) {
        const vec3 d = to_float_direction(v + std::min(lambda, 1.0) * (centroid - v));
        if (st.hits(dvec3(d), t_hit)) s.dir = d, hit = true;
      }
      // No float direction resolves the triangle (it subtends ~1e-7 rad
      // or less across): the direction towards the sample, its distance;
      // the only case where pdf() of the returned direction is 0 (the fuzz
      // test saw it for triangles under 2^-21 rad wide only).
      if (!hit) t_hit = glm::length(v);
    }
    s.dist = float(t_hit);
    s.pdf = float(st.pdf());
    return s.pdf > 0.0f && std::isfinite(s.pdf) && s.dist > 0.0f;
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir: 1 / Omega
  // where the ray meets the triangle (edges included, in double) and o
  // faces its front, 0 elsewhere.
  // The facing and ray tests come first, with the functions the set-up
  // uses, so a direction that misses (most directions a BSDF samples) costs
  // no set-up.
  float pdf(const vec3& o, const vec3& dir) const {
    using namespace spherical_triangle_detail;
    const dvec3 od(o), q0(p0), q1(p1), q2(p2);
    const double triple = orientation_triple(od, q0, q1, q2);
    double t_hit;
    if (!(front_sign_ * triple > 0.0) || !ray_hits_triangle(q0 - od, q1 - od, q2 - od, q0, q1, q2, triple, dvec3(dir), t_hit))
      return 0.0f;
    const spherical_triangle st = set_up(o);
    if (!st.valid()) return 0.0f;
    const float p = float(st.pdf());
    return std::isfinite(p) ? p : 0.0f;
  }

  // The inverse of sample(): the unit-square point whose sample has the
  // direction dir (for a dir that meets the triangle; (0, 0) if o does not
  // face it).
  vec2 inverse(const vec3& o, const vec3& dir) const {
    const spherical_triangle st = set_up(o);
    if (!st.valid() || !(front_sign_ * st.triple() > 0.0)) return {0.0f, 0.0f};
    return vec2(st.invert_offset(dvec3(dir)));
  }

 private:
  // The unit float direction of v. Not inlined, so that the direction tested
  // against the triangle is the rounded float one that sample() returns: GCC
  // 12's SLP vectorizer was seen to forward the double value through a
  // double -> float -> double round trip (at -O3; not with
  // -fno-tree-slp-vectorize), which would test an unrounded direction.
  MCRT_NOINLINE static vec3 to_float_direction(const dvec3& v) { return vec3(glm::normalize(v)); }

  spherical_triangle set_up(const vec3& o) const { return {dvec3(o), dvec3(p0), dvec3(p1), dvec3(p2)}; }
  // +1 where o faces the front with orientation_triple > 0, i.e. where the
  // front normal and the winding normal (p1 - p0) x (p2 - p0) disagree.
  double front_sign_ = -1.0;
};

}  // namespace mcrt

#undef MCRT_NOINLINE
