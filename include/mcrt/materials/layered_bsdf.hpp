#pragma once
// Two interfaces with a thin slab between them, pbrt-v4's LayeredBxDF
// (src/pbrt/bxdfs.h; 4th ed., sec. 14.3, "Scattering from Layered
// Materials"; after Guo et al. 2018, "Position-Free Monte Carlo Simulation
// for Arbitrary Layered BSDFs"): `top` (a dielectric coat) over `bottom` (a
// diffuse or conductor base), a slab of `thickness` between them, filled,
// where `albedo` is not 0, with a homogeneous medium of unit extinction,
// that single-scattering albedo and a Henyey-Greenstein phase function of
// parameter g. pbrt-v4's coateddiffuse and coatedconductor are this BSDF
// (layered_materials.hpp). Two-sided as both of those: wo below the surface
// sees the same layers, mirrored.
//
// Nothing here has a closed form. Each of the triplet is a Monte Carlo
// estimate along random walks between the interfaces (at most max_depth
// scattering events each, Russian roulette after the 4th), n_samples walks
// averaged:
//  - sample(): one walk from wo; the sample's f / pdf is that walk's
//    weight (pdf_is_proportional), an UNBIASED estimate of the weight
//    f(wo, wi) |cos theta_i| / p(wi) once times |cos theta_i|; its pdf is
//    not the density of wi.
//  - eval(): an UNBIASED estimate of f(wo, wi) (without the cosine), walks
//    from both ends joined by next-event estimation with MIS inside the
//    slab (Guo et al. 2018, sec. 5).
//  - pdf(): an APPROXIMATION of the density of wi per unit SOLID ANGLE
//    (the first-order terms: entrance reflection, transmission-reflection-
//    transmission, transmission-transmission), mixed 9:1 with the uniform
//    density 1 / (4 pi) so that it is positive wherever sample() can go.
//
// How a renderer stays unbiased with them. Each estimate is a fixed
// function of its arguments: its random numbers come from a PCG stream
// seeded by a hash of (wo, wi) (eval, pdf) or of (wo, uc, u) (sample), as
// pbrt-v4 seeds its own. So pdf(wo, wi) is one fixed positive function p~:
//  - multiple importance sampling stays unbiased when every technique's
//    weight uses the same p~ for this BSDF (light sample: p~(wo, wi) from
//    pdf(); the BSDF's sample: pdf(wo, wi) again, not the sample's pdf):
//    weights built from any functions that are positive wherever their
//    technique can sample still sum to 1 at each direction (Veach 1997,
//    thesis sec. 9.2.2), and where sample() cannot go f = 0;
//  - the one-sample mixture of a light's density and the BSDF's
//    (mixture_integrator.hpp) is unbiased in the same way when written as
//    one-sample MIS with the balance heuristic: light branch
//    eval / (0.5 (p~ + p_light)), BSDF branch (f / pdf)_sample
//    * p~ / (0.5 (p~ + p_light));
//  - eval's estimate multiplies the light's radiance and a weight that
//    depends on p~ only: eval and pdf draw from different streams (their
//    hash keys differ), so the product's mean is f times the weight.
// The estimates are NOT a density: no chi-square test applies. tests/
// test_bsdfs.cpp checks them in expectation against the sampled weight and
// by energy (white furnace).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "mcrt/core/math.hpp"
#include "mcrt/core/rng.hpp"
#include "mcrt/materials/bsdf_sample.hpp"
#include "mcrt/materials/henyey_greenstein.hpp"
#include "mcrt/materials/shading_frame.hpp"

namespace mcrt {

template <class Top, class Bottom>
struct layered_bsdf {
  Top top;           // the coat: its transmission enters and leaves the slab
  Bottom bottom;     // the base: reflects inside the slab
  float thickness = 0.01f;  // in units of the medium's mean free path; >= FLT_MIN (pbrt-v4)
  color albedo{0.0f};       // single-scattering albedo of the medium; 0: no medium
  float g = 0.0f;           // Henyey-Greenstein asymmetry of the medium, in [-1, 1]
  int max_depth = 10;       // scattering events per walk
  int n_samples = 1;        // walks averaged per estimate, >= 1

  bool has_medium() const { return albedo != color(0.0f); }

  // Delta only when both interfaces are and no medium scatters (pbrt-v4's
  // Flags(): Specular alone then): a smooth coat over a smooth mirror.
  bool is_delta() const { return top.is_delta() && bottom.is_delta() && !has_medium(); }

  // An unbiased estimate of f(wo, wi), without the cosine.
  color eval(vec3 wo, vec3 wi, transport_mode mode = transport_mode::radiance) const {
    // Guard: the tangent plane has no side to enter from or leave by.
    if (wo.z == 0.0f || wi.z == 0.0f) return color(0.0f);
    if (wo.z < 0.0f) {  // two-sided: the mirrored configuration
      wo = -wo;
      wi = -wi;
    }
    // Entered through the top. Light leaves through the top when wi is on
    // wo's side (reflection), through the bottom otherwise.
    const bool reflect = same_hemisphere(wo, wi);
    const bool exit_top = reflect;
    const float exit_z = reflect ? thickness : 0.0f;
    const bool exit_delta = exit_top ? top.is_delta() : bottom.is_delta();
    const bool nonexit_delta = exit_top ? bottom.is_delta() : top.is_delta();

    // Reflection at the entrance interface, counted once per walk below.
    color f(0.0f);
    if (reflect) f = float(n_samples) * top.eval(wo, wi, mode);

    pcg32 rng(hash(wo, 0x6c61796572656431ull), hash(wi, 0x6576616c75617465ull));
    const auto r = [&rng] { return rng.uniform(); };
    const henyey_greenstein phase{g};

    for (int s = 0; s < n_samples; ++s) {
      // Into the slab through the top, from wo.
      bsdf_sample wos;
      {
        const float uc = r();
        const vec2 u = uniform2(r);
        if (!top.sample(wo, uc, u, wos, mode, bsdf_lobes::transmission) || !usable(wos)) continue;
      }
      // The "virtual light" direction: into the slab through the exit
      // interface, from wi, against the flow of light (adjoint mode).
      bsdf_sample wis;
      {
        const float uc = r();
        const vec2 u = uniform2(r);
        const bool ok = sample_at(exit_top, wi, uc, u, wis, adjoint(mode), bsdf_lobes::transmission);
        if (!ok || !usable(wis)) continue;
      }

      color beta = wos.f * abs_cos_theta(wos.wi) / wos.pdf;
      float z = thickness;
      vec3 w = wos.wi;

      for (int depth = 0; depth < max_depth; ++depth) {
        // A path counted by next-event estimation at this event leaves the
        // slab at the next one, which sample()'s walk reaches one iteration
        // later: at the last iteration it may not, or eval() would count
        // paths one event longer than sample() makes (pbrt-v4 does: its f()
        // exceeds its sampled weight by 2 % on a thick scattering slab at
        // maxdepth 10).
        const bool can_exit = depth + 1 < max_depth;
        // Russian roulette once the walk is long and carries little.
        if (depth > 3 && max_component(beta) < 0.25f) {
          const float q = std::max(0.0f, 1.0f - max_component(beta));
          if (r() < q) break;
          beta /= 1.0f - q;
        }

        if (!has_medium()) {
          // Straight to the other interface through the clear slab.
          z = (z == thickness) ? 0.0f : thickness;
          beta *= transmittance(thickness, w);
        } else {
          // A free flight of unit extinction along w.
          const float zp = step(z, w, r());
          if (zp == z) continue;  // a flight shorter than z's rounding
          if (0.0f < zp && zp < thickness) {
            // Scattering in the medium. Next-event estimation through the
            // exit interface along wis, weighted against the phase
            // function's own sample by the power heuristic.
            if (can_exit) {
              float wt = 1.0f;
              if (!exit_delta) wt = power_heuristic(wis.pdf, phase.pdf(-w, -wis.wi));
              f += beta * albedo * phase.p(-w, -wis.wi) * wt * transmittance(zp - exit_z, wis.wi) * wis.f / wis.pdf;
            }
            // The phase function's sample continues the walk.
            vec3 pw;
            float ppdf;
            phase.sample(-w, uniform2(r), pw, ppdf);
            if (!(ppdf > 0.0f) || pw.z == 0.0f) continue;
            beta *= albedo;  // p / pdf = 1: the phase function is sampled exactly
            w = pw;
            z = zp;
            // ... and, where it heads for the exit interface, counts what
            // that interface transmits into wi.
            if (((z < exit_z && w.z > 0.0f) || (z > exit_z && w.z < 0.0f)) && !exit_delta && can_exit) {
              const color f_exit = exit_top ? top.eval(-w, wi, mode) : bottom.eval(-w, wi, mode);
              if (f_exit != color(0.0f)) {
                const float exit_pdf = exit_pdf_of(exit_top, wi, -w, mode);
                f += beta * transmittance(zp - exit_z, pw) * f_exit * power_heuristic(ppdf, exit_pdf);
              }
            }
            continue;
          }
          z = std::clamp(zp, 0.0f, thickness);
        }

        if (z == exit_z) {
          // At the exit interface from inside: its reflection keeps the
          // walk in the slab (its transmission is what NEE counts).
          bsdf_sample bs;
          const float uc = r();
          const vec2 u = uniform2(r);
          const bool ok = sample_at(exit_top, -w, uc, u, bs, mode, bsdf_lobes::reflection);
          if (!ok || !usable(bs)) break;
          beta *= bs.f * abs_cos_theta(bs.wi) / bs.pdf;
          w = bs.wi;
        } else {
          // At the other interface. Next-event estimation along wis first,
          // then its reflection's sample, which also counts what the exit
          // interface transmits into wi from there.
          if (!nonexit_delta && can_exit) {
            float wt = 1.0f;
            const color f_non = exit_top ? bottom.eval(-w, -wis.wi, mode) : top.eval(-w, -wis.wi, mode);
            if (!exit_delta) {
              // The density the reflection's sample below would give -wis.wi.
              const float p_non = exit_top ? bottom.pdf(-w, -wis.wi, mode, bsdf_lobes::reflection)
                                           : top.pdf(-w, -wis.wi, mode, bsdf_lobes::reflection);
              wt = power_heuristic(wis.pdf, p_non);
            }
            f += beta * f_non * abs_cos_theta(wis.wi) * wt * transmittance(thickness, wis.wi) * wis.f / wis.pdf;
          }
          bsdf_sample bs;
          const float uc = r();
          const vec2 u = uniform2(r);
          const bool ok = sample_at(!exit_top, -w, uc, u, bs, mode, bsdf_lobes::reflection);
          if (!ok || !usable(bs)) break;
          beta *= bs.f * abs_cos_theta(bs.wi) / bs.pdf;
          w = bs.wi;
          if (!exit_delta && can_exit) {
            const color f_exit = exit_top ? top.eval(-w, wi, mode) : bottom.eval(-w, wi, mode);
            if (f_exit != color(0.0f)) {
              float wt = 1.0f;
              if (!nonexit_delta) {
                const float exit_pdf = exit_pdf_of(exit_top, wi, -w, mode);
                wt = power_heuristic(bs.pdf, exit_pdf);
              }
              f += beta * transmittance(thickness, bs.wi) * f_exit * wt;
            }
          }
        }
      }
    }
    return f / float(n_samples);
  }

  // One random walk from wo (pbrt-v4's LayeredBxDF::Sample_f): the coat's
  // sample, and where it enters the slab, scattering at the interfaces and
  // in the medium until the walk leaves through one of them. uc and u drive
  // the coat's sample; the walk's own numbers come from a stream seeded by
  // them and wo. The result's f / pdf is the walk's weight
  // (pdf_is_proportional: pdf is 1 and f the weight without the cosine,
  // but for the coat's own reflection, which keeps its f and pdf); delta
  // when every event on it was.
  bool sample(vec3 wo, float uc, vec2 u, bsdf_sample& out, transport_mode mode = transport_mode::radiance) const {
    out = bsdf_sample{};
    bool flip = false;
    if (wo.z < 0.0f) {
      wo = -wo;
      flip = true;
    }
    bsdf_sample bs;
    if (!top.sample(wo, uc, u, bs, mode) || !usable(bs)) return false;
    if (!bs.transmission) {
      // Reflected by the coat: that is the sample.
      if (flip) bs.wi = -bs.wi;
      bs.pdf_is_proportional = true;
      out = bs;
      return true;
    }
    vec3 w = bs.wi;
    bool specular_path = bs.delta;

    pcg32 rng(hash(wo, 0x6c61796572656432ull), hash(vec3(uc, u.x, u.y), 0x73616d706c652121ull));
    const auto r = [&rng] { return rng.uniform(); };
    const henyey_greenstein phase{g};

    // The walk's weight so far, f |cos| / pdf of its path (pbrt-v4 keeps f
    // and pdf apart; their product over a long walk in a slab can leave
    // single precision, their ratio does not).
    color beta = bs.f * (abs_cos_theta(bs.wi) / bs.pdf);
    float z = thickness;

    for (int depth = 0; depth < max_depth; ++depth) {
      // Russian roulette on the walk's weight; survivors carry 1 / (1 - q).
      if (depth > 3 && max_component(beta) < 0.25f) {
        const float q = std::max(0.0f, 1.0f - max_component(beta));
        if (r() < q) return false;
        beta /= 1.0f - q;
      }
      if (w.z == 0.0f) return false;

      if (has_medium()) {
        const float zp = step(z, w, r());
        if (zp == z) return false;
        if (0.0f < zp && zp < thickness) {
          // Scattered by the medium: the phase function's value over its
          // pdf is 1.
          vec3 pw;
          float ppdf;
          phase.sample(-w, uniform2(r), pw, ppdf);
          if (!(ppdf > 0.0f) || pw.z == 0.0f) return false;
          beta *= albedo;
          specular_path = false;
          w = pw;
          z = zp;
          continue;
        }
        z = std::clamp(zp, 0.0f, thickness);
      } else {
        z = (z == thickness) ? 0.0f : thickness;
        beta *= transmittance(thickness, w);
      }

      // Scattering at the interface the walk reached.
      const float iuc = r();
      const vec2 iu = uniform2(r);
      const bool ok = sample_at(z != 0.0f, -w, iuc, iu, bs, mode, bsdf_lobes::all);
      if (!ok || !usable(bs)) return false;
      specular_path = specular_path && bs.delta;
      w = bs.wi;

      if (bs.transmission) {
        // Left the slab: through the top, a reflection of the whole; through
        // the bottom, a transmission. f / pdf is the weight without the
        // last cosine, which the caller applies: returned as f with pdf 1.
        out.f = beta * (bs.f / bs.pdf);
        out.pdf = 1.0f;
        out.delta = specular_path;
        out.transmission = !same_hemisphere(wo, w);
        out.wi = flip ? -w : w;
        out.pdf_is_proportional = true;
        return true;
      }
      beta *= bs.f * (abs_cos_theta(bs.wi) / bs.pdf);
    }
    return false;
  }

  // An approximation of the density of wi per unit SOLID ANGLE (pbrt-v4's
  // LayeredBxDF::PDF): the terms of at most two interface events estimated
  // by sampling, mixed 9:1 with 1 / (4 pi). Positive everywhere off the
  // tangent plane.
  float pdf(vec3 wo, vec3 wi, transport_mode mode = transport_mode::radiance) const {
    if (wo.z == 0.0f || wi.z == 0.0f) return 0.0f;  // guard: as eval() and sample()
    if (wo.z < 0.0f) {
      wo = -wo;
      wi = -wi;
    }
    pcg32 rng(hash(wi, 0x6c61796572656433ull), hash(wo, 0x7064667064667064ull));
    const auto r = [&rng] { return rng.uniform(); };

    const bool reflect = same_hemisphere(wo, wi);
    float pdf_sum = 0.0f;
    if (reflect) pdf_sum += float(n_samples) * top.pdf(wo, wi, mode, bsdf_lobes::reflection);

    for (int s = 0; s < n_samples; ++s) {
      if (reflect) {
        // Transmission in through the top, reflection at the bottom,
        // transmission out through the top (TRT).
        bsdf_sample wos, wis;
        const float uc0 = r();
        const vec2 u0 = uniform2(r);
        const float uc1 = r();
        const vec2 u1 = uniform2(r);
        const bool ok_o = top.sample(wo, uc0, u0, wos, mode, bsdf_lobes::transmission);
        const bool ok_i = top.sample(wi, uc1, u1, wis, adjoint(mode), bsdf_lobes::transmission);
        if (ok_o && wos.f != color(0.0f) && wos.pdf > 0.0f && ok_i && wis.f != color(0.0f) && wis.pdf > 0.0f) {
          if (top.is_delta()) {
            pdf_sum += bottom.pdf(-wos.wi, -wis.wi, mode);
          } else {
            // Both ends rough: two estimates of the product's density,
            // combined by MIS.
            bsdf_sample rs;
            const float uc2 = r();
            const vec2 u2 = uniform2(r);
            if (bottom.sample(-wos.wi, uc2, u2, rs, mode) && rs.f != color(0.0f) && rs.pdf > 0.0f) {
              if (bottom.is_delta()) {
                pdf_sum += top.pdf(-rs.wi, wi, mode);
              } else {
                const float r_pdf = bottom.pdf(-wos.wi, -wis.wi, mode);
                pdf_sum += power_heuristic(wis.pdf, r_pdf) * r_pdf;
                const float t_pdf = top.pdf(-rs.wi, wi, mode);
                pdf_sum += power_heuristic(rs.pdf, t_pdf) * t_pdf;
              }
            }
          }
        }
      } else {
        // Transmission through both interfaces (TT).
        bsdf_sample wos, wis;
        const float uc0 = r();
        const vec2 u0 = uniform2(r);
        if (!top.sample(wo, uc0, u0, wos, mode) || !usable(wos) || !wos.transmission) continue;
        const float uc1 = r();
        const vec2 u1 = uniform2(r);
        if (!bottom.sample(wi, uc1, u1, wis, adjoint(mode)) || !usable(wis) || !wis.transmission) continue;
        if (top.is_delta())
          pdf_sum += bottom.pdf(-wos.wi, wi, mode);
        else if (bottom.is_delta())
          pdf_sum += top.pdf(wo, -wis.wi, mode);
        else
          pdf_sum += 0.5f * (top.pdf(wo, -wis.wi, mode) + bottom.pdf(-wos.wi, wi, mode));
      }
    }
    // The mixture with the uniform density (pbrt-v4's Lerp(0.9, 1/(4 pi), .)).
    return 0.1f * (1.0f / (4.0f * pi)) + 0.9f * (pdf_sum / float(n_samples));
  }

 private:
  // The density with which the exit interface's sample from wi (the
  // virtual light wis: adjoint mode, transmission only) gives the
  // direction d into the slab: what the next-event estimate along wis
  // weighs against a walk that reaches the exit heading along -d.
  // pbrt-v4 takes exitInterface.PDF(-w, wi, mode, Transmission) instead,
  // the density of wi given -w, which for a rough coat is another number:
  // its two weights then do not sum to 1 and its f() is biased, by up to
  // +7 % of the albedo of a rough coat (tests/test_bsdfs.cpp, Layered.*,
  // against the sampled walk, which is unbiased).
  float exit_pdf_of(bool exit_top, const vec3& wi, const vec3& d, transport_mode mode) const {
    return exit_top ? top.pdf(wi, d, adjoint(mode), bsdf_lobes::transmission)
                    : bottom.pdf(wi, d, adjoint(mode), bsdf_lobes::transmission);
  }

  // The sample of the top interface (at_top) or of the bottom one.
  bool sample_at(bool at_top, const vec3& wo, float uc, vec2 u, bsdf_sample& out, transport_mode mode,
                 bsdf_lobes lobes) const {
    return at_top ? top.sample(wo, uc, u, out, mode, lobes) : bottom.sample(wo, uc, u, out, mode, lobes);
  }

  // A sample the walk can continue from (pbrt-v4's checks: some f, a
  // positive pdf, a direction off the tangent plane).
  static bool usable(const bsdf_sample& s) { return s.f != color(0.0f) && s.pdf > 0.0f && s.wi.z != 0.0f; }

  static float max_component(const color& c) { return std::max(c.r, std::max(c.g, c.b)); }

  template <class R>
  static vec2 uniform2(R& r) {
    const float a = r();
    return {a, r()};
  }

  // Transmittance of the slab's medium (unit extinction) over a height
  // difference dz along w: exp(-|dz / cos theta|); 1 for no distance.
  static float transmittance(float dz, const vec3& w) {
    if (std::abs(dz) <= std::numeric_limits<float>::min()) return 1.0f;
    return std::exp(-std::abs(dz / w.z));
  }

  // The height after a free flight from z along w: the flight's length
  // along w is exponential with unit rate, its height difference |w.z|
  // times that (pbrt-v4 draws the height difference at rate 1 / |w.z|).
  static float step(float z, const vec3& w, float u) {
    const float dz = -std::log1p(-u) * std::abs(w.z);
    return w.z > 0.0f ? z + dz : z - dz;
  }

  // pbrt-v4's PowerHeuristic(1, f, 1, g), 1 when f^2 overflows.
  static float power_heuristic(float f, float g) {
    const float f2 = f * f, g2 = g * g;
    if (std::isinf(f2)) return 1.0f;
    return f2 / (f2 + g2);
  }

  // A 64-bit hash of a direction's bits under a key: the seeds of the
  // estimates' random streams.
  static std::uint64_t hash(const vec3& v, std::uint64_t key) {
    const auto bits = [](float x) { return static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(x)); };
    return mix64(mix64(key ^ (bits(v.x) | (bits(v.y) << 32))) ^ bits(v.z));
  }
};

}  // namespace mcrt
