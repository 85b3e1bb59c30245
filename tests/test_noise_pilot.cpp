// The noise pilot (render/noise_pilot.hpp): the image's mean variance of one
// pixel sample, the V of `auto`.
//
// Statistics: the pilot is an unbiased estimate for any number of samples
// per pixel (>= 2); 200 pilots of 2 samples per pixel (independent seeds)
// are compared with one of 256 samples per pixel on the same pixels, the
// check being |mean of the 200 - the 256-sample value| <= 5 standard
// errors of that difference (two-sided false-failure probability 6e-7,
// normal approximation: the mean of 200 such estimates is close to normal).
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include <cmath>
#include <cstdio>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "pilot_fixtures.hpp"

using namespace mcrt;
using mcrt_test::lit_floor;
using mcrt_test::settings;

TEST(NoisePilot, StrideGivesAboutThePixelsAskedAndTheAlbedoSeen) {
  EXPECT_EQ(noise_pilot_stride(100, 100, 1024), 3);
  EXPECT_EQ(noise_pilot_stride(300, 300, 1024), 9);
  EXPECT_EQ(noise_pilot_stride(16, 16, 1024), 1);
  const camera cam({0, 1.5f, -2}, {0, 0, 0}, {0, 1, 0}, 50, 1.0f);
  const noise_pilot_result r = estimate_image_variance(lit_floor(false), cam, settings(100, 100));
  EXPECT_EQ(r.stride, 3);
  EXPECT_EQ(r.pixels, 34 * 34);  // a pixel in each 3 x 3 block, the last row and column of blocks 1 pixel wide
  // Every diffuse surface seen has albedo 0.5 (the light is not diffuse).
  EXPECT_DOUBLE_EQ(r.mean_albedo2, 0.25);
}

// A view with nothing random in it (one emitter filling the view, pixel
// jitter included) has no variance; the
// lit floor has some, and sampling its light by projected solid angle (no
// variance of its own for an unoccluded diffuse receiver) leaves less.
TEST(NoisePilot, ZeroWithoutNoiseAndLessWithABetterStrategy) {
  scene flat;
  flat.materials = {diffuse_light{color(2.0f)}};
  flat.add(xy_rect_shape{-100, 100, -100, 100, 5, true}, 0);  // front side towards the camera
  const camera front({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 30, 1.0f);
  render_settings rs = settings(40, 40);
  rs.spp = 2;
  EXPECT_EQ(render(flat, front, rs).img.at(20, 20), color(2.0f)) << "the emitter fills the view";
  EXPECT_EQ(estimate_image_variance(flat, front, rs).image_variance, 0.0);

  const camera cam({0, 1.5f, -2}, {0, 0, 0}, {0, 1, 0}, 50, 1.0f);
  const double area = estimate_image_variance(lit_floor(false), cam, settings(64, 64)).image_variance;
  const double psa = estimate_image_variance(lit_floor(true), cam, settings(64, 64)).image_variance;
  EXPECT_GT(area, 0.0);
  EXPECT_GT(psa, 0.0) << "the shadow's edge and the pixel footprints stay noisy";
  EXPECT_LT(psa, 0.5 * area);
}

// Unbiased whatever the samples per pixel (see the header of this file).
TEST(NoisePilot, UnbiasedForAnySamplesPerPixel) {
  const scene sc = lit_floor(false);
  const camera cam({0, 1.5f, -2}, {0, 0, 0}, {0, 1, 0}, 50, 1.0f);
  render_settings rs = settings(24, 24);
  noise_pilot_settings many{1024, 256};
  rs.seed = 7;
  const double reference = estimate_image_variance(sc, cam, rs, many).image_variance;
  // The 256-sample value's own spread, from 8 seeds.
  std::vector<double> refs;
  for (std::uint64_t s = 100; s < 108; ++s) {
    rs.seed = s;
    refs.push_back(estimate_image_variance(sc, cam, rs, many).image_variance);
  }
  double rm = 0.0, rv = 0.0;
  for (double v : refs) rm += v / refs.size();
  for (double v : refs) rv += (v - rm) * (v - rm) / (refs.size() - 1);

  const int n = 200;
  double m = 0.0, v = 0.0;
  std::vector<double> xs;
  for (int i = 0; i < n; ++i) {
    rs.seed = 1000 + i;
    xs.push_back(estimate_image_variance(sc, cam, rs, {1024, 2}).image_variance);
    m += xs.back() / n;
  }
  for (double x : xs) v += (x - m) * (x - m) / (n - 1);
  const double se = std::sqrt(v / n + rv);
  std::printf("2 spp: mean %g, sd %g; 256 spp: %g (mean of 8: %g, sd %g)\n", m, std::sqrt(v), reference, rm, std::sqrt(rv));
  EXPECT_GT(reference, 0.0);
  EXPECT_LE(std::abs(m - reference), 5.0 * se) << "2 spp: " << m << ", 256 spp: " << reference << ", se " << se;
  EXPECT_LT(se, 0.1 * reference) << "the check must be sharp enough to mean something";
}

// A view across the edge of an emitter facing the camera (a lit floor and
// the light's front in view): the pilot's V, with the variance of what the
// camera rays meet first measured by K extra rays, is still unbiased (200
// pilots of 2 samples against the plain sample variance of 256, 5 standard
// errors as above), and spreads much less over seeds than without those
// rays (the two-sample variance of an edge pixel is 0 or large).
TEST(NoisePilot, EmittersInViewUnbiasedAndSteadier) {
  scene sc;
  sc.materials = {lambertian{color(0.3f)}, diffuse_light{color(20.0f)}};
  sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
  // A light over the floor, its front towards the camera.
  const rect r = xy_rect(-0.3f, 0.3f, 0.3f, 0.7f, 0.5f, true);
  sc.add_light(rect_area_sampler{r}, 1);
  const camera cam({0, 0.6f, -2}, {0, 0.4f, 0}, {0, 1, 0}, 40, 1.0f);
  render_settings rs = settings(32, 32);
  rs.seed = 3;
  ASSERT_GT(estimate_image_variance(sc, cam, rs, {1024, 2, 8}).pixels, 1000);
  // The reference: the plain sample variance of 256 samples per pixel.
  std::vector<double> refs;
  for (std::uint64_t seed = 100; seed < 108; ++seed) {
    rs.seed = seed;
    refs.push_back(estimate_image_variance(sc, cam, rs, {1024, 256, 0}).image_variance);
  }
  double rm = 0.0, rv = 0.0;
  for (double v : refs) rm += v / refs.size();
  for (double v : refs) rv += (v - rm) * (v - rm) / (refs.size() - 1);
  const int n = 200;
  auto stats = [&](int k_rays) {
    double m = 0.0, v = 0.0;
    std::vector<double> xs;
    for (int i = 0; i < n; ++i) {
      rs.seed = 1000 + i;
      xs.push_back(estimate_image_variance(sc, cam, rs, {1024, 2, k_rays}).image_variance);
      m += xs.back() / n;
    }
    for (double x : xs) v += (x - m) * (x - m) / (n - 1);
    return std::pair{m, v};
  };
  const auto [m8, v8] = stats(8);
  const auto [m0, v0] = stats(0);
  const double se = std::sqrt(v8 / n + rv / refs.size());
  std::printf("256 spp: %g (sd %g); 2 spp, K = 8: mean %g sd %g; K = 0: mean %g sd %g\n", rm, std::sqrt(rv), m8,
              std::sqrt(v8), m0, std::sqrt(v0));
  EXPECT_LE(std::abs(m8 - rm), 5.0 * se) << "K = 8: " << m8 << ", 256 spp: " << rm << ", se " << se;
  EXPECT_LT(se, 0.1 * rm) << "the check must be sharp enough to mean something";
  EXPECT_LT(std::sqrt(v8), 0.5 * std::sqrt(v0)) << "the emission rays must steady the pilot";
}

// V's reflected part alone (reflected_only, the low-variance pilot's:
// render/choice_gain_pilot.hpp): the same paths as the full pilot's (its
// emission rays draw from their own seeds), so with an emitter in view it
// is the full pilot's V less its emission term V_E, to rounding, with
// V_E > 0 here (the premise), and its own emission term is 0.
TEST(NoisePilot, ReflectedOnlyIsVLessTheEmissionTerm) {
  scene sc;
  sc.materials = {lambertian{color(0.3f)}, diffuse_light{color(20.0f)}};
  sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
  sc.add_light(rect_area_sampler{xy_rect(-0.3f, 0.3f, 0.3f, 0.7f, 0.5f, true)}, 1);
  const camera cam({0, 0.6f, -2}, {0, 0.4f, 0}, {0, 1, 0}, 40, 1.0f);
  render_settings rs = settings(32, 32);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    rs.seed = seed;
    noise_pilot_settings ps{1024, 2, 8};
    const noise_pilot_result full = estimate_image_variance(sc, cam, rs, ps);
    ps.reflected_only = true;
    const noise_pilot_result refl = estimate_image_variance(sc, cam, rs, ps);
    ASSERT_GT(full.edge_variance, 0.01 * full.image_variance) << "the premise: an emission term";
    EXPECT_EQ(refl.edge_variance, 0.0);
    EXPECT_NEAR(refl.image_variance, full.image_variance - full.edge_variance, 1e-9 * full.image_variance) << seed;
    ASSERT_EQ(refl.light_variance.size(), 1u);
    EXPECT_EQ(refl.light_variance[0], full.light_variance[0]);
  }
}

// A light in view whose edges cross few pixels: a pilot of every k-th
// pixel meets a share of the edge pixels that depends on where its grid
// falls, which no seed averages out: measured on a grid of half the
// stride, the emission term kept the pilot's mean over seeds 400x off at
// one pilot size; from a random pixel in each block, both terms are
// unbiased, and the pilot's mean over seeds is within 25 % of the image's
// mean variance (every pixel, 64 samples each) at each pilot size (a
// 96 x 96 image, pilots of 150-600 pixels).
TEST(NoisePilot, EmittersInViewAtAnyPilotSize) {
  // Two views of a light facing the camera: level with it (the floor behind
  // its edges unlit) and from above (its lower edge against the floor it
  // lights in front of it, where E and R vary together).
  for (const vec3 from : {vec3(0, 0.6f, -2), vec3(0, 1.5f, -2)}) {
    scene sc;
    sc.materials = {lambertian{color(0.3f)}, diffuse_light{color(20.0f)}};
    sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
    sc.add_light(rect_area_sampler{xy_rect(-0.3f, 0.3f, 0.3f, 0.7f, 0.5f, true)}, 1);
    const camera cam(from, {0, 0.4f, 0}, {0, 1, 0}, 40, 1.0f);
    render_settings rs = settings(96, 96);
    rs.seed = 5;
    const double ref = estimate_image_variance(sc, cam, rs, {96 * 96, 64, 0}).image_variance;
    for (const int pixels : {150, 300, 600}) {
      double mean = 0.0, least = std::numeric_limits<double>::infinity();
      const int seeds = 40;
      for (int i = 0; i < seeds; ++i) {
        rs.seed = 2000 + i;
        const double v = estimate_image_variance(sc, cam, rs, {pixels, 2, 8}).image_variance;
        mean += v / seeds, least = std::min(least, v);
      }
      std::printf("from y = %g, %d pixels: mean %g, least %g; every pixel: %g\n", from.y, pixels, mean, least, ref);
      EXPECT_NEAR(mean / ref, 1.0, 0.25) << pixels << " pixels: " << mean << ", every pixel: " << ref;
      // Never 0: the floor's own noise is in every pilot.
      EXPECT_GT(least, 0.0) << pixels << " pixels";
    }
  }
}

// The result does not depend on the thread count (rows are summed in order),
// so neither do the choices of `auto`.
// (Every pixel: a thread per 512 of them at most, so up to 7 here.) The
// receivers too: the diffuse surfaces the measured pixels' centres see,
// in pixel order.
TEST(NoisePilot, IdenticalForAnyThreadCount) {
  const scene sc = lit_floor(false);
  const camera cam({0, 1.5f, -2}, {0, 0, 0}, {0, 1, 0}, 50, 1.0f);
  render_settings rs = settings(77, 53);
  const noise_pilot_settings every_pixel{77 * 53, 2, 8};
  rs.threads = 1;
  const noise_pilot_result one = estimate_image_variance(sc, cam, rs, every_pixel);
  ASSERT_GT(one.receivers.size(), 1000u);
  ASSERT_LE(one.receivers.size(), std::size_t(one.pixels));
  for (const auto_receiver& r : one.receivers) {
    EXPECT_NEAR(glm::length(r.n), 1.0f, 1e-5f);
    EXPECT_LT(glm::dot(r.n, r.p - vec3(0, 1.5f, -2)), 0.0f) << "the normal faces the camera";
  }
  for (unsigned t : {2u, 3u, 8u}) {
    rs.threads = t;
    const noise_pilot_result many = estimate_image_variance(sc, cam, rs, every_pixel);
    EXPECT_EQ(many.image_variance, one.image_variance) << t << " threads";
    ASSERT_EQ(many.receivers.size(), one.receivers.size()) << t << " threads";
    for (std::size_t i = 0; i < one.receivers.size(); ++i)
      ASSERT_TRUE(many.receivers[i].p == one.receivers[i].p && many.receivers[i].n == one.receivers[i].n) << i;
  }
}

// The emission term with the image's own samples (edge_noise_factor): a
// sphere light in view, whose outline crosses pixels at every angle, over
// a lit floor, 48 x 48 pixels at 8 spp. The reference: at every pixel, N
// times the variance of the mean of E over the N camera rays of the
// image's sampler, from 64 independent scramblings, averaged over the
// image. The pilot's emission term times kappa_E, averaged over 40 seeds,
// must be within 30 % of it (the ratio is taken at the pixels where the
// pilot's K rays saw E vary; the model needs the term to a factor, not a
// few per cent); kappa_E < 0.5 (Sobol and stratified points resolve the
// outline far better than independent ones: the test's premise); with
// independent samples kappa_E is 1 exactly.
template <class Sampler>
void check_edge_noise_factor(sampler_kind kind) {
  scene sc;
  sc.materials = {lambertian{color(0.3f)}, diffuse_light{color(20.0f)}};
  sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
  sc.add_light(sphere_area_sampler{sphere{{0.0f, 0.5f, 0.0f}, 0.25f}}, 1);
  const camera cam({0, 0.8f, -2}, {0, 0.4f, 0}, {0, 1, 0}, 40, 1.0f);
  render_settings rs = settings(48, 48);
  rs.spp = 8;
  rs.sampler = kind;
  const float inv_w = 1.0f / 48.0f, inv_h = 1.0f / 48.0f;
  double ref = 0.0;
  const int scramblings = 64;
  std::vector<Sampler> samplers;
  for (int j = 0; j < scramblings; ++j) samplers.emplace_back(9000 + j, rs.spp);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      glm::dvec3 sum(0.0), sum2(0.0);
      for (Sampler& s : samplers) {
        auto px = s.start_pixel(x, y, 48);
        glm::dvec3 mean(0.0);
        for (int k = 0; k < rs.spp; ++k) {
          px.start_sample(k);
          mean += glm::dvec3(radiance_met_first(sc, camera_ray(cam, px, x, y, inv_w, inv_h))) / double(rs.spp);
        }
        sum += mean, sum2 += mean * mean;
      }
      const glm::dvec3 var = (sum2 - sum * sum / double(scramblings)) / double(scramblings - 1);
      ref += rs.spp * (var.x + var.y + var.z) / 3.0 / (48.0 * 48.0);
    }
  double term = 0.0, factor = 0.0;
  const int seeds = 40;
  for (int i = 0; i < seeds; ++i) {
    rs.seed = 3000 + i;
    const noise_pilot_result r = estimate_image_variance(sc, cam, rs, {600, 2, 8});
    ASSERT_FALSE(r.edge_pixels.empty());
    const double k = edge_noise_factor(sc, cam, rs, r.edge_pixels);
    term += k * r.edge_variance / seeds, factor += k / seeds;
    render_settings independent = rs;
    independent.sampler = sampler_kind::independent;
    EXPECT_EQ(edge_noise_factor(sc, cam, independent, r.edge_pixels), 1.0);
  }
  std::printf("%s: emission term %g (mean kappa_E %g); with %d scramblings at every pixel: %g\n",
              std::string(to_string(kind)).c_str(), term, factor, scramblings, ref);
  EXPECT_NEAR(term / ref, 1.0, 0.3) << term << " vs " << ref;
  EXPECT_LT(factor, 0.5);
}
TEST(NoisePilot, EdgeNoiseFactorSobol) { check_edge_noise_factor<sobol_sampler>(sampler_kind::sobol); }
TEST(NoisePilot, EdgeNoiseFactorStratified) { check_edge_noise_factor<stratified_sampler>(sampler_kind::stratified); }
