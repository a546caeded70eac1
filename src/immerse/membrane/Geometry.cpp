#include "immerse/membrane/Geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/membrane/MeshElement.hpp"

namespace immerse {
namespace {

MeshElement::Nodes element_nodes(const Mesh& mesh, std::span<const Vec3> X, std::size_t e, const Vec3& origin) {
  MeshElement::Nodes x;
  for (int i = 0; i < 6; ++i) x[i] = X[mesh.elements[e][i]] - origin;
  return x;
}

Vec3 mean_position(const std::vector<Vec3>& X) {
  Vec3 s;
  for (const auto& x : X) s += x;
  return X.empty() ? s : s / static_cast<double>(X.size());
}

/// The four sub-triangles (v0 m01 m20), (m01 v1 m12), (m20 m12 v2), (m01 m12 m20) as local node numbers.
constexpr std::array<std::array<int, 3>, 4> kSubTriangles{{{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}}};

/// Curved areas of an element's four sub-triangles, each by the 7-point rule mapped affinely onto the
/// sub-triangle in parent coordinates (Jacobian 1/4).
std::array<double, 4> sub_triangle_areas(const MeshElement::Nodes& x) {
  std::array<double, 4> a{};
  for (int k = 0; k < 4; ++k) {
    const auto& p0 = MeshElement::node_coordinates[kSubTriangles[k][0]];
    const auto& p1 = MeshElement::node_coordinates[kSubTriangles[k][1]];
    const auto& p2 = MeshElement::node_coordinates[kSubTriangles[k][2]];
    for (const auto& q : MeshElement::quadrature) {
      const double xi = p0[0] + q.xi * (p1[0] - p0[0]) + q.eta * (p2[0] - p0[0]);
      const double eta = p0[1] + q.xi * (p1[1] - p0[1]) + q.eta * (p2[1] - p0[1]);
      a[k] += 0.25 * q.weight * norm(MeshElement::jacobian(x, xi, eta));
    }
  }
  return a;
}

/// Volume moments about `origin`: m0 = V, m1 = ∫ r dV, m2 = ∫ r rᵀ dV.
struct VolumeMoments {
  double m0 = 0;
  Vec3 m1;
  Mat3 m2;
};

VolumeMoments volume_moments(const Mesh& mesh, const std::vector<Vec3>& X, const Vec3& origin) {
  // Per-element contributions in parallel, summed serially: the result does not depend on the thread count.
  std::vector<VolumeMoments> part(mesh.num_elements());
  const auto ne = static_cast<std::ptrdiff_t>(mesh.num_elements());
#pragma omp parallel for if (ne >= kMinElementsForThreads)
  for (std::ptrdiff_t e = 0; e < ne; ++e) {
    const auto x = element_nodes(mesh, X, static_cast<std::size_t>(e), origin);
    VolumeMoments& m = part[e];
    for (const auto& q : MeshElement::quadrature) {
      const Vec3 r = MeshElement::position(x, q.xi, q.eta);
      const double f = q.weight * dot(r, MeshElement::jacobian(x, q.xi, q.eta));  // w x·n dA
      m.m0 += f / 3;
      m.m1 += (f / 4) * r;
      m.m2 += (f / 5) * Mat3::outer(r, r);
    }
  }
  VolumeMoments sum;
  for (const auto& m : part) sum.m0 += m.m0, sum.m1 += m.m1, sum.m2 += m.m2;
  return sum;
}

/// Volume, volume centroid and second moment ∫ r rᵀ dV about the centroid.
struct CentralMoments {
  double volume;
  Vec3 centroid;
  Mat3 second;
};

CentralMoments central_moments(const Mesh& mesh, const std::vector<Vec3>& X) {
  const Vec3 origin = mean_position(X);
  const VolumeMoments m = volume_moments(mesh, X, origin);
  const Vec3 c = m.m1 / m.m0;
  return {m.m0, origin + c, m.m2 - m.m0 * Mat3::outer(c, c)};
}

/// Eigen-pairs of a symmetric 3×3 matrix by cyclic Jacobi rotations, values in decreasing order.
struct SymmetricEigen {
  std::array<double, 3> values;
  std::array<Vec3, 3> vectors;
};

SymmetricEigen symmetric_eigen(Mat3 a) {
  Mat3 v = Mat3::identity();
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
    if (off <= 1e-30 * ddot(a, a)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (a(p, q) == 0.0) continue;
        const double theta = (a(q, q) - a(p, p)) / (2 * a(p, q));
        const double t = std::copysign(1.0, theta) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        Mat3 rot = Mat3::identity();  // a <- rotᵀ a rot zeroes a(p, q)
        rot(p, p) = c, rot(q, q) = c, rot(p, q) = s, rot(q, p) = -s;
        a = transpose(rot) * a * rot;
        v = v * rot;
      }
  }
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int i, int j) { return a(i, i) > a(j, j); });
  SymmetricEigen r;
  for (int k = 0; k < 3; ++k) r.values[k] = a(order[k], order[k]), r.vectors[k] = v.col(order[k]);
  return r;
}

}  // namespace

std::vector<double> element_areas(const Mesh& mesh, std::span<const Vec3> X) {
  std::vector<double> part(mesh.num_elements(), 0.0);
  const auto ne = static_cast<std::ptrdiff_t>(mesh.num_elements());
#pragma omp parallel for if (ne >= kMinElementsForThreads)
  for (std::ptrdiff_t e = 0; e < ne; ++e) {
    const auto a = sub_triangle_areas(element_nodes(mesh, X, static_cast<std::size_t>(e), {}));
    part[e] = a[0] + a[1] + a[2] + a[3];
  }
  return part;
}

double area(const Mesh& mesh, const std::vector<Vec3>& X) {
  double s = 0;
  for (double a : element_areas(mesh, X)) s += a;
  return s;
}

LeastAreaRatio least_area_ratio(const Mesh& mesh, std::span<const Vec3> X, std::span<const double> reference_areas) {
  return least_area_ratio(element_areas(mesh, X), reference_areas);
}

LeastAreaRatio least_area_ratio(std::span<const double> a, std::span<const double> reference_areas) {
  LeastAreaRatio least{std::numeric_limits<double>::infinity(), 0};
  for (std::size_t e = 0; e < a.size(); ++e)
    if (const double r = a[e] / reference_areas[e]; r < least.ratio) least = {r, e};
  return least;
}

double volume(const Mesh& mesh, const std::vector<Vec3>& X) {
  return volume_moments(mesh, X, mean_position(X)).m0;
}

Mat3 inertia_tensor(const Mesh& mesh, const std::vector<Vec3>& X) {
  const Mat3 m = central_moments(mesh, X).second;
  return trace(m) * Mat3::identity() - m;
}

MembraneGeometry measure(const Mesh& mesh, const std::vector<Vec3>& X) {
  const CentralMoments m = central_moments(mesh, X);
  MembraneGeometry g;
  g.volume = m.volume;
  g.centroid = m.centroid;
  g.area = area(mesh, X);
  const SymmetricEigen eig = symmetric_eigen(m.second);
  for (int k = 0; k < 3; ++k) {
    g.semi_axes[k] = std::sqrt(5 * std::max(eig.values[k], 0.0) / g.volume);
    g.axes[k] = eig.vectors[k];
  }
  return g;
}

std::vector<double> node_area_weights(const Mesh& mesh, const std::vector<Vec3>& X) {
  std::vector<std::array<double, 4>> sub_area(mesh.num_elements());
  const auto ne = static_cast<std::ptrdiff_t>(mesh.num_elements());
#pragma omp parallel for if (ne >= kMinElementsForThreads)
  for (std::ptrdiff_t e = 0; e < ne; ++e)
    sub_area[e] = sub_triangle_areas(element_nodes(mesh, X, static_cast<std::size_t>(e), {}));
  // Serial gather: the sums do not depend on the thread count.
  std::vector<double> w(mesh.num_nodes(), 0.0);
  for (std::size_t e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 4; ++k)
      for (int i : kSubTriangles[k]) w[mesh.elements[e][i]] += sub_area[e][k] / 3;
  return w;
}

}  // namespace immerse
