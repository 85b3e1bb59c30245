// The three integrators (mixture, nee, mis) against each other and their
// parts: the multiple importance sampling weights of the two techniques sum
// to 1 for every direction, the light selection's probabilities and
// densities agree with what it samples, the next-event estimators stay
// unbiased when an emitter is not in the list of lights, and on the seed's
// Cornell scenes (global and direct light only) every integrator and sample
// generator gives the same mean image.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "support/lambert.hpp"
#ifdef MCRT_HAVE_SCENE_LOADER
#include "scene_loader.hpp"
#endif

using namespace mcrt;

namespace {

// A random light of every kind and strategy, facing roughly towards -y,
// around height 1 above the origin.
light random_light(pcg32& rng, int kind) {
  const vec3 c{rng.uniform() - 0.5f, 0.6f + rng.uniform(), rng.uniform() - 0.5f};
  const float a = 0.05f + 0.5f * rng.uniform(), b = 0.05f + 0.5f * rng.uniform();
  const float t = two_pi * rng.uniform();
  const vec3 e1{a * std::cos(t), 0.0f, a * std::sin(t)}, e2{-b * std::sin(t), 0.0f, b * std::cos(t)};
  switch (kind % 6) {
    case 0: return rect_area_sampler{rect::make(c, e1, e2)};  // e1 x e2 points down
    case 1: return rect_solid_angle_sampler{rect::make(c, e1, e2)};
    case 2: return ellipse_area_sampler{ellipse::make(c, e1, e2)};
    case 3: return ellipse_solid_angle_sampler{ellipse::make(c, e1, e2)};
    case 4: return ellipse_polar_solid_angle_sampler{ellipse::make(c, e1, e2)};
    default: return sphere_cone_sampler{sphere{c, 0.5f * a}};
  }
}

}  // namespace

// For a direction drawn by the light technique, the weight the integrator
// gives it (from the density returned with the sample) and the weight the
// material's technique would give the same direction (from the lights' pdf
// evaluated afresh) sum to 1, for both heuristics and for plain next-event
// estimation; with several lights chosen by power or uniformly, and with
// every light strategy. 20000 random configurations.
TEST(MisWeights, SumToOneForRandomConfigurations) {
  pcg32 rng(2024, 5);
  int checked = 0;
  for (int config = 0; config < 20000; ++config) {
    light_list lights;
    std::vector<emitter> emitters;
    const int count = 1 + static_cast<int>(rng.uniform() * 3.0f);
    for (int i = 0; i < count; ++i) {
      lights.push_back(random_light(rng, static_cast<int>(rng.uniform() * 6.0f)));
      emitters.push_back({static_cast<std::uint32_t>(i), 0.1f + rng.uniform()});
    }
    const vec3 o{2.0f * rng.uniform() - 1.0f, 0.0f, 2.0f * rng.uniform() - 1.0f};
    const vec3 n = glm::normalize(vec3{rng.uniform() - 0.5f, 1.0f, rng.uniform() - 0.5f});
    const light_choice how = rng.uniform() < 0.5f ? light_choice::power : light_choice::uniform;
    const light_selection sel(lights, emitters, o, n, how);
    if (sel.empty()) continue;
    float prob = 0.0f;
    const std::ptrdiff_t k = sel.pick(rng.uniform(), prob);
    ASSERT_GE(k, 0);
    EXPECT_FLOAT_EQ(prob, sel.probability(static_cast<std::size_t>(k)));
    light_sample s;
    if (!sample(lights[static_cast<std::size_t>(k)], o, n, rng.uniform2(), s)) continue;
    const float cos_theta = glm::dot(s.dir, n);
    if (!(cos_theta > 0.0f)) continue;
    const float p_material = cos_theta * inv_pi;
    const float p_light_sampled = sel.pdf(s.dir, k, s.pdf);  // as the light sample computes it
    const float p_light_evaluated = sel.pdf(s.dir);          // as the material's sample computes it
    ASSERT_GT(p_light_evaluated, 0.0f) << "a sampled direction must have a positive density";
    for (const mis_heuristic h : {mis_heuristic::power, mis_heuristic::balance}) {
      const path_settings set{50, 1, how, h};
      const float sum = heuristic_weights::light(set, p_light_sampled, p_material) +
                        heuristic_weights::material(set, p_material, p_light_evaluated);
      EXPECT_NEAR(sum, 1.0f, 1e-4f) << "config " << config << " p_light " << p_light_sampled << " vs "
                                    << p_light_evaluated << " p_material " << p_material;
    }
    const path_settings set{};
    EXPECT_EQ(light_sample_weights::light(set, p_light_sampled, p_material) +
                  light_sample_weights::material(set, p_material, p_light_evaluated),
              1.0f);
    ++checked;
  }
  EXPECT_GT(checked, 10000);
}

TEST(MisWeights, HeuristicsAreTheirFormulas) {
  EXPECT_FLOAT_EQ(power_heuristic(2.0f, 1.0f), 4.0f / 5.0f);
  EXPECT_FLOAT_EQ(balance_heuristic(2.0f, 1.0f), 2.0f / 3.0f);
  EXPECT_EQ(power_heuristic(0.0f, 1.0f), 0.0f);
  EXPECT_EQ(power_heuristic(1.0f, 0.0f), 1.0f);
  // Densities of tiny lights: no overflow when squared.
  EXPECT_FLOAT_EQ(power_heuristic(1e30f, 1.0f), 1.0f);
  EXPECT_FLOAT_EQ(power_heuristic(1.0f, 1e30f) + power_heuristic(1e30f, 1.0f), 1.0f);
  EXPECT_EQ(power_heuristic(1.0f, infinity), 0.0f);
}

// Lights are chosen with the probabilities the selection reports: by power
// (flux) or uniformly, among the emitters that face the point only.
// Chi-square goodness of fit, 3 degrees of freedom, 1e-4 significance.
TEST(LightSelection, ChoosesWithTheStatedProbabilities) {
  light_list lights;
  std::vector<emitter> emitters;
  for (int i = 0; i < 5; ++i) {
    const rect r = xz_rect(-1.0f + 0.4f * i, -0.8f + 0.4f * i, -0.1f, 0.1f, 2.0f, /*flip=*/i != 2);  // light 2 faces up
    lights.push_back(rect_area_sampler{r});
    emitters.push_back({static_cast<std::uint32_t>(i), 1.0f + static_cast<float>(i)});
  }
  const vec3 o{0.0f, 0.0f, 0.0f}, n{0.0f, 1.0f, 0.0f};
  for (const light_choice how : {light_choice::power, light_choice::uniform}) {
    const light_selection sel(lights, emitters, o, n, how);
    EXPECT_EQ(sel.probability(2), 0.0f) << "a light seen from behind is never chosen";
    double total = 0.0;
    for (std::size_t k = 0; k < 5; ++k) total += sel.probability(k);
    EXPECT_NEAR(total, 1.0, 1e-6);
    const double expected_p4 = how == light_choice::power ? 5.0 / (1 + 2 + 4 + 5) : 0.25;
    EXPECT_NEAR(sel.probability(4), expected_p4, 1e-6);
    std::map<std::ptrdiff_t, int> counts;
    pcg32 rng(7, 7);
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      float p;
      ++counts[sel.pick(rng.uniform(), p)];
    }
    EXPECT_EQ(counts.count(2), 0u);
    EXPECT_EQ(counts.count(-1), 0u);
    double chi2 = 0.0;
    for (std::size_t k : {0u, 1u, 3u, 4u}) {
      const double expected = n * sel.probability(k);
      chi2 += (counts[static_cast<std::ptrdiff_t>(k)] - expected) * (counts[static_cast<std::ptrdiff_t>(k)] - expected) / expected;
    }
    EXPECT_LT(chi2, 21.1) << "chi-square quantile 1 - 1e-4 with 3 degrees of freedom is 21.1";
  }
}

// has_bsdf, the integrators' test before their out-of-line BSDF vertex,
// says yes for exactly the materials with_bsdf hands a BSDF: every
// alternative of material, default-constructed (a conductor, bare or
// coated, given its complex IOR, which has no default).
TEST(Materials, HasBsdfIsWhatWithBsdfTakes) {
  const hit_record rec;
  const auto one = std::make_shared<const texture>(texture::constant(color(1.0f)));
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          material m{std::in_place_index<I>};
          if (auto* c = std::get_if<conductor_material>(&m)) c->eta = c->k = one;
          if (auto* c = std::get_if<coated_conductor_material>(&m)) {
            auto q = std::make_shared<coated_conductor_parameters>();
            q->conductor.eta = q->conductor.k = one;
            c->p = q;
          }
          bool called = false;
          const bool taken = with_bsdf(m, rec, [&](const auto&) { called = true; });
          EXPECT_EQ(taken, called) << "alternative " << I;
          EXPECT_EQ(has_bsdf(m), taken) << "alternative " << I;
        }(),
        ...);
  }(std::make_index_sequence<std::variant_size_v<material>>{});
}

// The one-emitter fast path of pick() and pdf() against the general walk:
// the same light with a second emitter that cannot be chosen (seen from
// behind) takes the walk over both, and must give the same light, the same
// P = 1 and bit for bit the same densities. 20000 random configurations of
// every strategy kind, by power and uniformly.
TEST(LightSelection, OneEmitterIsTheGeneralWalk) {
  pcg32 rng(31, 3);
  int compared = 0;
  for (int config = 0; config < 20000; ++config) {
    light_list lights{random_light(rng, static_cast<int>(rng.uniform() * 6.0f)),
                              rect_area_sampler{xz_rect(-1.0f, 1.0f, -1.0f, 1.0f, -3.0f, true)}};  // faces down, below o
    const std::vector<emitter> one{{0, 0.1f + rng.uniform()}};
    const std::vector<emitter> two{one[0], {1, 0.1f + rng.uniform()}};
    const vec3 o{2.0f * rng.uniform() - 1.0f, 0.0f, 2.0f * rng.uniform() - 1.0f};
    const vec3 n = glm::normalize(vec3{rng.uniform() - 0.5f, 1.0f, rng.uniform() - 0.5f});
    const light_choice how = rng.uniform() < 0.5f ? light_choice::power : light_choice::uniform;
    const light_selection fast(lights, one, o, n, how), walk(lights, two, o, n, how);
    ASSERT_EQ(fast.empty(), walk.empty());
    if (fast.empty()) continue;
    const float u = rng.uniform();
    float p_fast = -1.0f, p_walk = -2.0f;
    ASSERT_EQ(fast.pick(u, p_fast), 0);
    ASSERT_EQ(walk.pick(u, p_walk), 0);
    EXPECT_EQ(p_fast, 1.0f);
    EXPECT_EQ(p_walk, 1.0f);
    EXPECT_EQ(walk.probability(1), 0.0f);
    light_sample s;
    if (!sample(lights[0], o, n, rng.uniform2(), s)) continue;
    EXPECT_EQ(fast.pdf(s.dir), walk.pdf(s.dir)) << "config " << config;
    EXPECT_EQ(fast.pdf(s.dir, 0, s.pdf), walk.pdf(s.dir, 0, s.pdf));
    const vec3 other = glm::normalize(vec3{rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f});
    EXPECT_EQ(fast.pdf(other), walk.pdf(other));
    ++compared;
  }
  EXPECT_GT(compared, 10000);
}

// Without a light tree, the walk keeps which emitters face the point for the
// first 64 and asks the others again: with 70 emitters, every third facing
// away (among them emitters 64 to 69), no light facing away is ever chosen
// or given a probability, the probabilities sum to 1, and what pick()
// returns is what probability() says.
TEST(LightSelection, FacingBeyondTheKeptMask) {
  light_list lights;
  std::vector<emitter> emitters;
  for (int i = 0; i < 70; ++i) {
    const float x = -3.5f + 0.1f * static_cast<float>(i);
    lights.push_back(rect_area_sampler{xz_rect(x, x + 0.05f, -0.1f, 0.1f, 2.0f, /*flip=*/i % 3 != 1)});
    emitters.push_back({static_cast<std::uint32_t>(i), 1.0f + 0.01f * static_cast<float>(i)});
  }
  const vec3 o{0.0f, 0.0f, 0.0f}, n{0.0f, 1.0f, 0.0f};
  for (const light_choice how : {light_choice::power, light_choice::uniform}) {
    const light_selection sel(lights, emitters, o, n, how);
    double total = 0.0;
    for (std::size_t k = 0; k < 70; ++k) {
      if (k % 3 == 1) {
        EXPECT_EQ(sel.probability(k), 0.0f) << k;
      } else {
        EXPECT_GT(sel.probability(k), 0.0f) << k;
      }
      total += sel.probability(k);
    }
    EXPECT_NEAR(total, 1.0, 1e-5);
    for (int i = 0; i < 1000; ++i) {
      float p = 0.0f;
      const std::ptrdiff_t k = sel.pick((static_cast<float>(i) + 0.5f) / 1000.0f, p);
      ASSERT_GE(k, 0);
      EXPECT_NE(k % 3, 1) << "light " << k << " faces away";
      EXPECT_EQ(p, sel.probability(static_cast<std::size_t>(k)));
    }
  }
}

TEST(LightSelection, NonEmittingImportanceTargetsAreNotEmitters) {
  scene sc;
  sc.materials = {lambertian{color(0.5f)}, diffuse_light{color(4.0f)}, dielectric{1.5f}};
  sc.add_light(rect_area_sampler{xz_rect(-1, 1, -1, 1, 2, true)}, 1);
  sc.add_light(sphere_cone_sampler{sphere{{0, 1, 0}, 0.3f}}, 2);  // book 3's glass sphere
  EXPECT_EQ(sc.lights.size(), 2u);
  ASSERT_EQ(sc.emitters.size(), 1u);
  EXPECT_EQ(sc.emitters[0].light, 0u);
  EXPECT_NEAR(sc.emitters[0].power, pi * 4.0f * 4.0f, 1e-3f);  // pi * area * luminance
}

namespace {

// Mean and standard error of the mean over replicates of a scalar.
struct replicated {
  double mean = 0.0, stderr_ = 0.0;
};

replicated summarise(const std::vector<double>& v) {
  double s = 0.0, s2 = 0.0;
  for (double x : v) s += x, s2 += x * x;
  const double n = static_cast<double>(v.size());
  const double m = s / n;
  return {m, std::sqrt(std::max(s2 / n - m * m, 0.0) / (n - 1.0))};
}

double image_mean(const image& img) {
  double s = 0.0;
  for (const color& c : img.pixels) s += static_cast<double>(c.r) + c.g + c.b;
  return s / (3.0 * static_cast<double>(img.pixels.size()));
}

// The image mean of `replicates` renders with seeds 1..replicates.
template <class Scene>
replicated mean_image(const Scene& sc, const camera& cam, render_settings rs, int replicates) {
  std::vector<double> means;
  for (int r = 0; r < replicates; ++r) {
    rs.seed = static_cast<std::uint64_t>(1000 + r);
    means.push_back(image_mean(render(sc, cam, rs).img));
  }
  return summarise(means);
}

struct config {
  integrator_kind integrator;
  sampler_kind sampler;
  light_choice choose = light_choice::power;
};

std::string describe(const config& c) {
  return std::string(to_string(c.integrator)) + "/" + std::string(to_string(c.sampler)) +
         (c.choose == light_choice::uniform ? "/uniform" : "");
}

// Every configuration's mean image against the mixture's with the
// independent sampler: Welch's statistic |m_a - m_b| / sqrt(se_a^2 + se_b^2)
// <= 5 with 24 replicates each (about 46 degrees of freedom: two-sided
// false-failure probability 1e-5 per comparison).
template <class Scene>
void expect_same_mean(const Scene& sc, const camera& cam, render_settings rs, const std::vector<config>& configs,
                      const std::string& what) {
  constexpr int replicates = 24;
  rs.integrator = integrator_kind::mixture;
  rs.sampler = sampler_kind::independent;
  const replicated ref = mean_image(sc, cam, rs, replicates);
  ASSERT_GT(ref.mean, 0.0) << what;
  for (const config& c : configs) {
    rs.integrator = c.integrator;
    rs.sampler = c.sampler;
    rs.choose = c.choose;
    const replicated m = mean_image(sc, cam, rs, replicates);
    const double z = std::abs(m.mean - ref.mean) / std::sqrt(m.stderr_ * m.stderr_ + ref.stderr_ * ref.stderr_);
    EXPECT_LE(z, 5.0) << what << ": " << describe(c) << " mean " << m.mean << " +- " << m.stderr_ << ", mixture "
                      << ref.mean << " +- " << ref.stderr_;
  }
}

const std::vector<config> all_configs{
    {integrator_kind::nee, sampler_kind::independent},  {integrator_kind::mis, sampler_kind::independent},
    {integrator_kind::mixture, sampler_kind::sobol},     {integrator_kind::nee, sampler_kind::stratified},
    {integrator_kind::mis, sampler_kind::sobol},         {integrator_kind::mis, sampler_kind::stratified},
    {integrator_kind::nee, sampler_kind::sobol},         {integrator_kind::mixture, sampler_kind::stratified}};

}  // namespace

// Two lights, one in front of the other and brighter, a third facing away,
// and an emitter that is not in the list of lights: the next-event
// estimators must count the light of whatever emitter a shadow ray meets
// with the density of the whole technique, and the unlisted emitter through
// the material's sample. Both ways of choosing a light.
TEST(Integrators, AgreeOnOverlappingAndUnlistedLights) {
  scene sc;
  sc.materials = {lambertian{color(0.6f)}, diffuse_light{color(3.0f)}, diffuse_light{color(10.0f, 8.0f, 6.0f)},
                  diffuse_light{color(2.0f)}};
  sc.add(xz_rect_shape{-3, 3, -3, 3, 0}, 0);                                      // floor
  sc.add(yz_rect_shape{0, 3, -3, 3, -3}, 0);                                      // a wall
  sc.add_light(rect_solid_angle_sampler{xz_rect(-1, 1, -1, 1, 2, true)}, 1);      // large, behind
  sc.add_light(ellipse_area_sampler{ellipse::make({0.2f, 1.5f, 0}, {0.3f, 0, 0}, {0, 0, 0.3f})}, 2);  // small, in front
  sc.add_light(rect_area_sampler{xz_rect(1.5f, 2.5f, -1, 1, 2.5f, false)}, 1);    // faces up: never seen from below
  sc.add(sphere{{-1.5f, 0.5f, 0.5f}, 0.4f}, 3);                                    // emits, not listed
  const camera cam({0, 1.2f, -4}, {0, 0.6f, 0}, {0, 1, 0}, 60, 1.0f);
  render_settings rs;
  rs.width = rs.height = 20;
  rs.spp = 16;
  rs.max_depth = 3;
  std::vector<config> configs = all_configs;
  configs.push_back({integrator_kind::nee, sampler_kind::independent, light_choice::uniform});
  configs.push_back({integrator_kind::mis, sampler_kind::sobol, light_choice::uniform});
  expect_same_mean(sc, cam, rs, configs, "overlapping lights");
}

#ifdef MCRT_HAVE_SCENE_LOADER
// A shipped scene with every light switched to `strategy`, at 16 x 16 and
// 16 spp: every configuration against the mixture, global illumination and
// direct light only (--max-depth 1).
void expect_scene_agrees(const std::string& name, light_sampling strategy) {
  const cli::loaded_scene ls = cli::load_scene(std::string(MCRT_SCENES_DIR) + "/" + name + ".json", strategy);
  const camera cam(ls.cam.lookfrom, ls.cam.lookat, ls.cam.vup, ls.cam.vfov,
                   static_cast<float>(ls.cam.width) / static_cast<float>(ls.cam.height));
  render_settings rs;
  rs.width = rs.height = 16;
  rs.spp = 16;
  for (const int depth : {1, ls.max_depth}) {
    rs.max_depth = depth;
    expect_same_mean(ls.world, cam, rs, all_configs,
                     name + " " + std::string(to_string(strategy)) + " max depth " + std::to_string(depth));
  }
}

// The seed's Cornell scenes and book 3's (glass sphere sampled by the
// mixture only) and the materials scene (metal with fuzz, glass), both light
// strategies.
TEST(Integrators, AgreeInMeanOnTheCornellScenes) {
  for (const char* name :
       {"cornell_rect", "cornell_rect_large", "cornell_disk", "cornell_disk_large", "cornell_book3", "cornell_materials"})
    for (const light_sampling strategy : {light_sampling::area, light_sampling::solid_angle})
      expect_scene_agrees(name, strategy);
}

// The cosine-aware strategies (projected solid angle; the bilinear pre-warp
// where the shape has it) on scenes with each light shape: rectangle, disk,
// sphere (cornell_sphere), and book 3's glass sphere as the mixture's
// importance target.
TEST(Integrators, AgreeInMeanWithCosineAwareStrategies) {
  for (const char* name : {"cornell_rect", "cornell_disk_large", "cornell_sphere", "cornell_book3"})
    expect_scene_agrees(name, light_sampling::projected_solid_angle);
  for (const char* name : {"cornell_rect", "cornell_disk_large"})
    expect_scene_agrees(name, light_sampling::bilinear_solid_angle);
}

// The scene loader keeps a `rect` turned in a coordinate plane as a general
// rectangle (only one whose edges lie along the axes joins the axis-aligned
// set).
TEST(SceneLoader, TurnedRectanglesStayGeneral) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("mcrt_loader_" + std::to_string(::getpid()) + ".json");
  std::ofstream(file) << R"({
  "camera": {"lookfrom": [0, 1, -3], "lookat": [0, 0.5, 0], "vfov": 40, "width": 8, "height": 8},
  "materials": {"white": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]},
                "lamp": {"type": "diffuse_light", "emit": [4, 4, 4]}},
  "objects": [
    {"type": "rect", "corner": [0, 2, 0], "edge1": [900, 0, -500], "edge2": [-50, 0, -90], "material": "lamp"},
    {"type": "rect", "corner": [0, 0, 0], "edge1": [0, 0, 3], "edge2": [2, 0, 0], "material": "white"},
    {"type": "sphere", "center": [0, 0, 600], "radius": 100, "material": "white"}]})";
  const cli::loaded_scene ls = cli::load_scene(file.string());
  std::filesystem::remove(file);
  EXPECT_EQ(ls.world.axis_rects.size(), 1u) << "only the rectangle with edges along the axes is axis-aligned";
  EXPECT_EQ(std::get<std::vector<object<rect>>>(ls.world.objects).size(), 1u);
}

// `auto` (a strategy chosen per light and shading point) on a rectangle, a
// sphere and the two-light scene, where it mixes strategies within a path.
TEST(Integrators, AgreeInMeanWithAuto) {
  for (const char* name : {"cornell_rect", "cornell_sphere", "cornell_two_lights"})
    expect_scene_agrees(name, light_sampling::automatic);
}
#endif

// Direct light only under next-event estimation on the unoccluded floor
// under a rectangle, against Lambert's formula: with the Sobol generator the
// root-mean-square error over 64 floor points x 8 replicates falls at least
// as fast as N^-0.75 over N = 4 ... 256 samples (least-squares slope of log
// RMSE on log N <= -0.75; Owen-scrambled nets give about N^-1.5 for this
// smooth integrand), and with the independent one like N^-0.5 (slope within
// -0.5 +- 0.1: with 512 squared errors per N the RMSE is known to ~6 %, so
// the slope over a 64-fold range of N to about +-0.03).
namespace {

double floor_rmse(sampler_kind sk, light_sampling strategy, int n) {
  const float albedo = 0.5f, emit = 4.0f, h = 1.0f;
  scene sc;
  sc.materials = {lambertian{color(albedo)}, diffuse_light{color(emit)}};
  sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
  const rect lr = xz_rect(-0.3f, 0.3f, -0.2f, 0.2f, h, true);
  if (strategy == light_sampling::area)
    sc.add_light(rect_area_sampler{lr}, 1);
  else
    sc.add_light(rect_solid_angle_sampler{lr}, 1);
  const std::vector<glm::dvec3> poly{{-0.3, h, -0.2}, {0.3, h, -0.2}, {0.3, h, 0.2}, {-0.3, h, 0.2}};
  const path_settings set{1, 3};
  return with_sampler(sk, [&]<class S>() {
    const S sampler(77, n);
    double se = 0.0;
    int count = 0;
    for (int pt = 0; pt < 64; ++pt) {
      const float x = -1.0f + 2.0f * static_cast<float>(pt % 8) / 7.0f, z = -1.0f + 2.0f * static_cast<float>(pt / 8) / 7.0f;
      const double exact = albedo / std::numbers::pi * test::polygon_irradiance({x, 0.0, z}, {0.0, 1.0, 0.0}, poly, emit);
      for (int rep = 0; rep < 8; ++rep) {
        auto ps = sampler.start_pixel(pt, rep, 64);
        double sum = 0.0;
        for (int i = 0; i < n; ++i) {
          ps.start_sample(i);
          sum += nee_integrator::li(sc, ray{{x, 0.5f, z}, {0, -1, 0}}, ps, set).r;
        }
        const double rel = (sum / n - exact) / exact;
        se += rel * rel;
        ++count;
      }
    }
    return std::sqrt(se / count);
  });
}

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

TEST(Convergence, SobolBeatsNToTheMinusThreeQuartersOnDirectLight) {
  for (const light_sampling strategy : {light_sampling::area, light_sampling::solid_angle}) {
    std::vector<double> ns, sobol, independent;
    for (int n = 4; n <= 256; n *= 2) {
      ns.push_back(n);
      sobol.push_back(floor_rmse(sampler_kind::sobol, strategy, n));
      independent.push_back(floor_rmse(sampler_kind::independent, strategy, n));
    }
    const double s_sobol = loglog_slope(ns, sobol), s_indep = loglog_slope(ns, independent);
    const char* what = strategy == light_sampling::area ? "area" : "solid-angle";
    EXPECT_LE(s_sobol, -0.75) << what << ": sobol RMSE slope " << s_sobol;
    EXPECT_NEAR(s_indep, -0.5, 0.1) << what << ": independent RMSE slope " << s_indep;
    std::printf("%s: RMSE slope sobol %.3f, independent %.3f (RMSE at 256: %.3g vs %.3g)\n", what, s_sobol, s_indep,
                sobol.back(), independent.back());
  }
}
