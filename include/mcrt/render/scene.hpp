#pragma once
// A scene: shapes stored by type (one std::vector per shape type, so a ray
// pays only for the types a scene has, with no per-object dispatch), the
// materials they reference, and the lights sampled at each diffuse bounce.
#include <cstdint>
#include <tuple>
#include <vector>

#include "mcrt/geometry/axis_rect_set.hpp"
#include "mcrt/geometry/box.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/materials/material.hpp"
#include "mcrt/render/light.hpp"

namespace mcrt {

// A shape and the index of its material in the scene.
template <class Shape>
struct object {
  Shape shape;
  std::uint32_t material = 0;
};

template <class... Shapes>
struct basic_scene {
  axis_rect_set axis_rects;  // Shirley's xz/xy/yz rectangles, intersected as a set
  std::tuple<std::vector<object<Shapes>>...> objects;
  std::vector<material> materials;
  std::vector<light> lights;
  color background{0.0f};
  // Rays start this far from the surface they leave (self-intersection guard,
  // Shirley's t_min); set from the scene's size by whoever builds it.
  float ray_epsilon = 1e-3f;

  template <int Axis>
  void add(const axis_rect<Axis>& s, std::uint32_t material_index) {
    axis_rects.add(s, material_index);
  }

  // A rectangle whose edges lie along coordinate axes joins the fast
  // axis-aligned set; any other is kept as a general rectangle.
  void add(const rect& r, std::uint32_t material_index) {
    if (auto a = as_axis_rect(r, material_index))
      axis_rects.add(*a);
    else
      std::get<std::vector<object<rect>>>(objects).push_back({r, material_index});
  }

  template <class Shape>
  std::uint32_t add(const Shape& s, std::uint32_t material_index) {
    auto& v = std::get<std::vector<object<Shape>>>(objects);
    v.push_back({s, material_index});
    return static_cast<std::uint32_t>(v.size() - 1);
  }

  std::size_t object_count() const {
    return axis_rects.size() +
           std::apply([](const auto&... v) { return (v.size() + ... + std::size_t{0}); }, objects);
  }

  // Closest hit in (tmin, tmax). Every shape type offers intersect() (the
  // ray parameter only) and surface() (the full record); only the closest
  // hit pays for its record.
  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    closest c{tmax};
    if (!axis_rects.empty()) {
      const any_axis_rect* m;
      if (axis_rects.intersect(r, tmin, c.t, c.t, m)) {
        c.shape = m;
        c.fill = &fill_record<any_axis_rect>;
        c.material = m->material;
      }
    }
    std::apply([&](const auto&... v) { (closest_of(v, r, tmin, c), ...); }, objects);
    if (!c.shape) return false;
    c.fill(c.shape, r, c.t, rec);
    rec.material = c.material;
    return true;
  }

 private:
  struct closest {
    float t;
    const void* shape = nullptr;
    void (*fill)(const void*, const ray&, float, hit_record&) = nullptr;
    std::uint32_t material = 0;
  };

  template <class Shape>
  static void fill_record(const void* s, const ray& r, float t, hit_record& rec) {
    static_cast<const Shape*>(s)->surface(r, t, rec);
  }

  template <class Shape>
  static void closest_of(const std::vector<object<Shape>>& v, const ray& r, float tmin, closest& c) {
    for (const object<Shape>& o : v) {
      float t;
      if (o.shape.intersect(r, tmin, c.t, t)) {
        c.t = t;
        c.shape = &o.shape;
        c.fill = &fill_record<Shape>;
        c.material = o.material;
      }
    }
  }
};

using scene = basic_scene<rect, ellipse, sphere, box>;

}  // namespace mcrt
