// The path tracer against closed forms: a diffuse floor lit by a rectangle
// (Lambert's polygon formula) or a disk (the disk-to-parallel-plane
// configuration factor), for every light-sampling strategy. The floor sees
// nothing but the light, so its outgoing radiance is exactly albedo/pi * E.
//
// Statistics: each point is estimated from N independent paths with fixed
// seeds; the check is |mean - exact| <= 5 standard errors (two-sided
// false-failure probability 5.7e-7 per check, so the whole file stays below
// 1e-4), and additionally within 1 % of the exact value, so a large standard
// error cannot hide a bias.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mcrt/mcrt.hpp"
#include "support/lambert.hpp"

using namespace mcrt;

namespace {

constexpr float albedo = 0.5f;
constexpr float emit = 4.0f;

// Floor y = 0, 100 x 100, and one light facing down.
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

// Radiance leaving floor point (x, 0, z) upwards, estimated by the path tracer.
estimate floor_radiance(const scene& sc, float x, float z, std::size_t n, std::uint64_t seed) {
  pcg32 rng(seed, 17);
  const path_settings ps{1, 3};  // one scattering event: the floor's
  double s = 0.0, s2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = trace_path(sc, ray{{x, 0.5f, z}, {0, -1, 0}}, rng, ps).r;
    s += v;
    s2 += v * v;
  }
  const double mean = s / static_cast<double>(n);
  const double var = std::max(s2 / static_cast<double>(n) - mean * mean, 0.0);
  return {mean, std::sqrt(var / static_cast<double>(n))};
}

void check(const estimate& e, double exact, const std::string& what) {
  EXPECT_LE(std::abs(e.mean - exact), 5.0 * e.stderr_) << what << ": mean " << e.mean << " exact " << exact
                                                        << " stderr " << e.stderr_;
  EXPECT_LE(std::abs(e.mean - exact), 0.01 * exact) << what << ": mean " << e.mean << " exact " << exact;
}

const char* name(light_sampling s) { return s == light_sampling::area ? "area" : "solid-angle"; }

light rect_light(const rect& r, light_sampling s) {
  if (s == light_sampling::area) return rect_area_sampler{r};
  return rect_solid_angle_sampler{r};
}
// "area", "solid-angle" (parallel map) or "polar" (polar map).
light ellipse_light(const ellipse& e, const std::string& s) {
  if (s == "area") return ellipse_area_sampler{e};
  if (s == "polar") return ellipse_polar_solid_angle_sampler{e};
  return ellipse_solid_angle_sampler{e};
}

}  // namespace

class FloorUnderRect : public ::testing::TestWithParam<light_sampling> {};

TEST_P(FloorUnderRect, MatchesLambertsPolygonFormula) {
  const float h = 1.0f;
  const rect light_rect = xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, h, true);  // 0.6 x 0.4, facing down
  scene sc = floor_scene();
  sc.add(xz_rect_shape{-0.2f, 0.2f, -0.3f, 0.3f, h, true}, 1);
  sc.lights.push_back(rect_light(light_rect, GetParam()));
  const std::vector<glm::dvec3> poly{{-0.3, h, -0.2}, {0.3, h, -0.2}, {0.3, h, 0.2}, {-0.3, h, 0.2}};
  std::uint64_t seed = 1;
  for (const auto& [x, z] : {std::pair{0.0f, 0.0f}, {0.25f, 0.1f}, {0.7f, -0.4f}, {-2.0f, 1.5f}}) {
    const double exact = albedo / std::numbers::pi *
                         test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
    check(floor_radiance(sc, x, z, 400000, seed++), exact,
          std::string(name(GetParam())) + " at (" + std::to_string(x) + ", " + std::to_string(z) + ")");
  }
}

class FloorUnderDisk : public ::testing::TestWithParam<std::string> {};

TEST_P(FloorUnderDisk, MatchesTheDiskConfigurationFactor) {
  const float h = 0.8f, R = 0.5f;
  const ellipse disk = ellipse::make({0, h, 0}, {R, 0, 0}, {0, 0, R});  // x cross z = -y: faces down
  scene sc = floor_scene();
  sc.add(disk, 1);
  sc.lights.push_back(ellipse_light(disk, GetParam()));
  std::uint64_t seed = 100;
  for (const float d : {0.0f, 0.3f, 0.6f, 2.0f}) {
    const double exact = albedo / std::numbers::pi * test::disk_irradiance(h, d, R, emit);
    check(floor_radiance(sc, d, 0.0f, 400000, seed++), exact,
          GetParam() + " at d=" + std::to_string(d));
  }
}

INSTANTIATE_TEST_SUITE_P(Strategies, FloorUnderRect,
                         ::testing::Values(light_sampling::area, light_sampling::solid_angle),
                         [](const auto& info) { return std::string(info.param == light_sampling::area ? "Area" : "SolidAngle"); });
INSTANTIATE_TEST_SUITE_P(Strategies, FloorUnderDisk, ::testing::Values("area", "solid-angle", "polar"),
                         [](const auto& info) {
                           return std::string(info.param == "area" ? "Area" : info.param == "polar" ? "SolidAnglePolar" : "SolidAngle");
                         });

TEST(Render, ImageIsIdenticalForAnyThreadCount) {
  scene sc = floor_scene();
  sc.add(xz_rect_shape{-0.2f, 0.2f, -0.3f, 0.3f, 1.0f, true}, 1);
  sc.lights.push_back(rect_area_sampler{xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, 1.0f, true)});
  sc.add(sphere{{0.3f, 0.2f, 0.1f}, 0.2f}, 0);
  const camera cam({0, 0.7f, -2}, {0, 0, 0}, {0, 1, 0}, 50, 1.0f);
  render_settings rs;
  rs.width = 37;  // not a multiple of the tile size
  rs.height = 29;
  rs.spp = 7;
  rs.max_depth = 5;
  rs.seed = 42;
  rs.threads = 1;
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
