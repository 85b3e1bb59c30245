#pragma once
// What an `auto` sampler's chosen strategy gives on its own: the sample
// and the pdf of its member sampler for choice c (area, solid angle,
// projected solid angle; nothing for any other), the reference the
// `auto` tests compare sample(), its pdf and pdf() with bit for bit.
#include "mcrt/mcrt.hpp"

namespace mcrt::test {

template <class Auto>
bool own_sample(const Auto& s, light_sampling c, const vec3& o, const vec3& n, vec2 u, light_sample& out) {
  if (c == light_sampling::area) return s.area.sample(o, u, out);
  if (c == light_sampling::solid_angle) return s.solid_angle.sample(o, u, out);
  if (c == light_sampling::projected_solid_angle) return s.projected.sample(o, n, u, out);
  return false;
}

template <class Auto>
float own_pdf(const Auto& s, light_sampling c, const vec3& o, const vec3& n, const vec3& dir) {
  if (c == light_sampling::area) return s.area.pdf(o, dir);
  if (c == light_sampling::solid_angle) return s.solid_angle.pdf(o, dir);
  if (c == light_sampling::projected_solid_angle) return s.projected.pdf(o, n, dir);
  return 0.0f;
}

}  // namespace mcrt::test
