#pragma once
// Dense 3x3 matrix (row-major) for surface tensors: deformation gradient A, B = A A^T,
// tension tau, curvature kappa, bending moments m.
#include <array>
#include "immerse/core/Vec3.hpp"

namespace immerse {

struct Mat3 {
  std::array<double, 9> a{};  // a[3*i + j] = M_ij

  constexpr double& operator()(int i, int j) { return a[3 * i + j]; }
  constexpr double operator()(int i, int j) const { return a[3 * i + j]; }

  static constexpr Mat3 identity() {
    Mat3 m;
    m(0, 0) = m(1, 1) = m(2, 2) = 1.0;
    return m;
  }
  /// Outer product u v^T.
  static constexpr Mat3 outer(const Vec3& u, const Vec3& v) {
    Mat3 m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m(i, j) = u[i] * v[j];
    return m;
  }
  /// Matrix whose rows are r0, r1, r2.
  static constexpr Mat3 from_rows(const Vec3& r0, const Vec3& r1, const Vec3& r2) {
    Mat3 m;
    for (int j = 0; j < 3; ++j) { m(0, j) = r0[j]; m(1, j) = r1[j]; m(2, j) = r2[j]; }
    return m;
  }
  constexpr Vec3 row(int i) const { return {a[3 * i], a[3 * i + 1], a[3 * i + 2]}; }
  constexpr Vec3 col(int j) const { return {a[j], a[3 + j], a[6 + j]}; }

  constexpr Mat3& operator+=(const Mat3& b) { for (int i = 0; i < 9; ++i) a[i] += b.a[i]; return *this; }
  constexpr Mat3& operator-=(const Mat3& b) { for (int i = 0; i < 9; ++i) a[i] -= b.a[i]; return *this; }
  constexpr Mat3& operator*=(double s) { for (double& v : a) v *= s; return *this; }
};

constexpr Mat3 operator+(Mat3 a, const Mat3& b) { return a += b; }
constexpr Mat3 operator-(Mat3 a, const Mat3& b) { return a -= b; }
constexpr Mat3 operator*(Mat3 a, double s) { return a *= s; }
constexpr Mat3 operator*(double s, Mat3 a) { return a *= s; }

constexpr Mat3 operator*(const Mat3& a, const Mat3& b) {
  Mat3 c;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += a(i, k) * b(k, j);
      c(i, j) = s;
    }
  return c;
}
/// M v
constexpr Vec3 operator*(const Mat3& m, const Vec3& v) {
  return {m(0, 0) * v.x + m(0, 1) * v.y + m(0, 2) * v.z, m(1, 0) * v.x + m(1, 1) * v.y + m(1, 2) * v.z,
          m(2, 0) * v.x + m(2, 1) * v.y + m(2, 2) * v.z};
}
/// v^T M  (i.e. v . M)
constexpr Vec3 operator*(const Vec3& v, const Mat3& m) {
  return {v.x * m(0, 0) + v.y * m(1, 0) + v.z * m(2, 0), v.x * m(0, 1) + v.y * m(1, 1) + v.z * m(2, 1),
          v.x * m(0, 2) + v.y * m(1, 2) + v.z * m(2, 2)};
}
constexpr Mat3 transpose(const Mat3& m) {
  Mat3 t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t(i, j) = m(j, i);
  return t;
}
constexpr double trace(const Mat3& m) { return m(0, 0) + m(1, 1) + m(2, 2); }
constexpr double det(const Mat3& m) {
  return m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0)) +
         m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
}
/// Inverse by cofactors; the caller guarantees det(m) != 0.
constexpr Mat3 inverse(const Mat3& m) {
  const double d = det(m);
  Mat3 r;
  r(0, 0) = (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) / d;
  r(0, 1) = (m(0, 2) * m(2, 1) - m(0, 1) * m(2, 2)) / d;
  r(0, 2) = (m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1)) / d;
  r(1, 0) = (m(1, 2) * m(2, 0) - m(1, 0) * m(2, 2)) / d;
  r(1, 1) = (m(0, 0) * m(2, 2) - m(0, 2) * m(2, 0)) / d;
  r(1, 2) = (m(0, 2) * m(1, 0) - m(0, 0) * m(1, 2)) / d;
  r(2, 0) = (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0)) / d;
  r(2, 1) = (m(0, 1) * m(2, 0) - m(0, 0) * m(2, 1)) / d;
  r(2, 2) = (m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0)) / d;
  return r;
}
/// Frobenius inner product A : B.
constexpr double ddot(const Mat3& a, const Mat3& b) {
  double s = 0;
  for (int i = 0; i < 9; ++i) s += a.a[i] * b.a[i];
  return s;
}

}  // namespace immerse
