// One `auto` choice per pixel at a camera ray's first surface
// (sampling/auto_footprint.hpp): which footprint points share a plane, the
// dearest choice over them, and that sample(), its pdf and pdf() are that
// choice's strategy's bit for bit; the floor's radiance with it against
// Lambert's formula (6 standard errors of 32 replicates and 1 %, as
// test_render_floor.cpp); a pixel's footprint through the renderer.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/render/light.hpp"
#include "mcrt/render/renderer.hpp"
#include "mcrt/render/scene.hpp"
#include "mcrt/sampling/auto_footprint.hpp"
#include "mcrt/sampling/auto_strategy.hpp"
#include "mcrt/samplers/samplers.hpp"
#include "support/auto_own.hpp"
#include "support/lambert.hpp"
#include "support/radiance_estimate.hpp"

namespace {

using namespace mcrt;

const vec3 up(0.0f, 1.0f, 0.0f);

triangle make_triangle(const vec3& a, const vec3& b, const vec3& c) {
  auto m = std::make_shared<triangle_mesh>();
  m->p = {a, b, c};
  m->indices = {0, 1, 2};
  return triangle{m, 0};
}

TEST(AutoFootprint, PlaneOfTellsPlanesApart) {
  auto_footprint fp;
  fp.add({0.2f, 0.0f, 0.1f}, up);
  fp.add({0.3f, 0.0f, 0.1f}, up);
  fp.add({0.25f, 0.05f, 0.15f}, up);                         // a parallel plane 0.05 above
  fp.add({0.25f, 0.0f, 0.15f}, glm::normalize(vec3(1, 1, 0)));  // a tilted one
  EXPECT_EQ(fp.size(), 4);
  EXPECT_EQ(fp.plane_of({0.21f, 0.0f, 0.12f}, up), 0);
  EXPECT_EQ(fp.plane_of({5.0f, 0.0f, -3.0f}, up), 0) << "the whole plane";
  EXPECT_EQ(fp.plane_of({0.25f, 0.05f, 0.14f}, up), 2);
  EXPECT_EQ(fp.plane_of({0.25f, 0.0f, 0.15f}, glm::normalize(vec3(1, 1, 0))), 3);
  EXPECT_EQ(fp.plane_of({0.25f, 0.0f, 0.15f}, glm::normalize(vec3(0, 1, 1))), -1) << "another normal";
  EXPECT_EQ(fp.plane_of({0.22f, 0.02f, 0.1f}, up), -1) << "between the two parallel planes";
  // At most max_points are kept.
  for (int i = 0; i < 10; ++i) fp.add(vec3(float(i)), up);
  EXPECT_EQ(fp.size(), auto_footprint::max_points);
}

TEST(AutoFootprint, DearestOverThePlaneRemembered) {
  auto_footprint fp;
  fp.add({-1.0f, 0.0f, 0.0f}, up);
  fp.add({0.0f, 0.0f, 0.0f}, up);
  fp.add({0.0f, 0.5f, 0.0f}, up);  // another plane
  fp.add({1.0f, 0.0f, 0.0f}, up);
  int calls = 0;
  // Projected solid angle only at the parallel plane's point, solid angle
  // at x > 0.5, area elsewhere.
  const auto choose = [&](const vec3& o, const vec3& n) {
    ++calls;
    EXPECT_EQ(n, up);
    if (o.y > 0.25f) return light_sampling::projected_solid_angle;
    return o.x > 0.5f ? light_sampling::solid_angle : light_sampling::area;
  };
  const int light_a = 0, light_b = 0;
  EXPECT_EQ(fp.dearest(&light_a, 0, choose), light_sampling::solid_angle) << "the floor's points only";
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(fp.dearest(&light_a, 0, choose), light_sampling::solid_angle);
  EXPECT_EQ(calls, 3) << "remembered";
  EXPECT_EQ(fp.dearest(&light_a, 2, choose), light_sampling::projected_solid_angle);
  EXPECT_EQ(calls, 4);
  EXPECT_EQ(fp.dearest(&light_b, 2, choose), light_sampling::projected_solid_angle);
  EXPECT_EQ(calls, 5) << "another light asks again";
  EXPECT_EQ(auto_footprint::dearer(light_sampling::area, light_sampling::solid_angle), light_sampling::solid_angle);
  EXPECT_EQ(auto_footprint::dearer(light_sampling::projected_solid_angle, light_sampling::solid_angle),
            light_sampling::projected_solid_angle);
}

// At receivers on planes around the light, with a footprint of three
// points of the receiver's plane spread about it (and one off it): the choice is
// the dearest of the per-point choices at the footprint's points on the
// plane (the per-point choice off it), and sample(), its pdf and pdf() are
// that strategy's bit for bit. The footprint's choice must differ from the
// per-point one at some receivers, or the check says nothing.
template <class Auto, class Shape>
void check_footprint_agreement(const Shape& shape, const auto_params& params) {
  const Auto s(shape, params);
  pcg32 rng(33, 7);
  int differs = 0, sampled = 0;
  for (int i = 0; i < 4000; ++i) {
    const float dist = 0.3f + 4.0f * rng.uniform();
    const vec3 dir = glm::normalize(vec3(2 * rng.uniform() - 1, -rng.uniform() - 0.05f, 2 * rng.uniform() - 1));
    const vec3 o = dist * dir;
    const vec3 n = glm::normalize(vec3(2 * rng.uniform() - 1, 2 * rng.uniform() - 0.3f, 2 * rng.uniform() - 1));
    // Two tangents of the receiver's plane.
    const vec3 t1 = glm::normalize(glm::cross(n, std::abs(n.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 1, 0)));
    const vec3 t2 = glm::cross(n, t1);
    const float spread = 0.6f * rng.uniform();
    auto_footprint fp;
    fp.add(o + 0.3f * n, n);  // off the plane: not asked
    for (const auto& [a, b] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {-1.0f, 1.0f}})
      fp.add(o + spread * (a * t1 + b * t2), n);
    const bool on_plane = rng.uniform() < 0.8f;
    const vec3 q = on_plane ? o + 0.5f * spread * (rng.uniform() * t1 - rng.uniform() * t2) : o - 0.2f * n;
    light_sampling expected = s.choice(q, n);
    if (on_plane) {
      expected = light_sampling::area;
      for (int k = 1; k < fp.size(); ++k) expected = auto_footprint::dearer(expected, s.choice(fp.point(k), n));
    }
    const light_sampling c = s.choice(q, n, &fp);
    ASSERT_EQ(c, expected) << "receiver " << i;
    differs += c != s.choice(q, n);
    const vec2 u = rng.uniform2();
    light_sample ls, own;
    const bool got = s.sample(q, n, u, ls, &fp);
    const bool own_got = test::own_sample(s, c, q, n, u, own);
    ASSERT_EQ(got, own_got) << "receiver " << i;
    if (!got) continue;
    ASSERT_EQ(ls.dir, own.dir) << "receiver " << i;
    ASSERT_EQ(ls.pdf, own.pdf) << "receiver " << i;
    const float own_density = test::own_pdf(s, c, q, n, ls.dir);
    ASSERT_EQ(s.pdf(q, n, ls.dir, &fp), own_density) << "receiver " << i;
    // Through the light variant too.
    const light l = s;
    ASSERT_EQ(pdf(l, q, n, ls.dir, &fp), own_density) << "receiver " << i;
    ++sampled;
  }
  EXPECT_GT(sampled, 1000);
  EXPECT_GT(differs, 50) << "the footprint's choice is the per-point one almost everywhere: nothing tested";
}

auto_params noisy() {
  auto_params p;
  p.image_variance = 0.01f;
  p.radiance = 1.0f;
  return p;
}

TEST(AutoFootprint, SampleAndPdfAreTheFootprintsChoiceRect) {
  check_footprint_agreement<rect_auto_sampler>(xz_rect(-1.0f, 1.0f, -0.8f, 0.8f, 0.0f, true), noisy());
}
TEST(AutoFootprint, SampleAndPdfAreTheFootprintsChoiceDisk) {
  check_footprint_agreement<ellipse_auto_sampler>(ellipse::make({0, 0, 0}, {1.0f, 0, 0}, {0, 0, 0.8f}), noisy());
}
TEST(AutoFootprint, SampleAndPdfAreTheFootprintsChoiceTriangle) {
  const vec3 a(-1.0f, 0.0f, -0.8f), b(1.2f, 0.0f, -0.6f), c(-0.2f, 0.0f, 1.0f);
  check_footprint_agreement<triangle_auto_sampler>(make_triangle(a, b, c), noisy());
}
TEST(AutoFootprint, SampleAndPdfAreTheFootprintsChoiceSphere) {
  check_footprint_agreement<sphere_auto_sampler>(sphere{vec3(0.0f, 0.6f, 0.0f), 0.5f}, noisy());
}

// The floor under a rectangle sampled by `auto` (its choice changes over
// the floor), direct light only, each point's samples with a
// footprint of the floor around it wide enough to take a dearer strategy
// than the point's own at some points: nee and mis, Sobol and independent
// samples, against Lambert's formula.
TEST(AutoFootprint, FloorRadianceUnbiased) {
  const float albedo = 0.5f, emit = 4.0f, h = 1.0f;
  scene sc;
  sc.materials = {lambertian{color(albedo)}, diffuse_light{color(emit)}};
  sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
  const rect lr = xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, h, true);
  // V = 1e-4 of radiance 4: solid angle under the light, projected solid
  // angle 0.35-0.5 from its middle, solid angle again to 1.6, area beyond.
  auto_params p;
  p.image_variance = 1e-4f;
  p.radiance = emit;
  sc.add_light(rect_auto_sampler(lr, p), 1);
  const rect_auto_sampler& s = sc.lights.get<rect_auto_sampler>(0);
  const std::vector<glm::dvec3> poly{{-0.3, h, -0.2}, {0.3, h, -0.2}, {0.3, h, 0.2}, {-0.3, h, 0.2}};
  const path_settings set{1, 3};
  constexpr int replicates = 32, samples = 1024;
  int dearer = 0;
  int id = 0;
  for (const auto& [x, z] : {std::pair{0.0f, 0.0f}, {0.35f, 0.1f}, {0.8f, -0.5f}, {1.6f, 0.9f}, {3.0f, 2.0f}}) {
    const double exact = albedo / std::numbers::pi * test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
    const vec3 o(x, 0.0f, z);
    auto_footprint fp;
    for (const auto& [a, b] : {std::pair{-0.4f, -0.4f}, {0.4f, -0.4f}, {-0.4f, 0.4f}, {0.4f, 0.4f}})
      fp.add(o + vec3(a, 0.0f, b), up);
    dearer += s.choice(o, up, &fp) != s.choice(o, up);
    for (const integrator_kind ik : {integrator_kind::nee, integrator_kind::mis})
      for (const sampler_kind sk : {sampler_kind::sobol, sampler_kind::independent}) {
        const auto [mean, se] = test::radiance_along(sc, ray{{x, 0.5f, z}, {0, -1, 0}}, set, ik, sk, replicates,
                                                     samples, id, 500 + id, &fp);
        // (Piece by piece: GCC 12 flags a chain of + with a false -Wrestrict, bug 105329.)
        std::string what = "(";
        what += std::to_string(x);
        what += ", ";
        what += std::to_string(z);
        what += ") ";
        what += to_string(sk);
        EXPECT_LE(std::abs(mean - exact), std::max(6.0 * se, 1e-6 * exact)) << what << " mean " << mean << " exact " << exact;
        EXPECT_LE(std::abs(mean - exact), 0.01 * exact) << what;
      }
    ++id;
  }
  EXPECT_GT(dearer, 0) << "the footprint never changed the choice: nothing tested";
}

// The renderer's footprint of a pixel: where the corners of the filter's
// support meet a surface. Looking straight down at a floor, all four on it;
// across the floor's edge, only those that meet it; past it, none. The
// tile's shared corners give every pixel the same footprint as its own
// four rays, for the box, the Gaussian (support 3 pixels wide) and a
// filter whose support is not a whole number of pixels.
TEST(AutoFootprint, PixelFootprintThroughTheRenderer) {
  scene sc;
  sc.materials = {lambertian{color(0.5f)}};
  sc.add(xz_rect_shape{-1, 1, -1, 1, 0}, 0);
  const camera cam({0, 2, 0}, {0, 0, 0}, {0, 0, 1}, 60, 1.0f);
  const int w = 64, h = 64;
  const float iw = 1.0f / w, ih = 1.0f / h;
  const auto_footprint mid = pixel_footprint(sc, cam, w / 2, h / 2, iw, ih, pixel_filter::box());
  ASSERT_EQ(mid.size(), 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(mid.plane_of(mid.point(i), mid.normal(i)), 0);
    EXPECT_NEAR(mid.normal(i).y, 1.0f, 1e-6f);
  }
  // The pixel's corners are a pixel apart on the floor (2 tan 30 deg * 2 / 64).
  const float pixel = 2.0f * 2.0f * std::tan(std::numbers::pi_v<float> / 6.0f) / w;
  EXPECT_NEAR(glm::length(mid.point(0) - mid.point(3)), pixel * std::sqrt(2.0f), 0.01f * pixel);
  // A wider filter, a wider footprint.
  const auto_footprint wide = pixel_footprint(sc, cam, w / 2, h / 2, iw, ih, pixel_filter::gaussian());
  EXPECT_NEAR(glm::length(wide.point(0) - wide.point(3)), 3.0f * pixel * std::sqrt(2.0f), 0.01f * pixel);
  // The floor's edge: x = 1 at tan(theta) = 1/2 from the centre.
  int edge_x = -1;
  for (int x = w / 2; x < w; ++x)
    if (pixel_footprint(sc, cam, x, h / 2, iw, ih, pixel_filter::box()).size() < 4) {
      edge_x = x;
      break;
    }
  ASSERT_GT(edge_x, 0);
  const int n_edge = pixel_footprint(sc, cam, edge_x, h / 2, iw, ih, pixel_filter::box()).size();
  EXPECT_GT(n_edge, 0);
  EXPECT_LT(n_edge, 4);
  EXPECT_EQ(pixel_footprint(sc, cam, w - 1, h / 2, iw, ih, pixel_filter::box()).size(), 0) << "past the floor";
  // A tile across the edge.
  for (const pixel_filter& f : {pixel_filter::box(), pixel_filter::gaussian(), pixel_filter::box(vec2(0.7f, 0.5f))}) {
    tile_footprints tile;
    const int x0 = 48, y0 = 16, x1 = 64, y1 = 32;
    tile.trace(sc, cam, f, x0, y0, x1, y1, iw, ih);
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const auto_footprint a = tile.at(sc, cam, f, x, y, iw, ih), b = pixel_footprint(sc, cam, x, y, iw, ih, f);
        ASSERT_EQ(a.size(), b.size()) << x << " " << y;
        for (int i = 0; i < a.size(); ++i) {
          ASSERT_EQ(a.point(i), b.point(i)) << x << " " << y;
          ASSERT_EQ(a.normal(i), b.normal(i)) << x << " " << y;
        }
      }
  }
}

}  // namespace
