// pbrt-v4 scene files through the builder (src/pbrt/builder.hpp): direct
// light on a diffuse floor under lights placed by nested transforms,
// ReverseOrientation, a mirroring transform, a PLY quad and a two-sided
// light, against Lambert's polygon formula and the disk's and sphere's
// closed forms, under every integrator; the Cornell box of a pbrt file
// against the same box in the JSON format; and the refusals of the
// contract's "Errors" (one line naming the file and line).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <optional>
#include <string>
#include <tuple>

#include "pbrt/builder.hpp"
#include "scene_loader.hpp"
#include "texture_io.hpp"
#include "support/lambert.hpp"
#include "support/radiance_estimate.hpp"

using namespace mcrt;
namespace fs = std::filesystem;

namespace {

constexpr double albedo = 0.5, emit = 4.0;

// A directory of its own for each test's files.
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("mcrt_test_pbrt_scenes_" + std::to_string(::getpid())) / name;
  fs::create_directories(d);
  return d;
}

pbrt::built_scene from_text(const std::string& text, const std::string& dir = "",
                            std::optional<light_sampling> strategy = std::nullopt) {
  pbrt::parse_options po;
  po.search_directory = dir;
  pbrt::build_options bo;
  bo.decode_image = cli::decode_texture_image;
  bo.strategy = strategy;
  return pbrt::build_scene(pbrt::parse_text(text, "test.pbrt", po), dir, bo);
}

// A 10 x 10 floor at y = 0 of albedo 0.5, then the scene's lights. Rays
// leave a triangle from its hit point moved off the surface by the bound of
// that point's rounding (about 4e-7 |p|, hit_record::spawn_origin): on a
// floor of +-50 the light samples would start 2e-5 above it and see a few
// 1e-6 more light than the closed form at y = 0, more than the references'
// tolerance for rounding (1e-6); on +-5 the shift is ten times smaller.
std::string floor_scene(const std::string& lights) {
  return R"(Camera "perspective"
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 1 2  0 2 3 ]
)" + lights;
}

test::estimate floor_radiance(const scene& sc, integrator_kind ik, float x, float z, int id) {
  // One scattering event (the floor's): direct light only.
  return test::radiance_along(sc, ray{{x, 0.5f, z}, {0, -1, 0}}, path_settings{1, 3}, ik, sampler_kind::sobol, 32, 4096,
                              id, 7 + static_cast<std::uint64_t>(id));
}

void check(const test::estimate& e, double exact, const std::string& what) {
  EXPECT_LE(std::abs(e.mean - exact), std::max(6.0 * e.stderr_, 1e-6 * exact))
      << what << ": mean " << e.mean << " exact " << exact << " stderr " << e.stderr_;
  EXPECT_LE(std::abs(e.mean - exact), 0.01 * exact) << what << ": mean " << e.mean << " exact " << exact;
}

double polygon_floor(const std::vector<glm::dvec3>& poly, double x, double z) {
  return albedo / std::numbers::pi * test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
}

// The vertices of the scene's triangles after the first (the floor's
// two), as built: the references take the geometry in float as the scene
// holds it, and the vertices are checked against the expected ones apart.
std::vector<std::vector<glm::dvec3>> light_triangles(const scene& sc) {
  std::vector<std::vector<glm::dvec3>> out;
  const auto& tris = std::get<std::vector<object<triangle>>>(sc.objects);
  for (std::size_t i = 2; i < tris.size(); ++i) {
    const triangle& t = tris[i].shape;
    out.push_back({glm::dvec3(t.vertex(0)), glm::dvec3(t.vertex(1)), glm::dvec3(t.vertex(2))});
  }
  return out;
}

void expect_vertices(const std::vector<glm::dvec3>& got, const std::vector<glm::dvec3>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i)
    EXPECT_LT(glm::length(got[i] - want[i]), 1e-6) << "vertex " << i;
}

const std::vector<std::pair<float, float>> floor_points{{0.1f, 0.0f}, {0.4f, 0.3f}, {-0.6f, -0.5f}, {1.5f, 1.0f}};

class PbrtFloor : public ::testing::TestWithParam<integrator_kind> {};

std::string integrator_name(const ::testing::TestParamInfo<integrator_kind>& info) { return std::string(to_string(info.param)); }

// A triangle given in the z = 0 plane of its object space, clockwise seen
// from +z (its normal -z), turned by Rotate 90 about x to face up, then
// reversed by ReverseOrientation to face the floor, inside nested
// transforms: the world triangle is (-0.3, 1, -0.3), (0.2, 1, 0.5),
// (0.7, 1, -0.2).
const char* nested_triangle = R"(
AttributeBegin
  Translate 0.1 0 0
  AttributeBegin
    Translate 0 1 0
    Rotate 90 1 0 0
    ReverseOrientation
    AreaLightSource "diffuse" "rgb L" [ 4 4 4 ] %s
    Material "diffuse" "rgb reflectance" [ 0 0 0 ]
    Shape "trianglemesh" "point3 P" [ -0.4 -0.3 0  0.1 0.5 0  0.6 -0.2 0 ] "integer indices" [ 0 1 2 ]
  AttributeEnd
AttributeEnd
)";

std::string with(const char* fmt, const std::string& arg) {
  std::string out(fmt);
  out.replace(out.find("%s"), 2, arg);
  return out;
}

TEST_P(PbrtFloor, TriangleByNestedTransformsAndReverseOrientation) {
  const pbrt::built_scene b = from_text(floor_scene(with(nested_triangle, "")));
  ASSERT_EQ(b.world.emitters.size(), 1u);
  const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
  expect_vertices(poly, {{-0.3, 1, -0.3}, {0.2, 1, 0.5}, {0.7, 1, -0.2}});
  int id = 0;
  for (const auto& [x, z] : floor_points) check(floor_radiance(b.world, GetParam(), x, z, id++), polygon_floor(poly, x, z), "triangle");
}

// Without ReverseOrientation the same triangle faces up: the floor gets nothing.
TEST_P(PbrtFloor, ReverseOrientationDecidesTheEmittingSide) {
  std::string text = floor_scene(with(nested_triangle, ""));
  text.erase(text.find("ReverseOrientation"), std::string("ReverseOrientation").size());
  const pbrt::built_scene b = from_text(text);
  EXPECT_EQ(floor_radiance(b.world, GetParam(), 0.1f, 0.0f, 50).mean, 0.0);
}

// With shading normals the triangle faces them, and ReverseOrientation
// turns them (pbrt-v4 negates a mesh's N under it): N = +z in object space
// is -y in the world, so without ReverseOrientation the triangle faces the
// floor and lights it, and with it faces up and gives the floor nothing.
TEST_P(PbrtFloor, ReverseOrientationTurnsTheShadingNormals) {
  const std::string normals = "\"normal N\" [ 0 0 1  0 0 1  0 0 1 ] ";
  std::string reversed = floor_scene(with(nested_triangle, ""));
  reversed.insert(reversed.find("\"integer indices\" [ 0 1 2 ]"), normals);
  std::string plain = reversed;
  plain.erase(plain.find("ReverseOrientation"), std::string("ReverseOrientation").size());
  const pbrt::built_scene r = from_text(reversed), b = from_text(plain);
  EXPECT_EQ(floor_radiance(r.world, GetParam(), 0.1f, 0.0f, 51).mean, 0.0) << "reversed: faces up";
  const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
  int id = 70;
  for (const auto& [x, z] : floor_points)
    check(floor_radiance(b.world, GetParam(), x, z, id++), polygon_floor(poly, x, z), "normals facing the floor");
}

// Two-sided: the up-facing triangle lights the floor with its back, and its
// power counts both sides.
TEST_P(PbrtFloor, TwoSidedTriangleLightsFromItsBack) {
  std::string text = floor_scene(with(nested_triangle, "\"bool twosided\" true"));
  text.erase(text.find("ReverseOrientation"), std::string("ReverseOrientation").size());
  const pbrt::built_scene b = from_text(text);
  ASSERT_EQ(b.file_lights.size(), 1u);
  ASSERT_EQ(b.file_lights[0].size(), 2u);
  ASSERT_EQ(b.world.emitters.size(), 2u);
  EXPECT_FLOAT_EQ(b.world.emitters[0].power, b.world.emitters[1].power);
  const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
  expect_vertices(poly, {{-0.3, 1, -0.3}, {0.2, 1, 0.5}, {0.7, 1, -0.2}});
  int id = 60;
  for (const auto& [x, z] : floor_points) check(floor_radiance(b.world, GetParam(), x, z, id++), polygon_floor(poly, x, z), "two-sided");
}

// A quad from a PLY file, mirrored by Scale -1 1 1: pbrt-v4 reverses a
// triangle's world-space normal under a transform that swaps handedness, so
// the quad, which faces down in its file, still faces down.
TEST_P(PbrtFloor, PlyQuadUnderAMirror) {
  const fs::path dir = scratch("ply_quad");
  {
    std::ofstream ply(dir / "quad.ply");
    ply << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "-0.3 0 -0.2\n0.3 0 -0.2\n0.3 0 0.2\n-0.3 0 0.2\n4 0 1 2 3\n";
  }
  const pbrt::built_scene b = from_text(floor_scene(R"(
AttributeBegin
  Translate 0.05 1 0
  Scale -1 1 1
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Material "diffuse" "rgb reflectance" [ 0 0 0 ]
  Shape "plymesh" "string filename" "quad.ply"
AttributeEnd
)"),
                                        dir.string());
  ASSERT_EQ(b.world.emitters.size(), 2u);  // the quad's two triangles
  // The PLY quad v0 v1 v2 v3 as the triangles v0 v1 v2 and v0 v2 v3.
  const auto tris = light_triangles(b.world);
  ASSERT_EQ(tris.size(), 2u);
  const std::vector<glm::dvec3> poly{tris[0][0], tris[0][1], tris[0][2], tris[1][2]};
  expect_vertices(poly, {{0.35, 1, -0.2}, {-0.25, 1, -0.2}, {-0.25, 1, 0.2}, {0.35, 1, 0.2}});
  int id = 10;
  for (const auto& [x, z] : floor_points) check(floor_radiance(b.world, GetParam(), x, z, id++), polygon_floor(poly, x, z), "PLY quad");
}

// A disk of radius 0.5 at height 0.8: pbrt's +z normal turned by Rotate 90
// about x to face down.
// Its default strategy (area) and `auto` (the rule with its fixed v_rest).
TEST_P(PbrtFloor, DiskTurnedToFaceDown) {
  for (const std::optional<light_sampling> st : {std::optional<light_sampling>(), std::optional(light_sampling::automatic)}) {
  const pbrt::built_scene b = from_text(floor_scene(R"(
AttributeBegin
  Translate 0 0.8 0
  Rotate 90 1 0 0
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Material "diffuse" "rgb reflectance" [ 0 0 0 ]
  Shape "disk" "float radius" 0.5
AttributeEnd
)"), "", st);
  EXPECT_EQ(strategy_of(b.world.lights.at(0)), st.value_or(light_sampling::area));
  int id = st ? 120 : 20;
  for (const float d : {0.0f, 0.3f, 0.6f, 2.0f})
    check(floor_radiance(b.world, GetParam(), d, 0.0f, id++), albedo / std::numbers::pi * test::disk_irradiance(0.8, d, 0.5, emit),
          "disk at d=" + std::to_string(d) + (st ? " (auto)" : ""));
  }
}

// A sphere of radius 0.35 (a unit sphere scaled) at (0.1, 0.9, -0.05);
// its default strategy (the cone) and `auto`.
TEST_P(PbrtFloor, SphereScaledAndMoved) {
  for (const std::optional<light_sampling> st : {std::optional<light_sampling>(), std::optional(light_sampling::automatic)}) {
  const pbrt::built_scene b = from_text(floor_scene(R"(
AttributeBegin
  Translate 0.1 0.9 -0.05
  Scale 0.35 0.35 0.35
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Material "diffuse" "rgb reflectance" [ 0 0 0 ]
  Shape "sphere"
AttributeEnd
)"), "", st);
  EXPECT_EQ(strategy_of(b.world.lights.at(0)), st.value_or(light_sampling::solid_angle));
  const auto& spheres = std::get<std::vector<object<sphere>>>(b.world.objects);
  ASSERT_EQ(spheres.size(), 1u);
  const glm::dvec3 c(spheres[0].shape.center);
  const double r = spheres[0].shape.radius;
  EXPECT_LT(glm::length(c - glm::dvec3(0.1, 0.9, -0.05)), 1e-6);
  EXPECT_NEAR(r, 0.35, 1e-6);
  EXPECT_FALSE(spheres[0].shape.flip);
  int id = st ? 130 : 30;
  for (const auto& [x, z] : floor_points) {
    const glm::dvec3 w = c - glm::dvec3(x, 0.0, z);
    const double d2 = glm::dot(w, w);
    check(floor_radiance(b.world, GetParam(), x, z, id++), albedo * emit * (r * r / d2) * (w.y / std::sqrt(d2)),
          st ? "sphere (auto)" : "sphere");
  }
  }
}

// A diffusetransmission floor (reflectance 0.3, transmittance 0.6) under
// the nested triangle: seen from above it reflects R / pi times the
// irradiance Lambert's formula gives, seen from below it transmits T / pi
// times the same irradiance (one scattering event, direct light only).
TEST_P(PbrtFloor, DiffuseTransmissionReflectsAndTransmitsLambert) {
  std::string text = floor_scene(with(nested_triangle, ""));
  const std::string diffuse = "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]";
  text.replace(text.find(diffuse), diffuse.size(),
               "Material \"diffusetransmission\" \"rgb reflectance\" [ 0.3 0.3 0.3 ] "
               "\"rgb transmittance\" [ 0.6 0.6 0.6 ]");
  const pbrt::built_scene b = from_text(text);
  const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
  int id = 400;
  for (const auto& [x, z] : floor_points) {
    const double E = test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
    const test::estimate above = test::radiance_along(b.world, ray{{x, 0.5f, z}, {0, -1, 0}}, path_settings{1, 3},
                                                      GetParam(), sampler_kind::sobol, 32, 4096, id, 7 + id);
    ++id;
    const test::estimate below = test::radiance_along(b.world, ray{{x, -0.5f, z}, {0, 1, 0}}, path_settings{1, 3},
                                                      GetParam(), sampler_kind::sobol, 32, 4096, id, 7 + id);
    ++id;
    check(above, 0.3 / std::numbers::pi * E, "diffusetransmission from above");
    check(below, 0.6 / std::numbers::pi * E, "diffusetransmission from below");
  }
}

// A thindielectric pane (10 x 10 at y = 0.7) between the floor and the
// nested triangle (at y = 1): it blocks light samples (a delta surface), so
// the floor's direct light comes through it by BSDF samples alone. At eta 1
// the pane is invisible (R = 0): the floor gets Lambert's irradiance. At eta
// 1.5 the pane passes T_thin(theta) = 1 - 2R / (1 + R) of it, R the Fresnel
// reflectance at the angle of incidence (pbrt-v4's ThinDielectricBxDF),
// which falls with the angle: the radiance lies between T_thin at the
// largest angle to the light's vertices and T_thin(0) = 0.9231 times
// Lambert's. Paths of up to 3 bounces (floor, pane, light), no others: the
// triangle's own material is black, and the floor's light reflected by the
// pane back down would need a fourth event.
TEST_P(PbrtFloor, ThinDielectricPassesLightStraightThrough) {
  const std::string pane = R"(
AttributeBegin
  Material "thindielectric" "float eta" %s
  Shape "trianglemesh" "point3 P" [ -5 0.7 -5  5 0.7 -5  5 0.7 5  -5 0.7 5 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
)";
  const auto fresnel = [](double c) {  // unpolarized dielectric reflectance, eta 1.5, from outside
    const double eta = 1.5, s2 = 1.0 - c * c, ct = std::sqrt(1.0 - s2 / (eta * eta));
    const double rs = (c - eta * ct) / (c + eta * ct), rp = (eta * c - ct) / (eta * c + ct);
    return (rs * rs + rp * rp) / 2.0;
  };
  const auto t_thin = [&](double c) { const double R = fresnel(c); return 1.0 - 2.0 * R / (1.0 + R); };
  int id = 500;
  for (const char* eta : {"1", "1.5"}) {
    const pbrt::built_scene b = from_text(floor_scene(with(nested_triangle, "") + with(pane.c_str(), eta)));
    const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
    for (const auto& [x, z] : floor_points) {
      const test::estimate e = test::radiance_along(b.world, ray{{x, 0.5f, z}, {0, -1, 0}}, path_settings{3, 5},
                                                    GetParam(), sampler_kind::sobol, 32, 4096, id, 7 + id);
      ++id;
      const double lambert = polygon_floor(poly, x, z);
      if (std::string(eta) == "1") {
        check(e, lambert, "thindielectric eta 1");
        continue;
      }
      double c_min = 1.0;
      for (const glm::dvec3& v : poly) c_min = std::min(c_min, glm::normalize(v - glm::dvec3(x, 0.0, z)).y);
      EXPECT_LE(e.mean, t_thin(1.0) * lambert + 6.0 * e.stderr_) << "eta 1.5 at " << x << ", " << z;
      EXPECT_GE(e.mean, t_thin(c_min) * lambert - 6.0 * e.stderr_) << "eta 1.5 at " << x << ", " << z;
      EXPECT_LT(e.mean, 0.99 * lambert) << "the pane must take some light away";
    }
  }
}

// Shapes under the interface material (and its deprecated name "none") are
// no surfaces: a sphere around the whole scene, a disk between the light
// and the floor and a mesh through the floor change nothing, and the floor
// gets Lambert's irradiance from the nested triangle as without them.
TEST_P(PbrtFloor, InterfaceShapesLetEveryRayThrough) {
  const std::string around = R"(
AttributeBegin
  Material "interface"
  Shape "sphere" "float radius" 30
  Translate 0 0.6 0
  Rotate 90 1 0 0
  Shape "disk" "float radius" 3
AttributeEnd
AttributeBegin
  Material "none"
  Shape "trianglemesh" "point3 P" [ -5 -1 0  5 -1 0  0 2 0 ] "integer indices" [ 0 1 2 ]
AttributeEnd
)";
  const pbrt::built_scene b = from_text(floor_scene(with(nested_triangle, "") + around));
  EXPECT_EQ(b.world.object_count(), 3u) << "the floor's two triangles and the light's one";
  const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
  int id = 600;
  for (const auto& [x, z] : floor_points) check(floor_radiance(b.world, GetParam(), x, z, id++), polygon_floor(poly, x, z), "interface");
}

INSTANTIATE_TEST_SUITE_P(All, PbrtFloor, ::testing::Values(integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis),
                         integrator_name);

// Every triangle strategy (--light-sampling) under every integrator, on the
// floor under the nested triangle (one-sided) and under its two-sided
// variant lit from the back: the same closed form (Lambert's), and the
// lights built with the strategy asked for.
using TriangleStrategyCase = std::tuple<light_sampling, integrator_kind>;
class PbrtTriangleStrategies : public ::testing::TestWithParam<TriangleStrategyCase> {};

TEST_P(PbrtTriangleStrategies, MatchLambertOneAndTwoSided) {
  const auto [st, ik] = GetParam();
  std::string two = floor_scene(with(nested_triangle, "\"bool twosided\" true"));
  two.erase(two.find("ReverseOrientation"), std::string("ReverseOrientation").size());
  int id = 300;
  for (const std::string& text : {floor_scene(with(nested_triangle, "")), two}) {
    const pbrt::built_scene b = from_text(text, "", st);
    for (const light_ref l : b.world.lights) EXPECT_EQ(strategy_of(l), st);
    const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
    for (const auto& [x, z] : floor_points)
      check(floor_radiance(b.world, ik, x, z, id++), polygon_floor(poly, x, z), std::string(to_string(st)));
  }
}

INSTANTIATE_TEST_SUITE_P(All, PbrtTriangleStrategies,
                         ::testing::Combine(::testing::Values(light_sampling::area, light_sampling::solid_angle,
                                                              light_sampling::projected_solid_angle,
                                                              light_sampling::bilinear_solid_angle, light_sampling::pbrt,
                                                              light_sampling::automatic),
                                            ::testing::Values(integrator_kind::mixture, integrator_kind::nee,
                                                              integrator_kind::mis)),
                         [](const ::testing::TestParamInfo<TriangleStrategyCase>& info) {
                           std::string n = std::string(to_string(std::get<0>(info.param))) + "_" +
                                           std::string(to_string(std::get<1>(info.param)));
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

// pbrt-v4's triangle sampling takes area sampling below 3e-4 sr: a
// triangle 1/50 the size of the nested one (about 1e-4 sr from the floor)
// takes that branch at every floor point, the nested one the pre-warped
// spherical triangle, and both match Lambert's formula.
TEST(PbrtTriangleStrategies, PbrtsAreaBranchBelowItsThreshold) {
  std::string small = floor_scene(with(nested_triangle, ""));
  small.replace(small.find("Translate 0 1 0"), std::string("Translate 0 1 0").size(), "Translate 0 1 0\n    Scale 0.02 0.02 0.02");
  for (const bool tiny : {true, false}) {
    const pbrt::built_scene b = from_text(tiny ? small : floor_scene(with(nested_triangle, "")), "", light_sampling::pbrt);
    ASSERT_EQ(b.world.lights.size(), 1u);
    const auto& l = b.world.lights.get<triangle_pbrt_sampler>(0);
    const std::vector<glm::dvec3> poly = light_triangles(b.world).at(0);
    int id = 400 + 10 * tiny;
    for (const auto& [x, z] : floor_points) {
      const vec3 o(x, 0.0f, z);
      EXPECT_EQ(l.by_area(o), tiny) << x << " " << z;
      check(floor_radiance(b.world, integrator_kind::nee, x, z, id++), polygon_floor(poly, x, z),
            tiny ? "pbrt, area branch" : "pbrt, pre-warped branch");
    }
  }
}

// The vanishing variance (nee, direct light only, an unoccluded floor under
// a triangle of constant radiance): projected-solid-angle sampling's
// estimate is Omega_proj L rho / pi for every sample, so its standard error
// is at most 1/10 of solid-angle sampling's at equal sample counts (it is
// rounding only).
TEST(PbrtTriangleStrategies, ProjectedSolidAngleHasAlmostNoVariance) {
  const std::string text = floor_scene(with(nested_triangle, ""));
  const pbrt::built_scene sa = from_text(text, "", light_sampling::solid_angle);
  const pbrt::built_scene psa = from_text(text, "", light_sampling::projected_solid_angle);
  int id = 500;
  for (const auto& [x, z] : floor_points) {
    const test::estimate a = floor_radiance(sa.world, integrator_kind::nee, x, z, id);
    const test::estimate p = floor_radiance(psa.world, integrator_kind::nee, x, z, id++);
    EXPECT_GT(a.stderr_, 0.0);
    EXPECT_LE(p.stderr_, 0.1 * a.stderr_) << x << " " << z << ": psa " << p.stderr_ << " sa " << a.stderr_;
  }
}

// Many lights: 96 triangles in the plane y = 1 (one per cell of a 12 x 8
// grid, so none hides another from the floor), in three meshes of radiance
// 2, 20 and 5 (the last facing up: never seen from the floor, but chosen
// by power and uniformly); the floor's direct light is the sum of
// Lambert's formula over the triangles that face each point, under every
// light selection (96 emitters: power and uniform through the tree too)
// and both next-event estimators, within 6 standard errors and 1 %, with
// pbrt-v4's lightsampler names read from the file.
std::string light_grid_scene(const std::string& lightsampler) {
  pcg32 rng(77, 5);
  std::string meshes[3];
  for (int cell = 0; cell < 96; ++cell) {
    const float x0 = -1.8f + 0.3f * static_cast<float>(cell % 12), z0 = -1.2f + 0.3f * static_cast<float>(cell / 12);
    std::string& m = meshes[cell % 5 == 0 ? 2 : cell % 3 == 0 ? 1 : 0];
    for (int v = 0; v < 3; ++v) {
      const float x = x0 + 0.02f + 0.26f * rng.uniform(), z = z0 + 0.02f + 0.26f * rng.uniform();
      m += ' ';  // (piece by piece: GCC 12 flags a chain of + with a false -Wrestrict, bug 105329)
      m += std::to_string(x);
      m += " 1 ";
      m += std::to_string(z);
    }
  }
  // (Appended piece by piece: GCC 12 flags a chain of + with a false
  // -Wrestrict, bug 105329.)
  std::string text = "Integrator \"path\" \"string lightsampler\" \"";
  text += lightsampler;
  text += "\"\n";
  text += floor_scene("");
  const char* radiance[3] = {"2 2 2", "20 20 20", "5 5 5"};
  for (int i = 0; i < 3; ++i) {
    const std::size_t count = static_cast<std::size_t>(std::count(meshes[i].begin(), meshes[i].end(), ' ')) / 3;
    std::string idx;
    for (std::size_t k = 0; k < count; ++k) {
      idx += ' ';
      idx += std::to_string(k);
    }
    text += "AttributeBegin\n  AreaLightSource \"diffuse\" \"rgb L\" [ ";
    text += radiance[i];
    text += " ]\n  Material \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n";
    if (i == 2) text += "  ReverseOrientation\n";
    text += "  Shape \"trianglemesh\" \"point3 P\" [";
    text += meshes[i];
    text += " ] \"integer indices\" [";
    text += idx;
    text += " ]\nAttributeEnd\n";
  }
  return text;
}

TEST(PbrtManyLights, EverySelectionMatchesTheSumOfLambert) {
  struct selection {
    const char* file;  // the file's lightsampler ("" for the command line's)
    light_choice choose;
  };
  for (const selection sel : {selection{"power", light_choice::power}, selection{"uniform", light_choice::uniform},
                              selection{"bvh", light_choice::bvh}, selection{"bvh", light_choice::pbrt_bvh}}) {
    const pbrt::built_scene b = from_text(light_grid_scene(sel.file));
    EXPECT_EQ(b.light_select, sel.file);
    ASSERT_EQ(b.world.emitters.size(), 96u);
    ASSERT_FALSE(b.world.light_tree.empty());
    int id = 700;
    for (const auto& [x, z] : floor_points) {
      const vec3 o(x, 0.0f, z);
      double exact = 0.0, faced = 0.0;
      for (std::size_t k = 0; k < b.world.lights.size(); ++k) {
        if (!faces(b.world.lights[k], o)) continue;
        const auto& t = b.world.lights.get<triangle_area_sampler>(k).shape;
        const std::vector<glm::dvec3> poly{glm::dvec3(t.vertex(0)), glm::dvec3(t.vertex(1)), glm::dvec3(t.vertex(2))};
        const double L = std::get<diffuse_light>(b.world.materials[std::get<std::vector<object<triangle>>>(
                                                                         b.world.objects)[2 + k].material]).emit.r;
        exact += albedo / std::numbers::pi * test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, L);
        ++faced;
      }
      EXPECT_GT(faced, 40);
      EXPECT_LT(faced, 96);
      for (const integrator_kind ik : {integrator_kind::nee, integrator_kind::mis}) {
        path_settings set{1, 3};
        set.choose = sel.choose;
        const test::estimate e = test::radiance_along(b.world, ray{{x, 0.5f, z}, {0, -1, 0}}, set, ik,
                                                      sampler_kind::sobol, 32, 4096, id, 7 + static_cast<std::uint64_t>(id));
        ++id;
        check(e, exact, std::string(sel.file) + " " + std::string(to_string(ik)));
      }
    }
  }
}

// A textured floor: an 8-bit image (2 x 2 texels, sRGB-encoded, in a PPM
// file) as the reflectance, looked up bilinearly with v flipped (pbrt-v4's
// t = 1 - v), under a disk light; and a checkerboard of two constants. The
// radiance at a floor point is the texture's value there times E / pi.
// Texture coordinates a scene can drive to any float (a uv of 1e30, a
// uscale of 1e38): lookups stay in the image (a texel index that does not
// fit an int was undefined) and equal the lookup of the same place within
// one period; non-finite coordinates are taken as 0.
TEST(PbrtTextures, LookupsAtExtremeCoordinatesStayInTheImage) {
  auto img = std::make_shared<texture_image>();
  img->width = 4;
  img->height = 2;
  for (int i = 0; i < 8; ++i) img->texels.push_back(color(float(i)));
  constexpr float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (const texture_wrap wrap : {texture_wrap::repeat, texture_wrap::clamp, texture_wrap::black}) {
    texture t;
    t.k = texture::kind::image;
    t.img = img;
    t.wrap = wrap;
    for (const float u : {1e30f, -1e30f, 3e38f, -3e38f, 1e9f, inf, -inf, nan})
      for (const float v : {0.3f, 1e30f, nan}) {
        const color c = t.eval({u, v});
        EXPECT_TRUE(all_finite(c)) << u << " " << v;
        EXPECT_TRUE(c.r >= 0.0f && c.r <= 7.0f) << u << " " << v;
      }
    // Far out, a whole number of periods away: the texels of the first period.
    if (wrap == texture_wrap::repeat) {
      EXPECT_EQ(t.eval({1048576.0f + 0.375f, 0.25f}), t.eval({0.375f, 0.25f}));
    } else if (wrap == texture_wrap::clamp) {
      EXPECT_EQ(t.eval({1e30f, 0.25f}), t.eval({2.0f, 0.25f}));
    } else {
      EXPECT_EQ(t.eval({-1e30f, 0.25f}), color(0.0f));
    }
    EXPECT_EQ(t.eval({nan, 0.25f}), t.eval({0.0f, 0.25f}));
  }
  // A checkerboard's parity where floor(s) is beyond any integer type.
  texture ck;
  ck.k = texture::kind::checkerboard;
  ck.a = std::make_shared<texture>(texture::constant(color(1.0f)));
  ck.b = std::make_shared<texture>(texture::constant(color(2.0f)));
  EXPECT_EQ(ck.eval({1e30f, 0.5f}), color(1.0f));  // floats beyond 2^24 are even
  EXPECT_EQ(ck.eval({1e30f, 1.5f}), color(2.0f));
  EXPECT_EQ(ck.eval({-0.5f, 0.5f}), color(2.0f));  // floor: -1 + 0, odd
  EXPECT_EQ(ck.eval({-0.5f, -0.5f}), color(1.0f));  // -1 - 1, even
  EXPECT_EQ(ck.eval({inf, 0.5f}), ck.eval({0.0f, 0.5f}));
}

TEST(PbrtTextures, ImageAndCheckerboardReflectance) {
  const fs::path dir = scratch("textures");
  {
    // Row 0 (the image's top) = texels (0, 0), (1, 0).
    std::ofstream ppm(dir / "tex.ppm", std::ios::binary);
    const unsigned char px[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128};
    ppm << "P6\n2 2\n255\n";
    ppm.write(reinterpret_cast<const char*>(px), 12);
  }
  const auto srgb = [](double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); };
  const auto floor_with = [&](const std::string& texture) {
    return from_text(R"(Camera "perspective"
WorldBegin
)" + texture + R"(
Material "diffuse" "texture reflectance" "t"
Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  1 0 1  0 0 1 ] "integer indices" [ 0 1 2  0 2 3 ]
    "point2 uv" [ 0 0  1 0  1 1  0 1 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Translate 0.5 1 0.5
  Rotate 90 1 0 0
  Shape "disk" "float radius" 0.3
AttributeEnd
)",
                     dir.string());
  };
  const auto radiance = [](const pbrt::built_scene& b, float x, float z) {
    return test::radiance_along(b.world, ray{{x, 0.5f, z}, {0, -1, 0}}, path_settings{1, 3}, integrator_kind::mis,
                                sampler_kind::sobol, 16, 2048, 80, 3);
  };
  {
    const pbrt::built_scene b = floor_with(R"(Texture "t" "spectrum" "imagemap" "string filename" "tex.ppm")");
    // uv = (x, z) on this floor; texel centres at u, t = 0.25, 0.75.
    // (x, z) = (0.25, 0.75): s = 0.25, t = 1 - 0.75 = 0.25: texel (0, 0), red.
    const double e = test::disk_irradiance(1.0, std::hypot(0.25, 0.25), 0.3, 4.0) / std::numbers::pi;
    const test::estimate red = radiance(b, 0.25f, 0.75f);
    EXPECT_NEAR(red.mean, srgb(1.0) * e, 6 * red.stderr_ + 1e-3 * e);
    // (0.75, 0.25): s = 0.75, t = 0.75: texel (1, 1), grey 128.
    const test::estimate grey = radiance(b, 0.75f, 0.25f);
    EXPECT_NEAR(grey.mean, srgb(128.0 / 255.0) * e, 6 * grey.stderr_ + 1e-3 * e);
    // (0.5, 0.5): the mean of the four texels' red channels.
    const double e0 = test::disk_irradiance(1.0, 0.0, 0.3, 4.0) / std::numbers::pi;
    const test::estimate mid = radiance(b, 0.5f, 0.5f);
    EXPECT_NEAR(mid.mean, 0.25 * (srgb(1.0) + srgb(128.0 / 255.0)) * e0, 6 * mid.stderr_ + 1e-3 * e0);
  }
  {
    const pbrt::built_scene b = floor_with(R"(Texture "t" "spectrum" "checkerboard" "float uscale" 4 "float vscale" 4
    "rgb tex1" [ 0.8 0.8 0.8 ] "rgb tex2" [ 0.1 0.1 0.1 ])");
    // (0.1, 0.1): s = t = 0.4, floor 0 + 0: even, tex1; (0.35, 0.1): s = 1.4: odd, tex2.
    const double e1 = test::disk_irradiance(1.0, std::hypot(0.4, 0.4), 0.3, 4.0) / std::numbers::pi;
    const double e2 = test::disk_irradiance(1.0, std::hypot(0.15, 0.4), 0.3, 4.0) / std::numbers::pi;
    const test::estimate a = radiance(b, 0.1f, 0.1f), c = radiance(b, 0.35f, 0.1f);
    EXPECT_NEAR(a.mean, 0.8 * e1, 6 * a.stderr_ + 1e-3 * e1);
    EXPECT_NEAR(c.mean, 0.1 * e2, 6 * c.stderr_ + 1e-3 * e2);
  }
}

// A thin-lens camera (lensradius, focaldistance) over a checkerboard floor
// lit from above: focused on the floor, its image is the pinhole camera's
// (every ray of a film point meets the floor where the pinhole ray does,
// and a diffuse floor sends the same radiance to every lens point), so the
// two differ by noise alone: their RMS difference is that of two pinhole
// renders with different seeds, within 25 % (each RMS is estimated from
// 3 x 576 values: a few % of noise). Focused at pbrt's default 1e6 instead,
// the lens blurs the checks' edges by its radius (0.25 against checks of
// 0.25): the difference is over 3 times the noise. Under the independent
// sampler (whose lens sample comes from the pixel's stream) and Sobol's.
TEST(PbrtLens, ThePlaneOfFocusIsSharpAndTheRestBlurred) {
  const auto scene_with = [](const std::string& lens) {
    return from_text(R"(LookAt 0 3 0  0 0 0  0 0 1
Camera "perspective" "float fov" 20 )" + lens + R"(
WorldBegin
Texture "c" "spectrum" "checkerboard" "float uscale" 40 "float vscale" 40
    "rgb tex1" [ 0.8 0.8 0.8 ] "rgb tex2" [ 0.1 0.1 0.1 ]
Material "diffuse" "texture reflectance" "c"
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 1 2  0 2 3 ]
    "point2 uv" [ 0 0  1 0  1 1  0 1 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Material "diffuse" "rgb reflectance" [ 0 0 0 ]
  Shape "trianglemesh" "point3 P" [ -5 4 -5  5 4 -5  5 4 5  -5 4 5 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
)");
  };
  const pbrt::built_scene pinhole = scene_with(""), focused = scene_with(R"("float lensradius" 0.25 "float focaldistance" 3)"),
                          far = scene_with(R"("float lensradius" 0.25)");
  ASSERT_DOUBLE_EQ(focused.perspective.lens_radius, 0.25);
  ASSERT_DOUBLE_EQ(focused.perspective.focal_distance, 3.0);
  ASSERT_DOUBLE_EQ(far.perspective.focal_distance, 1e6);  // pbrt-v4's default
  for (const sampler_kind sk : {sampler_kind::independent, sampler_kind::sobol}) {
    render_settings rs;
    rs.width = rs.height = 24;
    rs.spp = 256;
    rs.max_depth = 1;
    rs.integrator = integrator_kind::nee;
    rs.sampler = sk;
    const auto image_of = [&](const pbrt::built_scene& b, std::uint64_t seed) {
      rs.seed = seed;
      const camera cam = pbrt::perspective_camera(b.camera_from_world, b.perspective, rs.width, rs.height);
      EXPECT_EQ(cam.has_lens(), b.perspective.lens_radius > 0.0);
      return render(b.world, cam, rs).img;
    };
    const image a = image_of(pinhole, 1), b = image_of(pinhole, 2), c = image_of(focused, 3), d = image_of(far, 4);
    const auto rms = [](const image& x, const image& y) {
      double s = 0.0;
      for (std::size_t i = 0; i < x.pixels.size(); ++i) {
        const glm::dvec3 e = glm::dvec3(x.pixels[i]) - glm::dvec3(y.pixels[i]);
        s += glm::dot(e, e);
      }
      return std::sqrt(s / (3.0 * double(x.pixels.size())));
    };
    const double noise = rms(a, b), sharp = rms(c, a), blurred = rms(d, a);
    const std::string what = std::string(to_string(sk));
    ASSERT_GT(noise, 0.0) << what;
    EXPECT_LT(sharp, 1.25 * noise) << what << ": focused " << sharp << ", two pinhole renders " << noise;
    EXPECT_GT(sharp, 0.8 * noise) << what << ": focused " << sharp << ", two pinhole renders " << noise;
    EXPECT_GT(blurred, 3.0 * noise) << what << ": out of focus " << blurred << ", two pinhole renders " << noise;
  }
}

// LookAt's camera-from-world is the inverse of an affine matrix: it must
// come out affine with its last row exactly 0 0 0 1, or the camera's check
// refuses it ("not affine"), as it once did for LookAt 0 1.6 -5  0 0.7 0
// 0 1 0, whose general 4x4 inverse leaves ~1e-17 there.
TEST(PbrtLookAt, EveryViewIsAcceptedWithAnExactAffineMatrix) {
  pcg32 rng(7, 11);
  const auto coord = [&] { return 20.0f * rng.uniform() - 10.0f; };
  std::vector<std::string> views = {"0 1.6 -5  0 0.7 0  0 1 0"};
  for (int i = 0; i < 300; ++i) {
    std::string v;
    for (int k = 0; k < 6; ++k) v += std::to_string(coord()) + " ";
    views.push_back(v + "0 1 0");
  }
  for (const std::string& view : views) {
    const pbrt::built_scene b = from_text("LookAt " + view + "\nCamera \"perspective\"\nWorldBegin\n" +
                                          "Shape \"sphere\"\n");
    const glm::dmat4& m = b.camera_from_world.m;
    EXPECT_EQ(m[0][3], 0.0) << view;
    EXPECT_EQ(m[1][3], 0.0) << view;
    EXPECT_EQ(m[2][3], 0.0) << view;
    EXPECT_EQ(m[3][3], 1.0) << view;
    // And it is the inverse: the eye maps to the camera's origin.
    const glm::dmat4 id = m * b.camera_from_world.inv;
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(id[j][k], j == k ? 1.0 : 0.0, 1e-12) << view;
  }
}

// A mix of two materials renders, in expectation, their mix: a floor that
// mixes a white and a black diffuse material with amount a (the black
// one's probability) reflects (1 - a) of the white one's light, under
// every integrator; the choice is a fixed function of the hit (two renders
// of the same seed are the same image); amount 0 and 1 are the materials
// themselves; a mix of mixes resolves.
TEST(PbrtMix, AmountIsTheSecondMaterialsShare) {
  const auto scene_with = [](const std::string& floor_material) {
    return from_text(R"(Camera "perspective"
WorldBegin
MakeNamedMaterial "white" "string type" "diffuse" "rgb reflectance" [ 0.8 0.8 0.8 ]
MakeNamedMaterial "black" "string type" "diffuse" "rgb reflectance" [ 0 0 0 ]
MakeNamedMaterial "half" "string type" "mix" "string materials" [ "white" "black" ]
)" + floor_material + R"(
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Material "diffuse" "rgb reflectance" [ 0 0 0 ]
  Shape "trianglemesh" "point3 P" [ -1 2 -1  -1 2 1  1 2 1  1 2 -1 ] "integer indices" [ 0 2 1  0 3 2 ]
AttributeEnd
)");
  };
  const std::vector<glm::dvec3> light{{-1, 2, -1}, {-1, 2, 1}, {1, 2, 1}, {1, 2, -1}};
  for (const auto& [what, material, share] : std::vector<std::tuple<std::string, std::string, double>>{
           {"amount 0.3", R"(Material "mix" "string materials" [ "white" "black" ] "float amount" 0.3)", 0.7},
           {"amount 0", R"(Material "mix" "string materials" [ "white" "black" ] "float amount" 0)", 1.0},
           {"amount 1", R"(Material "mix" "string materials" [ "white" "black" ] "float amount" 1)", 0.0},
           {"default amount", R"(NamedMaterial "half")", 0.5},
           {"mix of mixes", R"(MakeNamedMaterial "w" "string type" "mix" "string materials" [ "half" "white" ] "float amount" 0.5
Material "mix" "string materials" [ "w" "black" ] "float amount" 0.2)", 0.8 * 0.75}}) {
    const pbrt::built_scene b = scene_with(material);
    for (const integrator_kind ik : {integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis}) {
      // The choice is fixed at a hit: the expectation is over hit points.
      // 3000 points of a 0.2 x 0.2 patch, direct light only, each against
      // its own irradiance (Lambert's formula); the standard error is that
      // of the mean difference over the points.
      pcg32 rng(91, 7);
      double d_sum = 0.0, d_sq = 0.0, expect_sum = 0.0;
      const int n = 3000;
      for (int i = 0; i < n; ++i) {
        const vec3 x(0.2f * rng.uniform() - 0.1f, 0.0f, 0.2f * rng.uniform() - 0.1f);
        const ray r{x + vec3(0.3f, 1.0f, 0.2f), -vec3(0.3f, 1.0f, 0.2f)};
        const test::estimate e =
            test::radiance_along(b.world, r, path_settings{1, 3}, ik, sampler_kind::independent, 2, 8, i, 17);
        const double expect = share * 0.8 / std::numbers::pi *
                              test::polygon_irradiance(glm::dvec3(x), glm::dvec3(0, 1, 0), light, 4.0);
        d_sum += e.mean - expect;
        d_sq += (e.mean - expect) * (e.mean - expect);
        expect_sum += expect;
      }
      const double m = d_sum / n, se = std::sqrt(std::max(0.0, d_sq / n - m * m) / (n - 1));
      EXPECT_NEAR(m, 0.0, 6.0 * se + 1e-4 * expect_sum / n) << what << " " << to_string(ik) << ": mean radiance "
                                                            << expect_sum / n + m << ", expected " << expect_sum / n;
    }
  }
}

// pbrt-v4's integrators that converge to path's image are accepted with
// the parameters their Create reads, and the built scene names the one
// asked for (integrator_requested, for --stats); mcrt renders each with
// its own integrator, so the scene is otherwise the same.
TEST(PbrtIntegrators, ThoseThatConvergeToPathsImageAreAccepted) {
  const std::string world = "WorldBegin\nShape \"sphere\"\n";
  EXPECT_EQ(from_text(world).integrator_requested, "volpath");  // pbrt-v4's default
  for (const auto& [type, params] : std::vector<std::pair<std::string, std::string>>{
           {"path", R"("string lightsampler" "power")"},
           {"volpath", R"("bool regularize" false)"},
           {"simplepath", R"("bool samplelights" false "bool samplebsdf" true)"},
           {"simplepath", ""},
           {"simplevolpath", ""},
           {"bdpt", R"("bool visualizestrategies" false "bool visualizeweights" false)"},
           {"mlt", R"("integer mutationsperpixel" 1000 "integer chains" 10 "float sigma" 0.02 "float largestepprobability" 0.5)"},
           {"sppm", R"("integer photonsperiteration" 100000 "float radius" 0.05 "integer seed" 3)"}}) {
    const pbrt::built_scene b =
        from_text("Integrator \"" + type + "\" \"integer maxdepth\" 7 " + params + "\n" + world);
    EXPECT_EQ(b.integrator_requested, type);
    EXPECT_EQ(b.max_depth, 7) << type;
    EXPECT_EQ(b.spp, from_text(world).spp) << type << ": the Sampler's pixelsamples, whatever the integrator";
  }
}

// A light's emitting material reflects with the shape's own material: a
// white diffuse emitter lit by another light sends back more than its
// emission (a black one, nothing more).
TEST(PbrtLights, AnEmitterReflectsWithItsMaterial) {
  const auto radiance_from_above = [](const char* reflectance) {
    const pbrt::built_scene b = from_text(std::string(R"(Camera "perspective"
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
  Material "diffuse" "rgb reflectance" [ )") + reflectance + R"( ]
  Shape "trianglemesh" "point3 P" [ -50 0 -50  -50 0 50  50 0 50  50 0 -50 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Translate 0 1 0
  Rotate 90 1 0 0
  Shape "disk" "float radius" 0.5
AttributeEnd
)");
    return test::radiance_along(b.world, ray{{0, 0.5f, 0}, {0, -1, 0}}, path_settings{1, 3}, integrator_kind::mis,
                                sampler_kind::sobol, 16, 4096, 90, 5);
  };
  const test::estimate black = radiance_from_above("0 0 0"), white = radiance_from_above("1 1 1");
  EXPECT_NEAR(black.mean, 1.0, 1e-6);  // emission only
  const double reflected = 1.0 / std::numbers::pi * test::disk_irradiance(1.0, 0.0, 0.5, 4.0);
  EXPECT_NEAR(white.mean, 1.0 + reflected, 6.0 * white.stderr_ + 1e-3 * reflected);
}

// A furnace: a plate at the centre of a closed cube whose 12 triangles face
// inwards and emit L = 1 (black: they reflect nothing). The radiance the
// plate sends up along wo after one scattering event is its BSDF's
// directional albedo, integral of f(wo, wi) |cos theta_i| over the sphere,
// which an estimate from eval() alone (uniform directions, a fixed seed)
// gives independently of the BSDF's sampling and of the integrators' light
// sampling and MIS weights (their NEE sees 12 lights, the BSDF's samples
// meet them too).
struct furnace_case {
  const char* name;
  const char* material;
};

class PbrtFurnace : public ::testing::TestWithParam<std::tuple<furnace_case, integrator_kind>> {};

TEST_P(PbrtFurnace, RadianceIsTheBsdfsAlbedo) {
  const auto& [fc, ik] = GetParam();
  const pbrt::built_scene b = from_text(std::string(R"(Camera "perspective"
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
  Material "diffuse" "rgb reflectance" [ 0 0 0 ]
  Translate -10 -10 -10
  Scale 20 20 20
  ReverseOrientation
  Include "unit_cube.pbrt"
AttributeEnd
)") + fc.material + R"(
Shape "trianglemesh" "point3 P" [ -1 0 -1  -1 0 1  1 0 1  1 0 -1 ] "integer indices" [ 0 1 2  0 2 3 ] "point2 uv" [ 0 0 0 1 1 1 1 0 ]
)",
                                        MCRT_SCENES_DIR "/pbrt");
  ASSERT_EQ(b.world.emitters.size(), 12u);
  const vec3 wo_world = glm::normalize(vec3(0.3f, 0.8f, -0.2f));
  const ray camera{vec3(0.1f, 0.0f, 0.05f) + 5.0f * wo_world, -wo_world};
  const test::estimate e = test::radiance_along(b.world, camera, path_settings{1, 3}, ik, sampler_kind::sobol, 32, 8192, 70, 11);
  // The albedo from eval() of the material's BSDF at the plate, in its shading frame.
  hit_record rec;
  ASSERT_TRUE(b.world.hit(camera, 1e-4f, infinity, rec));
  double albedo = 0.0;
  const int n = 1 << 21;
  pcg32 rng(12345, 678);
  double delta_part = 0.0;
  const int n_delta = 1 << 16;
  with_bsdf(b.world.materials[rec.material], rec, [&](const auto& bsdf) {
    const shading_frame fr = shading_frame::from_normal_tangent(rec.shading_normal(), rec.dpdu);
    const vec3 wo = fr.to_local(wo_world);
    for (int i = 0; i < n; ++i) {
      const vec3 wi = square_to_uniform_sphere(rng.uniform2());
      albedo += double(bsdf.eval(wo, wi).r) * std::abs(wi.z) / square_to_uniform_sphere_pdf();
    }
    // What eval() cannot see: the delta part (a smooth coat's reflection),
    // from the BSDF's delta samples (exact for a smooth coat: its weight
    // is 1 on each, its probability the Fresnel reflectance).
    for (int i = 0; i < n_delta; ++i) {
      bsdf_sample bs;
      const float uc = rng.uniform();
      if (bsdf.sample(wo, uc, rng.uniform2(), bs) && bs.delta)
        delta_part += double(bs.f.r) * std::abs(bs.wi.z) / double(bs.pdf);
    }
  });
  albedo = albedo / n + delta_part / n_delta;
  ASSERT_GT(albedo, 0.0);
  // The eval() estimate's own error is below 0.3 % here (its standard error).
  EXPECT_NEAR(e.mean, albedo, 6.0 * e.stderr_ + 0.005 * albedo) << fc.name << ": stderr " << e.stderr_;
}

INSTANTIATE_TEST_SUITE_P(
    Materials, PbrtFurnace,
    ::testing::Combine(::testing::Values(furnace_case{"rough_copper", R"(Material "conductor" "float roughness" 0.2)"},
                                         furnace_case{"anisotropic_gold", R"(Material "conductor" "spectrum eta" "metal-Au-eta"
    "spectrum k" "metal-Au-k" "float uroughness" 0.05 "float vroughness" 0.4)"},
                                         furnace_case{"rough_glass", R"(Material "dielectric" "float roughness" 0.3)"},
                                         furnace_case{"rough_glass_alpha", R"(Material "dielectric" "float eta" 1.33
    "float roughness" 0.5 "bool remaproughness" false)"},
                                         furnace_case{"coated_diffuse_rough", R"(Material "coateddiffuse"
    "rgb reflectance" [ 0.7 0.5 0.3 ] "float roughness" 0.1)"},
                                         furnace_case{"coated_diffuse_smooth", R"(Material "coateddiffuse"
    "rgb reflectance" [ 0.7 0.5 0.3 ])"},
                                         furnace_case{"coated_diffuse_slab", R"(Material "coateddiffuse"
    "rgb reflectance" [ 0.3 0.3 0.3 ] "float roughness" 0.05 "float thickness" 0.2 "rgb albedo" [ 0.8 0.8 0.8 ]
    "float g" 0.4)"},
                                         furnace_case{"coated_copper", R"(Material "coatedconductor"
    "float interface.roughness" 0.05 "float conductor.roughness" 0.2)"}),
                       ::testing::Values(integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis)),
    [](const auto& info) {
      return std::string(std::get<0>(info.param).name) + "_" + std::string(to_string(std::get<1>(info.param)));
    });

// A smooth mirror in the same furnace: the radiance is exactly the
// conductor's Fresnel reflectance at the angle (a delta path, no noise),
// channel by channel.
TEST(PbrtFurnaceSmooth, MirrorGivesTheFresnelReflectance) {
  const pbrt::built_scene b = from_text(std::string(R"(Camera "perspective"
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
  Material "diffuse" "rgb reflectance" [ 0 0 0 ]
  Translate -10 -10 -10
  Scale 20 20 20
  ReverseOrientation
  Include "unit_cube.pbrt"
AttributeEnd
Material "conductor" "rgb eta" [ 0.2 0.9 1.1 ] "rgb k" [ 3.9 2.4 2.2 ]
Shape "trianglemesh" "point3 P" [ -1 0 -1  -1 0 1  1 0 1  1 0 -1 ] "integer indices" [ 0 1 2  0 2 3 ]
)"),
                                        MCRT_SCENES_DIR "/pbrt");
  const vec3 wo = glm::normalize(vec3(0.5f, 0.4f, 0.1f));
  const ray camera{5.0f * wo, -wo};
  const color expected = fresnel_complex(wo.y, color(0.2f, 0.9f, 1.1f), color(3.9f, 2.4f, 2.2f));
  for (const integrator_kind ik : {integrator_kind::mixture, integrator_kind::nee, integrator_kind::mis}) {
    const independent_sampler smp(3, 1);
    auto ps = smp.start_pixel(0, 0, 1);
    ps.start_sample(0);
    const color c = with_integrator(ik, [&]<class I>() { return I::li(b.world, camera, ps, path_settings{1, 3}); });
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], expected[k], 1e-5f) << to_string(ik) << " channel " << k;
  }
}

// The Cornell box of scenes/pbrt/cornell_rect.pbrt and of
// scenes/cornell_rect.json render the same image (up to noise): camera,
// mirror, walls, boxes, light and materials all agree.
TEST(PbrtCornell, SameImageAsTheJsonScene) {
  const cli::loaded_scene a = cli::load_scene(std::string(MCRT_SCENES_DIR) + "/cornell_rect.json");
  const cli::loaded_scene b = cli::load_scene(std::string(MCRT_SCENES_DIR) + "/pbrt/cornell_rect.pbrt");
  EXPECT_EQ(b.cam.width, 600);
  EXPECT_EQ(b.spp, 100);
  EXPECT_EQ(b.max_depth, 50);
  EXPECT_EQ(b.filter, "box");
  EXPECT_TRUE(b.world.accelerated());
  render_settings rs;
  rs.width = rs.height = 32;
  rs.spp = 1024;
  rs.max_depth = 50;
  rs.integrator = integrator_kind::mis;
  const image ia = render(a.world, a.make_camera(rs.width, rs.height), rs).img;
  rs.seed = 1;
  const image ib = render(b.world, b.make_camera(rs.width, rs.height), rs).img;
  // 4 x 4 blocks of 8 x 8 pixels (65536 samples each: about 0.5 % noise
  // in the darker blocks), within 4 %, and the whole image within 1 %.
  double total_a = 0, total_b = 0;
  for (int by = 0; by < 4; ++by)
    for (int bx = 0; bx < 4; ++bx) {
      glm::dvec3 sa(0.0), sb(0.0);
      for (int y = 8 * by; y < 8 * by + 8; ++y)
        for (int x = 8 * bx; x < 8 * bx + 8; ++x) {
          sa += glm::dvec3(ia.at(x, y));
          sb += glm::dvec3(ib.at(x, y));
        }
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(sb[c], sa[c], 0.04 * sa[c] + 1e-3) << "block (" << bx << ", " << by << ") channel " << c;
      total_a += sa.x + sa.y + sa.z;
      total_b += sb.x + sb.y + sb.z;
    }
  EXPECT_NEAR(total_b, total_a, 0.01 * total_a);
}

// The shipped feature scene reads completely: its meshes from the three
// kinds of PLY file, its textures, materials and lights, and it renders
// finite radiance everywhere.
TEST(PbrtFeatures, TheFeatureSceneLoadsAndRenders) {
  const cli::loaded_scene ls = cli::load_scene(std::string(MCRT_SCENES_DIR) + "/pbrt/features/features.pbrt");
  EXPECT_TRUE(ls.world.accelerated());
  EXPECT_EQ(ls.file_lights.size(), 3u);       // the panel's two triangles and the disk
  EXPECT_EQ(ls.world.emitters.size(), 5u);    // the panel two-sided: each triangle twice
  EXPECT_EQ(ls.filter, "gaussian");           // pbrt-v4's default
  EXPECT_EQ(ls.spp, 64);
  EXPECT_EQ(ls.max_depth, 8);
  int textured = 0, conductors = 0, dielectrics = 0;
  for (const material& m : ls.world.materials) {
    textured += std::holds_alternative<textured_diffuse>(m);
    conductors += std::holds_alternative<conductor_material>(m);
    dielectrics += std::holds_alternative<dielectric_material>(m);
  }
  EXPECT_EQ(textured, 2);
  EXPECT_EQ(conductors, 2);
  EXPECT_EQ(dielectrics, 1);
  const auto& tris = std::get<std::vector<object<triangle>>>(ls.world.objects);
  EXPECT_GT(tris.size(), 1280u + 2 * 48 * 24);  // the icosphere's and the torus's triangles, at least
  render_settings rs;
  rs.width = 24;
  rs.height = 16;
  rs.spp = 4;
  rs.max_depth = 8;
  rs.filter = pixel_filter::gaussian();
  const render_result r = render(ls.world, ls.make_camera(rs.width, rs.height), rs);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  double sum = 0.0;
  for (const color& c : r.img.pixels) sum += c.r + c.g + c.b;
  EXPECT_GT(sum, 0.0);
}

// Bitterli's cornell-box and veach-mis as shipped (scenes/pbrt/, the
// converter's render settings kept: docs/pbrt.md) read completely, with the
// settings, lights and materials their files give, and render finite,
// non-zero radiance.
TEST(PbrtBitterli, TheShippedScenesLoadAndRender) {
  struct expected {
    const char* file;
    int width, height, spp, max_depth;
    const char* filter;
    float radius;
    std::size_t file_lights, conductors;  // file_lights: one per emitting triangle or sphere
  };
  for (const expected& e : {expected{"/pbrt/cornell-box/scene-v4.pbrt", 64, 64, 1, 4, "gaussian", 1.5f, 2, 0},
                            expected{"/pbrt/veach-mis/scene-v4.pbrt", 1280, 720, 1, 3, "triangle", 1.0f, 3, 4}}) {
    SCOPED_TRACE(e.file);
    const cli::loaded_scene ls = cli::load_scene(std::string(MCRT_SCENES_DIR) + e.file);
    EXPECT_EQ(ls.cam.width, e.width);
    EXPECT_EQ(ls.cam.height, e.height);
    EXPECT_EQ(ls.spp, e.spp);
    EXPECT_EQ(ls.max_depth, e.max_depth);
    EXPECT_EQ(ls.filter, e.filter);
    EXPECT_EQ(ls.filter_radius, vec2(e.radius));
    EXPECT_EQ(ls.file_lights.size(), e.file_lights);
    std::size_t conductors = 0;
    for (const material& m : ls.world.materials) conductors += std::holds_alternative<conductor_material>(m);
    EXPECT_EQ(conductors, e.conductors);
    render_settings rs;
    rs.width = 24;
    rs.height = 16;
    rs.spp = 4;
    rs.max_depth = e.max_depth;
    rs.filter = e.filter == std::string("gaussian") ? pixel_filter::gaussian(vec2(e.radius)) : pixel_filter::triangle(vec2(e.radius));
    const render_result r = render(ls.world, ls.make_camera(rs.width, rs.height), rs);
    EXPECT_EQ(r.nonfinite_samples, 0u);
    double sum = 0.0;
    for (const color& c : r.img.pixels) sum += c.r + c.g + c.b;
    EXPECT_GT(sum, 0.0);
  }
}

// Each refusal is one line: FILE:LINE: what.
struct refusal {
  const char* text;
  int line;
  const char* says;
};

class PbrtRefusal : public ::testing::TestWithParam<refusal> {};

TEST_P(PbrtRefusal, NamesTheFileAndLine) {
  const refusal& r = GetParam();
  try {
    from_text(r.text);
    ADD_FAILURE() << "accepted: " << r.text;
  } catch (const pbrt::parse_error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("test.pbrt:" + std::to_string(r.line) + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(r.says), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Contract, PbrtRefusal,
    ::testing::Values(
        refusal{"WorldBegin\nShape \"curve\"\n", 2, "Shape \"curve\": not supported (supported: trianglemesh"},
        refusal{"WorldBegin\nMaterial \"subsurface\"\n", 2, "not supported"},
        refusal{"WorldBegin\nMaterial \"coateddiffuse\"\n  \"integer nsamples\" 0\n", 3, "nsamples"},
        refusal{"WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"diffuse\"\nMaterial \"mix\"\n"
                "  \"string materials\" [ \"a\" \"b\" ]\n", 4, "names no material \"b\""},
        refusal{"WorldBegin\nMaterial \"coatedconductor\" \"rgb reflectance\" [ 1 1 1 ]\n  \"rgb conductor.k\" [ 1 1 1 ]\n",
                2, "both reflectance and conductor.eta/conductor.k"},
        refusal{"WorldBegin\nMaterial \"interface\"\nAreaLightSource \"diffuse\"\nShape \"sphere\"\n", 3,
                "interface material"},
        refusal{"WorldBegin\nMaterial \"interface\" \"float eta\" 1.5\n", 2, "not supported"},
        refusal{"WorldBegin\nLightSource \"infinite\"\n", 2, "LightSource \"infinite\": not supported"},
        refusal{"Camera \"orthographic\"\nWorldBegin\n", 1, "Camera \"orthographic\": not supported"},
        refusal{"Integrator \"randomwalk\"\nWorldBegin\n", 1, "Integrator \"randomwalk\": not supported (its image differs"},
        refusal{"Integrator \"ambientocclusion\"\nWorldBegin\n", 1, "another quantity"},
        refusal{"Integrator \"simplepath\" \"bool samplebsdf\" false\nWorldBegin\n", 1, "samplebsdf"},
        refusal{"Integrator \"bdpt\"\n  \"bool visualizestrategies\" true\nWorldBegin\n", 2, "visualizestrategies"},
        refusal{"Integrator \"sppm\" \"float radius\" -1\nWorldBegin\n", 1, "radius"},
        refusal{"Integrator \"bdpt\" \"string lightsampler\" \"power\"\nWorldBegin\n", 1, "lightsampler"},
        refusal{"Integrator \"path\" \"bool regularize\" true\nWorldBegin\n", 1, "regularize"},
        refusal{"Option \"bool wavefront\" true\nWorldBegin\n", 1, "Option \"bool wavefront\": not supported"},
        refusal{"Shape \"sphere\"\n", 1, "before WorldBegin"},
        refusal{"WorldBegin\nShape \"sphere\"\n  \"float zmin\" -0.5\n", 3, "zmin"},
        refusal{"WorldBegin\nShape \"sphere\" \"float bogus\" 1\n", 2, "\"float bogus\" is not supported"},
        refusal{"WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n  \"integer indices\" [0 1 3]\n", 3,
                "index out of range"},
        refusal{"WorldBegin\nNamedMaterial \"nothing\"\n", 2, "no material named \"nothing\""},
        refusal{"WorldBegin\nShape \"plymesh\" \"string filename\" \"missing.ply\"\n", 2, "missing.ply"},
        refusal{"WorldBegin\nScale 1 2 1\nShape \"sphere\"\n", 3, "not a similarity"},
        refusal{"WorldBegin\nAreaLightSource \"diffuse\" \"spectrum L\" \"metal-Cu-eta\"\n", 2, "metal-Cu-eta"},
        refusal{"WorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n", 2, "MakeNamedMedium"},
        refusal{"WorldBegin\nShape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 1]\n", 2, "not planar"},
        refusal{"Film \"rgb\" \"float iso\" 400\nWorldBegin\n", 1, "iso"},
        refusal{"WorldBegin\nTexture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"none.png\"\n", 2, "none.png"},
        refusal{"WorldBegin\nMaterial \"diffuse\" \"texture reflectance\" \"nothing\"\n", 2, "no texture \"nothing\""},
        refusal{"WorldBegin\nMaterial \"conductor\" \"rgb reflectance\" [0.9 0.9 0.9] \"rgb eta\" [1 1 1]\n", 2,
                "both reflectance and eta"},
        refusal{"WorldBegin\nAreaLightSource \"diffuse\" \"bool twosided\" true\nShape \"sphere\"\n", 3, "two-sided sphere"}));

// Seeded mutations of the shipped Cornell box through the parser and the
// builder: each input gives a scene or one parse_error line naming its file
// (no crash, hang or other exception), 10^5 inputs.
TEST(PbrtBuilder, FuzzedScenesBuildOrGiveOneLineErrors) {
  std::ifstream in(std::string(MCRT_SCENES_DIR) + "/pbrt/cornell_rect.pbrt");
  const std::string base((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(base.empty());
  pcg32 rng(2031, 9);
  const char alphabet[] = "[]\"#\\ \n0123456789.-+eE abcxyzAttributeBeginEndShapeReverseOrientation\"float\t";
  int built = 0, refused = 0;
  for (int i = 0; i < 100000; ++i) {
    std::string s = base;
    const int edits = 1 + static_cast<int>(rng.uniform() * 4);
    for (int k = 0; k < edits && !s.empty(); ++k) {
      const std::size_t at = static_cast<std::size_t>(rng.uniform() * static_cast<float>(s.size()));
      const char c = alphabet[static_cast<std::size_t>(rng.uniform() * (sizeof alphabet - 1))];
      switch (static_cast<int>(rng.uniform() * 4)) {
        case 0: s[at] = c; break;
        case 1: s.insert(s.begin() + static_cast<std::ptrdiff_t>(at), c); break;
        case 2: s.erase(at, 1 + static_cast<std::size_t>(rng.uniform() * 8)); break;
        default: s.insert(at, s.substr(at, static_cast<std::size_t>(rng.uniform() * 40))); break;
      }
    }
    try {
      pbrt::parse_options po;
      po.search_directory = std::string(MCRT_SCENES_DIR) + "/pbrt";
      const pbrt::built_scene b = pbrt::build_scene(pbrt::parse_text(s, "fuzz.pbrt", po), po.search_directory);
      ASSERT_GT(b.world.object_count(), 0u);
      ++built;
    } catch (const pbrt::parse_error& e) {
      const std::string what = e.what();
      ASSERT_EQ(what.find('\n'), std::string::npos) << what;
      ASSERT_TRUE(what.rfind("fuzz.pbrt:", 0) == 0 || what.find("unit_cube.pbrt:") != std::string::npos) << what;
      ++refused;
    }
  }
  std::printf("builder fuzz: %d inputs built, %d refused\n", built, refused);
  EXPECT_GT(built, 5000);
  EXPECT_GT(refused, 5000);
}

#ifdef MCRT_EXE
// The executable: exit status 2, one line on stderr, no output written.
TEST(PbrtCli, BadFileExitsWithTwoAndWritesNothing) {
  const fs::path dir = scratch("cli");
  {
    std::ofstream f(dir / "bad.pbrt");
    f << "Camera \"perspective\"\nWorldBegin\nShape \"curve\"\n";
  }
  const fs::path out = dir / "out.exr", err = dir / "err.txt";
  const std::string cmd = std::string(MCRT_EXE) + " render " + (dir / "bad.pbrt").string() + " -o " + out.string() +
                          " --quiet 2> " + err.string();
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_FALSE(fs::exists(out));
  std::ifstream e(err);
  std::string line, rest;
  std::getline(e, line);
  EXPECT_FALSE(std::getline(e, rest)) << "more than one line: " << rest;
  EXPECT_NE(line.find("bad.pbrt:3: Shape \"curve\": not supported"), std::string::npos) << line;
}

// A pbrt file renders: its Film's resolution and filename, overridden by
// the command line.
TEST(PbrtCli, RendersTheShippedCornellBox) {
  const fs::path dir = scratch("cli_render");
  const fs::path out = dir / "cb.exr";
  const std::string cmd = std::string(MCRT_EXE) + " render " + MCRT_SCENES_DIR + "/pbrt/cornell_rect.pbrt --width 16 --height 12 --spp 4 -o " +
                          out.string() + " --quiet";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::exists(out));
}
#endif

}  // namespace
