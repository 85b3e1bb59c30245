#pragma once
// Textures: a material parameter that varies over a surface, looked up at a
// hit's (u, v) as pbrt-v4's textures do (src/pbrt/textures.h): `constant`,
// `imagemap` (bilinear lookup at the finest level, uv mapping with scale and
// delta, v flipped as pbrt-v4 flips image rows: t = 1 - v), `checkerboard`
// (2-D, on the mapped (s, t)) and `scale` (a product of two textures). A
// texture is spectrum-valued (colour); a float texture is one whose three
// channels are equal. The image's texels are decoded by whoever builds the
// scene (the executable, through OpenImageIO): the library holds floats.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "mcrt/core/math.hpp"

namespace mcrt {

// Linear RGB texels, row 0 at the top of the image.
struct texture_image {
  int width = 0, height = 0;
  std::vector<color> texels;

  const color& at(int x, int y) const { return texels[static_cast<std::size_t>(y) * std::size_t(width) + std::size_t(x)]; }
};

enum class texture_wrap { repeat, clamp, black };

// pbrt-v4's UVMapping: s = su u + du, t = sv v + dv.
struct uv_mapping {
  float su = 1.0f, sv = 1.0f, du = 0.0f, dv = 0.0f;
  vec2 map(vec2 uv) const { return {su * uv.x + du, sv * uv.y + dv}; }
};

struct texture {
  enum class kind { constant, image, checkerboard, scale };
  kind k = kind::constant;
  color value{1.0f};                          // constant: the value; image: the scale
  std::shared_ptr<const texture_image> img;   // image
  texture_wrap wrap = texture_wrap::repeat;   // image
  bool invert = false;                        // image: 1 - value (after the scale, as pbrt-v4)
  uv_mapping mapping;                         // image, checkerboard
  std::shared_ptr<const texture> a, b;        // checkerboard: tex1, tex2; scale: tex, scale

  static texture constant(const color& c) {
    texture t;
    t.value = c;
    return t;
  }

  bool is_constant() const { return k == kind::constant; }

  color eval(vec2 uv) const {
    switch (k) {
      case kind::constant:
        return value;
      case kind::image: {
        const vec2 st = finite_or_zero(mapping.map(uv));
        // pbrt-v4 flips t so that v = 0 is the image's bottom row.
        color c = bilinear(st.x, 1.0f - st.y) * value;
        if (invert) c = glm::max(color(1.0f) - c, color(0.0f));
        return c;
      }
      case kind::checkerboard: {
        const vec2 st = finite_or_zero(mapping.map(uv));
        // The parity of floor(s) + floor(t), in float (a conversion to an
        // integer would overflow beyond 2^63; floats beyond 2^24 are even).
        const float parity = std::fmod(std::abs(std::floor(st.x)), 2.0f) + std::fmod(std::abs(std::floor(st.y)), 2.0f);
        return parity != 1.0f ? a->eval(uv) : b->eval(uv);
      }
      case kind::scale:
        return a->eval(uv) * b->eval(uv);
    }
    return value;
  }

 private:
  // The texel (x, y) under the wrap mode; black outside for `black`.
  color texel(int x, int y) const {
    const int w = img->width, h = img->height;
    switch (wrap) {
      case texture_wrap::repeat:
        x = ((x % w) + w) % w;
        y = ((y % h) + h) % h;
        break;
      case texture_wrap::clamp:
        x = std::clamp(x, 0, w - 1);
        y = std::clamp(y, 0, h - 1);
        break;
      case texture_wrap::black:
        if (x < 0 || x >= w || y < 0 || y >= h) return color(0.0f);
        break;
    }
    return img->at(x, y);
  }
  // Texture coordinates that the mapping made infinite or NaN (a uv or a
  // uscale near 3.4e38) are taken as 0.
  static vec2 finite_or_zero(vec2 st) {
    return {std::isfinite(st.x) ? st.x : 0.0f, std::isfinite(st.y) ? st.y : 0.0f};
  }
  // A coordinate whose texel index would not fit an int, brought back into
  // range with the same texels: by whole periods for repeat (s - floor(s)),
  // to just outside the image for clamp and black.
  float in_int_range(float s) const {
    return wrap == texture_wrap::repeat ? s - std::floor(s) : std::clamp(s, -1.0f, 2.0f);
  }
  // Bilinear interpolation of texel centres (pbrt-v4's Image::Bilerp:
  // texel (i, j) sits at ((i + 0.5) / w, (j + 0.5) / h)).
  color bilinear(float s, float t) const {
    float x = s * float(img->width) - 0.5f, y = t * float(img->height) - 0.5f;
    if (!(std::abs(x) < 1e9f)) x = in_int_range(s) * float(img->width) - 0.5f;
    if (!(std::abs(y) < 1e9f)) y = in_int_range(t) * float(img->height) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const int xi = static_cast<int>(fx), yi = static_cast<int>(fy);
    const float dx = x - fx, dy = y - fy;
    return (1 - dx) * (1 - dy) * texel(xi, yi) + dx * (1 - dy) * texel(xi + 1, yi) + (1 - dx) * dy * texel(xi, yi + 1) +
           dx * dy * texel(xi + 1, yi + 1);
  }
};

}  // namespace mcrt
