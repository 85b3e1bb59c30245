// The path tracer against closed forms: a diffuse floor lit by a rectangle
// (Lambert's polygon formula; edges along the axes, or turned in the
// light's horizontal plane), a triangle (the same formula), a disk (the disk-to-parallel-plane
// configuration factor) or a sphere (pi sin^2 alpha cos theta_c: the sphere
// lies wholly above the floor), for every integrator x sample generator x
// light strategy; and the vanishing variance of projected-solid-angle
// sampling under next-event estimation of direct light. The floor sees nothing but the light, so its outgoing radiance
// is exactly albedo/pi * E.
//
// Statistics: each point is estimated by R = 32 independent replicates (32
// pixels of the sampler, so 32 independent scramblings for the stratified
// and Sobol generators) of n samples each; the check is |mean - exact| <= 6
// standard errors of the mean of the replicate means (Student t with 31
// degrees of freedom: two-sided false-failure probability 1.2e-6 per check,
// below 1e-3 for the 801 checks of this file), and additionally within 1 %
// of the exact value, so a large standard error cannot hide a bias.
// Replicates, not the spread of single samples, give the standard error:
// the samples of one stratified or Sobol pixel are not independent. Where
// the estimator has almost no variance (the polar map of a disk seen on its
// axis under next-event estimation and Sobol points: standard error 6e-9 of
// the value), the statistical bound is floored at 1e-6 of the exact value:
// each sample is computed in single precision through a chain of some twenty
// rounded operations (2^-24 = 6e-8 each), whose systematic part the
// estimate cannot average away.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <string>
#include <utility>
#include <vector>
#include <tuple>

#include "mcrt/mcrt.hpp"
#include "support/lambert.hpp"
#include "support/light_strategies.hpp"
#include "support/radiance_estimate.hpp"

using namespace mcrt;

namespace {

constexpr float albedo = 0.5f;
constexpr float emit = 4.0f;
constexpr int replicates = 32;
constexpr int samples_per_replicate = 8192;

// Floor y = 0, 100 x 100, and a light added by the test.
scene floor_scene() {
  scene sc;
  sc.materials = {lambertian{color(albedo)}, diffuse_light{color(emit)}};
  sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
  return sc;
}

using test::estimate;

// Radiance leaving floor point (x, 0, z) upwards, estimated by integrator ik
// fed by sampler sk: one scattering event (the floor's), so direct light
// only; replicate r is pixel (point_id, r) of the sampler.
estimate floor_radiance(const scene& sc, integrator_kind ik, sampler_kind sk, float x, float z, int point_id,
                        std::uint64_t seed) {
  return test::radiance_along(sc, ray{{x, 0.5f, z}, {0, -1, 0}}, path_settings{1, 3}, ik, sk, replicates,
                              samples_per_replicate, point_id, seed);
}

void check(const estimate& e, double exact, const std::string& what) {
  EXPECT_LE(std::abs(e.mean - exact), std::max(6.0 * e.stderr_, 1e-6 * exact)) << what << ": mean " << e.mean << " exact " << exact
                                                        << " stderr " << e.stderr_;
  EXPECT_LE(std::abs(e.mean - exact), 0.01 * exact) << what << ": mean " << e.mean << " exact " << exact;
}

using combo = std::tuple<integrator_kind, sampler_kind, std::string>;

std::string combo_name(const ::testing::TestParamInfo<combo>& info) {
  const auto& [i, s, l] = info.param;
  std::string n = std::string(to_string(i)) + "_" + std::string(to_string(s)) + "_" + l;
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
}

const auto integrators = ::testing::Values(integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis);
const auto samplers = ::testing::Values(sampler_kind::independent, sampler_kind::stratified, sampler_kind::sobol);

using test::add_disk_light;
using test::add_rect_light;
using test::add_sphere_light;

// Radiance leaving the floor at (x, 0, z) under a sphere wholly above it:
// albedo/pi * L * pi sin^2 alpha cos theta_c (the projected solid angle of a
// cap above the horizon, Urena & Georgiev 2018, sec. 3).
double sphere_floor_radiance(const glm::dvec3& c, double r, double x, double z) {
  const glm::dvec3 w = c - glm::dvec3(x, 0.0, z);
  const double d2 = glm::dot(w, w);
  return albedo / std::numbers::pi * emit * std::numbers::pi * (r * r / d2) * (w.y / std::sqrt(d2));
}

}  // namespace

class FloorUnderRect : public ::testing::TestWithParam<combo> {};

TEST_P(FloorUnderRect, MatchesLambertsPolygonFormula) {
  const auto& [ik, sk, strategy] = GetParam();
  const float h = 1.0f;
  const rect light_rect = xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, h, true);  // 0.6 x 0.4, facing down
  scene sc = floor_scene();
  add_rect_light(sc, light_rect, strategy);
  const std::vector<glm::dvec3> poly{{-0.3, h, -0.2}, {0.3, h, -0.2}, {0.3, h, 0.2}, {-0.3, h, 0.2}};
  int id = 0;
  for (const auto& [x, z] : {std::pair{0.0f, 0.0f}, {0.25f, 0.1f}, {0.7f, -0.4f}, {-2.0f, 1.5f}}) {
    const double exact = albedo / std::numbers::pi *
                         test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
    check(floor_radiance(sc, ik, sk, x, z, id, 1 + id), exact,
          strategy + " at (" + std::to_string(x) + ", " + std::to_string(z) + ")");
    ++id;
  }
}

// The same, under a rectangle whose normal is a coordinate axis but whose
// edges are turned 30 degrees in its plane (horizontal, facing down): the
// scene must intersect it as the rectangle its edges describe, as the
// strategies sample it, not as an axis-aligned one.
class FloorUnderTurnedRect : public ::testing::TestWithParam<combo> {};

TEST_P(FloorUnderTurnedRect, MatchesLambertsPolygonFormula) {
  const auto& [ik, sk, strategy] = GetParam();
  const float h = 1.0f, c = std::cos(glm::radians(30.0f)), s = std::sin(glm::radians(30.0f));
  const vec3 e1 = 0.8f * vec3(c, 0, s), e2 = 0.5f * vec3(-s, 0, c);  // e1 x e2 = -0.4 y: faces down
  const vec3 corner = vec3(0.05f, h, -0.03f) - 0.5f * (e1 + e2);
  const rect light_rect = rect::make(corner, e1, e2);
  ASSERT_EQ(light_rect.n, vec3(0, -1, 0));
  scene sc = floor_scene();
  add_rect_light(sc, light_rect, strategy);
  const glm::dvec3 dc(corner), d1(e1), d2(e2);
  const std::vector<glm::dvec3> poly{dc, dc + d1, dc + d1 + d2, dc + d2};
  int id = 30;
  for (const auto& [x, z] : {std::pair{0.05f, -0.03f}, {0.4f, 0.3f}, {-0.35f, 0.2f}, {0.7f, -0.4f}, {-2.0f, 1.5f}}) {
    const double exact = albedo / std::numbers::pi *
                         test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
    check(floor_radiance(sc, ik, sk, x, z, id, 300 + id), exact,
          strategy + " at (" + std::to_string(x) + ", " + std::to_string(z) + ")");
    ++id;
  }
}

// Under a triangle of a mesh (a light of its own, sampled by area), tilted
// and facing down: through the scene's triangles and the integrators'
// triangle lights.
class FloorUnderTriangle : public ::testing::TestWithParam<combo> {};

TEST_P(FloorUnderTriangle, MatchesLambertsPolygonFormula) {
  const auto& [ik, sk, strategy] = GetParam();
  auto mesh = std::make_shared<triangle_mesh>();
  mesh->p = {{-0.4f, 1.0f, -0.3f}, {0.6f, 0.9f, -0.2f}, {0.1f, 1.2f, 0.5f}};  // (p1 - p0) x (p2 - p0) points down
  mesh->indices = {0, 1, 2};
  const triangle tri{mesh, 0};
  ASSERT_LT(tri.normal().y, 0.0f);
  scene sc = floor_scene();
  ASSERT_EQ(strategy, "area");
  sc.add_light(triangle_area_sampler{tri}, 1);
  const std::vector<glm::dvec3> poly{glm::dvec3(mesh->p[0]), glm::dvec3(mesh->p[1]), glm::dvec3(mesh->p[2])};
  int id = 40;
  for (const auto& [x, z] : {std::pair{0.1f, 0.0f}, {0.5f, 0.4f}, {-0.8f, -0.6f}, {1.5f, 1.0f}}) {
    const double exact = albedo / std::numbers::pi * test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
    check(floor_radiance(sc, ik, sk, x, z, id, 400 + id), exact,
          strategy + " at (" + std::to_string(x) + ", " + std::to_string(z) + ")");
    ++id;
  }
}

class FloorUnderDisk : public ::testing::TestWithParam<combo> {};

TEST_P(FloorUnderDisk, MatchesTheDiskConfigurationFactor) {
  const auto& [ik, sk, strategy] = GetParam();
  const float h = 0.8f, R = 0.5f;
  const ellipse disk = ellipse::make({0, h, 0}, {R, 0, 0}, {0, 0, R});  // x cross z = -y: faces down
  scene sc = floor_scene();
  add_disk_light(sc, disk, strategy);
  int id = 10;
  for (const float d : {0.0f, 0.3f, 0.6f, 2.0f}) {
    const double exact = albedo / std::numbers::pi * test::disk_irradiance(h, d, R, emit);
    check(floor_radiance(sc, ik, sk, d, 0.0f, id, 100 + id), exact, strategy + " at d=" + std::to_string(d));
    ++id;
  }
}

class FloorUnderSphere : public ::testing::TestWithParam<combo> {};

TEST_P(FloorUnderSphere, MatchesTheProjectedCap) {
  const auto& [ik, sk, strategy] = GetParam();
  const glm::dvec3 c(0.1, 0.9, -0.05);
  const double r = 0.35;
  scene sc = floor_scene();
  add_sphere_light(sc, sphere{vec3(c), static_cast<float>(r)}, strategy);
  int id = 20;
  for (const auto& [x, z] : {std::pair{0.1f, -0.05f}, {0.4f, 0.2f}, {-0.9f, 0.3f}, {2.5f, -1.0f}}) {
    check(floor_radiance(sc, ik, sk, x, z, id, 200 + id), sphere_floor_radiance(c, r, x, z),
          strategy + " at (" + std::to_string(x) + ", " + std::to_string(z) + ")");
    ++id;
  }
}

INSTANTIATE_TEST_SUITE_P(All, FloorUnderRect,
                         ::testing::Combine(integrators, samplers,
                                            ::testing::Values("area", "solid-angle", "projected-solid-angle",
                                                              "bilinear-solid-angle", "auto")),
                         combo_name);
INSTANTIATE_TEST_SUITE_P(All, FloorUnderTurnedRect,
                         ::testing::Combine(integrators, samplers,
                                            ::testing::Values("area", "solid-angle", "projected-solid-angle",
                                                              "bilinear-solid-angle", "auto")),
                         combo_name);
INSTANTIATE_TEST_SUITE_P(All, FloorUnderTriangle, ::testing::Combine(integrators, samplers, ::testing::Values("area")),
                         combo_name);
INSTANTIATE_TEST_SUITE_P(All, FloorUnderDisk,
                         ::testing::Combine(integrators, samplers,
                                            ::testing::Values("area", "solid-angle", "polar", "projected-solid-angle",
                                                              "bilinear-solid-angle", "auto")),
                         combo_name);
INSTANTIATE_TEST_SUITE_P(All, FloorUnderSphere,
                         ::testing::Combine(integrators, samplers,
                                            ::testing::Values("area", "solid-angle", "projected-solid-angle", "auto")),
                         combo_name);

// The vanishing variance: under next-event estimation of direct light alone
// (--integrator nee --max-depth 1), an unoccluded floor of constant albedo
// under a light of constant radiance, each sample's estimate is
// albedo/pi * L * cos theta / pdf, constant when pdf is proportional to
// cos theta (projected solid angle), so only rounding is left. The relative
// RMSE against the closed form, over 4 points x 64 replicates of 16 spp
// (independent numbers), must be at most 1/10 of solid-angle sampling's at
// equal spp (measured: 1.8e-8 against 1.3e-2 for the rectangle, 6.2e-8
// against 3.2e-2 for the sphere). The
// check is deterministic (fixed seeds); the solid-angle RMSE is itself
// estimated from 256 replicate means, a relative uncertainty of about 5 %.
double relative_rmse(const scene& sc, const std::vector<std::pair<float, float>>& points,
                     const std::vector<double>& exact) {
  constexpr int reps = 64, spp = 16;
  const independent_sampler sampler(99, spp);
  const path_settings set{1, 3};
  double se = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    for (int r = 0; r < reps; ++r) {
      auto ps = sampler.start_pixel(static_cast<int>(k), r, 1024);
      double sum = 0.0;
      for (int i = 0; i < spp; ++i) {
        ps.start_sample(i);
        sum += nee_integrator::li(sc, ray{{points[k].first, 0.5f, points[k].second}, {0, -1, 0}}, ps, set).r;
      }
      const double e = (sum / spp - exact[k]) / exact[k];
      se += e * e;
      ++n;
    }
  }
  return std::sqrt(se / n);
}

TEST(VanishingVariance, RectangleUnderNextEventEstimation) {
  const rect light_rect = xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, 1.0f, true);
  const std::vector<glm::dvec3> poly{{-0.3, 1, -0.2}, {0.3, 1, -0.2}, {0.3, 1, 0.2}, {-0.3, 1, 0.2}};
  const std::vector<std::pair<float, float>> pts{{0.0f, 0.0f}, {0.25f, 0.1f}, {0.7f, -0.4f}, {-2.0f, 1.5f}};
  std::vector<double> exact;
  for (const auto& [x, z] : pts)
    exact.push_back(albedo / std::numbers::pi * test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit));
  scene sa = floor_scene(), psa = floor_scene();
  add_rect_light(sa, light_rect, "solid-angle");
  add_rect_light(psa, light_rect, "projected-solid-angle");
  const double e_sa = relative_rmse(sa, pts, exact), e_psa = relative_rmse(psa, pts, exact);
  std::cout << "relative RMSE at 16 spp: projected solid angle " << e_psa << ", solid angle " << e_sa << "\n";
  EXPECT_LE(e_psa, e_sa / 10.0) << "relative RMSE: projected solid angle " << e_psa << ", solid angle " << e_sa;
  EXPECT_GT(e_sa, 1e-3) << "the solid-angle estimator must have variance here for the comparison to mean anything";
}

TEST(VanishingVariance, SphereUnderNextEventEstimation) {
  const glm::dvec3 c(0.1, 0.9, -0.05);
  const double r = 0.35;
  const std::vector<std::pair<float, float>> pts{{0.1f, -0.05f}, {0.4f, 0.2f}, {-0.9f, 0.3f}, {2.5f, -1.0f}};
  std::vector<double> exact;
  for (const auto& [x, z] : pts) exact.push_back(sphere_floor_radiance(c, r, x, z));
  scene sa = floor_scene(), psa = floor_scene();
  add_sphere_light(sa, sphere{vec3(c), static_cast<float>(r)}, "solid-angle");
  add_sphere_light(psa, sphere{vec3(c), static_cast<float>(r)}, "projected-solid-angle");
  const double e_sa = relative_rmse(sa, pts, exact), e_psa = relative_rmse(psa, pts, exact);
  std::cout << "relative RMSE at 16 spp: projected solid angle " << e_psa << ", solid angle " << e_sa << "\n";
  EXPECT_LE(e_psa, e_sa / 10.0) << "relative RMSE: projected solid angle " << e_psa << ", solid angle " << e_sa;
  EXPECT_GT(e_sa, 1e-3) << "the solid-angle estimator must have variance here for the comparison to mean anything";
}

// The same scene, settings and seed give the same image bit for bit whatever
// the thread count, for every integrator and sample generator; another seed
// gives another image.
class ThreadCount : public ::testing::TestWithParam<std::tuple<integrator_kind, sampler_kind>> {};

TEST_P(ThreadCount, ImageIsIdenticalForAnyThreadCount) {
  scene sc = floor_scene();
  sc.add_light(rect_area_sampler{xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, 1.0f, true)}, 1);
  sc.add(sphere{{0.3f, 0.2f, 0.1f}, 0.2f}, 0);
  const camera cam({0, 0.7f, -2}, {0, 0, 0}, {0, 1, 0}, 50, 1.0f);
  render_settings rs;
  rs.width = 37;  // not a multiple of the tile size
  rs.height = 29;
  rs.spp = 7;
  rs.max_depth = 5;
  rs.seed = 42;
  rs.threads = 1;
  std::tie(rs.integrator, rs.sampler) = GetParam();
  const render_result one = render(sc, cam, rs);
  for (unsigned t : {2u, 3u, 8u}) {
    rs.threads = t;
    const render_result many = render(sc, cam, rs);
    ASSERT_EQ(one.img.pixels.size(), many.img.pixels.size());
    for (std::size_t i = 0; i < one.img.pixels.size(); ++i)
      ASSERT_EQ(one.img.pixels[i], many.img.pixels[i]) << "pixel " << i << " with " << t << " threads";
  }
  rs.seed = 43;
  const render_result other = render(sc, cam, rs);
  EXPECT_NE(one.img.pixels, other.img.pixels) << "the seed must change the image";
}

INSTANTIATE_TEST_SUITE_P(All, ThreadCount, ::testing::Combine(integrators, samplers),
                         [](const auto& info) {
                           return std::string(to_string(std::get<0>(info.param))) + "_" +
                                  std::string(to_string(std::get<1>(info.param)));
                         });

// With a progress reporter the image's time is the rendering's, not rounded
// up to the reporting interval: the tile that completes the image wakes the
// reporter. A small image takes milliseconds; with a 60 s interval the old
// wait would return after 60 s. The image is the one rendered without a
// reporter, and the last report says the image is complete.
TEST(Progress, ReporterDoesNotDelayTheImage) {
  scene sc = floor_scene();
  sc.add_light(rect_area_sampler{xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, 1.0f, true)}, 1);
  const camera cam({0, 0.7f, -2}, {0, 0, 0}, {0, 1, 0}, 50, 1.0f);
  render_settings rs;
  rs.width = 40;
  rs.height = 30;
  rs.spp = 4;
  rs.threads = 2;
  int reports = 0;
  double last_fraction = -1.0;
  const auto start = std::chrono::steady_clock::now();
  const render_result with = render(
      sc, cam, rs, [&](double fraction, double) { ++reports, last_fraction = fraction; }, std::chrono::seconds(60));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(wall, 30.0);
  EXPECT_LT(with.seconds, 30.0);
  // (Once at the end at least: the workers may finish every tile before
  // the reporter's first look.)
  EXPECT_GE(reports, 1);
  EXPECT_EQ(last_fraction, 1.0);
  EXPECT_EQ(with.img.pixels, render(sc, cam, rs).img.pixels);
}
