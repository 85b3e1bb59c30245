// Ray origins without a scene-scaled t_min: every shape bounds the error of
// its hit points (hit_record::offset), rays leave from spawn_origin and are
// intersected from t = 0 (Pharr et al., "Physically Based Rendering", 4th
// ed., sec. 6.8).
//
// 1. No self-intersection, deterministically: rays that hit a shape (a
//    closed triangle mesh, a sphere, a rotated box, a turned rectangle and
//    ellipse, an axis-aligned rectangle), placed at the origin and 10^3 and
//    10^4 away, each leave the hit point again in a random direction, down
//    to grazing ones (cosines from 10^-4): a ray leaving a convex shape's
//    outside, or either side of a flat one, meets nothing; one going into a
//    closed shape meets its far side, never the face it left.
// 2. Direct light against Lambert's polygon formula on receivers far from
//    the origin: the faces of a rotated cube mesh and of the analytic
//    rotated box, a sphere, a turned rectangle and ellipse, each under a
//    ceiling light turned in its plane and partly behind the receiver's
//    horizon (shadow rays leave at grazing angles), at offsets 0, 10^3 and
//    10^4; and a slab 0.01 thick (10^-4 of its width, at 10^4 from the
//    origin: a few ulps of its coordinates) over a floor 0.01 below it:
//    its top face is lit as Lambert says, and the floor under it stays
//    dark (no shadow ray slips through the slab or the gap).
//
// Statistics as in test_render_receivers.cpp: R = 32 independent Sobol
// scramblings of n = 8192 samples (32768 for the mixture), and the check is
// |mean - exact| <= 1e-3 exact + 6 standard errors (Student t, 31 degrees of
// freedom: two-sided false-failure probability 1.2e-6 per check, below 1e-3
// for this file's checks). 6 standard errors must be at most 1 % of the
// value, and at most 0.1 % for next-event estimation with projected-solid-
// angle sampling, whose light samples are each the exact irradiance of the
// part of the light the receiver sees: there the bias allowed is 0.1 % and
// the noise cannot hide it.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "support/lambert.hpp"
#include "support/light_strategies.hpp"
#include "support/radiance_estimate.hpp"

using namespace mcrt;

namespace {

constexpr float albedo = 0.5f;
constexpr float emit = 15.0f;
constexpr int replicates = 32;
constexpr int samples_per_replicate = 8192;  // 4x for the mixture

// Where the test scenes are placed: the origin, 10^3 and 10^4 from it along
// a direction no axis is (every coordinate large).
vec3 placement(float distance) { return distance * vec3(1.0f, 0.7f, -1.3f) / glm::length(vec3(1.0f, 0.7f, -1.3f)); }

// Rotation by `degrees` about a unit axis (Rodrigues), in double.
glm::dmat3 rotation(const glm::dvec3& axis, double degrees) {
  const glm::dvec3 k = glm::normalize(axis);
  const double a = degrees * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
  const glm::dmat3 K(0, k.z, -k.y, -k.z, 0, k.x, k.y, -k.x, 0);  // columns: K v = k x v
  return glm::dmat3(1.0) + s * K + (1.0 - c) * K * K;
}

// A cube mesh of side `size` (or a box of sides `extent`), centred at
// `centre`, turned by R: 12 triangles wound outwards.
std::shared_ptr<const triangle_mesh> box_mesh(const vec3& centre, const glm::dvec3& extent, const glm::dmat3& R) {
  triangle_mesh m;
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 local(((c & 1) ? 0.5 : -0.5) * extent.x, ((c & 2) ? 0.5 : -0.5) * extent.y,
                           ((c & 4) ? 0.5 : -0.5) * extent.z);
    m.p.push_back(centre + vec3(R * local));
  }
  // Faces as corner indices, counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces)
    for (const int k : {f[0], f[1], f[2], f[0], f[2], f[3]}) m.indices.push_back(static_cast<std::uint32_t>(k));
  return std::make_shared<const triangle_mesh>(std::move(m));
}

// An icosphere (the icosahedron subdivided `levels` times, on the sphere).
std::shared_ptr<const triangle_mesh> icosphere(const vec3& centre, float radius, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<glm::dvec3> v{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<glm::uvec3> f{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (glm::dvec3& p : v) p = glm::normalize(p);
  for (int l = 0; l < levels; ++l) {
    std::vector<glm::uvec3> g;
    for (const glm::uvec3& tri : f) {
      glm::uvec3 mid;
      for (int e = 0; e < 3; ++e) {
        v.push_back(glm::normalize(v[tri[e]] + v[tri[(e + 1) % 3]]));  // duplicates are harmless here
        mid[e] = static_cast<unsigned>(v.size() - 1);
      }
      g.push_back({tri[0], mid[0], mid[2]});
      g.push_back({tri[1], mid[1], mid[0]});
      g.push_back({tri[2], mid[2], mid[1]});
      g.push_back(mid);
    }
    f = g;
  }
  triangle_mesh m;
  for (const glm::dvec3& p : v) m.p.push_back(centre + vec3(double(radius) * p));
  for (const glm::uvec3& tri : f)
    for (int e = 0; e < 3; ++e) m.indices.push_back(tri[e]);
  return std::make_shared<const triangle_mesh>(std::move(m));
}

void add_mesh(scene& sc, const std::shared_ptr<const triangle_mesh>& mesh, std::uint32_t material) {
  for (const triangle& t : triangles_of(mesh)) sc.add(t, material);
}

// A unit direction on the side of n with cosine cos_theta to it, at azimuth phi.
vec3 direction_at(const vec3& n, float cos_theta, float phi) {
  const onb b(n);
  const float s = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
  return glm::normalize(b.to_world({s * std::cos(phi), s * std::sin(phi), cos_theta}));
}

// ---- 1. no self-intersection ---------------------------------------------------

enum class shape_kind { mesh_sphere, mesh_cube, sphere, box, rect, ellipse, axis_rect };
const char* name_of(shape_kind k) {
  switch (k) {
    case shape_kind::mesh_sphere: return "mesh_sphere";
    case shape_kind::mesh_cube: return "mesh_cube";
    case shape_kind::sphere: return "sphere";
    case shape_kind::box: return "box";
    case shape_kind::rect: return "rect";
    case shape_kind::ellipse: return "ellipse";
    case shape_kind::axis_rect: return "axis_rect";
  }
  return "?";
}
bool closed(shape_kind k) { return k != shape_kind::rect && k != shape_kind::ellipse && k != shape_kind::axis_rect; }

// One shape of the given size at `centre` (size 1 at 10^4: coordinates
// 10^4 times the shape's size).
scene shape_scene(shape_kind k, const vec3& centre, float size) {
  scene sc;
  sc.materials = {lambertian{color(albedo)}};
  const glm::dmat3 R = rotation({1.0, 2.0, 0.5}, 25.0);
  switch (k) {
    case shape_kind::mesh_sphere: add_mesh(sc, icosphere(centre, 0.5f * size, 3), 0); break;
    case shape_kind::mesh_cube: add_mesh(sc, box_mesh(centre, glm::dvec3(size), R), 0); break;
    case shape_kind::sphere: sc.add(sphere{centre, 0.5f * size}, 0); break;
    case shape_kind::box:
      sc.add(box{vec3(-0.5f * size), vec3(0.5f * size), rigid_y::make(15.0f, centre)}, 0);
      break;
    case shape_kind::rect: {
      const vec3 e1(R * glm::dvec3(size, 0, 0)), e2(R * glm::dvec3(0, 0, 0.7 * size));
      sc.add(rect::make(centre - 0.5f * (e1 + e2), e1, e2), 0);
      break;
    }
    case shape_kind::ellipse:
      sc.add(ellipse::make(centre, vec3(R * glm::dvec3(0.5 * size, 0, 0)), vec3(R * glm::dvec3(0, 0, 0.3 * size))), 0);
      break;
    case shape_kind::axis_rect:
      sc.add(xz_rect(centre.x - 0.5f * size, centre.x + 0.5f * size, centre.z - 0.4f * size, centre.z + 0.4f * size,
                     centre.y),
             0);
      break;
  }
  sc.build_accelerator();
  return sc;
}

bool is_mesh(shape_kind k) { return k == shape_kind::mesh_sphere || k == shape_kind::mesh_cube; }

// Is o inside the convex closed mesh of the scene's triangles, exactly (in
// double, on the inner side of every triangle's plane, the normals wound
// outwards)?
bool inside_convex_mesh(const scene& sc, const vec3& o) {
  for (const auto& obj : std::get<std::vector<object<triangle>>>(sc.objects)) {
    const glm::dvec3 p0(obj.shape.vertex(0)), p1(obj.shape.vertex(1)), p2(obj.shape.vertex(2));
    if (glm::dot(glm::dvec3(o) - p0, glm::cross(p1 - p0, p2 - p0)) >= 0.0) return false;
  }
  return true;
}

using shape_case = std::tuple<shape_kind, float, float>;  // shape, distance from the origin, size

class LeavingRays : public ::testing::TestWithParam<shape_case> {};

TEST_P(LeavingRays, NeverMeetTheSurfaceTheyLeave) {
  const auto& [kind, distance, size] = GetParam();
  const vec3 centre = placement(distance);
  const scene sc = shape_scene(kind, centre, size);
  pcg32 rng(7 + static_cast<std::uint64_t>(kind), 11);
  // The sphere's hit points are rounded to the coordinates' ulps (10^-3 at
  // 10^4), which turns its computed normal by up to 2 10^-3 for the small
  // one: a direction that grazes the computed normal's plane may truly
  // point into the sphere. Its rays are judged by the exact (double)
  // intersection of the float ray with the float sphere instead.
  const sphere* ball = kind == shape_kind::sphere ? &std::get<std::vector<object<sphere>>>(sc.objects)[0].shape : nullptr;
  // The parameters of the exact sphere's hits along the ray from o along d
  // (t0 <= t1), or false where it misses.
  const auto exact_roots = [&](const vec3& o, const vec3& d, double& t0, double& t1) {
    const glm::dvec3 oc = glm::dvec3(o) - glm::dvec3(ball->center), dd(d);
    const double a = glm::dot(dd, dd), hb = glm::dot(oc, dd), c = glm::dot(oc, oc) - double(ball->radius) * ball->radius;
    const double disc = hb * hb - a * c;
    if (disc < 0.0) return false;
    t0 = (-hb - std::sqrt(disc)) / a;
    t1 = (-hb + std::sqrt(disc)) / a;
    return true;
  };
  int hits = 0, outward_self = 0, inward_self = 0, judged_exactly = 0;
  constexpr int rays = 20000;
  for (int i = 0; i < rays; ++i) {
    // A ray from a random point 2 sizes away towards a random point of the
    // shape's box.
    const vec3 from = centre + 2.0f * size * square_to_uniform_sphere(rng.uniform2());
    const vec3 to = centre + 0.5f * size * (vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0f - 1.0f);
    hit_record rec;
    if (!sc.hit(ray{from, glm::normalize(to - from)}, 0.0f, infinity, rec)) continue;
    ++hits;
    const vec3 nf = rec.facing_normal();
    // Cosines spread over 10^-4 .. 1, logarithmically: most rays graze.
    const float cos_theta = std::pow(10.0f, -4.0f * rng.uniform());
    const float phi = two_pi * rng.uniform();
    const vec3 out = direction_at(nf, cos_theta, phi);
    const vec3 o_out = rec.spawn_origin(out);
    hit_record r2;
    double t0 = 0.0, t1 = 0.0;
    if (ball && exact_roots(o_out, out, t0, t1) && t1 > 0.0)
      ++judged_exactly;  // truly meets the sphere: not a leaving ray
    else if (sc.hit(ray{o_out, out}, 0.0f, infinity, r2))
      ++outward_self;
    if (!closed(kind)) {
      // The other side of a flat shape: nothing either.
      const vec3 in = direction_at(-nf, cos_theta, phi);
      if (sc.hit(ray{rec.spawn_origin(in), in}, 0.0f, infinity, r2)) ++inward_self;
      continue;
    }
    // Into the shape, at least 3 degrees off its plane: it meets the far
    // side, never the face it left (a flat face's self-hit has its normal
    // exactly; the sphere's lies short of the exact chord).
    const vec3 in = direction_at(-nf, std::max(cos_theta, 0.05f), phi);
    const vec3 o_in = rec.spawn_origin(in);
    if (!sc.hit(ray{o_in, in}, 0.0f, infinity, r2)) {
      // A closed shape's inside always meets its far side. Within the
      // offset (10^-3 at 10^4) of an edge of the small mesh cube, the
      // origin moved off one face may lie past the next one, outside: the
      // ray then rightly meets nothing.
      if (is_mesh(kind) && !inside_convex_mesh(sc, o_in))
        ++judged_exactly;
      else
        ++inward_self;
      continue;
    }
    if (ball) {
      if (!exact_roots(o_in, in, t0, t1) || !(t0 < 0.0 && t1 > 0.0) || r2.t < 0.5 * t1) ++inward_self;
    } else if (glm::dot(r2.n, rec.n) > 1.0f - 1e-6f) {
      ++inward_self;

    }
  }
  const std::string what = std::string(name_of(kind)) + " at " + std::to_string(distance);
  EXPECT_GT(hits, rays / 10) << what;
  EXPECT_LE(judged_exactly, hits / 20) << what << ": few rays are ambiguous (1.8 % for the small sphere at 10^4)";
  EXPECT_EQ(outward_self, 0) << what << ": rays leaving the outside met the shape again";
  EXPECT_EQ(inward_self, 0) << what << ": rays into the shape (or off a flat shape's back) met the face they left";
}

INSTANTIATE_TEST_SUITE_P(
    All, LeavingRays,
    ::testing::Combine(::testing::Values(shape_kind::mesh_sphere, shape_kind::mesh_cube, shape_kind::sphere,
                                         shape_kind::box, shape_kind::rect, shape_kind::ellipse, shape_kind::axis_rect),
                       ::testing::Values(0.0f, 1e3f, 1e4f), ::testing::Values(100.0f, 1.0f)),
    [](const auto& info) {
      return std::string(name_of(std::get<0>(info.param))) + "_at" +
             std::to_string(static_cast<int>(std::get<1>(info.param))) + "_size" +
             std::to_string(static_cast<int>(std::get<2>(info.param)));
    });

// ---- 2. direct light against Lambert's formula --------------------------------

// A light 60 x 40 turned 20 degrees in its plane, facing down, centred
// `above` over `centre` and `aside` to the side along x.
rect ceiling_light(const vec3& centre, float above, float aside) {
  const rigid_y turn = rigid_y::make(20.0f, vec3(0.0f));
  const vec3 e1 = turn.rotate({0, 0, 40}), e2 = turn.rotate({60, 0, 0});
  const vec3 c = centre + vec3(aside, above, 0.0f);
  return rect::make(c - 0.5f * (e1 + e2), e1, e2, true);
}

std::vector<glm::dvec3> polygon_of(const rect& r) {
  const glm::dvec3 c(r.corner), e1(r.e1), e2(r.e2);
  return {c, c + e1, c + e1 + e2, c + e2};
}

// A receiver point and its outward normal.
struct receiver {
  vec3 p, n;
  std::string name;
};

enum class receiver_kind { mesh_cube, box, sphere, rect, ellipse };
const char* name_of(receiver_kind k) {
  switch (k) {
    case receiver_kind::mesh_cube: return "mesh_cube";
    case receiver_kind::box: return "box";
    case receiver_kind::sphere: return "sphere";
    case receiver_kind::rect: return "rect";
    case receiver_kind::ellipse: return "ellipse";
  }
  return "?";
}

// The receiver of `kind` (size 100) at `centre` and points of it the light
// lights, most with part of the light behind their horizon.
std::vector<receiver> add_receiver(scene& sc, receiver_kind kind, const vec3& centre) {
  std::vector<receiver> out;
  const glm::dmat3 R = rotation({1.0, 2.0, 0.5}, 25.0);
  switch (kind) {
    case receiver_kind::mesh_cube: {
      const auto mesh = box_mesh(centre, glm::dvec3(100.0), R);
      add_mesh(sc, mesh, 0);
      // Each face's centre and a point near a corner, for the faces the
      // light sees at least in part.
      const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
      for (int f = 0; f < 6; ++f) {
        const vec3 a = mesh->p[faces[f][0]], b = mesh->p[faces[f][1]], c = mesh->p[faces[f][2]], d = mesh->p[faces[f][3]];
        const vec3 n = glm::normalize(glm::cross(b - a, c - a));
        if (n.y < -0.2f) continue;  // faces turned away from the ceiling light
        out.push_back({0.25f * (a + b + c + d), n, "face " + std::to_string(f) + " centre"});
        out.push_back({0.7f * c + 0.1f * (a + b + d), n, "face " + std::to_string(f) + " corner"});
      }
      break;
    }
    case receiver_kind::box: {
      const box b{vec3(-50.0f), vec3(50.0f), rigid_y::make(15.0f, centre)};
      sc.add(b, 0);
      out.push_back({b.xf.to_world({0, 50, 0}), vec3(0, 1, 0), "top centre"});
      out.push_back({b.xf.to_world({40, 50, -35}), vec3(0, 1, 0), "top corner"});
      out.push_back({b.xf.to_world({0, 30, -50}), b.xf.rotate({0, 0, -1}), "front, high"});
      out.push_back({b.xf.to_world({50, 45, 10}), b.xf.rotate({1, 0, 0}), "side, high"});
      break;
    }
    case receiver_kind::sphere: {
      sc.add(sphere{centre, 50.0f}, 0);
      for (const auto& [theta, phi] : {std::pair{10.0, 0.0}, {60.0, 30.0}, {85.0, 200.0}, {80.0, 10.0}}) {
        const double t = theta * std::numbers::pi / 180.0, f = phi * std::numbers::pi / 180.0;
        const vec3 n(glm::dvec3(std::sin(t) * std::cos(f), std::cos(t), std::sin(t) * std::sin(f)));
        out.push_back({centre + 50.0f * n, n, "polar " + std::to_string(static_cast<int>(theta))});
      }
      break;
    }
    case receiver_kind::rect: {
      const glm::dmat3 tilt = rotation({0.3, 0.0, 1.0}, 60.0);  // steep: its horizon cuts the light
      const vec3 e1(tilt * glm::dvec3(0, 0, 100)), e2(tilt * glm::dvec3(100, 0, 0));
      const rect r = rect::make(centre - 0.5f * (e1 + e2), e1, e2);
      sc.add(r, 0);
      out.push_back({r.center(), r.n, "centre"});
      out.push_back({r.corner + 0.9f * r.e1 + 0.1f * r.e2, r.n, "corner"});
      break;
    }
    case receiver_kind::ellipse: {
      const glm::dmat3 tilt = rotation({0.3, 0.0, 1.0}, 62.0);  // steep: its horizon cuts the light
      const ellipse e = ellipse::make(centre, vec3(tilt * glm::dvec3(0, 0, 30)), vec3(tilt * glm::dvec3(50, 0, 0)));  // z x x: up
      sc.add(e, 0);
      out.push_back({e.center, e.n, "centre"});
      out.push_back({e.center + 0.8f * e.a1, e.n, "rim"});
      break;
    }
  }
  return out;
}

using light_case = std::tuple<receiver_kind, float, integrator_kind, std::string>;

class FarReceivers : public ::testing::TestWithParam<light_case> {};

TEST_P(FarReceivers, MatchLambertsFormula) {
  const auto& [kind, distance, ik, strategy] = GetParam();
  const vec3 centre = placement(distance);
  scene sc;
  sc.materials = {lambertian{color(albedo)}, diffuse_light{color(emit)}};
  const std::vector<receiver> points = add_receiver(sc, kind, centre);
  const rect light = ceiling_light(centre, 110.0f, 60.0f);
  test::add_rect_light(sc, light, strategy);
  sc.build_accelerator();
  const std::vector<glm::dvec3> poly = polygon_of(light);
  const bool exact_samples = strategy == "projected-solid-angle" && ik == integrator_kind::nee;
  int id = 0, grazing = 0;
  for (const receiver& rc : points) {
    const double exact =
        albedo / std::numbers::pi * test::clipped_polygon_irradiance(glm::dvec3(rc.p), glm::dvec3(rc.n), poly, emit);
    if (!(exact > 0.0)) continue;
    // Cut by the horizon, or seen at a grazing angle: a vertex of the
    // light behind the receiver's plane or within 0.2 of it in cosine.
    double min_cos = 1.0;
    for (const glm::dvec3& v : poly)
      min_cos = std::min(min_cos, glm::dot(glm::dvec3(rc.n), glm::normalize(v - glm::dvec3(rc.p))));
    if (min_cos < 0.2)
      ++grazing;
    const ray camera_ray{rc.p + 30.0f * rc.n, -rc.n};
    const test::estimate e =
        test::radiance_along(sc, camera_ray, path_settings{1, 3}, ik, sampler_kind::sobol, replicates,
                             samples_per_replicate * (ik == integrator_kind::mixture ? 4 : 1), id, 2000 + id);
    const std::string what = std::string(name_of(kind)) + " " + rc.name + " at " + std::to_string(distance);
    EXPECT_LE(std::abs(e.mean - exact), 1e-3 * exact + 6.0 * e.stderr_)
        << what << ": mean " << e.mean << " exact " << exact << " stderr " << e.stderr_ << " (relative error "
        << (e.mean - exact) / exact << ")";
    EXPECT_LE(6.0 * e.stderr_, (exact_samples ? 1e-3 : 1e-2) * exact)
        << what << ": the noise would hide a bias: stderr " << e.stderr_;
    ++id;
  }
  EXPECT_GE(id, 2) << "receiver points lit";
  EXPECT_GE(grazing, 1) << "points with the light at grazing angles or cut by their horizon";
}

INSTANTIATE_TEST_SUITE_P(
    All, FarReceivers,
    ::testing::Combine(::testing::Values(receiver_kind::mesh_cube, receiver_kind::box, receiver_kind::sphere,
                                         receiver_kind::rect, receiver_kind::ellipse),
                       ::testing::Values(0.0f, 1e3f, 1e4f),
                       ::testing::Values(integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis),
                       ::testing::Values("area", "projected-solid-angle")),
    [](const auto& info) {
      std::string n = std::string(name_of(std::get<0>(info.param))) + "_at" +
                      std::to_string(static_cast<int>(std::get<1>(info.param))) + "_" +
                      std::string(to_string(std::get<2>(info.param))) + "_" + std::get<3>(info.param);
      for (char& ch : n)
        if (ch == '-') ch = '_';
      return n;
    });

// A slab 100 x 0.01 x 100 turned 10 degrees, 10^4 from the origin, over a
// floor 0.01 below it, under the ceiling light: the slab's top is lit as
// Lambert says, and the floor under it stays dark.
class ThinSlab : public ::testing::TestWithParam<std::tuple<integrator_kind, std::string>> {};

TEST_P(ThinSlab, IsLitOnTopAndShadowsTheFloorUnderIt) {
  const auto& [ik, strategy] = GetParam();
  const vec3 centre = placement(1e4f);
  const glm::dmat3 R = rotation({1.0, 0.0, 0.3}, 10.0);
  scene sc;
  sc.materials = {lambertian{color(albedo)}, diffuse_light{color(emit)}};
  const auto slab = box_mesh(centre, {100.0, 0.01, 100.0}, R);
  add_mesh(sc, slab, 0);
  // The floor: a 400 x 400 quad parallel to the slab, 0.01 under its
  // bottom face.
  const vec3 up(R * glm::dvec3(0, 1, 0));
  const vec3 floor_centre = centre - (0.005f + 0.01f) * up;
  {
    triangle_mesh m;
    const vec3 a(R * glm::dvec3(200, 0, 0)), b(R * glm::dvec3(0, 0, 200));
    m.p = {floor_centre - a - b, floor_centre + a - b, floor_centre + a + b, floor_centre - a + b};
    m.indices = {0, 2, 1, 0, 3, 2};  // wound to face +up
    add_mesh(sc, std::make_shared<const triangle_mesh>(std::move(m)), 0);
  }
  const rect light = ceiling_light(centre, 110.0f, 60.0f);
  test::add_rect_light(sc, light, strategy);
  sc.build_accelerator();
  const std::vector<glm::dvec3> poly = polygon_of(light);
  // The slab's top face (its triangles' normals are up).
  const vec3 top = centre + 0.005f * up;
  int id = 0;
  for (const vec3& offset : {vec3(0.0f), vec3(R * glm::dvec3(45, 0, -40)), vec3(R * glm::dvec3(-30, 0, 20))}) {
    const vec3 p = top + offset;
    const double exact =
        albedo / std::numbers::pi * test::clipped_polygon_irradiance(glm::dvec3(p), glm::dvec3(up), poly, emit);
    ASSERT_GT(exact, 0.0);
    const test::estimate e =
        test::radiance_along(sc, ray{p + 30.0f * up, -up}, path_settings{1, 3}, ik, sampler_kind::sobol, replicates,
                             samples_per_replicate * (ik == integrator_kind::mixture ? 4 : 1), id, 3000 + id);
    EXPECT_LE(std::abs(e.mean - exact), 1e-3 * exact + 6.0 * e.stderr_)
        << "slab top: mean " << e.mean << " exact " << exact << " stderr " << e.stderr_;
    EXPECT_LE(6.0 * e.stderr_, 1e-2 * exact) << "slab top: stderr " << e.stderr_;
    ++id;
  }
  // The floor under the slab, seen from the middle of the 0.01 gap: no
  // light at all reaches it (a shadow ray that slipped through the slab's
  // two faces or started past them would bring some).
  for (const vec3& offset : {vec3(0.0f), vec3(R * glm::dvec3(40, 0, 40)), vec3(R * glm::dvec3(-45, 0, 0))}) {
    const vec3 p = floor_centre + offset;
    hit_record rec;
    ASSERT_TRUE(sc.hit(ray{p + 0.005f * up, -up}, 0.0f, infinity, rec)) << "the camera ray meets the floor";
    const test::estimate e =
        test::radiance_along(sc, ray{p + 0.005f * up, -up}, path_settings{1, 3}, ik, sampler_kind::sobol, 4, 8192, id,
                             3000 + id);
    EXPECT_EQ(e.mean, 0.0) << "light under the slab at " << offset.x << ", " << offset.z;
    ++id;
  }
}

INSTANTIATE_TEST_SUITE_P(
    All, ThinSlab,
    ::testing::Combine(::testing::Values(integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis),
                       ::testing::Values("area", "projected-solid-angle")),
    [](const auto& info) {
      std::string n = std::string(to_string(std::get<0>(info.param))) + "_" + std::get<1>(info.param);
      for (char& ch : n)
        if (ch == '-') ch = '_';
      return n;
    });

}  // namespace
