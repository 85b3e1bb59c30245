#pragma once
// A scene: shapes stored by type (one std::vector per shape type, so a ray
// pays only for the types a scene has, with no per-object dispatch), the
// materials they reference, and the lights sampled at each diffuse bounce.
#include <cstdint>
#include <tuple>
#include <vector>

#include "mcrt/geometry/axis_rect.hpp"
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
  std::tuple<std::vector<object<Shapes>>...> objects;
  std::vector<material> materials;
  std::vector<light> lights;
  color background{0.0f};
  // Rays start this far from the surface they leave (self-intersection guard,
  // Shirley's t_min); set from the scene's size by whoever builds it.
  float ray_epsilon = 1e-3f;

  template <class Shape>
  std::uint32_t add(const Shape& s, std::uint32_t material_index) {
    auto& v = std::get<std::vector<object<Shape>>>(objects);
    v.push_back({s, material_index});
    return static_cast<std::uint32_t>(v.size() - 1);
  }

  std::size_t object_count() const {
    return std::apply([](const auto&... v) { return (v.size() + ... + std::size_t{0}); }, objects);
  }

  // Closest hit in (tmin, tmax).
  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const {
    bool any = false;
    std::apply([&](const auto&... v) { (hit_all(v, r, tmin, tmax, rec, any), ...); }, objects);
    return any;
  }

 private:
  template <class Shape>
  static void hit_all(const std::vector<object<Shape>>& v, const ray& r, float tmin, float& tmax,
                      hit_record& rec, bool& any) {
    for (const object<Shape>& o : v) {
      if (o.shape.hit(r, tmin, tmax, rec)) {
        tmax = rec.t;
        rec.material = o.material;
        any = true;
      }
    }
  }
};

using scene = basic_scene<yz_rect_shape, xz_rect_shape, xy_rect_shape, rect, ellipse, sphere, box>;

}  // namespace mcrt
