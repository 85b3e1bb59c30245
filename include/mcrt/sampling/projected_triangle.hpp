#pragma once
// Sampling a triangle light in proportion to projected solid angle at a
// receiver with unit normal n: density cos(theta) / Omega_proj per unit
// SOLID ANGLE (cos(theta) = n . dir), i.e. 1 / Omega_proj per unit projected
// solid angle, over the part of the triangle above the receiver's horizon.
// For an unoccluded triangle of constant radiance L on a diffuse receiver
// the estimate L cos(theta) / pdf = L Omega_proj has zero variance. After
// Peters 2021, "BRDF Importance Sampling for Polygonal Lights" (ACM TOG
// 40(4), SIGGRAPH 2021), below [P21]: the triangle is the 3-vertex case of
// the rectangle's construction (projected_rectangle.hpp, whose header
// derives every form used here), with the same choice of forms, the same
// thresholds and the same exact fallback.
//
// Steps (per receiver point; the light's frame is cached by the strategy):
//  1. The light frame: o at the origin, the triangle in the plane z = -h,
//     h > 0 (one-sided light, front = triangle::normal(): no sample behind
//     it), its vertices wound counter-clockwise seen from the front, each
//     edge k a vector E_k formed from the exact double difference of its
//     float end points, n given by its components nL in that frame.
//  2. Clipping (Sutherland-Hodgman, one plane) by the receiver's horizon
//     n . p > 0: the visible part is a convex polygon of 3 or 4 vertices,
//     each kept as a vertex of the triangle plus a short offset along an
//     edge, so that differences of nearby vertices keep their relative
//     precision.
//  3. Omega_proj in closed form: Lambert's formula ([P21] sec. 3;
//     projected_polygon.hpp, (L)) on the clipped polygon. Edge k, on the
//     line through the vertex A (offset from the foot of o) along the unit
//     direction e = E_k / |E_k|, lies in a plane through o with the inward
//     unit normal
//       m = (-h e_y, h e_x, -c) / q,   c = A x e (2-D cross product), q = sqrt(h^2 + c^2),
//     (c the signed distance of the line from the foot of o, q that from
//     o; for the rectangle's edges this is (0, h, y0)/q0 etc.), and its
//     segment [a, b] (coordinates along e, length len) subtends the angle
//     gamma = atan2(len q, q^2 + a b); the horizon edge has the normal n.
//     Lambert's sum is used as is below direct_condition, otherwise
//     rewritten without cancellation as the chord form (C) of
//     projected_rectangle.hpp (a small or distant light), or as the
//     complement form (Z) of projected_polygon.hpp (a thin sliver above a
//     grazing horizon).
//  4. The map of projected_polygon.hpp ([P21] sec. 4-5, central and
//     decentral cases) in the receiver's frame; the sampled direction is
//     carried onto the light plane for its distance and, if rounding put
//     it outside, moved onto the triangle.
//
// Thresholds and fallbacks (as projected_rectangle.hpp). Each form's
// condition number K (sum of the magnitudes of its terms, including the
// cancelling parts of m_z, over Omega_proj) bounds its relative rounding
// error by a few K DBL_EPSILON. The map is used while K <= max_condition
// for the form of its sub-areas; the density, the pdf and the map then
// agree to ~1e-9 relative or better. Where no form is that accurate (tiny
// lights, small lights hugging the horizon, views almost in the light's
// plane, degenerate clips) the visible polygon is sampled uniformly by area
// with its exact pdf t^3 / (h A_visible) per unit SOLID ANGLE (t the
// distance along the ray): for sample() and pdf() alike, decided from
// (light, o, n) only, so the sample, the pdf returned with it, pdf(o, n,
// dir) and the true density always agree.
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/projected_polygon.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"

namespace mcrt {

namespace projected_triangle_detail {

inline double cross2(const dvec2& a, const dvec2& b) { return a.x * b.y - a.y * b.x; }

// The triangle in its own frame (step 1), fixed per light.
struct triangle_frame {
  dvec3 ex{1.0, 0.0, 0.0}, ey{0.0, 1.0, 0.0}, ez{0.0, 0.0, 1.0};  // ez: the front normal
  dvec3 p0{0.0};                  // first vertex (world space)
  std::array<dvec2, 3> q{};       // vertices relative to p0 in (ex, ey), counter-clockwise; q[0] = 0
  std::array<dvec2, 3> e{};       // edge vectors E_k = q[k + 1] - q[k], each from its own float difference
  std::array<double, 3> len{};    // |E_k|
  double area = 0.0;              // of the triangle
  bool valid = false;             // false for degenerate (zero-area or non-finite) triangles
};

inline triangle_frame make_triangle_frame(const triangle& t) {
  triangle_frame f;
  dvec3 p[3] = {dvec3(t.vertex(0)), dvec3(t.vertex(1)), dvec3(t.vertex(2))};
  dvec3 c = glm::cross(p[1] - p[0], p[2] - p[0]);
  const double cl = glm::length(c);
  if (!(cl > 0.0) || !std::isfinite(cl)) return f;
  // The front side is triangle::normal()'s; wind the vertices
  // counter-clockwise seen from it.
  if (glm::dot(c, dvec3(t.normal())) < 0.0) {
    std::swap(p[1], p[2]);
    c = -c;
  }
  f.ez = c / cl;
  f.p0 = p[0];
  const dvec3 d01 = p[1] - p[0];  // exact: differences of floats in double
  f.ex = d01 / glm::length(d01);
  f.ey = glm::cross(f.ez, f.ex);
  const auto in_plane = [&](const dvec3& v) { return dvec2(glm::dot(v, f.ex), glm::dot(v, f.ey)); };
  f.q = {dvec2(0.0), in_plane(d01), in_plane(p[2] - p[0])};
  f.e = {f.q[1], in_plane(p[2] - p[1]), -f.q[2]};
  for (int k = 0; k < 3; ++k) f.len[k] = glm::length(f.e[k]);
  f.area = 0.5 * cl;
  f.valid = f.len[0] > 0.0 && f.len[1] > 0.0 && f.len[2] > 0.0 && cross2(f.q[1], f.q[2]) > 0.0;
  return f;
}

}  // namespace projected_triangle_detail

// Per-receiver set-up of the projected solid angle of a triangle (steps
// 1-3 of the header), the choice of method, and (with_map) the map.
class projected_triangle {
 public:
  using method = projected_rectangle::method;
  // The rectangle's thresholds (projected_rectangle.hpp): largest condition
  // number of the map's form (~1e-9 relative), and the one below which
  // Lambert's sum is used without evaluating (C).
  static constexpr double max_condition = projected_rectangle::max_condition;
  static constexpr double direct_condition = projected_rectangle::direct_condition;

  projected_triangle(const projected_triangle_detail::triangle_frame& f, const vec3& o, const vec3& n,
                     bool with_map = false)
      : f_(f) {
    if (!f_.valid) return;
    const dvec3 d = f_.p0 - dvec3(o);  // exact: a difference of floats in double
    h_ = -glm::dot(d, f_.ez);
    foot_ = {glm::dot(d, f_.ex), glm::dot(d, f_.ey)};
    // One-sided light: o strictly in front (also rejects NaN).
    if (!(h_ > 0.0) || !std::isfinite(h_) || !std::isfinite(foot_.x) || !std::isfinite(foot_.y)) return;
    nd_ = dvec3(n);
    const double nl = glm::length(nd_);
    if (!(nl > 0.0) || !std::isfinite(nl)) return;
    nd_ *= 1.0 / nl;
    nL_ = {glm::dot(nd_, f_.ex), glm::dot(nd_, f_.ey), glm::dot(nd_, f_.ez)};
    clip();
    if (count_ < 3) return;
    closed_forms(with_map);
    if (with_map && how_ == method::map) prepare_map();
  }

  method how() const { return how_; }
  bool valid() const { return how_ != method::none; }
  // Whether sample_offset() can return a point (with_map given for the map).
  bool can_sample() const { return how_ == method::area || (how_ == method::map && map_ok_); }
  // Omega_proj of the visible part (sr, projected; 0 if nothing is visible).
  double projected_solid_angle() const { return omega_; }
  // Area of the visible part on the light (the area fallback's normaliser).
  double visible_area() const { return area_; }
  int vertex_count() const { return count_; }
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

  // u in [0,1)^2 -> point on the triangle minus o (in double); false if
  // there is nothing to sample. Needs with_map for the map.
  bool sample_offset(vec2 u, dvec3& v) const {
    if (how_ == method::area) {
      v = to_offset(area_sample(dvec2(u)));
      return true;
    }
    if (how_ != method::map || !map_ok_) return false;
    const dvec3 x = poly_.sample(dvec2(u));
    const dvec3 dir = x.x * t_ + x.y * b_ + x.z * nd_;
    const double dz = -glm::dot(dir, f_.ez);
    if (!(dz > 0.0)) return false;
    const double t = h_ / dz;
    v = to_offset(onto_triangle(dvec2(t * glm::dot(dir, f_.ex), t * glm::dot(dir, f_.ey))));
    return true;
  }

  // Density per unit SOLID ANGLE of the unit direction dir whose ray meets
  // the triangle at distance t: cos(theta) / Omega_proj on the map,
  // t^3 / (h A_visible) on the area fallback, 0 below the horizon.
  double pdf_direction(const dvec3& dir, double t) const {
    if (how_ == method::none) return 0.0;
    const double c = glm::dot(dir, nd_);
    if (!(c > 0.0)) return 0.0;
    if (how_ == method::map) return c / omega_;
    return t * t * t / (h_ * area_);
  }

  // Point o + v of the visible part -> unit square; the inverse of
  // sample_offset() (needs with_map for the map).
  dvec2 invert_offset(const dvec3& v) const {
    if (how_ == method::area) return area_invert({glm::dot(v, f_.ex), glm::dot(v, f_.ey)});
    const dvec3 dir = v / glm::length(v);
    return poly_.invert({glm::dot(dir, t_), glm::dot(dir, b_), glm::dot(dir, nd_)});
  }

  // Ray o + t dir (dir unit) against the triangle in its frame; t is the
  // distance to the hit. Closed: points on the edges count as inside.
  bool intersect(const dvec3& dir, double& t) const {
    if (!(h_ > 0.0)) return false;
    const double dz = glm::dot(dir, f_.ez);
    if (!(dz < 0.0)) return false;
    t = h_ / -dz;
    return inside(dvec2(t * glm::dot(dir, f_.ex), t * glm::dot(dir, f_.ey)) - foot_);
  }

 private:
  static constexpr int max_vertices = projected_polygon::max_vertices;
  static constexpr int horizon = 3;  // edge kind of the clipped edge along the horizon

  static int next3(int i) { return i == 2 ? 0 : i + 1; }
  // Vertex i of the triangle relative to the foot of o.
  dvec2 corner(int i) const { return foot_ + f_.q[i]; }
  // Vertex k of the clipped polygon, and the difference of two vertices
  // formed from their triangle vertices (an edge vector) and their offsets.
  dvec2 vertex(int k) const { return corner(base_[k]) + off_[k]; }
  dvec2 vertex_difference(int a, int b) const {  // vertex(b) - vertex(a)
    const int ia = base_[a], ib = base_[b];
    const dvec2 cd = ia == ib ? dvec2(0.0) : ib == next3(ia) ? f_.e[ia] : -f_.e[ib];
    return cd + (off_[b] - off_[a]);
  }
  dvec3 to_offset(const dvec2& p) const { return p.x * f_.ex + p.y * f_.ey - h_ * f_.ez; }

  // Whether x (relative to the first vertex) lies in the closed triangle.
  bool inside(const dvec2& x) const {
    using projected_triangle_detail::cross2;
    return cross2(f_.e[0], x - f_.q[0]) >= 0.0 && cross2(f_.e[1], x - f_.q[1]) >= 0.0 &&
           cross2(f_.e[2], x - f_.q[2]) >= 0.0;
  }
  // p (relative to the foot of o) unchanged if it lies in the triangle,
  // else its barycentric coordinates clamped to >= 0 and renormalised: a
  // point of the map that rounding put just outside.
  dvec2 onto_triangle(const dvec2& p) const {
    using projected_triangle_detail::cross2;
    const dvec2 x = p - foot_;
    // Twice the areas opposite vertices 2, 0, 1.
    double w[3];
    for (int k = 0; k < 3; ++k) w[k] = cross2(f_.e[k], x - f_.q[k]);
    if (w[0] >= 0.0 && w[1] >= 0.0 && w[2] >= 0.0) return p;
    for (double& wk : w) wk = std::max(wk, 0.0);
    const double s = w[0] + w[1] + w[2];
    if (!(s > 0.0)) return corner(0);
    // Barycentric weight of vertex 1 is w[2] / s, of vertex 2 w[0] / s.
    return foot_ + (w[2] / s) * f_.q[1] + (w[0] / s) * f_.q[2];
  }

  // Step 2: the part of the triangle with n . p > 0.
  void clip() {
    double z[3];
    for (int i = 0; i < 3; ++i) {
      const dvec2 c = corner(i);
      z[i] = c.x * nL_.x + c.y * nL_.y - h_ * nL_.z;
    }
    int k = 0;
    const auto add_clip_point = [&](int i, double s, double oms, int kind, double seg) {
      // On edge i at the fraction s from vertex i (oms = 1 - s), kept
      // relative to the nearer vertex.
      const int j = next3(i);
      if (s <= 0.5) {
        base_[k] = i;
        off_[k] = s * f_.e[i];
      } else {
        base_[k] = j;
        off_[k] = -oms * f_.e[i];
      }
      kind_[k] = kind;
      seg_[k] = seg;
      height_[k] = 0.0;
      ++k;
    };
    for (int i = 0; i < 3; ++i) {
      const int j = next3(i);
      const bool in_i = z[i] > 0.0, in_j = z[j] > 0.0;
      if (in_i) {
        const double s = in_j ? 1.0 : z[i] / (z[i] - z[j]);
        base_[k] = i;
        off_[k] = {0.0, 0.0};
        kind_[k] = i;
        seg_[k] = s * f_.len[i];
        height_[k] = z[i];
        ++k;
        if (!in_j) add_clip_point(i, s, -z[j] / (z[i] - z[j]), horizon, 0.0);
      } else if (in_j) {
        const double oms = z[j] / (z[j] - z[i]);
        add_clip_point(i, -z[i] / (z[j] - z[i]), oms, i, oms * f_.len[i]);
      }
    }
    count_ = k;
  }

  // Step 3: per-edge angles and normals, Lambert, (C), (Z), the choice
  // (projected_rectangle.hpp, step 3).
  void closed_forms(bool with_map) {
    using namespace projected_rectangle_detail;
    using projected_triangle_detail::cross2;
    const double hh = h_ * h_;
    // Per triangle edge: unit direction, signed line distance c, q and 1/q.
    std::array<dvec2, 3> ue{};
    std::array<double, 3> line{}, r{}, ir{};
    for (int e = 0; e < 3; ++e) {
      ue[e] = f_.e[e] / f_.len[e];
      line[e] = cross2(corner(e), ue[e]);
      r[e] = std::sqrt(hh + line[e] * line[e]);
      ir[e] = 1.0 / r[e];
    }
    double lambert = 0.0, lambert_mag = 0.0;
    bool decentral = false;
    std::array<double, max_vertices> Ys{}, Xs{}, mzmags{};
    for (int k = 0; k < count_; ++k) {
      const int kn = k + 1 == count_ ? 0 : k + 1;
      const dvec2 a = vertex(k), b = vertex(kn);
      double Y, X, mz, mzmag;
      if (kind_[k] == horizon) {
        const dvec2 dv = vertex_difference(k, kn);
        const double cr = a.x * dv.y - a.y * dv.x;
        Y = std::sqrt(hh * glm::dot(dv, dv) + cr * cr);  // |A x B| = |A x (B - A)|
        X = glm::dot(a, b) + hh;
        mz = 1.0;
        mzmag = 1.0;
      } else {
        const int e = kind_[k];
        const double pa = glm::dot(a, ue[e]), pb = glm::dot(b, ue[e]);
        Y = seg_[k] * r[e];
        X = hh + line[e] * line[e] + pa * pb;
        // m_z of the inward normal (-h e_y, h e_x, -c) / q.
        const double t1 = -h_ * ue[e].y * nL_.x, t2 = h_ * ue[e].x * nL_.y, t3 = -line[e] * nL_.z;
        mz = (t1 + t2 + t3) * ir[e];
        mzmag = (std::abs(t1) + std::abs(t2) + std::abs(t3)) * ir[e];
      }
      const double g = fast_math::atan2_upper(Y, X);
      Ys[k] = Y, Xs[k] = X, mzmags[k] = mzmag;
      gamma_[k] = g;
      mz_[k] = mz;
      decentral = decentral || mz < 0.0;
      lambert += 0.5 * mz * g;
      lambert_mag += 0.5 * mzmag * g;
    }
    const bool direct = lambert > 0.0 && lambert_mag <= direct_condition * lambert;
    // The edge normals in the light frame (the map and (Z) need them).
    if (with_map || !direct) {
      for (int k = 0; k < count_; ++k) {
        if (kind_[k] == horizon) {
          mL_[k] = nL_;
        } else {
          const int e = kind_[k];
          mL_[k] = dvec3(-h_ * ue[e].y, h_ * ue[e].x, -line[e]) * ir[e];
        }
      }
    }
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
      const dvec2 a = vertex_difference(0, k), b = vertex_difference(0, k + 1);
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
    // (C): the chord polygon's area vector from the fan of differences
    // (projected_rectangle.hpp, step 3).
    dvec3 area_vec(0.0);
    {
      const dvec2 p0 = vertex(0);
      const double l0 = std::sqrt(glm::dot(p0, p0) + hh);
      const dvec3 v0(p0.x / l0, p0.y / l0, -h_ / l0);
      dvec3 prev(0.0);
      for (int k = 1; k < count_; ++k) {
        const dvec2 pk = vertex(k), dk = vertex_difference(0, k);
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

  // The complement form (Z) of every edge (projected_polygon.hpp); false if
  // it has no area.
  bool complement_form() {
    double sum = 0.0, mag = 0.0;
    for (int k = 0; k < count_; ++k) {
      const int kn = k + 1 == count_ ? 0 : k + 1;
      // 1 - |m_z| = |n x m|^2 / (1 + |m_z|), the cross product in the light frame.
      const double omz = glm::dot(glm::cross(nL_, mL_[k]), glm::cross(nL_, mL_[k])) / (1.0 + std::abs(mz_[k]));
      omz_[k] = kind_[k] == horizon ? 0.0 : omz;
      const double zp = unit_height(k), zq = unit_height(kn), zz = zp * zq;
      const double s = sin_[k], c = cos_[k];
      // Delta phi - gamma = arg((P_xy . Q_xy + i |P_xy x Q_xy|) (cos g - i sin g)),
      // P_xy . Q_xy = c - zz, |P_xy x Q_xy| = s |m_z| (projected_polygon.hpp).
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
    const dvec2 p = vertex(k);
    return height_[k] / std::sqrt(glm::dot(p, p) + h_ * h_);
  }

  // Step 4: the polygon in the receiver's frame (Duff et al. 2017 basis).
  void prepare_map() {
    const double sign = std::copysign(1.0, nd_.z);
    const double a = -1.0 / (sign + nd_.z), bb = nd_.x * nd_.y * a;
    t_ = {1.0 + sign * nd_.x * nd_.x * a, sign * bb, -sign * nd_.x};
    b_ = {bb, sign + nd_.y * nd_.y * a, -nd_.y};
    // The light's axes in the receiver's frame.
    const dvec3 EX(glm::dot(f_.ex, t_), glm::dot(f_.ex, b_), nL_.x), EY(glm::dot(f_.ey, t_), glm::dot(f_.ey, b_), nL_.y),
        EZ(glm::dot(f_.ez, t_), glm::dot(f_.ez, b_), nL_.z);
    poly_.count = count_;
    poly_.complement = complement_;
    poly_.condition = complement_ ? cond_z_ : cond_lambert_;
    for (int k = 0; k < count_; ++k) {
      const dvec2 p = vertex(k);
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
  // visible polygon (one triangle, Turk's square-root map, when nothing is
  // clipped; triangle_area.hpp).
  dvec2 area_sample(dvec2 u) const {
    double target = u.x * area_;
    int k = 1;
    while (k + 2 < count_ && target > fan_[k]) target -= fan_[k++];
    const double s = std::sqrt(std::clamp(target / fan_[k], 0.0, 1.0));
    const dvec2 a = vertex_difference(0, k), b = vertex_difference(0, k + 1);
    return vertex(0) + s * ((1.0 - u.y) * a + u.y * b);
  }
  dvec2 area_invert(const dvec2& p) const {
    // The fan triangle whose barycentric coordinates (al, be) in the basis
    // (v_k - v_0, v_k+1 - v_0) are least negative; s = al + be, u2 = be / s.
    const dvec2 q = p - vertex(0);
    double before = 0.0, best = -infinity, u1 = 1.0, u2 = 1.0;
    for (int k = 1; k + 1 < count_; ++k) {
      const dvec2 a = vertex_difference(0, k), b = vertex_difference(0, k + 1);
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

  projected_triangle_detail::triangle_frame f_;
  double h_ = 0.0;
  dvec2 foot_{0.0};  // the first vertex relative to the foot of o, in (ex, ey)
  dvec3 nd_{0.0, 0.0, 1.0}, nL_{0.0, 0.0, 1.0}, t_{1.0, 0.0, 0.0}, b_{0.0, 1.0, 0.0};
  int count_ = 0;
  std::array<int, max_vertices> base_{}, kind_{};
  std::array<dvec2, max_vertices> off_{};
  std::array<dvec3, max_vertices> mL_{};
  std::array<double, max_vertices> seg_{}, height_{}, gamma_{}, sin_{}, cos_{}, mz_{}, omz_{}, zterm_{}, fan_{};
  double omega_ = 0.0, omega_lambert_ = 0.0, omega_chord_ = 0.0, omega_z_ = 0.0, area_ = 0.0;
  double cond_lambert_ = 0.0, cond_chord_ = 0.0, cond_z_ = 0.0;
  bool complement_ = false, map_ok_ = false;
  method how_ = method::none;
  projected_polygon poly_;
};

// Light-sampling strategy: exact projected-solid-angle sampling of a
// triangle clipped at the receiver's horizon (projected_triangle above),
// with the interface of light_sample.hpp's normal-aware form. One-sided
// (front = triangle::normal(), as triangle_area_sampler): no sample and pdf
// 0 behind the light, in its plane, or where the light lies wholly below
// the horizon of n.
struct triangle_projected_solid_angle_sampler {
  triangle shape;  // fixed after construction (the frame below is derived from it)

  explicit triangle_projected_solid_angle_sampler(const triangle& t)
      : shape(t), frame_(projected_triangle_detail::make_triangle_frame(t)) {}

  bool faces(const vec3& o) const {
    return frame_.valid && glm::dot(dvec3(o) - frame_.p0, frame_.ez) > 0.0;
  }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    const projected_triangle pt(frame_, o, n, true);
    dvec3 v;
    if (!pt.sample_offset(u, v)) return false;
    const double d = glm::length(v);
    if (!(d > 0.0)) return false;
    const vec3 dir(v / d);
    // The pdf of the float direction returned, computed as pdf() computes
    // it (a direction that rounds to the horizon gets no sample).
    const double p = pt.pdf_direction(dvec3(dir), d);
    if (!(p > 0.0) || !(p <= double(FLT_MAX))) return false;
    s.dir = dir;
    s.dist = float(d);
    s.pdf = float(p);
    return true;
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir for the
  // receiver's normal n. The ray test comes first, so a direction that
  // misses costs no set-up.
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const {
    if (!frame_.valid) return 0.0f;
    const dvec3 d = frame_.p0 - dvec3(o);
    const double h = -glm::dot(d, frame_.ez);
    if (!(h > 0.0)) return 0.0f;
    const dvec3 dd(dir);
    const double dz = glm::dot(dd, frame_.ez);
    if (!(dz < 0.0)) return 0.0f;
    const double t = h / -dz;
    const dvec2 x(t * glm::dot(dd, frame_.ex) - glm::dot(d, frame_.ex), t * glm::dot(dd, frame_.ey) - glm::dot(d, frame_.ey));
    using projected_triangle_detail::cross2;
    for (int k = 0; k < 3; ++k)
      if (!(cross2(frame_.e[k], x - frame_.q[k]) >= 0.0)) return 0.0f;
    if (!(glm::dot(dd, dvec3(n)) > 0.0)) return 0.0f;
    const projected_triangle pt(frame_, o, n);
    const double p = pt.pdf_direction(dd, t);
    return p <= double(FLT_MAX) ? float(p) : 0.0f;
  }

  // The light's projected solid angle at o for the normal n (sr,
  // projected): Lambert's sum over the visible part's edges, or its
  // cancellation-free forms (projected_triangle); 0 where no part is
  // visible (and where no form is well conditioned: the area fallback's
  // receivers).
  double projected_solid_angle(const vec3& o, const vec3& n) const {
    const projected_triangle pt(frame_, o, n);
    return pt.how() == projected_triangle::method::map ? pt.projected_solid_angle() : 0.0;
  }

  // Unit direction dir -> the unit-square point sample() maps onto it
  // (projected_polygon::invert, or the area fallback's inverse); false (u
  // untouched) where pdf() is 0.
  bool invert(const vec3& o, const vec3& n, const vec3& dir, vec2& u) const {
    const projected_triangle pt(frame_, o, n, true);
    if (!pt.can_sample()) return false;
    const dvec3 dd(dir);
    double t;
    if (!pt.intersect(dd, t) || !(pt.pdf_direction(dd, t) > 0.0)) return false;
    u = vec2(pt.invert_offset(t * dd));
    return true;
  }

  const projected_triangle_detail::triangle_frame& frame() const { return frame_; }

 private:
  projected_triangle_detail::triangle_frame frame_;
};

}  // namespace mcrt
