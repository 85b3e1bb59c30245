#pragma once
// 50-digit references for the spherical triangle (Boost.Multiprecision),
// independent of the library's closed forms: Van Oosterom & Strackee's
// solid angle, and Arvo's map as the paper states it. Used by
// tests/test_spherical_triangle.cpp and bench/triangle_sa_extremes.cpp.
#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>

#include "mcrt/core/math.hpp"

namespace mcrt::test {

using mp = boost::multiprecision::cpp_bin_float_50;
struct v3 {
  mp x, y, z;
};
inline v3 to_mp(const dvec3& p) { return {p.x, p.y, p.z}; }
inline v3 operator-(const v3& a, const v3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline v3 operator+(const v3& a, const v3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline v3 operator*(const mp& s, const v3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline mp dot(const v3& a, const v3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline v3 cross(const v3& a, const v3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline mp norm(const v3& a) { return sqrt(dot(a, a)); }
inline v3 unit(const v3& a) { return (1 / norm(a)) * a; }
inline dvec3 to_d(const v3& a) {
  return {static_cast<double>(a.x), static_cast<double>(a.y), static_cast<double>(a.z)};
}

// Van Oosterom & Strackee with 50 significant digits: no cancellation that
// matters at the extremes of the tests' battery (the worst loses ~20 digits).
inline double reference_solid_angle(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2) {
  const v3 oo = to_mp(o), a = to_mp(p0) - oo, b = to_mp(p1) - oo, c = to_mp(p2) - oo;
  const mp la = norm(a), lb = norm(b), lc = norm(c);
  const mp num = abs(dot(a, cross(b, c)));
  return static_cast<double>(2 * atan2(num, la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la));
}

// Arvo's algorithm as the paper states it (sec. 2: Girard's formula, eq. 1,
// for the area; the first stage's cos |AC'| from the cosine laws, eqs. 2-3;
// the second stage's z = 1 - u2 (1 - C'.B)), in 50 digits, where its
// cancellations cost nothing: A = p0, B = p1, C = p2.
inline dvec3 arvo_reference(const dvec3& o, const dvec3& p0, const dvec3& p1, const dvec3& p2, double u1, double u2) {
  const v3 oo = to_mp(o);
  const v3 A = unit(to_mp(p0) - oo), B = unit(to_mp(p1) - oo), C = unit(to_mp(p2) - oo);
  const auto angle = [](const v3& x, const v3& y, const v3& z) {  // at x, between arcs xy and xz
    const v3 n1 = cross(x, y), n2 = cross(x, z);
    return mp(atan2(norm(cross(n1, n2)), dot(n1, n2)));
  };
  const mp alpha = angle(A, B, C), beta = angle(B, C, A), gamma = angle(C, A, B);
  const mp area = alpha + beta + gamma - boost::math::constants::pi<mp>();
  const mp sub = u1 * area;
  const mp s = sin(sub - alpha), t = cos(sub - alpha);
  const mp u = t - cos(alpha), v = s + sin(alpha) * dot(A, B);
  const mp q = ((v * t - u * s) * cos(alpha) - v) / ((v * s + u * t) * sin(alpha));
  const v3 Cs = q * A + sqrt(1 - q * q) * unit(C - dot(C, A) * A);
  const mp z = 1 - u2 * (1 - dot(Cs, B));
  return to_d(z * B + sqrt(1 - z * z) * unit(Cs - dot(Cs, B) * B));
}

}  // namespace mcrt::test
