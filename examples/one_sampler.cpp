// One light sampler on its own, outside the renderer: the irradiance a point
// receives from a rectangle light of radiance L, E = L * integral of cos(theta)
// over the light's solid angle, estimated by sampling directions towards the
// light with two strategies, each used through its triplet (sample, pdf per
// unit solid angle, and the pdf returned with the sample), and compared with
// Lambert's polygon formula. The program prints both estimates and exits
// with status 1 if either is off by more than 5 standard errors, or if a
// sample's pdf disagrees with pdf().
//
// Build: any C++20 compiler with GLM, e.g.
//   g++ -std=c++20 -O2 -I include examples/one_sampler.cpp -o one_sampler
#include <cmath>
#include <cstdio>
#include <vector>

#include <mcrt/core/rng.hpp>
#include <mcrt/sampling/projected_rectangle.hpp>
#include <mcrt/sampling/spherical_rectangle.hpp>

using namespace mcrt;

// Lambert's formula (e.g. Arvo 1995, "Applications of Irradiance Tensors",
// eq. 2): E = L/2 sum_i gamma_i n . normalize(r_i x r_i+1), r_i the unit
// vectors from x to the polygon's vertices, gamma_i the angle between them.
double lambert(const dvec3& x, const dvec3& n, const std::vector<dvec3>& poly, double L) {
  double sum = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const dvec3 a = glm::normalize(poly[i] - x), b = glm::normalize(poly[(i + 1) % poly.size()] - x);
    const dvec3 c = glm::cross(a, b);
    sum += std::atan2(glm::length(c), glm::dot(a, b)) * glm::dot(n, glm::normalize(c));
  }
  return std::abs(0.5 * L * sum);
}

struct estimate {
  double mean, stderr_;
  bool pdf_agrees;
};

// E ~ L * mean of cos(theta) / pdf over N samples; draw(u, s) samples one
// direction, pdf(dir) evaluates the strategy's density for it.
template <class Draw, class Pdf>
estimate irradiance(const vec3& n, float L, int N, Draw draw, Pdf pdf) {
  pcg32 rng(7, 11);
  double s = 0.0, s2 = 0.0;
  bool agrees = true;
  for (int i = 0; i < N; ++i) {
    light_sample ls;
    double f = 0.0;
    if (draw(rng.uniform2(), ls)) {
      f = L * std::max(0.0f, glm::dot(n, ls.dir)) / ls.pdf;
      // The returned pdf and pdf() are the same density.
      agrees = agrees && std::abs(pdf(ls.dir) - ls.pdf) <= 1e-4f * ls.pdf;
    }
    s += f;
    s2 += f * f;
  }
  const double mean = s / N, var = std::max(s2 / N - mean * mean, 0.0);
  return {mean, std::sqrt(var / N), agrees};
}

int main() {
  // A 2 x 1 light facing down at height 1.5, a receiver at the origin whose
  // normal leans 40 degrees towards +x.
  const float L = 5.0f;
  const rect light = xz_rect(-0.5f, 1.5f, -0.5f, 0.5f, 1.5f, /*flip=*/true);
  const vec3 o(0.0f), n = glm::normalize(vec3(std::sin(0.7f), std::cos(0.7f), 0.0f));
  const std::vector<dvec3> poly{dvec3(light.corner), dvec3(light.corner + light.e1),
                                dvec3(light.corner + light.e1 + light.e2), dvec3(light.corner + light.e2)};
  const double exact = lambert(dvec3(o), dvec3(n), poly, L);

  // Uniform in the light's solid angle (Urena, Fajardo & King 2013).
  const rect_solid_angle_sampler sa(light);
  const estimate e_sa = irradiance(
      n, L, 100000, [&](vec2 u, light_sample& s) { return sa.sample(o, u, s); },
      [&](const vec3& d) { return sa.pdf(o, d); });
  // Proportional to cos(theta) within it (Peters 2021): E[cos / pdf] is
  // constant, so the estimate has (almost) no variance.
  const rect_projected_solid_angle_sampler psa(light);
  const estimate e_psa = irradiance(
      n, L, 100000, [&](vec2 u, light_sample& s) { return psa.sample(o, n, u, s); },
      [&](const vec3& d) { return psa.pdf(o, n, d); });

  std::printf("Lambert's formula       E = %.6f\n", exact);
  std::printf("solid angle             E = %.6f +- %.6f\n", e_sa.mean, e_sa.stderr_);
  std::printf("projected solid angle   E = %.6f +- %.2g\n", e_psa.mean, e_psa.stderr_);
  bool ok = e_sa.pdf_agrees && e_psa.pdf_agrees;
  // 5 standard errors, and at least the rounding of single precision.
  for (const estimate& e : {e_sa, e_psa}) ok = ok && std::abs(e.mean - exact) <= 5.0 * e.stderr_ + 1e-5 * exact;
  if (!ok) std::printf("an estimate or a pdf disagrees\n");
  return ok ? 0 : 1;
}
