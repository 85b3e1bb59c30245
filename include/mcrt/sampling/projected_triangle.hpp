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
//  3. Omega_proj in closed form: Lambert's formula (Arvo 1995, eq. 2;
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
//  4. The map of projected_polygon.hpp ([P21]; its central and
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

// back: the frame of the triangle's back side (a two-sided light's second
// one-sided light).
inline triangle_frame make_triangle_frame(const triangle& t, bool back = false) {
  triangle_frame f;
  dvec3 p[3] = {dvec3(t.vertex(0)), dvec3(t.vertex(1)), dvec3(t.vertex(2))};
  dvec3 c = glm::cross(p[1] - p[0], p[2] - p[0]);
  const double cl = glm::length(c);
  if (!(cl > 0.0) || !std::isfinite(cl)) return f;  // zero area or non-finite vertices
  // The front side is triangle::normal()'s; wind the vertices
  // counter-clockwise seen from it.
  if (glm::dot(c, dvec3(back ? -t.normal() : t.normal())) < 0.0) {
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
  // A triangle too thin for its edge vectors (rounded to the frame) to keep
  // a positive orientation is degenerate: no sample, pdf 0.
  f.valid = f.len[0] > 0.0 && f.len[1] > 0.0 && f.len[2] > 0.0 && cross2(f.q[1], f.q[2]) > 0.0;
  return f;
}

}  // namespace projected_triangle_detail

// Per-receiver set-up of the projected solid angle of a triangle (steps
// 1-3 of the header), the choice of method, and (with_map) the map; all
// but the clip and the per-edge closed forms are projected_light_polygon's
// (projected_polygon.hpp), shared with the rectangle.
class projected_triangle : public projected_light_polygon<projected_triangle> {
 public:
  projected_triangle(const projected_triangle_detail::triangle_frame& f, const vec3& o, const vec3& n,
                     bool with_map = false)
      : projected_light_polygon(f.ex, f.ey, f.ez), q_(f.q), e_(f.e), len_(f.len) {
    if (!f.valid) return;
    const dvec3 d = f.p0 - dvec3(o);  // exact: a difference of floats in double
    h_ = -glm::dot(d, ez_);
    foot_ = {glm::dot(d, ex_), glm::dot(d, ey_)};
    // One-sided light: o strictly in front; a non-finite o (NaN, or inf
    // making h or the foot inf) has nothing to sample.
    if (!(h_ > 0.0) || !std::isfinite(h_) || !std::isfinite(foot_.x) || !std::isfinite(foot_.y)) return;
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

  // u in [0,1)^2 -> point on the triangle minus o (in double); false if
  // there is nothing to sample. Needs with_map for the map.
  bool sample_offset(vec2 u, dvec3& v) const {
    if (how_ == method::area) {
      v = to_offset(fan_sample(dvec2(u)));
      return true;
    }
    if (how_ != method::map || !map_ok_) return false;
    dvec2 p;
    if (!map_point(u, p)) return false;
    v = to_offset(onto_triangle(p));
    return true;
  }

  // Point o + v of the visible part -> unit square; the inverse of
  // sample_offset() (needs with_map for the map).
  dvec2 invert_offset(const dvec3& v) const {
    if (how_ == method::area) return fan_invert({glm::dot(v, ex_), glm::dot(v, ey_)});
    return map_invert(v);
  }

  // Ray o + t dir (dir unit) against the triangle in its frame; t is the
  // distance to the hit. Closed: points on the edges count as inside.
  bool intersect(const dvec3& dir, double& t) const {
    if (!(h_ > 0.0)) return false;
    const double dz = glm::dot(dir, ez_);
    if (!(dz < 0.0)) return false;
    t = h_ / -dz;
    return inside(dvec2(t * glm::dot(dir, ex_), t * glm::dot(dir, ey_)) - foot_);
  }

 private:
  friend class projected_light_polygon<projected_triangle>;
  static constexpr int horizon = 3;  // edge kind of the clipped edge along the horizon

  static int next3(int i) { return i == 2 ? 0 : i + 1; }
  // Vertex i of the triangle relative to the foot of o.
  dvec2 corner(int i) const { return foot_ + q_[i]; }
  // Vertex k of the clipped polygon, and the difference of two vertices
  // formed from their triangle vertices (an edge vector, from its own float
  // difference) and their offsets.
  dvec2 vertex(int k) const { return corner(base_[k]) + off_[k]; }
  dvec2 vertex_difference(int a, int b) const {  // vertex(b) - vertex(a)
    const int ia = base_[a], ib = base_[b];
    const dvec2 cd = ia == ib ? dvec2(0.0) : ib == next3(ia) ? e_[ia] : -e_[ib];
    return cd + (off_[b] - off_[a]);
  }
  bool on_horizon(int k) const { return kind_[k] == horizon; }

  // Whether x (relative to the first vertex) lies in the closed triangle.
  bool inside(const dvec2& x) const {
    using projected_triangle_detail::cross2;
    return cross2(e_[0], x - q_[0]) >= 0.0 && cross2(e_[1], x - q_[1]) >= 0.0 && cross2(e_[2], x - q_[2]) >= 0.0;
  }
  // p (relative to the foot of o) unchanged if it lies in the triangle,
  // else its barycentric coordinates clamped to >= 0 and renormalised: a
  // point of the map that rounding put just outside.
  dvec2 onto_triangle(const dvec2& p) const {
    using projected_triangle_detail::cross2;
    const dvec2 x = p - foot_;
    // Twice the areas opposite vertices 2, 0, 1.
    double w[3];
    for (int k = 0; k < 3; ++k) w[k] = cross2(e_[k], x - q_[k]);
    if (w[0] >= 0.0 && w[1] >= 0.0 && w[2] >= 0.0) return p;
    for (double& wk : w) wk = std::max(wk, 0.0);
    const double s = w[0] + w[1] + w[2];
    if (!(s > 0.0)) return corner(0);  // every weight clamped: only for a non-finite point
    // The barycentric weight of vertex 1 is w[2] / s, that of vertex 2 w[0] / s.
    return foot_ + (w[2] / s) * q_[1] + (w[0] / s) * q_[2];
  }

  // Step 2: the part of the triangle with n . p > 0 (Sutherland-Hodgman,
  // as projected_rectangle's clip).
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
        off_[k] = s * e_[i];
      } else {
        base_[k] = j;
        off_[k] = -oms * e_[i];
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
        seg_[k] = s * len_[i];
        height_[k] = z[i];
        ++k;
        if (!in_j) add_clip_point(i, s, -z[j] / (z[i] - z[j]), horizon, 0.0);
      } else if (in_j) {
        const double oms = z[j] / (z[j] - z[i]);
        add_clip_point(i, -z[i] / (z[j] - z[i]), oms, i, oms * len_[i]);
      }
    }
    count_ = k;
  }

  // Step 3: per-edge angles and normals (the edge planes of the header),
  // then Lambert, (C), (Z) and the choice (projected_light_polygon::choose).
  void closed_forms(bool with_map) {
    using projected_triangle_detail::cross2;
    const double hh = h_ * h_;
    // Per triangle edge: unit direction, signed line distance c, q and 1/q.
    std::array<dvec2, 3> ue{};
    std::array<double, 3> line{}, r{}, ir{};
    for (int e = 0; e < 3; ++e) {
      ue[e] = e_[e] / len_[e];
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
    choose(with_map, lambert, lambert_mag, decentral, Ys, Xs, mzmags, [&] {
      for (int k = 0; k < count_; ++k)
        mL_[k] = kind_[k] == horizon ? nL_ : dvec3(-h_ * ue[kind_[k]].y, h_ * ue[kind_[k]].x, -line[kind_[k]]) * ir[kind_[k]];
    });
  }

  std::array<dvec2, 3> q_{}, e_{};  // the frame's vertices and edge vectors
  std::array<double, 3> len_{};
  dvec2 foot_{0.0};  // the first vertex relative to the foot of o, in (ex, ey)
  std::array<int, max_vertices> base_{}, kind_{};
  std::array<dvec2, max_vertices> off_{};
  std::array<double, max_vertices> seg_{};
};

// Light-sampling strategy: exact projected-solid-angle sampling of a
// triangle clipped at the receiver's horizon (projected_triangle above),
// with the interface of light_sample.hpp's normal-aware form. One-sided
// (front = triangle::normal(), as triangle_area_sampler): no sample and pdf
// 0 behind the light, in its plane, or where the light lies wholly below
// the horizon of n.
struct triangle_projected_solid_angle_sampler {
  triangle shape;  // fixed after construction (the frame below is derived from it)

  // back: sample the triangle's back side instead (the other half of a
  // two-sided light).
  explicit triangle_projected_solid_angle_sampler(const triangle& t, bool back = false)
      : shape(t), frame_(projected_triangle_detail::make_triangle_frame(t, back)) {}

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
