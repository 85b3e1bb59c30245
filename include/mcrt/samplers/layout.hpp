#pragma once
// The dimensions one camera sample (one path) draws, at fixed places, so that
// across the spp samples of a pixel each 2-D draw of bounce k comes from the
// same pair of dimensions and stays a well-stratified point set (pbrt-v4's
// samplers own such a layout, "Physically Based Rendering", 4th ed., sec. 8.3;
// a sampler whose dimensions are consumed in a path-dependent order loses
// its stratification).
//
//   dims 0, 1            pixel position (2-D)
//   for scattering event k = 0, 1, ... at base b = 2 + 7 k:
//     b + 0              light choice (1-D); the mixture integrator's choice
//                        of component and light
//     b + 1, b + 2       light sample (2-D): the unit-square point a light
//                        strategy maps onto the light
//     b + 3              material choice (1-D): reflect or refract for glass,
//                        the radius of a metal's fuzz
//     b + 4, b + 5       material sample (2-D): the direction the material
//                        samples (cosine hemisphere, fuzz direction)
//     b + 6              Russian roulette (1-D)
//
//   dims lens, lens + 1  the point on a thin lens (2-D), drawn only by a
//                        camera with a lens; placed past the dimensions of
//                        every bounce (2^30, over 10^8 bounces away), so that
//                        a lens moves none of the others
//
// The 2-D pairs are (0, 1), (b + 1, b + 2), (b + 4, b + 5) and (lens, lens + 1).
// A draw that a bounce does not need is simply not made: the places of the
// others do not move.
namespace mcrt::layout {

inline constexpr int pixel = 0;             // 2-D
inline constexpr int lens = 1 << 30;        // 2-D
inline constexpr int dims_per_bounce = 7;
inline constexpr int light_choice = 0;      // offsets within a bounce
inline constexpr int light = 1;             // 2-D
inline constexpr int material_choice = 3;
inline constexpr int material = 4;          // 2-D
inline constexpr int roulette = 6;

// First dimension of scattering event k (k = 0 at the first surface a camera
// ray meets).
constexpr int bounce(int k) { return 2 + dims_per_bounce * k; }

}  // namespace mcrt::layout
