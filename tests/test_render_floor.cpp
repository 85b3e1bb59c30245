// The path tracer against closed forms: a diffuse floor lit by a rectangle
// (Lambert's polygon formula) or a disk (the disk-to-parallel-plane
// configuration factor), for every integrator x sample generator x light
// strategy. The floor sees nothing but the light, so its outgoing radiance
// is exactly albedo/pi * E.
//
// Statistics: each point is estimated by R = 32 independent replicates (32
// pixels of the sampler, so 32 independent scramblings for the stratified
// and Sobol generators) of n samples each; the check is |mean - exact| <= 6
// standard errors of the mean of the replicate means (Student t with 31
// degrees of freedom: two-sided false-failure probability 1.2e-6 per check,
// below 3e-4 for the 180 checks of this file), and additionally within 1 %
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

#include <cmath>
#include <string>
#include <tuple>

#include "mcrt/mcrt.hpp"
#include "support/lambert.hpp"

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
  sc.ray_epsilon = 1e-4f;
  return sc;
}

struct estimate {
  double mean, stderr_;
};

// Radiance leaving floor point (x, 0, z) upwards, estimated by integrator
// I fed by sampler S: one scattering event (the floor's), so direct light
// only; replicate r is pixel (point_id, r) of the sampler.
template <class I, class S>
estimate floor_radiance(const scene& sc, float x, float z, int point_id, std::uint64_t seed) {
  const S sampler(seed, samples_per_replicate);
  const path_settings set{1, 3};
  double s = 0.0, s2 = 0.0;
  for (int r = 0; r < replicates; ++r) {
    auto ps = sampler.start_pixel(point_id, r, 1024);
    double sum = 0.0;
    for (int i = 0; i < samples_per_replicate; ++i) {
      ps.start_sample(i);
      sum += I::li(sc, ray{{x, 0.5f, z}, {0, -1, 0}}, ps, set).r;
    }
    const double m = sum / samples_per_replicate;
    s += m;
    s2 += m * m;
  }
  const double mean = s / replicates;
  const double var = std::max(s2 / replicates - mean * mean, 0.0) * replicates / (replicates - 1);
  return {mean, std::sqrt(var / replicates)};
}

estimate floor_radiance(const scene& sc, integrator_kind ik, sampler_kind sk, float x, float z, int point_id,
                        std::uint64_t seed) {
  return with_integrator(ik, [&]<class I>() {
    return with_sampler(sk, [&]<class S>() { return floor_radiance<I, S>(sc, x, z, point_id, seed); });
  });
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

}  // namespace

class FloorUnderRect : public ::testing::TestWithParam<combo> {};

TEST_P(FloorUnderRect, MatchesLambertsPolygonFormula) {
  const auto& [ik, sk, strategy] = GetParam();
  const float h = 1.0f;
  const rect light_rect = xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, h, true);  // 0.6 x 0.4, facing down
  scene sc = floor_scene();
  if (strategy == "area")
    sc.add_light(rect_area_sampler{light_rect}, 1);
  else
    sc.add_light(rect_solid_angle_sampler{light_rect}, 1);
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

class FloorUnderDisk : public ::testing::TestWithParam<combo> {};

TEST_P(FloorUnderDisk, MatchesTheDiskConfigurationFactor) {
  const auto& [ik, sk, strategy] = GetParam();
  const float h = 0.8f, R = 0.5f;
  const ellipse disk = ellipse::make({0, h, 0}, {R, 0, 0}, {0, 0, R});  // x cross z = -y: faces down
  scene sc = floor_scene();
  if (strategy == "area")
    sc.add_light(ellipse_area_sampler{disk}, 1);
  else if (strategy == "polar")
    sc.add_light(ellipse_polar_solid_angle_sampler{disk}, 1);
  else
    sc.add_light(ellipse_solid_angle_sampler{disk}, 1);
  int id = 10;
  for (const float d : {0.0f, 0.3f, 0.6f, 2.0f}) {
    const double exact = albedo / std::numbers::pi * test::disk_irradiance(h, d, R, emit);
    check(floor_radiance(sc, ik, sk, d, 0.0f, id, 100 + id), exact, strategy + " at d=" + std::to_string(d));
    ++id;
  }
}

INSTANTIATE_TEST_SUITE_P(All, FloorUnderRect,
                         ::testing::Combine(integrators, samplers, ::testing::Values("area", "solid-angle")), combo_name);
INSTANTIATE_TEST_SUITE_P(All, FloorUnderDisk,
                         ::testing::Combine(integrators, samplers, ::testing::Values("area", "solid-angle", "polar")),
                         combo_name);

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
