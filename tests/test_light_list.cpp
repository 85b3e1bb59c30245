// The scene's light list (render/light_list.hpp) against a std::vector of
// the `light` variant it replaces: the same lights, bit for bit, for every
// strategy of every shape, through push_back, set, take and compact; and the
// bytes a light takes are its own strategy's.
#include <gtest/gtest.h>

#include <bit>
#include <memory>
#include <vector>

#include "mcrt/core/rng.hpp"
#include "mcrt/render/light_importance.hpp"
#include "mcrt/render/light_list.hpp"

using namespace mcrt;

namespace {

// A random shape of each kind, above the floor y = 0 and facing every way.
struct shapes {
  rect r;
  ellipse e;
  sphere s;
  triangle t;
};

shapes random_shapes(pcg32& rng, const std::shared_ptr<triangle_mesh>& mesh) {
  const vec3 c{rng.uniform() - 0.5f, 0.6f + rng.uniform(), rng.uniform() - 0.5f};
  const float a = 0.05f + 0.5f * rng.uniform(), b = 0.05f + 0.5f * rng.uniform();
  const float phi = two_pi * rng.uniform(), tilt = 0.5f * (rng.uniform() - 0.5f);
  const vec3 e1{a * std::cos(phi), tilt * a, a * std::sin(phi)}, e2{-b * std::sin(phi), 0.0f, b * std::cos(phi)};
  const bool flip = rng.uniform() < 0.5f;
  const auto base = static_cast<std::uint32_t>(mesh->p.size());
  mesh->p.insert(mesh->p.end(), {c, c + e1, c + e2 + 0.3f * e1});
  mesh->indices.insert(mesh->indices.end(), {base, base + 1, base + 2});
  return {rect::make(c, e1, e2, flip), ellipse::make(c, e1, e2), sphere{c, 0.5f * a},
          triangle{mesh, base / 3}};
}

// Alternative I of `light` on its shape among sh.
template <std::size_t I>
light make_alternative(const shapes& sh) {
  using S = std::variant_alternative_t<I, light>;
  using Shape = std::decay_t<decltype(std::declval<S>().shape)>;
  const Shape* shape;
  if constexpr (std::is_same_v<Shape, rect>)
    shape = &sh.r;
  else if constexpr (std::is_same_v<Shape, ellipse>)
    shape = &sh.e;
  else if constexpr (std::is_same_v<Shape, sphere>)
    shape = &sh.s;
  else
    shape = &sh.t;
  return light(std::in_place_index<I>, S(*shape));
}

template <std::size_t... I>
light make_light(std::size_t i, const shapes& sh, std::index_sequence<I...>) {
  light out;
  ((i == I ? (out = make_alternative<I>(sh), 0) : 0), ...);
  return out;
}
light make_light(std::size_t i, const shapes& sh) {
  return make_light(i, sh, std::make_index_sequence<std::variant_size_v<light>>{});
}

// Light k of the list and the variant agree, bit for bit, at random points.
void expect_same(const light_list& list, const std::vector<light>& ref, std::size_t k, pcg32& rng) {
  const light_ref l = list[k];
  const light& v = ref[k];
  ASSERT_EQ(l.index(), v.index()) << "light " << k;
  EXPECT_EQ(strategy_of(l), strategy_of(v));
  EXPECT_EQ(std::bit_cast<std::uint32_t>(surface_area(l)), std::bit_cast<std::uint32_t>(surface_area(v)));
  const light_bounds bl = bounds_of(l, 2.0f), bv = bounds_of(v, 2.0f);
  EXPECT_EQ(bl.box.lo, bv.box.lo);
  EXPECT_EQ(bl.box.hi, bv.box.hi);
  EXPECT_EQ(bl.normals.w, bv.normals.w);
  EXPECT_EQ(bl.centre, bv.centre);
  for (int i = 0; i < 8; ++i) {
    const vec3 o{3.0f * (rng.uniform() - 0.5f), 2.0f * rng.uniform() - 0.5f, 3.0f * (rng.uniform() - 0.5f)};
    const vec3 n = glm::normalize(vec3{rng.uniform() - 0.5f, rng.uniform() - 0.3f, rng.uniform() - 0.5f});
    const vec2 u = rng.uniform2();
    ASSERT_EQ(faces(l, o), faces(v, o));
    light_sample sl, sv;
    const bool okl = sample(l, o, n, u, sl), okv = sample(v, o, n, u, sv);
    ASSERT_EQ(okl, okv) << "light " << k;
    if (okl) {
      EXPECT_EQ(sl.dir, sv.dir);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(sl.pdf), std::bit_cast<std::uint32_t>(sv.pdf));
      EXPECT_EQ(std::bit_cast<std::uint32_t>(pdf(l, o, n, sl.dir)), std::bit_cast<std::uint32_t>(pdf(v, o, n, sv.dir)));
    }
    const double xl = exact_importance(l, 2.0f, o, n, false), xv = exact_importance(v, 2.0f, o, n, false);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(xl), std::bit_cast<std::uint64_t>(xv));
  }
}

constexpr std::size_t kinds = std::variant_size_v<light>;

}  // namespace

// Every alternative, pushed in random order: the list gives what the variant
// gives, and get_if / get find exactly the light's own strategy.
TEST(LightList, EveryStrategyAsTheVariant) {
  pcg32 rng(41, 7);
  const auto mesh = std::make_shared<triangle_mesh>();
  std::vector<shapes> sh;
  for (std::size_t i = 0; i < 40 * kinds; ++i) sh.push_back(random_shapes(rng, mesh));
  light_list list;
  std::vector<light> ref;
  for (std::size_t i = 0; i < sh.size(); ++i) {
    const std::size_t kind = static_cast<std::size_t>(rng.uniform() * float(kinds)) % kinds;
    ref.push_back(make_light(kind, sh[i]));
    list.push_back(ref.back());
  }
  ASSERT_EQ(list.size(), ref.size());
  for (std::size_t k = 0; k < list.size(); ++k) expect_same(list, ref, k, rng);
  std::size_t seen = 0;
  for (const light_ref l : list) EXPECT_EQ(l.position(), seen++);
  EXPECT_EQ(seen, list.size());
  for (std::size_t k = 0; k < list.size(); ++k) {
    EXPECT_EQ(list.get_if<triangle_area_sampler>(k) != nullptr, std::holds_alternative<triangle_area_sampler>(ref[k]));
    if (!std::holds_alternative<rect_auto_sampler>(ref[k])) {
      EXPECT_THROW((void)list.get<rect_auto_sampler>(k), std::bad_variant_access);
    }
  }
  EXPECT_THROW((void)list.at(list.size()), std::out_of_range);
}

// Lights changed at random (set to the same or another strategy, taken out
// and given back) and compacted at random: after each step the list is the
// variant vector given the same changes.
TEST(LightList, SetTakeAndCompactKeepEveryLight) {
  pcg32 rng(43, 9);
  const auto mesh = std::make_shared<triangle_mesh>();
  std::vector<shapes> sh;
  for (int i = 0; i < 60; ++i) sh.push_back(random_shapes(rng, mesh));
  light_list list;
  std::vector<light> ref;
  for (std::size_t i = 0; i < sh.size(); ++i) {
    ref.push_back(make_light(i % kinds, sh[i]));
    list.push_back(ref.back());
  }
  for (int step = 0; step < 3000; ++step) {
    const std::size_t k = static_cast<std::size_t>(rng.uniform() * float(ref.size())) % ref.size();
    const float what = rng.uniform();
    if (what < 0.6f) {
      const std::size_t kind = static_cast<std::size_t>(rng.uniform() * float(kinds)) % kinds;
      ref[k] = make_light(kind, sh[k]);
      list.set(k, ref[k]);
    } else if (what < 0.8f) {
      light taken = list.take(k);
      ASSERT_EQ(taken.index(), ref[k].index());
      list.set(k, std::move(taken));
    } else if (what < 0.85f) {
      list.compact();
    }
    if (step % 50 == 0)
      for (std::size_t j = 0; j < ref.size(); ++j) expect_same(list, ref, j, rng);
    else
      expect_same(list, ref, k, rng);
  }
  list.shrink_to_fit();
  for (std::size_t j = 0; j < ref.size(); ++j) expect_same(list, ref, j, rng);
}

// A light takes its own strategy's bytes and a 4-byte entry, not the
// variant's: 10^4 triangles sampled by area, after shrink_to_fit.
TEST(LightList, ALightTakesItsOwnStrategysBytes) {
  pcg32 rng(47, 3);
  const auto mesh = std::make_shared<triangle_mesh>();
  light_list list;
  for (int i = 0; i < 10000; ++i) list.push_back(triangle_area_sampler{random_shapes(rng, mesh).t});
  list.shrink_to_fit();
  EXPECT_EQ(list.bytes(), 10000 * (sizeof(triangle_area_sampler) + sizeof(std::uint32_t)));
  EXPECT_LT(list.bytes() * 5, 10000 * sizeof(light)) << "a fifth of the variant's at most";
  // Half of them sampled by solid angle: the area samplers' places are
  // holes until compact(), then the two arrays hold one light each.
  for (std::size_t k = 0; k < list.size(); k += 2)
    list.set(k, triangle_solid_angle_sampler{list.get<triangle_area_sampler>(k).shape});
  list.shrink_to_fit();
  EXPECT_EQ(list.bytes(), 5000 * sizeof(triangle_area_sampler) + 5000 * sizeof(triangle_solid_angle_sampler) +
                              10000 * sizeof(std::uint32_t));
  for (std::size_t k = 0; k < list.size(); ++k)
    EXPECT_EQ(strategy_of(list[k]), k % 2 == 0 ? light_sampling::solid_angle : light_sampling::area);
}
