#pragma once
// `pbrt`: the light sampling pbrt-v4 ships, thresholds included, so that
// the anchor of every comparison is one flag away on any scene (Pharr,
// Jakob & Humphreys, pbrt-v4, src/pbrt/shapes.h and shapes.cpp):
//  * triangles (Triangle::Sample, Triangle::PDF): uniform by area where the
//    triangle's solid angle is below 3e-4 sr or above 6.22 sr (pbrt-v4's
//    MinSphericalSampleArea and MaxSphericalSampleArea, where its spherical
//    triangle loses precision), otherwise the spherical triangle with the
//    bilinear cosine pre-warp (triangle_bilinear_solid_angle_sampler);
//  * rectangles (BilinearPatch::Sample, BilinearPatch::PDF of a rectangular
//    patch): uniform by area where the spherical rectangle's solid angle is
//    at most 1e-4 sr, otherwise the spherical rectangle with the pre-warp
//    (rect_bilinear_solid_angle_sampler);
//  * spheres (Sphere::Sample): the cone of directions (sphere_cone_sampler);
//  * disks (Disk::Sample): uniform by area (ellipse_area_sampler).
// The first two are the composite strategies below; the render layer maps
// the last two to the existing strategies.
//
// Each threshold depends on the observer only, so sample(), the pdf it
// returns and pdf() take the same branch and agree as the branch's own
// strategy does; the density is the area density converted to solid angle
// on one side of the threshold and the pre-warped map's on the other. The
// solid angle deciding it is mcrt's exact one (Van Oosterom & Strackee in
// double, triangle_solid_angle; pbrt-v4
// evaluates the same quantity in float): the branch taken can differ from
// pbrt-v4's only within its float rounding of the threshold.
#include <utility>

#include "mcrt/geometry/rect.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/sampling/bilinear_spherical_rectangle.hpp"
#include "mcrt/sampling/bilinear_spherical_triangle.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/rect_area.hpp"
#include "mcrt/sampling/spherical_triangle.hpp"
#include "mcrt/sampling/triangle_area.hpp"

namespace mcrt {

// What both composites share: area sampling where the shape's by_area(o)
// says so, the pre-warped map elsewhere, both one-sided.
template <class Derived, class Area, class Warped>
struct pbrt_choice {
  bool faces(const vec3& o) const { return warped_.faces(o); }

  bool sample(const vec3& o, const vec3& n, vec2 u, light_sample& s) const {
    if (!faces(o)) return false;
    return self().by_area(o) ? area_.sample(o, u, s) : warped_.sample(o, n, u, s);
  }

  // Density per unit SOLID ANGLE at o of the unit direction dir for the
  // receiver's normal n: the area density converted to solid angle, or the
  // pre-warped map's, by the threshold at o as sample() decides it.
  float pdf(const vec3& o, const vec3& n, const vec3& dir) const {
    if (!faces(o)) return 0.0f;
    return self().by_area(o) ? area_.pdf(o, dir) : warped_.pdf(o, n, dir);
  }

 protected:
  pbrt_choice(Area area, Warped warped) : area_(std::move(area)), warped_(std::move(warped)) {}
  const Derived& self() const { return static_cast<const Derived&>(*this); }

  Area area_;
  Warped warped_;
};

// pbrt-v4's triangle light sampling (the header's first item). One-sided
// (back: the back side of a two-sided light), like both of its strategies.
struct triangle_pbrt_sampler
    : pbrt_choice<triangle_pbrt_sampler, triangle_area_sampler, triangle_bilinear_solid_angle_sampler> {
  triangle shape;
  // pbrt-v4's Triangle::MinSphericalSampleArea and MaxSphericalSampleArea (sr).
  static constexpr double min_solid_angle = 3e-4, max_solid_angle = 6.22;

  explicit triangle_pbrt_sampler(const triangle& t, bool back = false)
      : pbrt_choice(triangle_area_sampler(t, back), triangle_bilinear_solid_angle_sampler(t, back)), shape(t) {}

  // Whether pbrt-v4 samples the triangle by area from o.
  bool by_area(const vec3& o) const {
    const double omega =
        triangle_solid_angle(dvec3(o), dvec3(shape.vertex(0)), dvec3(shape.vertex(1)), dvec3(shape.vertex(2)));
    return omega < min_solid_angle || omega > max_solid_angle;
  }
};

// pbrt-v4's rectangle light sampling (the header's second item). One-sided.
struct rect_pbrt_sampler : pbrt_choice<rect_pbrt_sampler, rect_area_sampler, rect_bilinear_solid_angle_sampler> {
  rect shape;
  // pbrt-v4's BilinearPatch::MinSphericalSampleArea (sr): area sampling at
  // or below it.
  static constexpr double min_solid_angle = 1e-4;

  explicit rect_pbrt_sampler(const rect& r)
      : pbrt_choice(rect_area_sampler(r), rect_bilinear_solid_angle_sampler(r)), shape(r) {}

  // Whether pbrt-v4 samples the rectangle by area from o: its solid angle
  // as the two triangles (corner, +e1, +e1+e2) and (corner, +e1+e2, +e2).
  bool by_area(const vec3& o) const {
    const dvec3 od(o), c(shape.corner), e1(shape.e1), e2(shape.e2);
    const double omega = triangle_solid_angle(od, c, c + e1, c + e1 + e2) +
                         triangle_solid_angle(od, c, c + e1 + e2, c + e2);
    return omega <= min_solid_angle;
  }
};

}  // namespace mcrt
