#pragma once
// Triangle meshes: shared vertex arrays and the triangles that index them,
// intersected watertight (Woop, Benthin & Wald 2013, "Watertight Ray/Triangle
// Intersection", JCGT 2(1); Pharr, Jakob & Humphreys, "Physically Based
// Rendering", 4th ed., sec. 6.5.3): a ray through an edge or a vertex shared
// by two triangles hits at least one of them, whatever the floating-point
// rounding, and a hit is reported only where its distance is conservatively
// greater than zero. The hit point is interpolated from the vertices with
// the bound of its rounding (PBRT 4th ed., sec. 6.8.5), so rays leave it from
// hit_record::spawn_origin without meeting the triangle again.
//
// Orientation: a triangle's geometric normal is normalize((p1 - p0) x
// (p2 - p0)) of its vertices, reversed when the mesh is reversed (pbrt-v4's
// ReverseOrientation); where the mesh has shading normals, it is turned to
// the side of their interpolation instead (as pbrt-v4's triangles do).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "mcrt/core/ray.hpp"
#include "mcrt/geometry/aabb.hpp"
#include "mcrt/geometry/hit_record.hpp"

namespace mcrt {

struct triangle_mesh {
  std::vector<vec3> p;                  // positions (world space)
  std::vector<vec3> n;                  // shading normals: empty, or one per position
  std::vector<vec2> uv;                 // texture coordinates: empty, or one per position
  std::vector<std::uint32_t> indices;   // three per triangle, into p (and n, uv)
  bool reverse_orientation = false;

  std::size_t triangle_count() const { return indices.size() / 3; }
};

// Where a ray meets a triangle: the parameter and the barycentric
// coordinates of the hit, p = b0 p0 + b1 p1 + b2 p2.
struct triangle_hit {
  float t = 0.0f, b0 = 0.0f, b1 = 0.0f, b2 = 0.0f;
};

namespace detail {

// a b - c d with one rounding (Kahan's algorithm with an FMA): the edge
// functions of the watertight test lose their sign to cancellation without it.
inline float difference_of_products(float a, float b, float c, float d) {
  const float cd = c * d;
  const float err = std::fma(-c, d, cd);
  return std::fma(a, b, -cd) + err;
}

inline int max_dimension(const vec3& v) { return v.x > v.y ? (v.x > v.z ? 0 : 2) : (v.y > v.z ? 1 : 2); }
inline vec3 permute(const vec3& v, int x, int y, int z) { return {v[x], v[y], v[z]}; }

}  // namespace detail

// The watertight ray-triangle test of Woop, Benthin & Wald 2013 (sec. 3-4):
// the vertices in a frame where the ray is the +z axis through the origin
// (translation, a permutation that makes d's largest component z, a shear),
// where the 2-D edge functions decide inside and outside exactly up to
// their sign's rounding, recomputed in double where one is 0. Hits with t
// in (0, tmax); t must exceed the bound of its own rounding (PBRT 4th ed.,
// sec. 6.8.7), so a ray leaving the triangle's surface never meets it at t
// ~ 0.
//
// The ray's part of that frame (the permutation and the shear, sec. 3's
// per-ray precomputation) is set up once per ray: a traversal tests many
// triangles with one watertight_ray.
struct watertight_ray {
  vec3 o;
  int kx = 0, ky = 1, kz = 2;  // d's largest component becomes z
  float sx = 0.0f, sy = 0.0f, sz = 1.0f;

  explicit watertight_ray(const ray& r) : o(r.o) {
    const vec3 a = glm::abs(r.d);
    kz = detail::max_dimension(a);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    const float dx = component(r.d, kx), dy = component(r.d, ky), dz = component(r.d, kz);
    // Shear so that the ray runs along +z (z is scaled later, only where the
    // test passes).
    sx = -dx / dz;
    sy = -dy / dz;
    sz = 1.0f / dz;
  }

  // v's component k (glm's operator[] takes a branch per call).
  static float component(const vec3& v, int k) { return (&v.x)[k]; }

  // p - o in the permuted, sheared frame (z not yet scaled). The shear's
  // products are fused (one rounding each) whatever the compiler's
  // contraction, so that a vector test over several triangles computes
  // the same numbers (triangle_leaf.hpp).
  vec3 to_frame(const vec3& p) const {
    const float x = component(p, kx) - component(o, kx);
    const float y = component(p, ky) - component(o, ky);
    const float z = component(p, kz) - component(o, kz);
    return {std::fma(sx, z, x), std::fma(sy, z, y), z};
  }
};
static_assert(sizeof(float[3]) == sizeof(vec3), "watertight_ray::component reads a vec3 as three floats");

inline std::optional<triangle_hit> intersect_triangle(const watertight_ray& wr, float tmax, const vec3& p0,
                                                      const vec3& p1, const vec3& p2) {
  vec3 p0t = wr.to_frame(p0), p1t = wr.to_frame(p1), p2t = wr.to_frame(p2);
  // Edge functions (twice the signed areas of the sub-triangles the origin
  // makes); a zero may be the rounding of a tiny value of either sign, so
  // it is recomputed in double.
  float e0 = detail::difference_of_products(p1t.x, p2t.y, p1t.y, p2t.x);
  float e1 = detail::difference_of_products(p2t.x, p0t.y, p2t.y, p0t.x);
  float e2 = detail::difference_of_products(p0t.x, p1t.y, p0t.y, p1t.x);
  if (e0 == 0.0f || e1 == 0.0f || e2 == 0.0f) [[unlikely]] {
    e0 = static_cast<float>(double(p1t.x) * double(p2t.y) - double(p1t.y) * double(p2t.x));
    e1 = static_cast<float>(double(p2t.x) * double(p0t.y) - double(p2t.y) * double(p0t.x));
    e2 = static_cast<float>(double(p0t.x) * double(p1t.y) - double(p0t.y) * double(p1t.x));
  }
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return std::nullopt;
  const float det = e0 + e1 + e2;
  if (det == 0.0f) return std::nullopt;
  // The scaled hit distance, compared with 0 and tmax before the division.
  p0t.z *= wr.sz;
  p1t.z *= wr.sz;
  p2t.z *= wr.sz;
  const float t_scaled = std::fma(e2, p2t.z, std::fma(e1, p1t.z, e0 * p0t.z));
  if (det < 0.0f && (t_scaled >= 0.0f || t_scaled < tmax * det)) return std::nullopt;
  if (det > 0.0f && (t_scaled <= 0.0f || t_scaled > tmax * det)) return std::nullopt;
  // Degenerate triangles (zero area) are never hit (tested here, where few
  // triangles arrive, rather than first).
  const vec3 c = glm::cross(p2 - p0, p1 - p0);
  if (glm::dot(c, c) == 0.0f) return std::nullopt;
  const float inv_det = 1.0f / det;
  const triangle_hit h{t_scaled * inv_det, e0 * inv_det, e1 * inv_det, e2 * inv_det};
  // t conservatively above 0: the bound of its rounding (PBRT 4th ed., eqs.
  // 6.31-6.35, from the errors of the transformed z, x, y and of the edge
  // functions).
  const float max_zt = std::max({std::abs(p0t.z), std::abs(p1t.z), std::abs(p2t.z)});
  const float delta_z = rounding_gamma(3) * max_zt;
  const float max_xt = std::max({std::abs(p0t.x), std::abs(p1t.x), std::abs(p2t.x)});
  const float max_yt = std::max({std::abs(p0t.y), std::abs(p1t.y), std::abs(p2t.y)});
  const float delta_x = rounding_gamma(5) * (max_xt + max_zt);
  const float delta_y = rounding_gamma(5) * (max_yt + max_zt);
  const float delta_e = 2.0f * (rounding_gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
  const float max_e = std::max({std::abs(e0), std::abs(e1), std::abs(e2)});
  const float delta_t =
      3.0f * (rounding_gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * std::abs(inv_det);
  if (!(h.t > delta_t)) return std::nullopt;
  return h;
}

// The same for one ray and one triangle.
inline std::optional<triangle_hit> intersect_triangle(const ray& r, float tmax, const vec3& p0, const vec3& p1,
                                                      const vec3& p2) {
  return intersect_triangle(watertight_ray(r), tmax, p0, p1, p2);
}

// One triangle of a mesh, as a shape of the scene.
struct triangle {
  std::shared_ptr<const triangle_mesh> mesh;
  std::uint32_t index = 0;  // the triangle's number in the mesh

  const vec3& vertex(int k) const { return mesh->p[mesh->indices[3 * std::size_t(index) + std::size_t(k)]]; }

  // The unit geometric normal of the front side (the orientation rule at
  // the top of this header).
  vec3 normal() const { return normal_of(vertex(0), vertex(1), vertex(2)); }

  // The same from the triangle's vertices p0, p1, p2 (as vertex(0..2)),
  // read by the caller.
  vec3 normal_of(const vec3& p0, const vec3& p1, const vec3& p2) const {
    vec3 ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    if (!mesh->n.empty()) {
      const std::size_t i = 3 * std::size_t(index);
      const vec3 ns = mesh->n[mesh->indices[i]] + mesh->n[mesh->indices[i + 1]] + mesh->n[mesh->indices[i + 2]];
      if (glm::dot(ng, ns) < 0.0f) ng = -ng;
    } else if (mesh->reverse_orientation) {
      ng = -ng;
    }
    return ng;
  }

  aabb bounds() const {
    aabb b;
    for (int k = 0; k < 3; ++k) b.grow(vertex(k));
    return b;
  }

  float area() const { return 0.5f * glm::length(glm::cross(vertex(1) - vertex(0), vertex(2) - vertex(0))); }

  bool intersect(const ray& r, float tmin, float tmax, float& t) const {
    const std::optional<triangle_hit> h = intersect_triangle(r, tmax, vertex(0), vertex(1), vertex(2));
    if (!h || !(h->t > tmin)) return false;
    t = h->t;
    return true;
  }

  // The hit record of the hit h: the point interpolated from the vertices,
  // its rounding bound as the offset; the shading normal interpolated from
  // the vertex normals, the texture coordinates (pbrt-v4's (0,0), (1,0),
  // (1,1) where the mesh has none) and dp/du (pbrt-v4's Triangle::
  // InteractionFromIntersection).
  void surface_at(const ray& r, const triangle_hit& h, hit_record& rec) const {
    surface_at(r, h, rec, vertex(0), vertex(1), vertex(2));
  }
  // The same with the vertices p0, p1, p2 (as vertex(0..2)) the caller has
  // (the scene's accelerator keeps a copy beside its leaves): the mesh's
  // indices are read only where it has normals or uv.
  void surface_at(const ray& r, const triangle_hit& h, hit_record& rec, const vec3& p0, const vec3& p1,
                  const vec3& p2) const {
    rec.t = h.t;
    rec.n = normal_of(p0, p1, p2);
    rec.p = h.b0 * p0 + h.b1 * p1 + h.b2 * p2;
    // PBRT 4th ed., eq. 6.28: gamma(7) (|b0 p0| + |b1 p1| + |b2 p2|).
    const vec3 error = rounding_gamma(7) * (glm::abs(h.b0 * p0) + glm::abs(h.b1 * p1) + glm::abs(h.b2 * p2));
    rec.offset = glm::dot(glm::abs(rec.n), error);
    rec.front_face = glm::dot(r.d, rec.n) < 0.0f;
    vec2 uv0{0.0f, 0.0f}, uv1{1.0f, 0.0f}, uv2{1.0f, 1.0f};
    if (!mesh->uv.empty()) {
      const std::size_t i = 3 * std::size_t(index);
      uv0 = mesh->uv[mesh->indices[i]], uv1 = mesh->uv[mesh->indices[i + 1]], uv2 = mesh->uv[mesh->indices[i + 2]];
    }
    rec.uv = h.b0 * uv0 + h.b1 * uv1 + h.b2 * uv2;
    const vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
    const vec3 dp02 = p0 - p2, dp12 = p1 - p2;
    const float det = detail::difference_of_products(duv02.x, duv12.y, duv02.y, duv12.x);
    // A degenerate uv mapping gives no tangent: the shading frame then takes
    // any basis about the normal.
    rec.dpdu = std::abs(det) < 1e-9f ? vec3(0.0f) : (duv12.y * dp02 - duv02.y * dp12) / det;
    if (!mesh->n.empty()) {
      const std::size_t i = 3 * std::size_t(index);
      const std::uint32_t v0 = mesh->indices[i], v1 = mesh->indices[i + 1], v2 = mesh->indices[i + 2];
      const vec3 ns = h.b0 * mesh->n[v0] + h.b1 * mesh->n[v1] + h.b2 * mesh->n[v2];
      const float len2 = glm::dot(ns, ns);
      rec.ns = len2 > 0.0f ? ns / std::sqrt(len2) : rec.n;
    } else {
      rec.ns = vec3(0.0f);
    }
  }

  // The hit record of a hit at t found by intersect() (recomputes the
  // intersection for its barycentric coordinates; the scene's accelerator
  // keeps them from its own test instead).
  void surface(const ray& r, float t, hit_record& rec) const {
    if (const std::optional<triangle_hit> h = intersect_triangle(r, infinity, vertex(0), vertex(1), vertex(2))) {
      surface_at(r, *h, rec);
      rec.t = t;
    } else {
      rec.t = t;
      rec.p = r.at(t);
      rec.n = normal();
      rec.offset = 0.0f;
      rec.front_face = glm::dot(r.d, rec.n) < 0.0f;
    }
  }

  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    float t;
    if (!intersect(r, tmin, tmax, t)) return false;
    surface(r, t, rec);
    return true;
  }
};

// The triangles of a mesh, in face order.
inline std::vector<triangle> triangles_of(const std::shared_ptr<const triangle_mesh>& mesh) {
  std::vector<triangle> out;
  out.reserve(mesh->triangle_count());
  for (std::size_t i = 0; i < mesh->triangle_count(); ++i) out.push_back({mesh, static_cast<std::uint32_t>(i)});
  return out;
}

}  // namespace mcrt
