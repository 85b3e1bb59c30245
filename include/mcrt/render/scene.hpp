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
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/materials/material.hpp"
#include "mcrt/render/light.hpp"

namespace mcrt {

// A light that emits (its shape's material is a diffuse_light): a target of
// next-event estimation. `light` indexes the scene's lights; `power` is the
// flux it emits, pi * area * luminance of its radiance (one-sided lambertian
// emitter), by which a light may be chosen among several.
struct emitter {
  std::uint32_t light = 0;
  float power = 0.0f;
};

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
  // Every directly sampled shape with its strategy (Shirley's list of
  // "lights": the emitters and the non-emitting importance targets such as
  // book 3's glass sphere), as the mixture pdf samples them.
  std::vector<light> lights;
  // The lights that emit, for the next-event estimators (nee, mis).
  std::vector<emitter> emitters;
  color background{0.0f};
  // Rays start this far from the surface they leave (self-intersection guard,
  // Shirley's t_min); set from the scene's size by whoever builds it.
  float ray_epsilon = 1e-3f;
  // Shapes added by add() (not add_light) whose material emits, or was not
  // yet known when they were added: light that only the material's samples
  // of a next-event estimator can find (see nee_integrator.hpp).
  std::size_t unsampled_emitters = 0;

  template <int Axis>
  void add(const axis_rect<Axis>& s, std::uint32_t material_index) {
    note_material(material_index);
    axis_rects.add(s, material_index);
  }

  // A rectangle whose two edges lie exactly along coordinate axes joins the
  // fast axis-aligned set (as_axis_rect); any other, including one turned in
  // a coordinate plane, is kept as a general rectangle.
  void add(const rect& r, std::uint32_t material_index) {
    note_material(material_index);
    add_geometry(r, material_index);
  }

  template <class Shape>
  std::uint32_t add(const Shape& s, std::uint32_t material_index) {
    note_material(material_index);
    return add_geometry(s, material_index);
  }

  // Adds a directly sampled shape: its geometry with `material_index`, and
  // `strategy` (which holds the shape) to the lights; when the material is a
  // diffuse_light the light is also an emitter. Returns the light's index.
  template <class Strategy>
  std::uint32_t add_light(const Strategy& strategy, std::uint32_t material_index) {
    add_geometry(strategy.shape, material_index);
    const auto k = static_cast<std::uint32_t>(lights.size());
    lights.emplace_back(strategy);
    if (const auto* e = std::get_if<diffuse_light>(&materials.at(material_index)))
      emitters.push_back({k, pi * surface_area(strategy.shape) * luminance(e->emit)});
    return k;
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
  void note_material(std::uint32_t m) {
    if (m >= materials.size() || std::holds_alternative<diffuse_light>(materials[m])) ++unsampled_emitters;
  }

  void add_geometry(const rect& r, std::uint32_t material_index) {
    if (auto a = as_axis_rect(r, material_index))
      axis_rects.add(*a);
    else
      std::get<std::vector<object<rect>>>(objects).push_back({r, material_index});
  }
  template <class Shape>
  std::uint32_t add_geometry(const Shape& s, std::uint32_t material_index) {
    auto& v = std::get<std::vector<object<Shape>>>(objects);
    v.push_back({s, material_index});
    return static_cast<std::uint32_t>(v.size() - 1);
  }

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

// Triangles (of meshes) are tested one by one, after the analytic shapes: a
// scene without them pays one empty-list check per ray.
using scene = basic_scene<rect, ellipse, sphere, box, triangle>;

}  // namespace mcrt
