#pragma once
// Sampling a rectangle light in proportion to projected solid angle at a
// receiver with unit normal n: density cos(theta) / Omega_proj per unit
// SOLID ANGLE (cos(theta) = n . dir), i.e. 1 / Omega_proj per unit projected
// solid angle, over the part of the light above the receiver's horizon. For
// an unoccluded light of constant radiance L on a diffuse receiver the
// estimate L cos(theta) / pdf = L Omega_proj has zero variance.
//
// Steps (per receiver point; the light's frame is cached by the strategy):
//  1. The light frame of spherical_rectangle.hpp: o at the origin, the
//     rectangle [x0, x1] x [y0, y1] in the plane z = -h, h > 0 (one-sided
//     light: no sample behind it), n given by its components nL there.
//  2. Clipping (Sutherland-Hodgman, one plane) by the receiver's horizon
//     n . p > 0: the visible part is a convex polygon of 3, 4 or 5 vertices,
//     each kept as a corner of the rectangle plus a short offset, so that
//     differences of nearby vertices keep their relative precision. Clip
//     points are where a rectangle edge crosses the horizon plane, at the
//     fraction z_i / (z_i - z_j) of the edge (z the heights of its corners
//     above that plane).
//  3. Omega_proj in closed form: Lambert's formula (projected_polygon.hpp,
//     (L)) on the clipped polygon. Every edge of the rectangle lies in a
//     plane through o with an exactly known inward normal, (0, h, y0)/q0,
//     -(h, 0, x1)/p1, -(0, h, y1)/q1, (h, 0, x0)/p0 (q_j = sqrt(h^2 + y_j^2),
//     p_i = sqrt(h^2 + x_i^2)), and subtends from o the angle
//     gamma = atan2(len q, q^2 + a b) of the segment [a, b] (length len) of
//     its line at distance q; the horizon edge has the normal n itself.
//     Where its condition number is at most direct_condition, Lambert's sum
//     is used as is; otherwise it is rewritten without its cancellation
//     for small or distant lights (terms O(eps), sum O(eps^2)):
//       Omega_proj = (1/2) sum_i sin(gamma_i) m_z,i + (1/2) sum_i (gamma_i - sin gamma_i) m_z,i
//                  = -n . (1/2) sum_fan (v_i - v_0) x (v_{i+1} - v_0) + (1/2) sum_i (gamma_i - sin gamma_i) m_z,i   (C)
//     The first sum is the projected area of the planar "chord" polygon of
//     the unit vertex directions v_i (sin(gamma) m = v_i x v_{i+1} up to the
//     winding), computed as a fan of differences v_i - v_0, each formed from
//     the exact difference of the vertices on the light (V_i - V_0)/L_i -
//     V_0 (L_i^2 - L_0^2)/(L_i L_0 (L_i + L_0)), L = |V|; the second is the
//     sum of the elliptic segments between the arcs and their chords,
//     gamma - sin(gamma) = gamma^3/6 - ... by its series for small gamma. For
//     a small light every term of (C) is of the size of the result or
//     smaller (the segments are O(eps^3)).
//     For a thin sliver just above the horizon (a grazing normal) both forms
//     cancel (terms O(1), result O(delta^2)); there the complement form (Z)
//     of projected_polygon.hpp, whose terms are O(delta^2), is used.
//  4. The map of projected_polygon.hpp (after Peters 2021) in the
//     receiver's frame; the sampled direction is carried onto the light
//     plane for its distance and clamped to the rectangle (rounding only).
//
// Thresholds and fallbacks. Each form's condition number K = (sum of the
// magnitudes of its terms, including the cancelling parts of m_z) /
// Omega_proj bounds its relative rounding error by a few K DBL_EPSILON,
// for the closed form and for every sub-area the map evaluates. The map is
// used while K <= max_condition for the form of its sub-areas (Lambert's,
// or the complement form where Lambert's is worse): the density, the pdf
// and the map then agree to ~1e-9 relative or better, below a float's
// resolution. Where neither form is that accurate (lights below ~1e-11 sr,
// small lights within ~1 degree of the horizon, views within ~1e-6 of the
// light's plane with the receiver's normal close to the light's, degenerate
// clips), the visible polygon is sampled uniformly by area with its exact
// pdf d^3 / (h A_visible) per unit solid angle: for sample() and pdf()
// alike, decided from (light, o, n) only, so the sample, the pdf returned
// with it, pdf(o, n, dir) and the true density always agree.
#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>

#include "mcrt/core/fast_math.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/projected_polygon.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"

namespace mcrt {

namespace projected_rectangle_detail {

using projected_polygon_detail::arc_minus_chord;  // gamma - sin(gamma), projected_polygon.hpp

}  // namespace projected_rectangle_detail

// Per-receiver set-up of the projected solid angle of a rectangle (steps
// 1-3 of the header), the choice of method, and (with_map) the map; the
// parts shared with the triangle are projected_light_polygon's
// (projected_polygon.hpp).
class projected_rectangle : public projected_light_polygon<projected_rectangle> {
 public:
  projected_rectangle(const spherical_rectangle_detail::rect_frame& f, const vec3& corner, const vec3& o,
                      const vec3& n, bool with_map = false)
      : projected_light_polygon(f.ex, f.ey, f.ez), w_(f.w), l_(f.l) {
    const dvec3 d = dvec3(corner) - dvec3(o);  // exact: a difference of floats in double
    h_ = -glm::dot(d, ez_);
    x0_ = glm::dot(d, ex_);
    y0_ = glm::dot(d, ey_);
    x1_ = x0_ + w_;
    y1_ = y0_ + l_;
    // One-sided light: o strictly in front (also rejects NaN and degenerate
    // rectangles, as spherical_rectangle does).
    if (!(h_ > 0.0) || !(w_ * l_ > 0.0)) return;
    nd_ = dvec3(n);
    const double nl = glm::length(nd_);
    if (!(nl > 0.0) || !std::isfinite(nl)) return;
    nd_ *= 1.0 / nl;
    nL_ = {glm::dot(nd_, ex_), glm::dot(nd_, ey_), glm::dot(nd_, ez_)};
    clip();
    if (count_ < 3) return;
    closed_forms(with_map);
    if (with_map && how_ == method::map) prepare_map();
  }

  // u in [0,1)^2 -> point on the rectangle minus o (in double); false if
  // there is nothing to sample. Needs with_map for the map.
  bool sample_offset(vec2 u, dvec3& v) const {
    if (how_ == method::area) {
      v = to_offset(area_sample(dvec2(u)));
      return true;
    }
    if (how_ != method::map || !map_ok_) return false;
    dvec2 p;
    if (!map_point(u, p)) return false;
    v = to_offset({std::clamp(p.x, x0_, x1_), std::clamp(p.y, y0_, y1_)});
    return true;
  }

  // Point o + v of the visible part -> unit square; the inverse of
  // sample_offset() (needs with_map for the map).
  dvec2 invert_offset(const dvec3& v) const {
    if (how_ == method::area) return area_invert({glm::dot(v, ex_), glm::dot(v, ey_)});
    return map_invert(v);
  }

  // Ray o + t dir (dir unit) against the rectangle, in the local frame, as
  // spherical_rectangle::intersect; t is the distance to the hit.
  bool intersect(const dvec3& dir, double& t) const {
    if (!(h_ > 0.0)) return false;
    const double dz = glm::dot(dir, ez_);
    if (!(dz < 0.0)) return false;
    t = h_ / -dz;
    const double x = t * glm::dot(dir, ex_), y = t * glm::dot(dir, ey_);
    return x >= x0_ && x <= x1_ && y >= y0_ && y <= y1_;
  }

 private:
  friend class projected_light_polygon<projected_rectangle>;
  bool on_horizon(int k) const { return kind_[k] == horizon; }
  static constexpr int horizon = 4;  // edge kind of the clipped edge along the horizon

  // Corner i of the rectangle in the light plane: (x0, y0), (x1, y0), (x1, y1), (x0, y1).
  static constexpr double corner_x[4] = {0.0, 1.0, 1.0, 0.0}, corner_y[4] = {0.0, 0.0, 1.0, 1.0};
  dvec2 corner(int i) const { return {x0_ + corner_x[i] * w_, y0_ + corner_y[i] * l_}; }
  // Edge i runs from corner i to corner i + 1 along dir(i), length len(i).
  static dvec2 edge_dir(int i) {
    constexpr double dx[4] = {1.0, 0.0, -1.0, 0.0}, dy[4] = {0.0, 1.0, 0.0, -1.0};
    return {dx[i], dy[i]};
  }
  double edge_len(int i) const { return (i & 1) ? l_ : w_; }
  // The sign of edge i's inward normal (0, h, y0), -(h, 0, x1), -(0, h, y1),
  // (h, 0, x0) (over its length), and the coordinate of its line.
  static double edge_sign(int i) { return i == 0 || i == 3 ? 1.0 : -1.0; }
  double edge_line(int i) const { return i == 0 ? y0_ : i == 1 ? x1_ : i == 2 ? y1_ : x0_; }

  // Vertex k in the light plane and the difference of two vertices formed
  // from their corners (exact multiples of w and l) and their offsets.
  dvec2 vertex(int k) const { return corner(base_[k]) + off_[k]; }
  dvec2 vertex_difference(int a, int b) const {  // vertex(b) - vertex(a)
    const dvec2 cd((corner_x[base_[b]] - corner_x[base_[a]]) * w_, (corner_y[base_[b]] - corner_y[base_[a]]) * l_);
    return cd + (off_[b] - off_[a]);
  }

  // Step 2: the part of the rectangle with n . p > 0.
  void clip() {
    double z[4];
    for (int i = 0; i < 4; ++i) {
      const dvec2 c = corner(i);
      z[i] = c.x * nL_.x + c.y * nL_.y - h_ * nL_.z;
    }
    int k = 0;
    const auto add_clip_point = [&](int i, double s, double oms, int kind, double seg) {
      // On edge i at the fraction s from corner i (oms = 1 - s), kept
      // relative to the nearer corner.
      const int j = (i + 1) & 3;
      if (s <= 0.5) {
        base_[k] = i;
        off_[k] = (s * edge_len(i)) * edge_dir(i);
      } else {
        base_[k] = j;
        off_[k] = (-oms * edge_len(i)) * edge_dir(i);
      }
      kind_[k] = kind;
      seg_[k] = seg;
      height_[k] = 0.0;
      ++k;
    };
    for (int i = 0; i < 4; ++i) {
      const int j = (i + 1) & 3;
      const bool in_i = z[i] > 0.0, in_j = z[j] > 0.0;
      if (in_i) {
        const double s = in_j ? 1.0 : z[i] / (z[i] - z[j]);
        base_[k] = i;
        off_[k] = {0.0, 0.0};
        kind_[k] = i;
        seg_[k] = s * edge_len(i);
        height_[k] = z[i];
        ++k;
        if (!in_j) add_clip_point(i, s, -z[j] / (z[i] - z[j]), horizon, 0.0);
      } else if (in_j) {
        const double oms = z[j] / (z[j] - z[i]);
        add_clip_point(i, -z[i] / (z[j] - z[i]), oms, i, oms * edge_len(i));
      }
    }
    count_ = k;
    whole_ = z[0] > 0.0 && z[1] > 0.0 && z[2] > 0.0 && z[3] > 0.0;
  }

  // Step 3: per-edge angles and normals, then Lambert, (C), (Z) and the
  // choice (projected_light_polygon::choose). Where Lambert's sum is used
  // as is (the common case) the density needs only the arc angles and m_z;
  // the edge normals (for the map) and the terms of (C) and (Z) are formed
  // only when needed.
  void closed_forms(bool with_map) {
    const double hh = h_ * h_;
    // q0, p1, q1, p0 (distances of the edge lines) and their reciprocals.
    const std::array<double, 4> r = fast_math::sqrt4(hh + y0_ * y0_, hh + x1_ * x1_, hh + y1_ * y1_, hh + x0_ * x0_);
    const std::array<double, 4> ir =
        fast_math::inverse_sqrt4(hh + y0_ * y0_, hh + x1_ * x1_, hh + y1_ * y1_, hh + x0_ * x0_);
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
        const bool along_x = (e & 1) == 0;  // edges 0 and 2 run along x at y = y0, y1
        const double pa = along_x ? a.x : a.y, pb = along_x ? b.x : b.y;
        const double line = edge_line(e);
        Y = seg_[k] * r[e];
        X = hh + line * line + pa * pb;
        // m_z of the inward normals (0, h, y0)/q0, -(h, 0, x1)/p1, -(0, h, y1)/q1, (h, 0, x0)/p0.
        const double nh = along_x ? nL_.y : nL_.x;
        mz = edge_sign(e) * (h_ * nh + line * nL_.z) * ir[e];
        mzmag = (std::abs(h_ * nh) + std::abs(line * nL_.z)) * ir[e];
      }
      const double g = fast_math::atan2_upper(Y, X);
      Ys[k] = Y, Xs[k] = X, mzmags[k] = mzmag;
      gamma_[k] = g;
      mz_[k] = mz;
      decentral = decentral || mz < 0.0;
      lambert += 0.5 * mz * g;
      lambert_mag += 0.5 * mzmag * g;
    }
    // The edge normals in the light frame (the map and (Z) need them).
    choose(with_map, lambert, lambert_mag, decentral, Ys, Xs, mzmags, [&] {
      for (int k = 0; k < count_; ++k) {
        if (kind_[k] == horizon) {
          mL_[k] = nL_;
        } else {
          const int e = kind_[k];
          const double sg = edge_sign(e) * ir[e], line = edge_line(e);
          mL_[k] = (e & 1) == 0 ? dvec3(0.0, sg * h_, sg * line) : dvec3(sg * h_, 0.0, sg * line);
        }
      }
    });
  }

  // Area fallback: uniform on the rectangle when it is whole, else on the
  // fan of triangles (v0, v_k, v_k+1) of the visible polygon.
  dvec2 area_sample(dvec2 u) const {
    if (whole_) return {x0_ + u.x * w_, y0_ + u.y * l_};
    return fan_sample(u);
  }
  dvec2 area_invert(const dvec2& p) const {
    if (whole_) return {std::clamp((p.x - x0_) / w_, 0.0, 1.0), std::clamp((p.y - y0_) / l_, 0.0, 1.0)};
    return fan_invert(p);
  }

  double w_ = 0.0, l_ = 0.0, x0_ = 0.0, x1_ = 0.0, y0_ = 0.0, y1_ = 0.0;
  std::array<int, max_vertices> base_{}, kind_{};
  std::array<dvec2, max_vertices> off_{};
  std::array<double, max_vertices> seg_{};
  bool whole_ = false;  // nothing clipped
};

// Light-sampling strategy: exact projected-solid-angle sampling of a
// rectangle clipped at the receiver's horizon (projected_rectangle above),
// with the interface of light_sample.hpp's normal-aware form. One-sided: no
// sample and pdf 0 behind the light, in its plane, or where the light lies
// wholly below the horizon of n.
struct rect_projected_solid_angle_sampler {
  rect shape;  // fixed after construction (the frame below is derived from it)

  explicit rect_projected_solid_angle_sampler(const rect& r)
      : shape(r), frame_(spherical_rectangle_detail::make_rect_frame(r)) {}

  bool faces(const vec3& o) const {
    const dvec3 n = glm::cross(dvec3(shape.e1), dvec3(shape.e2));
    return glm::dot(dvec3(o) - dvec3(shape.corner), n) * double(glm::dot(dvec3(n), dvec3(shape.n))) > 0.0;
  }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    const projected_rectangle pr(frame_, shape.corner, o, n, true);
    dvec3 v;
    if (!pr.sample_offset(u, v)) return false;
    const double d = glm::length(v);
    if (!(d > 0.0)) return false;
    const vec3 dir(v / d);
    // The pdf of the float direction returned, computed as pdf() computes
    // it (a direction that rounds to the horizon gets no sample).
    const double p = pr.pdf_direction(dvec3(dir), d);
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
    const dvec3 d = dvec3(shape.corner) - dvec3(o);
    const double h = -glm::dot(d, frame_.ez);
    if (!(h > 0.0)) return 0.0f;
    const dvec3 dd(dir);
    const double dz = glm::dot(dd, frame_.ez);
    if (!(dz < 0.0)) return 0.0f;
    const double t = h / -dz;
    const double x = t * glm::dot(dd, frame_.ex) - glm::dot(d, frame_.ex);
    const double y = t * glm::dot(dd, frame_.ey) - glm::dot(d, frame_.ey);
    if (!(x >= 0.0 && x <= frame_.w && y >= 0.0 && y <= frame_.l)) return 0.0f;
    if (!(glm::dot(dd, dvec3(n)) > 0.0)) return 0.0f;
    const projected_rectangle pr(frame_, shape.corner, o, n);
    const double p = pr.pdf_direction(dd, t);
    return p <= double(FLT_MAX) ? float(p) : 0.0f;
  }

  // The light's projected solid angle at o for the normal n (sr,
  // projected): Lambert's sum over the visible part's edges, or its
  // cancellation-free forms (projected_rectangle); 0 where no part is
  // visible (and where no form is well conditioned: the area fallback's
  // receivers, right in the light's plane).
  double projected_solid_angle(const vec3& o, const vec3& n) const {
    const projected_rectangle pr(frame_, shape.corner, o, n);
    return pr.how() == projected_rectangle::method::map ? pr.projected_solid_angle() : 0.0;
  }

  // Unit direction dir -> the unit-square point sample() maps onto it
  // (projected_polygon::invert, or the area fallback's inverse); false (u
  // untouched) where pdf() is 0.
  bool invert(const vec3& o, const vec3& n, const vec3& dir, vec2& u) const {
    const projected_rectangle pr(frame_, shape.corner, o, n, true);
    if (!pr.can_sample()) return false;
    const dvec3 dd(dir);
    double t;
    if (!pr.intersect(dd, t) || !(pr.pdf_direction(dd, t) > 0.0)) return false;
    u = vec2(pr.invert_offset(t * dd));
    return true;
  }

 private:
  spherical_rectangle_detail::rect_frame frame_;
};

}  // namespace mcrt
