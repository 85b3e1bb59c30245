#pragma once
// Which light a next-event estimator samples at a shading point, and the
// density of that whole technique (choose a light, then sample it) per unit
// solid angle: the quantity both the shadow-ray estimate and the multiple
// importance sampling weights need (Veach 1997, sec. 9.2; pbrt-v4's
// LightSampler, "Physically Based Rendering", 4th ed., sec. 12.6).
//
// Only the scene's emitters take part (book 3's glass sphere, sampled by the
// mixture pdf but emitting nothing, gets no shadow rays), and among them only
// those that can offer the point a sample (`faces`: a one-sided light seen
// from behind is left out, so no sample is wasted on it). Among those a
// light is chosen
//   - by power (the default): P(k) = Phi_k / sum of Phi_j, Phi the emitted
//     flux, so a bright or large light gets more samples than a dim one; or
//   - uniformly: P(k) = 1 / count.
// The technique's density at a direction is p_L(dir) = sum_k P(k) p_k(o, dir),
// the sum over every facing emitter: the shadow ray returns the radiance of
// whatever it meets first, so one light's sample may land on another light
// in front of it, and the estimate stays unbiased only with the density of
// the whole mixture (with one light the sum has one term).
#include <cstddef>
#include <cstdint>
#include <span>

#include "mcrt/render/light.hpp"
#include "mcrt/render/scene.hpp"

namespace mcrt {

enum class light_choice { power, uniform };

class light_selection {
 public:
  // o: the shading point; n: the unit normal of its surface (for the
  // cosine-aware strategies' densities).
  light_selection(std::span<const light> lights, std::span<const emitter> emitters, const vec3& o, const vec3& n,
                  light_choice how)
      : lights_(lights), emitters_(emitters), o_(o), n_(n), uniform_(how == light_choice::uniform) {
    for (const emitter& e : emitters_)
      if (faces(lights_[e.light], o_)) {
        ++count_;
        total_ += e.power;
      }
    // By power, lights of zero power are never chosen; when they are all the
    // facing lights, there is nothing to choose.
    if (!uniform_ && !(total_ > 0.0f)) count_ = 0;
  }

  template <class Scene>
  light_selection(const Scene& sc, const vec3& o, const vec3& n, light_choice how)
      : light_selection(sc.lights, sc.emitters, o, n, how) {}

  bool empty() const { return count_ == 0; }
  // Whether the choice needs a random number (more than one candidate).
  bool needs_choice() const { return emitters_.size() > 1; }

  const vec3& point() const { return o_; }
  const vec3& normal() const { return n_; }

  // Picks a facing emitter with u in [0, 1): its index in the scene's
  // lights, or -1 when there is none; prob is P(k).
  std::ptrdiff_t pick(float u, float& prob) const {
    if (count_ == 0) return -1;
    if (uniform_) {
      std::size_t k = std::min(static_cast<std::size_t>(u * static_cast<float>(count_)), count_ - 1);
      for (const emitter& e : emitters_) {
        if (!faces(lights_[e.light], o_)) continue;
        if (k-- == 0) {
          prob = 1.0f / static_cast<float>(count_);
          return e.light;
        }
      }
      return -1;
    }
    // By power: walk the cumulative sum; the last facing light with power
    // takes whatever rounding leaves over.
    const float target = u * total_;
    float acc = 0.0f;
    std::ptrdiff_t last = -1;
    float last_power = 0.0f;
    for (const emitter& e : emitters_) {
      if (!(e.power > 0.0f) || !faces(lights_[e.light], o_)) continue;
      acc += e.power;
      last = e.light;
      last_power = e.power;
      if (target < acc) break;
    }
    prob = last_power / total_;
    return last;
  }

  // P(k) of the light with index k among the scene's lights (0 when it is
  // not a facing emitter).
  float probability(std::size_t k) const {
    for (const emitter& e : emitters_)
      if (e.light == k) return probability_of(e);
    return 0.0f;
  }

  // Density per unit SOLID ANGLE at o of the whole technique, p_L(dir) =
  // sum_k P(k) p_k(o, dir). When the light `known` is known to have density
  // known_pdf at dir (the light dir was sampled from), that term is not
  // evaluated again.
  float pdf(const vec3& dir, std::ptrdiff_t known = -1, float known_pdf = 0.0f) const {
    if (count_ == 0) return 0.0f;
    float sum = 0.0f;
    for (const emitter& e : emitters_) {
      const float p = probability_of(e);
      if (!(p > 0.0f)) continue;
      sum += p * (static_cast<std::ptrdiff_t>(e.light) == known ? known_pdf : mcrt::pdf(lights_[e.light], o_, n_, dir));
    }
    return sum;
  }

 private:
  float probability_of(const emitter& e) const {
    if (count_ == 0 || !faces(lights_[e.light], o_)) return 0.0f;
    return uniform_ ? 1.0f / static_cast<float>(count_) : e.power / total_;
  }

  std::span<const light> lights_;
  std::span<const emitter> emitters_;
  vec3 o_, n_;
  bool uniform_;
  std::size_t count_ = 0;
  float total_ = 0.0f;
};

}  // namespace mcrt
