#pragma once
// What the tests of `auto`'s pilots share (test_noise_pilot.cpp,
// test_choice_gain_pilot.cpp): a lit floor and direct-light settings.
#include "mcrt/mcrt.hpp"

namespace mcrt_test {

using namespace mcrt;

// A diffuse floor (albedo 0.5) under a rectangular light (radiance 4, 1.2 x
// 0.8 at height 0.8, facing down), sampled by area or by projected solid
// angle; a small sphere casts a shadow.
inline scene lit_floor(bool projected = false) {
  scene sc;
  sc.materials = {lambertian{color(0.5f)}, diffuse_light{color(4.0f)}};
  sc.add(xz_rect_shape{-50, 50, -50, 50, 0}, 0);
  sc.add(sphere{{0.3f, 0.15f, 0.1f}, 0.15f}, 0);
  const rect r = xz_rect(-0.6f, 0.6f, -0.4f, 0.4f, 0.8f, true);
  if (projected)
    sc.add_light(rect_projected_solid_angle_sampler{r}, 1);
  else
    sc.add_light(rect_area_sampler{r}, 1);
  return sc;
}

// Direct light (max depth 1), nee, 2 threads, w x h pixels.
inline render_settings settings(int w, int h) {
  render_settings rs;
  rs.width = w;
  rs.height = h;
  rs.max_depth = 1;
  rs.integrator = integrator_kind::nee;
  rs.threads = 2;
  return rs;
}

}  // namespace mcrt_test
