// Cost of the cosine-aware rectangle strategies against the spherical
// rectangle, sample plus pdf per call, on the light and observers of
// BM_SampleRectSolidAngle (bench/observers.hpp: the Cornell ceiling light,
// 4096 observers 0.2 to 5 light sizes away in front of it):
//
//  BM_RectPSA_SolidAngle       rect_solid_angle_sampler (ignores the normal)
//  BM_RectPSA_Exact<normals>   rect_projected_solid_angle_sampler
//  BM_RectPSA_Bilinear<normals> rect_bilinear_solid_angle_sampler
//  BM_RectPSA_FloorPeters21<normals> Peters 2021 as published (see below)
//  BM_RectPSA_FloorPeters21WithPdf<normals> the same, its pdf charged as a second call's
//
// Receiver normals: "Up", n = (0, 1, 0) for every observer (a floor under
// the light: the light is wholly above every horizon, no clipping);
// "Random", per observer a unit normal uniform on the hemisphere around the
// direction to the light's centre (fixed seed; the horizon clips the light
// for the fraction given by the counter "clipped"). The same observer,
// normal and u sequence for every strategy. Interleaved A/B:
//   build/mcrt_bench_samplers --benchmark_filter=RectPSA
//     --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/sampling/bilinear_spherical_rectangle.hpp"
#include "mcrt/sampling/projected_rectangle.hpp"
#include "mcrt/sampling/spherical_rectangle.hpp"
#include "observers.hpp"

namespace {

using namespace mcrt;

enum class normals { up, random };

std::vector<vec3> receiver_normals(const rect& light, const std::vector<vec3>& obs, normals kind) {
  std::vector<vec3> out;
  out.reserve(obs.size());
  pcg32 rng(5, 3);
  for (const vec3& o : obs) {
    if (kind == normals::up) {
      out.emplace_back(0.0f, 1.0f, 0.0f);
      continue;
    }
    const vec3 to_light = glm::normalize(light.center() - o);
    for (;;) {
      const vec3 d{2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f};
      const float l2 = glm::dot(d, d);
      if (l2 > 1.0f || l2 < 1e-4f) continue;
      const vec3 n = d / std::sqrt(l2);
      out.push_back(glm::dot(n, to_light) >= 0.0f ? n : -n);
      break;
    }
  }
  return out;
}

// The fraction of observers whose horizon cuts the light.
double clipped_fraction(const rect& r, const std::vector<vec3>& obs, const std::vector<vec3>& ns) {
  std::size_t clipped = 0;
  const vec3 p[4] = {r.corner, r.corner + r.e1, r.corner + r.e2, r.corner + r.e1 + r.e2};
  for (std::size_t i = 0; i < obs.size(); ++i) {
    int below = 0;
    for (const vec3& q : p) below += glm::dot(q - obs[i], ns[i]) <= 0.0f;
    clipped += below > 0;
  }
  return double(clipped) / double(obs.size());
}

// As bench::run_sample_and_pdf, with the receiver's normal.
template <class Sampler>
void run_with_normals(benchmark::State& state, const Sampler& sampler, const std::vector<vec3>& obs,
                      const std::vector<vec3>& ns) {
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & (obs.size() - 1);
    light_sample s;
    if (sampler.sample(obs[k], ns[k], rng.uniform2(), s)) benchmark::DoNotOptimize(sampler.pdf(obs[k], ns[k], s.dir));
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_RectPSA_SolidAngle(benchmark::State& state) {
  const rect_solid_angle_sampler sampler{bench::cornell_rect_light()};
  bench::run_sample_and_pdf(state, sampler, bench::observers_around(sampler.shape));
}
BENCHMARK(BM_RectPSA_SolidAngle);

template <normals N>
void BM_RectPSA_Exact(benchmark::State& state) {
  const rect_projected_solid_angle_sampler sampler{bench::cornell_rect_light()};
  const std::vector<vec3> obs = bench::observers_around(sampler.shape);
  const std::vector<vec3> ns = receiver_normals(sampler.shape, obs, N);
  run_with_normals(state, sampler, obs, ns);
  state.counters["clipped"] = clipped_fraction(sampler.shape, obs, ns);
}
BENCHMARK(BM_RectPSA_Exact<normals::up>)->Name("BM_RectPSA_Exact/Up");
BENCHMARK(BM_RectPSA_Exact<normals::random>)->Name("BM_RectPSA_Exact/Random");

template <normals N>
void BM_RectPSA_Bilinear(benchmark::State& state) {
  const rect_bilinear_solid_angle_sampler sampler{bench::cornell_rect_light()};
  const std::vector<vec3> obs = bench::observers_around(sampler.shape);
  const std::vector<vec3> ns = receiver_normals(sampler.shape, obs, N);
  run_with_normals(state, sampler, obs, ns);
  state.counters["clipped"] = clipped_fraction(sampler.shape, obs, ns);
}
BENCHMARK(BM_RectPSA_Bilinear<normals::up>)->Name("BM_RectPSA_Bilinear/Up");
BENCHMARK(BM_RectPSA_Bilinear<normals::random>)->Name("BM_RectPSA_Bilinear/Random");


// ---------------------------------------------------------------- floor
// Peters 2021, "BRDF Importance Sampling for Polygonal Lights" (ACM TOG
// 40(4)), projected-solid-angle sampling of a polygon as published with the
// paper (the author's GLSL, MomentsInGraphics/vulkan_renderer,
// src/shaders/polygon_sampling.glsl: prepare_projected_solid_angle_polygon_
// sampling and sample_projected_solid_angle_polygon with its default two
// iterations; clipping at the horizon as polygon_clipping.glsl), ported to
// C++ in float with the C library's atan, sin, cos: the rectangle's corners
// in the receiver's frame, clipped, the polygon set up and sampled, the
// direction taken back to world space. The pdf cos / Omega_proj comes free
// with the sample. None of the library's guards (float throughout, no
// fallback, Lambert's sum as is), so this bounds from below what the
// published algorithm costs per sample plus pdf on these observers.
namespace peters21 {

constexpr int max_vertices = 5;
constexpr float pi_f = 3.14159265358979f;

inline float kahan(float a, float b, float c, float d) {
  const float cd = c * d;
  const float err = std::fma(c, d, -cd);
  const float res = std::fma(a, b, -cd);
  return res - err;
}
inline vec3 cross_stable(const vec3& l, const vec3& r) {
  return {kahan(l.y, r.z, l.z, r.y), kahan(l.z, r.x, l.x, r.z), kahan(l.x, r.y, l.y, r.x)};
}
inline vec2 rotate_90(vec2 v) { return {-v.y, v.x}; }
inline bool is_inner_ellipse(vec2 e) { return std::signbit(e.x); }
inline float positive_atan(float t) { return std::atan(t) + (t < 0.0f ? pi_f : 0.0f); }
inline float mix_fma(float x, float y, float a) { return std::fma(a, y, std::fma(-a, x, x)); }
inline float inversesqrt(float x) { return 1.0f / std::sqrt(x); }

inline vec2 ellipse_from_edge(const vec3& v0, const vec3& v1) {
  const vec3 normal = cross_stable(v0, v1);
  float scaling = 1.0f / normal.z;
  scaling = is_inner_ellipse(vec2(normal)) ? -scaling : scaling;
  vec2 e = vec2(normal) * scaling;
  e.x = normal.z != 0.0f ? e.x : infinity;
  return e;
}
inline vec2 ellipse_transform(vec2 e, vec2 p) { return glm::dot(e, p) * e + p; }
inline float get_ellipse_det(vec2 e) { return std::fma(e.x, e.x, std::fma(e.y, e.y, 1.0f)); }
inline float get_ellipse_rsqrt_det(vec2 e) { return inversesqrt(get_ellipse_det(e)); }
inline float get_ellipse_direction_factor_rsq(vec2 e, vec2 d) {
  const float ed = glm::dot(e, d);
  return std::fma(ed, ed, glm::dot(d, d));
}
inline float get_ellipse_direction_factor(vec2 e, vec2 d) { return inversesqrt(get_ellipse_direction_factor_rsq(e, d)); }
inline float get_ellipse_normalized_direction_factor(vec2 e, vec2 d) {
  const float ed = glm::dot(e, d);
  return inversesqrt(std::fma(ed, ed, 1.0f));
}
inline float area_between_from_tangents(float in_rsd, float in_tan, float out_rsd, float out_tan) {
  const float inner = in_rsd * positive_atan(in_tan);
  const float result = std::fma(out_rsd, positive_atan(out_tan), -inner);
  return result > 0.0f ? 0.5f * result : 0.0f;
}
inline float area_between_in_sector(vec2 ie, float in_rsd, vec2 oe, float out_rsd, vec2 d0, vec2 d1) {
  const float det = std::max(0.0f, glm::dot(d1, rotate_90(d0)));
  const float in_dot = in_rsd * glm::dot(d0, ellipse_transform(ie, d1));
  const float out_dot = out_rsd * glm::dot(d0, ellipse_transform(oe, d1));
  return area_between_from_tangents(in_rsd, det / in_dot, out_rsd, det / out_dot);
}
inline float ellipse_area_in_sector(vec2 e, vec2 d0, vec2 d1) {
  const float rsd = get_ellipse_rsqrt_det(e);
  const float det = std::max(0.0f, glm::dot(d1, rotate_90(d0)));
  const float edot = rsd * glm::dot(d0, ellipse_transform(e, d1));
  const float area = 0.5f * rsd * positive_atan(det / edot);
  return rsd > 0.0f ? area : 0.0f;
}

struct polygon {
  int vertex_count = 0;
  vec2 vertices[max_vertices];
  vec2 ellipses[max_vertices];
  vec2 inner_ellipse_0;
  float sector_psa[max_vertices];
  float psa = 0.0f;
};

inline void compare_and_swap(polygon& p, int l, int r) {
  const vec2 lc = p.vertices[l];
  const float nz = kahan(lc.x, -p.vertices[r].y, lc.y, -p.vertices[r].x);
  const bool swap = nz == 0.0f ? std::isinf(p.ellipses[r].x) : nz > 0.0f;
  if (swap) {
    std::swap(p.vertices[l], p.vertices[r]);
    std::swap(p.ellipses[l], p.ellipses[r]);
  }
}
inline void sort_vertices(polygon& p) {
  if (p.vertex_count == 3) {
    compare_and_swap(p, 1, 2);
  } else if (p.vertex_count == 4) {
    compare_and_swap(p, 1, 3);
  } else {
    compare_and_swap(p, 2, 4);
    compare_and_swap(p, 1, 3);
    compare_and_swap(p, 1, 2);
    compare_and_swap(p, 0, 3);
    compare_and_swap(p, 3, 4);
  }
  compare_and_swap(p, 0, 2);
  if (p.vertex_count >= 4) compare_and_swap(p, 2, 3);
  compare_and_swap(p, 0, 1);
}

// vertices: clockwise as seen from the origin, the first repeated at
// vertex_count when vertex_count < max_vertices.
inline polygon prepare(int vertex_count, const vec3 (&v)[max_vertices]) {
  polygon p;
  p.vertex_count = vertex_count;
  p.inner_ellipse_0 = {1.0f, 0.0f};
  p.vertices[0] = vec2(v[0]);
  p.ellipses[0] = ellipse_from_edge(v[0], v[1]);
  vec2 previous = p.ellipses[0];
  for (int i = 1; i != max_vertices; ++i) {
    p.vertices[i] = vec2(v[i]);
    if (i > 2 && i == vertex_count) break;
    const vec2 e = ellipse_from_edge(v[i], v[(i + 1) % max_vertices]);
    const bool inner = is_inner_ellipse(e);
    p.ellipses[i] = inner ? previous : e;
    p.inner_ellipse_0 = (is_inner_ellipse(previous) && !inner) ? previous : p.inner_ellipse_0;
    previous = e;
  }
  const vec2 e = p.ellipses[0];
  const bool inner = is_inner_ellipse(e);
  p.ellipses[0] = inner ? previous : e;
  p.inner_ellipse_0 = (is_inner_ellipse(previous) && !inner) ? previous : p.inner_ellipse_0;
  p.psa = 0.0f;
  if (p.inner_ellipse_0.x > 0.0f) {  // central case
    for (int i = 0; i != max_vertices; ++i) {
      if (i > 2 && i == p.vertex_count) break;
      p.sector_psa[i] = ellipse_area_in_sector(p.ellipses[i], p.vertices[i], p.vertices[(i + 1) % max_vertices]);
      p.psa += p.sector_psa[i];
    }
  } else {
    sort_vertices(p);
    vec2 ie = p.inner_ellipse_0, oe{};
    float in_rsd = get_ellipse_rsqrt_det(ie), out_rsd = 0.0f;
    for (int i = 0; i != max_vertices - 1; ++i) {
      if (i > 1 && i + 1 == p.vertex_count) break;
      const vec2 ve = p.ellipses[i];
      const bool vi = is_inner_ellipse(ve);
      const float vr = get_ellipse_rsqrt_det(ve);
      if (i == 0) {
        oe = ve;
        out_rsd = vr;
      } else {
        ie = vi ? ve : ie;
        in_rsd = vi ? vr : in_rsd;
        oe = vi ? oe : ve;
        out_rsd = vi ? out_rsd : vr;
      }
      p.sector_psa[i] = area_between_in_sector(ie, in_rsd, oe, out_rsd, p.vertices[i], p.vertices[i + 1]);
      p.psa += p.sector_psa[i];
    }
  }
  return p;
}

inline vec2 normalize_approx_and_flip(vec2 r, vec2 semi_circle) {
  float scaling = 1.0f / (std::abs(r.x) + std::abs(r.y));
  scaling = glm::dot(r, semi_circle) >= 0.0f ? scaling : -scaling;
  return scaling * r;
}
// 2 x 2 matrix as columns m[col][row] (GLSL layout).
struct mat2c {
  float m[2][2];
};
inline mat2c outer(vec2 c, vec2 r) { return {{{c.x * r.x, c.y * r.x}, {c.x * r.y, c.y * r.y}}}; }
inline vec2 solve_homogeneous_quadratic(const mat2c& q) {
  const float coeff_xy = 0.5f * (q.m[0][1] + q.m[1][0]);
  const float sqrt_disc = std::sqrt(std::max(0.0f, coeff_xy * coeff_xy - q.m[0][0] * q.m[1][1]));
  const float scaled_root = std::abs(coeff_xy) + sqrt_disc;
  return coeff_xy >= 0.0f ? vec2(scaled_root, -q.m[0][0]) : vec2(q.m[1][1], scaled_root);
}

inline vec2 sample_sector_between_ellipses(vec2 rn, float target_area, vec2 ie, vec2 oe, vec2 d0, vec2 d1,
                                           int iteration_count) {
  vec2 qd[3];
  qd[0] = glm::normalize(d0);
  qd[2] = glm::normalize(d1);
  qd[1] = qd[0] + qd[2];
  float nf[2][3] = {{get_ellipse_normalized_direction_factor(ie, qd[0]), get_ellipse_direction_factor(ie, qd[1]),
                     get_ellipse_normalized_direction_factor(ie, qd[2])},
                    {get_ellipse_normalized_direction_factor(oe, qd[0]), get_ellipse_direction_factor(oe, qd[1]),
                     get_ellipse_normalized_direction_factor(oe, qd[2])}};
  const float sector_areas[2] = {nf[1][0] * nf[1][1] - nf[0][0] * nf[0][1], nf[1][1] * nf[1][2] - nf[0][1] * nf[0][2]};
  float tqa = mix_fma(-sector_areas[0], sector_areas[1], rn.x);
  const bool first = tqa <= 0.0f;
  qd[2] = first ? qd[0] : qd[2];
  nf[0][2] = first ? nf[0][0] : nf[0][2];
  nf[1][2] = first ? nf[1][0] : nf[1][2];
  tqa += first ? sector_areas[0] : -sector_areas[1];
  tqa *= std::abs(qd[1].x * qd[2].y - qd[2].x * qd[1].y);
  vec2 qn[2] = {qd[1] * nf[0][1] + qd[2] * nf[0][2], qd[1] * nf[1][1] + qd[2] * nf[1][2]};
  qn[0] = ellipse_transform(ie, qn[0]);
  qn[1] = ellipse_transform(oe, qn[1]);
  const float qo[2] = {glm::dot(qn[0], qd[1]) * nf[0][1], glm::dot(qn[1], qd[1]) * nf[1][1]};
  mat2c q = outer((qo[1] * nf[1][2]) * rotate_90(qd[2]), qn[0]);
  const mat2c q2 = outer((qo[0] * nf[0][2]) * rotate_90(qd[2]) + tqa * qn[0], qn[1]);
  for (int c = 0; c < 2; ++c)
    for (int r = 0; r < 2; ++r) q.m[c][r] -= q2.m[c][r];
  vec2 dir = solve_homogeneous_quadratic(q);
  const float acceptable_error = 1.0e-5f;
  iteration_count = std::abs(rn.x - 0.5f) <= 0.5f - acceptable_error ? iteration_count : 0;
  const float in_rsd = get_ellipse_rsqrt_det(ie), out_rsd = get_ellipse_rsqrt_det(oe);
  for (int i = 0; i != iteration_count; ++i) {
    dir = normalize_approx_and_flip(dir, qd[1]);
    const vec2 idir = ellipse_transform(ie, dir), odir = ellipse_transform(oe, dir);
    const float det = std::max(0.0f, glm::dot(dir, rotate_90(qd[0])));
    const float error = target_area - area_between_from_tangents(in_rsd, det / (in_rsd * glm::dot(qd[0], idir)), out_rsd,
                                                                 det / (out_rsd * glm::dot(qd[0], odir)));
    mat2c a = outer(idir - odir, rotate_90(dir));
    const mat2c b = outer((2.0f * error) * idir, odir);
    for (int c = 0; c < 2; ++c)
      for (int r = 0; r < 2; ++r) a.m[c][r] -= b.m[c][r];
    dir = solve_homogeneous_quadratic(a);
  }
  dir = glm::dot(dir, qd[1]) >= 0.0f ? dir : -dir;
  const float inner_factor = 1.0f / get_ellipse_direction_factor_rsq(ie, dir);
  const float outer_factor = 1.0f / get_ellipse_direction_factor_rsq(oe, dir);
  return dir * std::sqrt(mix_fma(inner_factor, outer_factor, rn.y));
}

inline vec3 sample(const polygon& p, vec2 rn) {
  float target = rn.x * p.psa;
  vec3 out;
  vec2 oe{}, d0{};
  if (p.inner_ellipse_0.x > 0.0f) {
    for (int i = 0; i != max_vertices; ++i) {
      if (i > 0) target -= p.sector_psa[i - 1];
      oe = p.ellipses[i];
      d0 = p.vertices[i];
      if ((i >= 2 && i + 1 == p.vertex_count) || target < p.sector_psa[i]) break;
    }
    const float sqrt_det = std::sqrt(get_ellipse_det(oe));
    const float angle = 2.0f * target * sqrt_det;
    vec2 xy = (std::cos(angle) * sqrt_det) * d0 + std::sin(angle) * rotate_90(ellipse_transform(oe, d0));
    xy *= std::sqrt(rn.y / get_ellipse_direction_factor_rsq(oe, xy));
    out = {xy, 0.0f};
  } else {
    float sector = 0.0f;
    vec2 ie = p.inner_ellipse_0, d1{};
    for (int i = 0; i != max_vertices - 1; ++i) {
      const vec2 ve = p.ellipses[i];
      if (i == 0) {
        oe = ve;
      } else {
        target -= p.sector_psa[i - 1];
        const bool vi = is_inner_ellipse(ve);
        ie = vi ? ve : ie;
        oe = vi ? oe : ve;
      }
      d0 = p.vertices[i];
      d1 = p.vertices[i + 1];
      sector = p.sector_psa[i];
      if ((i >= 1 && i + 2 == p.vertex_count) || target < sector) break;
    }
    rn.x = target / sector;
    out = {sample_sector_between_ellipses(rn, target, ie, oe, d0, d1, 2), 0.0f};
  }
  out.z = std::sqrt(std::max(0.0f, std::fma(-out.x, out.x, std::fma(-out.y, out.y, 1.0f))));
  return out;
}

// The rectangle's corners in the receiver's frame (Duff et al. 2017 basis),
// clockwise as seen from o, clipped at z = 0 (Sutherland-Hodgman, as
// polygon_clipping.glsl's table does case by case); the first vertex
// repeated at the count. Returns the count (0: nothing above the horizon).
struct frame {
  vec3 t, b, n;
  explicit frame(const vec3& nn) : n(nn) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z), bb = n.x * n.y * a;
    t = {1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x};
    b = {bb, sign + n.y * n.y * a, -n.y};
  }
  vec3 to_local(const vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  vec3 to_world(const vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};
inline int clip(const rect& r, const vec3& o, const frame& f, vec3 (&v)[max_vertices]) {
  vec3 c[4] = {f.to_local(r.corner - o), f.to_local(r.corner + r.e1 - o), f.to_local(r.corner + r.e1 + r.e2 - o),
               f.to_local(r.corner + r.e2 - o)};
  // Clockwise as seen from the origin (counterclockwise about the zenith
  // for a polygon above): the triple product of the first three corners is
  // positive; reverse the order otherwise.
  if (glm::dot(c[0], glm::cross(c[1], c[2])) < 0.0f) std::swap(c[1], c[3]);
  int k = 0;
  for (int i = 0; i < 4; ++i) {
    const vec3 &a = c[i], &b = c[(i + 1) & 3];
    if (a.z > 0.0f) v[k++] = a;
    if ((a.z > 0.0f) != (b.z > 0.0f)) {
      const float s = a.z / (a.z - b.z);
      v[k++] = vec3(vec2(a) + s * (vec2(b) - vec2(a)), 0.0f);
    }
  }
  if (k < 3) return 0;
  if (k < max_vertices) v[k] = v[0];
  return k;
}

}  // namespace peters21

// sample + pdf of Peters 2021 as published (see above) on the observers.
// With charge_pdf (BM_RectPSA_FloorPeters21WithPdf) the pdf of the sampled
// direction is charged as a second call from the same receiver would pay it,
// as the library's pdf() does: the clip and the polygon's set-up again (its
// projected solid angle), then cos / Omega_proj. Not the published usage (a
// shader prepares once per shading point and reuses the set-up for the light
// sample and the BSDF direction's pdf), but the like-for-like counterpart of
// sample() + pdf() through a stateless interface.
template <normals N, bool charge_pdf>
void BM_RectPSA_FloorPeters21(benchmark::State& state) {
  const rect light = bench::cornell_rect_light();
  const std::vector<vec3> obs = bench::observers_around(light);
  const std::vector<vec3> ns = receiver_normals(light, obs, N);
  pcg32 rng(1, 2);
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & (obs.size() - 1);
    const peters21::frame f(ns[k]);
    vec3 v[peters21::max_vertices];
    const int count = peters21::clip(light, obs[k], f, v);
    if (count == 0) continue;
    const peters21::polygon p = peters21::prepare(count, v);
    const vec3 local = peters21::sample(p, rng.uniform2());
    const vec3 dir = f.to_world(local);
    benchmark::DoNotOptimize(dir);
    if constexpr (charge_pdf) {
      const peters21::frame f2(ns[k]);
      vec3 v2[peters21::max_vertices];
      const int count2 = peters21::clip(light, obs[k], f2, v2);
      if (count2 == 0) continue;
      const peters21::polygon p2 = peters21::prepare(count2, v2);
      benchmark::DoNotOptimize(glm::dot(dir, ns[k]) / p2.psa);
    } else {
      benchmark::DoNotOptimize(local.z / p.psa);
    }
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RectPSA_FloorPeters21<normals::up, false>)->Name("BM_RectPSA_FloorPeters21/Up");
BENCHMARK(BM_RectPSA_FloorPeters21<normals::random, false>)->Name("BM_RectPSA_FloorPeters21/Random");
BENCHMARK(BM_RectPSA_FloorPeters21<normals::up, true>)->Name("BM_RectPSA_FloorPeters21WithPdf/Up");
BENCHMARK(BM_RectPSA_FloorPeters21<normals::random, true>)->Name("BM_RectPSA_FloorPeters21WithPdf/Random");

}  // namespace
