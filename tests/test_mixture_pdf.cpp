// Shirley's mixture pdf as the path tracer uses it (render/pdf.hpp): half
// cosine, half the lights, lights that face away left out. Its generated
// directions must follow value() (chi-square over the whole sphere, 1%
// family-wise significance with the Sidak correction of support/chi2.hpp)
// and value() must integrate to 1 over the sphere.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "support/chi2.hpp"

using namespace mcrt;

namespace {

struct mixture_case {
  std::string name;
  std::vector<light> lights;
  vec3 p, n;  // shading point and its normal
};

std::vector<mixture_case> cases() {
  const rect cornell_light = xz_rect(213, 343, 227, 332, 554, true);
  const ellipse disk = ellipse::make({278, 554, 279.5f}, {65, 0, 0}, {0, 0, 65});
  const sphere glass{{190, 90, 190}, 90};
  return {
      {"FloorRectArea", {rect_area_sampler{cornell_light}}, {300, 0, 200}, {0, 1, 0}},
      {"FloorRectSolidAngle", {rect_solid_angle_sampler{cornell_light}}, {300, 0, 200}, {0, 1, 0}},
      {"WallDiskAreaAndSphere", {ellipse_area_sampler{disk}, sphere_cone_sampler{glass}}, {555, 300, 300}, {-1, 0, 0}},
      {"WallDiskSolidAngleAndSphere", {ellipse_solid_angle_sampler{disk}, sphere_cone_sampler{glass}}, {0, 200, 100}, {1, 0, 0}},
      // The ceiling is behind the light's emitting side: only the sphere is sampled.
      {"CeilingLightFacesAway", {rect_area_sampler{cornell_light}, sphere_cone_sampler{glass}}, {100, 555, 100}, {0, -1, 0}},
      {"NoLightFacesThePoint", {rect_solid_angle_sampler{cornell_light}}, {278, 556, 279}, {0, 1, 0}},
  };
}

class Mixture : public testing::TestWithParam<mixture_case> {};

TEST_P(Mixture, GeneratedDirectionsFollowValueWhichIntegratesToOne) {
  const mixture_case& c = GetParam();
  const cosine_pdf cos(c.n);
  const light_pdf lights(c.lights, c.p, c.n);
  const mixture_pdf mix(cos, lights);
  auto sample = [&](pcg32& rng, vec3& dir) {
    float p;
    const float u_select = rng.uniform();
    return mix.generate(u_select, rng.uniform2(), dir, p) && std::abs(p - mix.value(dir)) <= 1e-4f * p;
  };
  auto value = [&](const vec3& dir) { return static_cast<double>(mix.value(dir)); };
  test::chi2_options opt;
  opt.sample_count = 1'000'000;
  opt.seed = 11;
  // The grid's pole is put perpendicular to the normal, so the lights (seen
  // near the normal from these points) fall on well-shaped cells rather than
  // on the thin wedges around a pole, where a light's sliver in a cell full
  // of cosine density is too small for the cell quadrature to notice.
  const vec3 side = std::abs(c.n.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 0, 1);
  const dvec3 axis = glm::normalize(dvec3(glm::cross(c.n, side)));
  const test::chi2_result r = test::chi2_test_directions(sample, value, axis, 2.0, opt);
  EXPECT_TRUE(r.passed) << r.report;
  EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.report;
}

INSTANTIATE_TEST_SUITE_P(Cases, Mixture, testing::ValuesIn(cases()), [](const auto& info) { return info.param.name; });

TEST(Mixture, LightsThatFaceAwayAreLeftOut) {
  const rect r = xz_rect(0, 1, 0, 1, 2, true);  // emits downwards
  const std::vector<light> ls{rect_area_sampler{r}};
  EXPECT_FALSE(light_pdf(ls, {0.5f, 0.0f, 0.5f}, {0.0f, 1.0f, 0.0f}).empty());
  EXPECT_TRUE(light_pdf(ls, {0.5f, 3.0f, 0.5f}, {0.0f, 1.0f, 0.0f}).empty());
  // With no light, the mixture is the cosine pdf itself.
  const cosine_pdf cos({0, 1, 0});
  const light_pdf none(ls, {0.5f, 3.0f, 0.5f}, {0.0f, 1.0f, 0.0f});
  const mixture_pdf mix(cos, none);
  for (const vec3 d : {vec3(0, 1, 0), glm::normalize(vec3(1, 1, 0)), vec3(0, -1, 0)})
    EXPECT_FLOAT_EQ(mix.value(d), cos.value(d));
}

}  // namespace
