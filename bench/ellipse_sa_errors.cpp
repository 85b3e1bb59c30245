// Error table of the solvers of the spherical ellipse's maps, per axis
// ratio and solid-angle decade (markdown on stdout):
//   residual  max over u of |Omega_p(psi(u)) - u Omega| / Omega, Omega_p and
//             Omega from the Carlson closed form (exact to ~1e-13) at the
//             slice the solver returns (the solver's own running residual,
//             partly from local quadrature, does not enter it); for the
//             polar map, the same for its sector area (through its inverse);
//   E[1/pdf]  relative error of E[1/pdf] = the solver's Omega (1/pdf is
//             constant in the spherical mode) against a boundary quadrature
//             of the solid angle (below). The polar map carries the Omega
//             of the Newton column.
// Configurations: an ellipse with semi-axes 1 and 1/ratio seen on its axis
// from the height that gives the solid angle wanted (bisection on h).
#include <cstdio>
#include <numbers>

#include "mcrt/sampling/spherical_ellipse.hpp"
#include "mcrt/sampling/spherical_ellipse_polar.hpp"

namespace {

using namespace mcrt;

// Solid angle by the boundary form of Omega = int h / r^3 dA (Stokes):
// Omega = int_0^{2 pi} (|a1 x a2| + cos t k2 - sin t k1) / (s (s + h)) dt
// along the rim, s the distance to the rim point, by the trapezoidal rule
// (spectrally accurate for this periodic, smooth integrand), doubled until
// two estimates agree to 1e-13. Independent of the cone set-up.
double omega_quadrature(const ellipse& e, const vec3& o) {
  const dvec3 od(o), c(e.center), a1(e.a1), a2(e.a2);
  const dvec3 cr = glm::cross(a1, a2);
  const double area = glm::length(cr);
  const dvec3 n = cr / area, co = c - od;
  const double hs = -glm::dot(co, n), h = std::abs(hs);
  const dvec3 w = co + hs * n;
  const double k1 = glm::dot(n, glm::cross(w, a1)), k2 = glm::dot(n, glm::cross(w, a2));
  const auto f = [&](double t) {
    const double s = glm::length(co + std::cos(t) * a1 + std::sin(t) * a2);
    return (area + std::cos(t) * k2 - std::sin(t) * k1) / (s * (s + h));
  };
  constexpr double two_pi = 2.0 * std::numbers::pi;
  int nodes = 256;
  double sum = 0.0;
  for (int j = 0; j < nodes; ++j) sum += f(two_pi * j / nodes);
  double estimate = sum * two_pi / nodes;
  while (nodes < (1 << 24)) {
    for (int j = 0; j < nodes; ++j) sum += f(two_pi * (j + 0.5) / nodes);
    nodes *= 2;
    const double next = sum * two_pi / nodes;
    const bool converged = std::abs(next - estimate) <= 1e-13 * std::abs(next);
    estimate = next;
    if (converged) break;
  }
  return std::abs(estimate);
}

template <class Solver>
double max_residual(const spherical_ellipse& se) {
  const double omega = spherical_ellipse_area(se), omega_s = Solver::area(se);
  double worst = 0.0;
  for (int i = 0; i <= 200; ++i) {
    const double u = (i + 0.5) / 201.0;
    const spherical_ellipse_slice sl = Solver::invert(se, omega_s, u);
    const double r = std::abs(newton_carlson_solver::partial_area(se, omega, sl) - u * omega) / omega;
    worst = std::max(worst, r);
  }
  return worst;
}

// The polar map: max over u1 of |u1(point(u1)) - u1|, u1 of the point by the
// closed-form sector area of the inverse, i.e. |Omega_q - u1 Omega| / Omega.
double max_polar_residual(const spherical_ellipse& se) {
  const double omega = spherical_ellipse_area(se);
  double worst = 0.0;
  for (int i = 0; i <= 200; ++i) {
    const double u = (i + 0.5) / 201.0;
    const dvec2 p = square_to_spherical_ellipse_polar({u, 0.5}, se, omega);
    worst = std::max(worst, std::abs(spherical_ellipse_polar_to_square(p, se, omega).x - u));
  }
  return worst;
}

}  // namespace

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const double ratios[] = {1.0, 10.0, 1e2, 1e3, 1e4};
  const double targets[] = {1e-8, 1e-6, 1e-4, 1e-2, 1.0, 2.0 * std::numbers::pi * (1.0 - 1e-3)};
  std::printf(
      "| a/b | Omega (sr) | mode | Newton residual | Newton E[1/pdf] err | polar residual | seed residual | seed "
      "E[1/pdf] err |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (double ratio : ratios)
    for (double target : targets) {
      const ellipse e = ellipse::make({0, 0, 0}, {1, 0, 0}, {0, static_cast<float>(1.0 / ratio), 0});
      // Omega decreases with h: bisection in log h.
      double lo = -8.0, hi = 8.0;
      for (int i = 0; i < 80; ++i) {
        const double mid = 0.5 * (lo + hi);
        const ellipse_cone c = make_ellipse_cone(e, vec3(0.0f, 0.0f, static_cast<float>(std::pow(10.0, mid))));
        (c.omega > target ? lo : hi) = mid;
      }
      const vec3 o(0.0f, 0.0f, static_cast<float>(std::pow(10.0, 0.5 * (lo + hi))));
      const ellipse_cone c = make_ellipse_cone(e, o);
      const ellipse_cone cs = make_ellipse_cone<bisection_simpson_solver>(e, o);
      const double ref = omega_quadrature(e, o);
      std::printf("| %g | %.3g | %s | %.1e | %.1e | %.1e | %.1e | %.1e |\n", ratio, ref,
                  c.mode == ellipse_cone_mode::spherical ? "map" : "area", max_residual<newton_carlson_solver>(c.se),
                  std::abs(c.omega / ref - 1.0), max_polar_residual(c.se), max_residual<bisection_simpson_solver>(c.se),
                  std::abs(cs.omega / ref - 1.0));
    }
}
