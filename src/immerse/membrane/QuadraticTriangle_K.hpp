#pragma once
// Six-node curved triangle (paper §3, eq. 38): u(xi, eta) = sum_i u_i N_i(xi, eta), with local node order
// {v0, v1, v2, m01, m12, m20} (see Mesh.hpp) at parametric points (0,0), (1,0), (0,1), (1/2,0), (1/2,1/2), (0,1/2).
// With zeta = 1 - xi - eta:
//   N0 = zeta (2 zeta - 1),  N1 = xi (2 xi - 1),  N2 = eta (2 eta - 1),
//   N3 = 4 xi zeta,          N4 = 4 xi eta,        N5 = 4 eta zeta.
// Also: the quadrature rules used on the element (degree-4 six-point rule on the triangle, three-point
// Gauss-Legendre along an edge) and the edge lists of the contour integral (42).
// Verified by the test MembraneKinematics.ShapeFunctionIntegralsVanishAtVertices (the six-point rule integrates the
// shape functions exactly) and, through ElasticMembrane, the study membrane_inflation (both force methods).
#include <array>

namespace immerse::tri6 {

constexpr int kNodes = 6;

struct Point { double xi, eta; };

/// Parametric coordinates of the six nodes.
constexpr std::array<Point, kNodes> kNodePoints{{{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}}};

/// Shape-function values and parametric derivatives at one point.
struct Shape {
  std::array<double, kNodes> N, dxi, deta;
};

constexpr Shape shape(double xi, double eta) {
  const double z = 1 - xi - eta;
  return {{z * (2 * z - 1), xi * (2 * xi - 1), eta * (2 * eta - 1), 4 * xi * z, 4 * xi * eta, 4 * eta * z},
          {1 - 4 * z, 4 * xi - 1, 0, 4 * (z - xi), 4 * eta, -4 * eta},
          {1 - 4 * z, 0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (z - eta)}};
}

/// Degree-4 six-point rule on the reference triangle (Dunavant 1985); weights sum to the area 1/2.
struct QuadPoint { double xi, eta, w; };
inline constexpr double kQa = 0.44594849091596488632, kQwa = 0.22338158967801146570 / 2;
inline constexpr double kQb = 0.09157621350977074346, kQwb = 0.10995174365532186764 / 2;
constexpr int kQuadPoints = 6;
constexpr std::array<QuadPoint, kQuadPoints> kQuad{{{kQa, kQa, kQwa},
                                                    {1 - 2 * kQa, kQa, kQwa},
                                                    {kQa, 1 - 2 * kQa, kQwa},
                                                    {kQb, kQb, kQwb},
                                                    {1 - 2 * kQb, kQb, kQwb},
                                                    {kQb, 1 - 2 * kQb, kQwb}}};

/// Edges of the contour C_n in eq. (42), traversed counter-clockwise: {start vertex, mid-side node, end vertex}.
constexpr std::array<std::array<int, 3>, 3> kEdges{{{0, 3, 1}, {1, 4, 2}, {2, 5, 0}}};

/// Quadratic Lagrange basis along an edge, s in [0, 1] from start (0) through mid (1/2) to end (1).
struct EdgeShape {
  std::array<double, 3> L, dL;
};
constexpr EdgeShape edge_shape(double s) {
  return {{(1 - s) * (1 - 2 * s), 4 * s * (1 - s), s * (2 * s - 1)}, {4 * s - 3, 4 - 8 * s, 4 * s - 1}};
}

/// Three-point Gauss-Legendre rule on [0, 1] (exact to degree 5).
inline constexpr double kGl = 0.38729833462074168852;  // sqrt(3/5)/2
constexpr std::array<double, 3> kEdgeS{0.5 - kGl, 0.5, 0.5 + kGl};
constexpr std::array<double, 3> kEdgeW{5.0 / 18, 8.0 / 18, 5.0 / 18};

/// Node-sharing fractions of the four flat sub-triangles {v0,m01,m20}, {m01,v1,m12}, {m20,m12,v2}, {m01,m12,m20}.
constexpr std::array<std::array<int, 3>, 4> kSubTriangles{{{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}}};

}  // namespace immerse::tri6
