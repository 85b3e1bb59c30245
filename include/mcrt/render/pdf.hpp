#pragma once
// Shirley's pdf classes ("The Rest of Your Life", sec. 9-11): a pdf over
// directions that can both generate a direction and give its density per
// unit SOLID ANGLE. Value types built on the stack at each bounce (no heap),
// composed statically.
#include <cstddef>
#include <span>

#include "mcrt/core/onb.hpp"
#include "mcrt/sampling/light_sample.hpp"
#include "mcrt/sampling/warp.hpp"

namespace mcrt {

// Cosine-weighted directions about a unit normal: density cos(theta)/pi per
// unit solid angle on the normal's hemisphere.
class cosine_pdf {
 public:
  explicit cosine_pdf(const vec3& n) : uvw_(n) {}
  float value(const vec3& dir) const { return std::max(glm::dot(dir, uvw_.w), 0.0f) * inv_pi; }
  vec3 generate(vec2 u) const { return glm::normalize(uvw_.to_world(square_to_cosine_hemisphere(u))); }

 private:
  onb uvw_;
};

// Shirley's hittable_pdf over a list of lights: a light is picked uniformly
// among those that can offer o a sample (Light::faces), then sampled. The
// density is the average of their densities; lights that face away from o
// take no part, so the mixture stays normalised.
//
// Lights is a container (size(), operator[]) of lights: of types with
// faces/sample/pdf (see sampling/light_sample.hpp), of std::variants of
// them through the dispatch in light.hpp, or a scene's light_list. It is
// held by reference and must outlive the light_pdf.
template <class Lights>
class light_pdf {
 public:
  // o: the point; n: the unit normal of its surface, for the strategies
  // that weigh by the cosine there.
  light_pdf(const Lights& lights, const vec3& o, const vec3& n) : lights_(lights), o_(o), n_(n) {
    for (std::size_t i = 0; i < lights_.size(); ++i) count_ += faces(lights_[i], o_) ? 1 : 0;
  }

  bool empty() const { return count_ == 0; }

  // u_pick in [0,1) chooses the light, u samples it. Returns the index of the
  // light chosen (or -1 when it gave no sample).
  std::ptrdiff_t generate(float u_pick, vec2 u, light_sample& s) const {
    std::size_t k = std::min(static_cast<std::size_t>(u_pick * static_cast<float>(count_)), count_ - 1);
    for (std::size_t i = 0; i < lights_.size(); ++i) {
      if (!faces(lights_[i], o_)) continue;
      if (k-- == 0) return sample(lights_[i], o_, n_, u, s) ? static_cast<std::ptrdiff_t>(i) : -1;
    }
    return -1;
  }

  // Density per unit solid angle of dir (unit).
  float value(const vec3& dir) const { return value(dir, -1, 0.0f); }

  // Same, when light `known` is already known to have density known_pdf at
  // dir (the light the direction was sampled from): saves its evaluation.
  float value(const vec3& dir, std::ptrdiff_t known, float known_pdf) const {
    if (count_ == 0) return 0.0f;
    float sum = 0.0f;
    for (std::size_t i = 0; i < lights_.size(); ++i)
      sum += static_cast<std::ptrdiff_t>(i) == known ? known_pdf : pdf(lights_[i], o_, n_, dir);
    return sum / static_cast<float>(count_);
  }

 private:
  const Lights& lights_;
  vec3 o_, n_;
  std::size_t count_ = 0;
};

// Shirley's mixture_pdf with equal weights, as in the book and the thesis:
// half the directions from the lights, half from the cosine pdf. Where no
// light faces the point, the cosine pdf alone.
template <class Lights>
class mixture_pdf {
 public:
  mixture_pdf(const cosine_pdf& cos, const light_pdf<Lights>& lights) : cos_(cos), lights_(lights) {}

  // Density per unit SOLID ANGLE of the unit direction dir.
  float value(const vec3& dir) const {
    return lights_.empty() ? cos_.value(dir) : 0.5f * (cos_.value(dir) + lights_.value(dir));
  }

  // u_select in [0,1) chooses the component (and, rescaled, the light); u
  // samples it. Returns false when the chosen light had no direction to
  // offer (a zero-valued sample). pdf is value(dir), computed without
  // evaluating the chosen light twice.
  bool generate(float u_select, vec2 u, vec3& dir, float& pdf) const {
    if (lights_.empty()) {
      dir = cos_.generate(u);
      pdf = cos_.value(dir);
      return true;
    }
    if (u_select < 0.5f) {
      dir = cos_.generate(u);
      pdf = 0.5f * (cos_.value(dir) + lights_.value(dir));
      return true;
    }
    light_sample s;
    const std::ptrdiff_t k = lights_.generate(2.0f * u_select - 1.0f, u, s);
    if (k < 0) return false;
    dir = s.dir;
    pdf = 0.5f * (cos_.value(dir) + lights_.value(dir, k, s.pdf));
    return true;
  }

 private:
  const cosine_pdf& cos_;
  const light_pdf<Lights>& lights_;
};

}  // namespace mcrt
