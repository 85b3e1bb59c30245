#pragma once
// A scene: shapes stored by type (one std::vector per shape type, so a ray
// pays only for the types a scene has, with no per-object dispatch), the
// materials they reference, and the lights sampled at each diffuse bounce.
// A scene of more than one shape in those lists is intersected through a
// bounding volume hierarchy over all of them (accel/bvh.hpp), once
// build_accelerator() has built it; Shirley's axis-aligned rectangles stay a
// set of their own, tested before it.
#include <array>
#include <cstdint>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "mcrt/accel/bvh.hpp"

#include "mcrt/geometry/axis_rect_set.hpp"
#include "mcrt/geometry/box.hpp"
#include "mcrt/geometry/ellipse.hpp"
#include "mcrt/geometry/rect.hpp"
#include "mcrt/geometry/sphere.hpp"
#include "mcrt/geometry/triangle_leaf.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "mcrt/materials/material.hpp"
#include "mcrt/render/light.hpp"
#include "mcrt/render/light_importance.hpp"
#include "mcrt/render/light_list.hpp"

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
  light_list lights;
  // The lights that emit, for the next-event estimators (nee, mis).
  std::vector<emitter> emitters;
  // The hierarchy over the emitters (item i: emitters[i]) by which
  // light_selection chooses among many (build_light_tree).
  light_bvh light_tree;
  color background{0.0f};
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
    light_tree = light_bvh();  // a tree over the lights before this one no longer holds them all
    const auto k = static_cast<std::uint32_t>(lights.size());
    lights.emplace_back(strategy);
    if (const auto* e = std::get_if<diffuse_light>(&materials.at(material_index)))
      emitters.push_back({k, pi * surface_area(strategy.shape) * luminance(e->emit)});
    return k;
  }

  // A scene with at most this many shapes in its lists keeps testing the
  // lists. On random small shapes (bench/bench_samplers_scene_accel.cpp:
  // closest hits, 1 to 64 spheres and triangles) the hierarchy is slower
  // than the list for one shape and faster from two on (the numbers:
  // bench/results/pbrt/README.md).
  static constexpr std::size_t list_limit = 1;

  // Builds the hierarchy over every shape of the lists (not the
  // axis-aligned set, which is intersected as a set) when they hold more
  // than `limit`; from then on hit() traverses it. Shapes added later send
  // hit() back to the lists until it is called again.
  void build_accelerator(std::size_t limit = list_limit) {
    accel_active_ = false;
    prims_.clear();
    tri_verts_.clear();
    if (list_object_count() <= limit) return;
    std::vector<aabb> bounds;
    std::vector<prim_ref> refs;
    bounds.reserve(list_object_count());
    refs.reserve(list_object_count());
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (
          [&] {
            const auto& v = std::get<I>(objects);
            for (std::size_t j = 0; j < v.size(); ++j) {
              bounds.push_back(v[j].shape.bounds());
              refs.push_back({static_cast<std::uint32_t>(I), static_cast<std::uint32_t>(j)});
            }
          }(),
          ...);
    }(std::index_sequence_for<Shapes...>{});
    // Triangles are tested a leaf at a time, four at once
    // (geometry/triangle_leaf.hpp): their leaves are priced so.
    std::size_t triangles = 0;
    if constexpr (has_triangles) triangles = std::get<triangle_type>(objects).size();
    accel_ = bvh(bounds, triangles > 0 ? triangle_leaf_width : 1);
    // The shapes in the leaves' order; a triangle's vertices (and its index
    // among the triangles) at its place: a leaf's tests read adjacent
    // memory, and a triangle's test reads nothing else.
    prims_.resize(refs.size());
    if (triangles > 0) tri_verts_.resize(refs.size());
    for (std::size_t k = 0; k < refs.size(); ++k) {
      prims_[k] = refs[accel_.order()[k]];
      if constexpr (has_triangles)
        if (triangles > 0) {
          if (prims_[k].type == triangle_type) {
            const triangle& t = std::get<triangle_type>(objects)[prims_[k].object].shape;
            const vec3 p0 = t.vertex(0), p1 = t.vertex(1), p2 = t.vertex(2);
            if (prims_[k].object >= reversed_bit) throw std::length_error("scene: more than 2^31 - 1 triangles");
            // Whether the front (the orientation rule's normal) is the side
            // of (p2 - p0) x (p1 - p0), against (p1 - p0) x (p2 - p0).
            const bool reversed = glm::dot(t.normal_of(p0, p1, p2), glm::cross(p1 - p0, p2 - p0)) < 0.0f;
            tri_verts_[k] = {{p0, p1, p2}, prims_[k].object | (reversed ? reversed_bit : 0u)};
          } else {
            tri_verts_[k] = {{vec3(0.0f), vec3(0.0f), vec3(0.0f)}, not_a_triangle};
          }
        }
    }
    accel_.renumber_in_order();
    accel_active_ = true;
  }

  // Builds the light hierarchy over the emitters (render/light_selection.hpp
  // uses it for bvh, and for power and uniform past a few emitters). Lights
  // added later are not in it until it is called again. The loaders call it
  // once every light is added, so the lights' arrays are trimmed here to
  // the lights they hold (a vector's growth leaves up to half again).
  void build_light_tree() {
    lights.shrink_to_fit();
    std::vector<light_bounds> items;
    items.reserve(emitters.size());
    for (const emitter& e : emitters) items.push_back(bounds_of(lights[e.light], e.power));
    light_tree = light_bvh(items);
  }

  // Whether hit() traverses the hierarchy.
  bool accelerated() const { return accel_active_; }
  const bvh& accelerator() const { return accel_; }

  std::size_t object_count() const {
    return axis_rects.size() +
           std::apply([](const auto&... v) { return (v.size() + ... + std::size_t{0}); }, objects);
  }

  // Closest hit in (tmin, tmax). Every shape type offers intersect() (the
  // ray parameter only) and surface() (the full record); only the closest
  // hit pays for its record.
  bool hit(const ray& r, float tmin, float tmax, hit_record& rec) const { return find<true>(r, tmin, tmax, rec); }

  // The closest hit's material and side only, what a shadow ray's radiance
  // needs (render/path.hpp): rec.t, rec.material and rec.front_face are
  // set, as hit() sets them (up to rounding at grazing hits on spheres),
  // and the rest of the record (point, rounding bound, normals, uv) is
  // not computed.
  bool hit_side(const ray& r, float tmin, float tmax, hit_record& rec) const {
    return find<false>(r, tmin, tmax, rec);
  }

 private:
  // hit() (Full) and hit_side().
  template <bool Full>
  bool find(const ray& r, float tmin, float tmax, hit_record& rec) const {
    closest c{tmax};
    if (!axis_rects.empty()) {
      const any_axis_rect* m;
      if (axis_rects.intersect(r, tmin, c.t, c.t, m)) {
        c.shape = m;
        c.fill = &fill_record<any_axis_rect>;
        c.side = &side_record<any_axis_rect>;
        c.material = m->material;
      }
    }
    if (accel_active_) return hit_accelerated<Full>(r, tmin, c, rec);
    std::apply([&](const auto&... v) { (closest_of(v, r, tmin, c), ...); }, objects);
    if (!c.shape) return false;
    (Full ? c.fill : c.side)(c.shape, r, c.t, rec);
    rec.material = c.material;
    return true;
  }

  void note_material(std::uint32_t m) {
    if (m >= materials.size() || std::holds_alternative<diffuse_light>(materials[m])) ++unsampled_emitters;
  }

  struct closest {
    float t;
    const void* shape = nullptr;
    void (*fill)(const void*, const ray&, float, hit_record&) = nullptr;
    void (*side)(const void*, const ray&, float, hit_record&) = nullptr;  // t and front_face only
    std::uint32_t material = 0;
  };

  template <class T, std::size_t I = 0>
  static constexpr std::size_t type_index() {
    if constexpr (I == sizeof...(Shapes))
      return I;
    else if constexpr (std::is_same_v<T, std::tuple_element_t<I, std::tuple<Shapes...>>>)
      return I;
    else
      return type_index<T, I + 1>();
  }
  static constexpr std::size_t triangle_type = type_index<triangle>();
  static constexpr bool has_triangles = triangle_type < sizeof...(Shapes);

  // A shape of the hierarchy: its type's place in Shapes and its index in
  // that type's list.
  struct prim_ref {
    std::uint32_t type = 0, object = 0;
  };
  bvh accel_;
  std::vector<prim_ref> prims_;  // in the hierarchy's order
  // A triangle's vertices and index at its place in that order (tag
  // not_a_triangle at another shape's), the index's top bit set where the
  // triangle's front is the side of (p2 - p0) x (p1 - p0) (reversed_bit);
  // empty in a scene without triangles.
  std::vector<triangle_vertices, large_array_allocator<triangle_vertices>> tri_verts_;
  static constexpr std::uint32_t not_a_triangle = ~std::uint32_t(0);
  static constexpr std::uint32_t reversed_bit = std::uint32_t(1) << 31;
  bool accel_active_ = false;

  std::size_t list_object_count() const {
    return std::apply([](const auto&... v) { return (v.size() + ... + std::size_t{0}); }, objects);
  }

  // The shape ref's hit's t in (tmin, tmax), or infinity.
  template <std::size_t I>
  float intersect_ref(std::uint32_t object, const ray& r, float tmin, float tmax) const {
    float t;
    return std::get<I>(objects)[object].shape.intersect(r, tmin, tmax, t) ? t : infinity;
  }
  template <std::size_t... I>
  float intersect_ref(const prim_ref& p, const ray& r, float tmin, float tmax, std::index_sequence<I...>) const {
    float t = infinity;
    ((p.type == I ? (void)(t = intersect_ref<I>(p.object, r, tmin, tmax)) : void()), ...);
    return t;
  }
  template <bool Full, std::size_t... I>
  void fill_ref(const prim_ref& p, const ray& r, float t, hit_record& rec, std::index_sequence<I...>) const {
    ((p.type == I ? (void)(fill_one<Full, I>(p.object, r, t, rec)) : void()), ...);
  }
  template <bool Full, std::size_t I>
  void fill_one(std::uint32_t object, const ray& r, float t, hit_record& rec) const {
    const auto& o = std::get<I>(objects)[object];
    if constexpr (Full)
      o.shape.surface(r, t, rec);
    else
      side_of(o.shape, r, t, rec);
    rec.material = o.material;
  }

  // Kept out of hit() (GCC's and Clang's noinline): the lists' path of the
  // scenes without a hierarchy stays as small as it was without one.
  template <bool Full>
#if defined(__GNUC__) || defined(__clang__)
  [[gnu::noinline]]
#endif
  bool hit_accelerated(const ray& r, float tmin, closest& c, hit_record& rec) const {
    triangle_hit tri{};  // the barycentrics of the closest triangle so far
    float tmax = c.t;
    std::int64_t best = -1;
    if (!tri_verts_.empty()) {
      const watertight_ray wr(r);
      best = accel_.closest_leaf(r, tmin, tmax, [&](std::uint32_t first, std::uint32_t count, float t0, float& t1) {
        const triangle_vertices* tv = &tri_verts_[first];
        bool triangles_only = true;
        for (std::uint32_t i = 0; i < count; ++i) triangles_only &= tv[i].tag != not_a_triangle;
        if (triangles_only) {
          const int j = closest_in_leaf(wr, t0, t1, tv, static_cast<int>(count), tri);
          return j < 0 ? std::int64_t(-1) : std::int64_t(first) + j;
        }
        // A leaf with other shapes: one by one.
        std::int64_t k = -1;
        for (std::uint32_t i = 0; i < count; ++i) {
          if (tv[i].tag != not_a_triangle) {
            const std::optional<triangle_hit> h = intersect_triangle(wr, t1, tv[i].p[0], tv[i].p[1], tv[i].p[2]);
            if (!h || !(h->t > t0) || !(h->t < t1)) continue;
            tri = *h;
            t1 = h->t;
          } else {
            const float t = intersect_ref(prims_[first + i], r, t0, t1, std::index_sequence_for<Shapes...>{});
            if (!(t < t1)) continue;
            t1 = t;
          }
          k = std::int64_t(first) + i;
        }
        return k;
      });
    } else {
      best = accel_.closest(r, tmin, tmax, [&](std::uint32_t slot, float t0, float t1) -> float {
        return intersect_ref(prims_[slot], r, t0, t1, std::index_sequence_for<Shapes...>{});
      });
    }
    if (best < 0) {
      // The axis-aligned set's hit, if any.
      if (!c.shape) return false;
      (Full ? c.fill : c.side)(c.shape, r, c.t, rec);
      rec.material = c.material;
      return true;
    }
    const auto slot = static_cast<std::size_t>(best);
    if constexpr (has_triangles)
      if (!tri_verts_.empty() && tri_verts_[slot].tag != not_a_triangle) {
        const triangle_vertices& tv = tri_verts_[slot];
        const auto& o = std::get<triangle_type>(objects)[tv.tag & ~reversed_bit];
        if constexpr (Full) {
          o.shape.surface_at(r, tri, rec, tv.p[0], tv.p[1], tv.p[2]);
        } else {
          // The side from the vertices and the orientation bit, without
          // the mesh's normals (the same side as surface_at's normal, up to
          // rounding at grazing hits).
          const float along = glm::dot(r.d, glm::cross(tv.p[1] - tv.p[0], tv.p[2] - tv.p[0]));
          rec.t = tri.t;
          rec.front_face = (tv.tag & reversed_bit) ? along > 0.0f : along < 0.0f;
        }
        rec.material = o.material;
        return true;
      }
    fill_ref<Full>(prims_[slot], r, tmax, rec, std::index_sequence_for<Shapes...>{});
    return true;
  }

  void add_geometry(const rect& r, std::uint32_t material_index) {
    if (auto a = as_axis_rect(r, material_index))
      axis_rects.add(*a);
    else
      std::get<std::vector<object<rect>>>(objects).push_back({r, material_index});
    accel_active_ = false;
  }
  template <class Shape>
  std::uint32_t add_geometry(const Shape& s, std::uint32_t material_index) {
    auto& v = std::get<std::vector<object<Shape>>>(objects);
    v.push_back({s, material_index});
    accel_active_ = false;
    return static_cast<std::uint32_t>(v.size() - 1);
  }


  template <class Shape>
  static void fill_record(const void* s, const ray& r, float t, hit_record& rec) {
    static_cast<const Shape*>(s)->surface(r, t, rec);
  }
  // t and front_face of a hit at t: the shape's front_face(r, t) where it
  // has one (the side without the rest of the record), else its record.
  template <class Shape>
  static void side_of(const Shape& shape, const ray& r, float t, hit_record& rec) {
    if constexpr (requires { shape.front_face(r, t); }) {
      rec.t = t;
      rec.front_face = shape.front_face(r, t);
    } else {
      shape.surface(r, t, rec);
    }
  }
  template <class Shape>
  static void side_record(const void* s, const ray& r, float t, hit_record& rec) {
    side_of(*static_cast<const Shape*>(s), r, t, rec);
  }

  template <class Shape>
  static void closest_of(const std::vector<object<Shape>>& v, const ray& r, float tmin, closest& c) {
    for (const object<Shape>& o : v) {
      float t;
      if (o.shape.intersect(r, tmin, c.t, t)) {
        c.t = t;
        c.shape = &o.shape;
        c.fill = &fill_record<Shape>;
        c.side = &side_record<Shape>;
        c.material = o.material;
      }
    }
  }
};

// Triangles (of meshes) are tested one by one, after the analytic shapes: a
// scene without them pays one empty-list check per ray.
using scene = basic_scene<rect, ellipse, sphere, box, triangle>;

}  // namespace mcrt
