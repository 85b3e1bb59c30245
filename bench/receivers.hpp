#pragma once
// Receivers for the light-selection tools (light_select_variance.cpp,
// light_select_floor.cpp): diffuse points at which each selection is
// weighed, either
//   - floor: uniform on the floor y = 0 within |x|, |z| < 9, normal +y
//     (bench/many_lights.py's scenes), or
//   - camera: the first surfaces the scene file's camera sees through
//     uniform image points (pinhole rays), normal turned towards the
//     camera; emitters and misses are skipped. These are the points a
//     render's direct light is estimated at.
#include <cmath>
#include <string>
#include <vector>

#include "mcrt/mcrt.hpp"
#include "pbrt/builder.hpp"
#include "pbrt/camera.hpp"

namespace mcrt::bench {

struct receiver {
  vec3 o{0.0f};  // the point (a camera hit: its spawn origin on the normal's side)
  vec3 n{0.0f, 1.0f, 0.0f};
};

// `count` receivers of the kind named ("floor" or "camera") from rng.
inline std::vector<receiver> make_receivers(const pbrt::built_scene& b, const std::string& kind, int count,
                                            pcg32& rng, float floor_height = 0.0f) {
  std::vector<receiver> out;
  if (kind == "camera") {
    const camera cam = pbrt::perspective_camera(b.camera_from_world, b.perspective, b.film.width, b.film.height);
    const scene& sc = b.world;
    for (int tries = 0; static_cast<int>(out.size()) < count && tries < 100 * count; ++tries) {
      const float s = rng.uniform(), t = rng.uniform();
      const ray r = cam.generate(s, t);
      hit_record rec;
      if (!sc.hit(r, 0.0f, infinity, rec)) continue;
      const color le = emitted(sc.materials[rec.material], rec);
      if (le.r + le.g + le.b > 0.0f) continue;
      const vec3 n = glm::dot(r.d, rec.n) < 0.0f ? rec.n : -rec.n;
      out.push_back({rec.spawn_origin(n), n});
    }
    return out;
  }
  for (int i = 0; i < count; ++i) {
    const float x = 18.0f * (rng.uniform() - 0.5f), z = 18.0f * (rng.uniform() - 0.5f);
    out.push_back({vec3{x, floor_height, z}, vec3{0.0f, 1.0f, 0.0f}});
  }
  return out;
}

}  // namespace mcrt::bench
