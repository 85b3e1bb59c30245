#pragma once
// A light of the render tests by the name of its strategy, as the command
// line names them: the shape's geometry and the strategy's sampler, added
// to the scene with material `material` (the light's).
#include <gtest/gtest.h>

#include <string>

#include "mcrt/mcrt.hpp"

namespace mcrt::test {

inline void add_rect_light(scene& sc, const rect& r, const std::string& strategy, std::uint32_t material = 1) {
  if (strategy == "area")
    sc.add_light(rect_area_sampler{r}, material);
  else if (strategy == "solid-angle")
    sc.add_light(rect_solid_angle_sampler{r}, material);
  else if (strategy == "projected-solid-angle")
    sc.add_light(rect_projected_solid_angle_sampler{r}, material);
  else if (strategy == "bilinear-solid-angle")
    sc.add_light(rect_bilinear_solid_angle_sampler{r}, material);
  else if (strategy == "auto")
    sc.add_light(rect_auto_sampler{r}, material);
  else
    FAIL() << "no rectangle strategy " << strategy;
}

// "polar" is the solid-angle strategy with the polar map.
inline void add_disk_light(scene& sc, const ellipse& e, const std::string& strategy, std::uint32_t material = 1) {
  if (strategy == "area")
    sc.add_light(ellipse_area_sampler{e}, material);
  else if (strategy == "solid-angle")
    sc.add_light(ellipse_solid_angle_sampler{e}, material);
  else if (strategy == "polar")
    sc.add_light(ellipse_polar_solid_angle_sampler{e}, material);
  else if (strategy == "projected-solid-angle")
    sc.add_light(ellipse_projected_solid_angle_sampler{e}, material);
  else if (strategy == "bilinear-solid-angle")
    sc.add_light(ellipse_bilinear_solid_angle_sampler{e}, material);
  else if (strategy == "auto")
    sc.add_light(ellipse_auto_sampler{e}, material);
  else
    FAIL() << "no ellipse strategy " << strategy;
}

inline void add_sphere_light(scene& sc, const sphere& sp, const std::string& strategy, std::uint32_t material = 1) {
  if (strategy == "area")
    sc.add_light(sphere_area_sampler{sp}, material);
  else if (strategy == "solid-angle")
    sc.add_light(sphere_cone_sampler{sp}, material);
  else if (strategy == "projected-solid-angle")
    sc.add_light(sphere_projected_solid_angle_sampler{sp}, material);
  else if (strategy == "auto")
    sc.add_light(sphere_auto_sampler{sp}, material);
  else
    FAIL() << "no sphere strategy " << strategy;
}

}  // namespace mcrt::test
