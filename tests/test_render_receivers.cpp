// Direct light on receivers that are not floors, against Lambert's polygon
// formula: the front face of the Cornell box's tall box (rotated 15 degrees
// about y: a vertical receiver whose normal is no coordinate axis) under
// the box's ceiling light turned in its plane (its normal is -y exactly,
// its edges turned by 0, 15 or 40 degrees about its centre). The ceiling
// light lies partly behind the face's horizon, so the receiver sees the
// part of it in front of the face's plane, reaching down to directions that
// graze the face: shadow rays leave the face at grazing angles. Everything
// else is left out, so nothing occludes the light (the box is convex and the
// receiver on its outside).
//
// Every integrator x light strategy with Sobol points, direct light only
// (--max-depth 1). Statistics as in test_render_floor.cpp: R = 32
// independent scramblings of n = 8192 samples each (32768 for the mixture,
// half of whose samples follow the cosine and mostly miss the light), and
// the check is |mean - exact| <= 1e-3 exact + 6 standard errors (Student t
// with 31 degrees of freedom: two-sided false-failure probability 1.2e-6 per
// check, below 1e-4 for the 225 checks of this file), so the bias allowed
// is 0.1 % plus the noise; and 6 standard errors must themselves be at most
// 1 % of the value, so the noise cannot hide a bias of the size the shadow
// rays' self-intersection or a misplaced light make (0.2 % to 80 %).
#include <gtest/gtest.h>

#include <cmath>
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
constexpr float emit = 15.0f;  // the Cornell light's
constexpr int replicates = 32;
constexpr int samples_per_replicate = 8192;  // 4x for the mixture

// The ceiling light of scenes/cornell_rect.json (x in [213, 343], z in
// [227, 332], y = 554, facing down) turned by `degrees` in its plane about
// its centre. Its edges keep y = 0 exactly, so its normal is -y exactly.
rect turned_ceiling_light(float degrees) {
  const rigid_y turn = rigid_y::make(degrees, vec3(0.0f));
  const vec3 e1 = turn.rotate({0, 0, 105}), e2 = turn.rotate({130, 0, 0});  // z x x = +y; flipped: -y
  const vec3 centre{278.0f, 554.0f, 279.5f};
  return rect::make(centre - 0.5f * (e1 + e2), e1, e2, true);
}

// Shirley's tall box (scenes/cornell_rect.json): rotated 15 degrees about
// y, then moved to (265, 0, 295).
box tall_box() { return box{{0, 0, 0}, {165, 330, 165}, rigid_y::make(15.0f, {265, 0, 295})}; }

using combo = std::tuple<integrator_kind, std::string, int>;

}  // namespace

class TallBoxFrontFace : public ::testing::TestWithParam<combo> {};

TEST_P(TallBoxFrontFace, MatchesLambertsFormulaAtGrazingAngles) {
  const auto& [ik, strategy, degrees] = GetParam();
  const rect light = turned_ceiling_light(static_cast<float>(degrees));
  ASSERT_EQ(light.n, vec3(0, -1, 0));
  const box b = tall_box();
  scene sc;
  sc.materials = {lambertian{color(albedo)}, diffuse_light{color(emit)}};
  sc.add(b, 0);
  test::add_rect_light(sc, light, strategy);
  EXPECT_EQ(sc.axis_rects.size(), degrees == 0 ? 1u : 0u) << "only the unturned light is axis-aligned";

  const glm::dvec3 c(light.corner), e1(light.e1), e2(light.e2);
  const std::vector<glm::dvec3> poly{c, c + e1, c + e1 + e2, c + e2};
  const vec3 n = b.xf.rotate({0, 0, -1});  // the front face's outward normal (local z = 0)
  int id = 0;
  // Points of the front face (local x, y): near its top, where the light is
  // seen at the steepest (most grazing) angles, down to near the floor.
  for (const auto& [lx, ly] : {std::pair{82.5f, 320.0f}, {10.0f, 300.0f}, {155.0f, 250.0f}, {82.5f, 150.0f},
                               {40.0f, 30.0f}}) {
    const vec3 p = b.xf.to_world({lx, ly, 0.0f});
    const ray camera_ray{p + 100.0f * n, -n};
    const double exact =
        albedo / std::numbers::pi * test::clipped_polygon_irradiance(glm::dvec3(p), glm::dvec3(n), poly, emit);
    ASSERT_GT(exact, 0.0);
    const test::estimate e = test::radiance_along(sc, camera_ray, path_settings{1, 3}, ik, sampler_kind::sobol,
                                                  replicates,
                                                  samples_per_replicate * (ik == integrator_kind::mixture ? 4 : 1),
                                                  id, 1000 + id);
    const std::string what = strategy + " at local (" + std::to_string(lx) + ", " + std::to_string(ly) + ")";
    EXPECT_LE(std::abs(e.mean - exact), 1e-3 * exact + 6.0 * e.stderr_)
        << what << ": mean " << e.mean << " exact " << exact << " stderr " << e.stderr_ << " (relative error "
        << (e.mean - exact) / exact << ")";
    EXPECT_LE(6.0 * e.stderr_, 1e-2 * exact) << what << ": the noise would hide a bias: stderr " << e.stderr_;
    ++id;
  }
}

INSTANTIATE_TEST_SUITE_P(
    All, TallBoxFrontFace,
    ::testing::Combine(::testing::Values(integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis),
                       ::testing::Values("area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle",
                                         "auto"),
                       ::testing::Values(0, 15, 40)),
    [](const auto& info) {
      std::string n = std::string(to_string(std::get<0>(info.param))) + "_" + std::get<1>(info.param) + "_turned" +
                      std::to_string(std::get<2>(info.param));
      for (char& ch : n)
        if (ch == '-') ch = '_';
      return n;
    });
