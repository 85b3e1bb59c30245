#pragma once
// A leaf's triangles against one ray at once: the watertight test of
// triangle_mesh.hpp (Woop, Benthin & Wald 2013) over up to four triangles
// stored side by side, its arithmetic in the four lanes of one vector, as
// Embree's Triangle4 leaves test four triangles at once (Wald et al. 2014,
// "Embree: a kernel framework for efficient CPU ray tracing", sec. 4). A
// hierarchy built with leaf_block = 4 (accel/bvh.hpp) has leaves of up to
// four triangles, each tested for the price of about one.
//
// The vector part only rejects, and it computes exactly the scalar test's
// numbers (the same operations in the same order, fused where that fuses),
// so a triangle it rejects the scalar test rejects too. A triangle it does
// not reject, or whose edge function is 0 (where the scalar test recomputes
// in double), is tested again by intersect_triangle, in the leaf's order
// and with the closest hit so far: the hits are bit for bit those of
// testing the triangles one by one (tests/test_triangle_leaf.cpp).
#include <array>
#include <bit>
#include <cstdint>
#include <optional>

#if defined(__FMA__) && defined(__SSE4_1__)
#include <immintrin.h>
#endif

#include "mcrt/geometry/triangle_mesh.hpp"

namespace mcrt {

// A triangle's vertices as an accelerator stores them, leaf by leaf, and a
// tag of the caller's (the scene: the triangle's index among its
// triangles). 40 bytes.
struct triangle_vertices {
  std::array<vec3, 3> p;
  std::uint32_t tag = 0;
};
static_assert(sizeof(triangle_vertices) == 40);

// The most triangles one vector test takes.
inline constexpr int triangle_leaf_width = 4;

namespace detail {

#if defined(__FMA__) && defined(__SSE4_1__)
// Bit j set where tris[j] (j < count <= 4) may be hit in (0, tmax): not
// rejected by the watertight test's edge-function signs, determinant and
// distance, or with an edge function of 0.
inline unsigned triangle_candidates(const watertight_ray& wr, float tmax, const triangle_vertices* tris, int count) {
  // The leaf as a structure of arrays: soa[3 v + k] holds coordinate k of
  // vertex v, lane j from triangle j (triangle 0 again in unused lanes).
  const auto& t0 = tris[0];
  const auto& t1 = tris[count > 1 ? 1 : 0];
  const auto& t2 = tris[count > 2 ? 2 : 0];
  const auto& t3 = tris[count > 3 ? 3 : 0];
  // Rows p0x p0y p0z p1x and p1y p1z p2x p2y of each triangle, transposed.
  __m128 a0 = _mm_loadu_ps(&t0.p[0].x), a1 = _mm_loadu_ps(&t1.p[0].x), a2 = _mm_loadu_ps(&t2.p[0].x),
         a3 = _mm_loadu_ps(&t3.p[0].x);
  __m128 b0 = _mm_loadu_ps(&t0.p[1].y), b1 = _mm_loadu_ps(&t1.p[1].y), b2 = _mm_loadu_ps(&t2.p[1].y),
         b3 = _mm_loadu_ps(&t3.p[1].y);
  _MM_TRANSPOSE4_PS(a0, a1, a2, a3);
  _MM_TRANSPOSE4_PS(b0, b1, b2, b3);
  const __m128 soa[9] = {a0, a1, a2, a3, b0, b1, b2, b3, _mm_setr_ps(t0.p[2].z, t1.p[2].z, t2.p[2].z, t3.p[2].z)};
  const __m128 ox = _mm_set1_ps(watertight_ray::component(wr.o, wr.kx));
  const __m128 oy = _mm_set1_ps(watertight_ray::component(wr.o, wr.ky));
  const __m128 oz = _mm_set1_ps(watertight_ray::component(wr.o, wr.kz));
  const __m128 sx = _mm_set1_ps(wr.sx), sy = _mm_set1_ps(wr.sy), sz = _mm_set1_ps(wr.sz);
  __m128 x[3], y[3], z[3];
  for (std::size_t v = 0; v < 3; ++v) {
    // watertight_ray::to_frame
    const __m128 xv = _mm_sub_ps(soa[3 * v + static_cast<std::size_t>(wr.kx)], ox);
    const __m128 yv = _mm_sub_ps(soa[3 * v + static_cast<std::size_t>(wr.ky)], oy);
    z[v] = _mm_sub_ps(soa[3 * v + static_cast<std::size_t>(wr.kz)], oz);
    x[v] = _mm_fmadd_ps(sx, z[v], xv);
    y[v] = _mm_fmadd_ps(sy, z[v], yv);
  }
  // difference_of_products(a, b, c, d): fma(a, b, -cd) + fma(-c, d, cd).
  const auto dop = [](__m128 a, __m128 b, __m128 c, __m128 d) {
    const __m128 cd = _mm_mul_ps(c, d);
    return _mm_add_ps(_mm_fmsub_ps(a, b, cd), _mm_fnmadd_ps(c, d, cd));
  };
  const __m128 e0 = dop(x[1], y[2], y[1], x[2]);
  const __m128 e1 = dop(x[2], y[0], y[2], x[0]);
  const __m128 e2 = dop(x[0], y[1], y[0], x[1]);
  const __m128 zero = _mm_setzero_ps();
  const __m128 any_zero =
      _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(e0, zero), _mm_cmpeq_ps(e1, zero)), _mm_cmpeq_ps(e2, zero));
  const __m128 neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(e0, zero), _mm_cmplt_ps(e1, zero)), _mm_cmplt_ps(e2, zero));
  const __m128 pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(e0, zero), _mm_cmpgt_ps(e1, zero)), _mm_cmpgt_ps(e2, zero));
  const __m128 det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
  const __m128 z0 = _mm_mul_ps(z[0], sz), z1 = _mm_mul_ps(z[1], sz), z2 = _mm_mul_ps(z[2], sz);
  const __m128 ts = _mm_fmadd_ps(e2, z2, _mm_fmadd_ps(e1, z1, _mm_mul_ps(e0, z0)));
  const __m128 tmax_det = _mm_mul_ps(_mm_set1_ps(tmax), det);
  // The scalar test's rejections, as it writes them (a NaN rejects nothing).
  const __m128 reject_neg =
      _mm_and_ps(_mm_cmplt_ps(det, zero), _mm_or_ps(_mm_cmpge_ps(ts, zero), _mm_cmplt_ps(ts, tmax_det)));
  const __m128 reject_pos =
      _mm_and_ps(_mm_cmpgt_ps(det, zero), _mm_or_ps(_mm_cmple_ps(ts, zero), _mm_cmpgt_ps(ts, tmax_det)));
  const __m128 reject = _mm_or_ps(_mm_or_ps(_mm_and_ps(neg, pos), _mm_cmpeq_ps(det, zero)),
                                  _mm_or_ps(reject_neg, reject_pos));
  const unsigned keep = static_cast<unsigned>(_mm_movemask_ps(any_zero)) | ~static_cast<unsigned>(_mm_movemask_ps(reject));
  return keep & ((1u << count) - 1u);
}
#else
// Without FMA and SSE 4.1: every triangle goes to the scalar test.
inline unsigned triangle_candidates(const watertight_ray&, float, const triangle_vertices*, int count) {
  return (1u << count) - 1u;
}
#endif

}  // namespace detail

// The closest hit in (tmin, tmax) among tris[0 .. count) (count <= 4), as
// testing them one by one with intersect_triangle and lowering tmax at each
// hit: returns the index of the closest, with tmax lowered to its t and
// hit set, or -1 (tmax and hit untouched).
inline int closest_in_leaf(const watertight_ray& wr, float tmin, float& tmax, const triangle_vertices* tris, int count,
                           triangle_hit& hit) {
  int best = -1;
  for (unsigned m = detail::triangle_candidates(wr, tmax, tris, count); m != 0; m &= m - 1) {
    const int j = std::countr_zero(m);
    const triangle_vertices& t = tris[j];
    const std::optional<triangle_hit> h = intersect_triangle(wr, tmax, t.p[0], t.p[1], t.p[2]);
    if (h && h->t > tmin && h->t < tmax) {
      tmax = h->t;
      hit = *h;
      best = j;
    }
  }
  return best;
}

// Whether any of tris[0 .. count) is hit in (tmin, tmax).
inline bool any_in_leaf(const watertight_ray& wr, float tmin, float tmax, const triangle_vertices* tris, int count) {
  for (unsigned m = detail::triangle_candidates(wr, tmax, tris, count); m != 0; m &= m - 1) {
    const triangle_vertices& t = tris[std::countr_zero(m)];
    const std::optional<triangle_hit> h = intersect_triangle(wr, tmax, t.p[0], t.p[1], t.p[2]);
    if (h && h->t > tmin && h->t < tmax) return true;
  }
  return false;
}

}  // namespace mcrt
